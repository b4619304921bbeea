"""Browser tests of `vibrotribo serve`: a real headless Chromium (Debian's `chromium`, driven by
Playwright) against the server started on a free port. The program is the one named by
VIBROTRIBO_BIN (default: target/debug/vibrotribo); screenshots go to
target/browser-artefacts/ (or BROWSER_ARTEFACTS)."""

import json
import os
import pathlib
import shutil
import subprocess
import tempfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def binary():
    return os.environ.get("VIBROTRIBO_BIN", str(ROOT / "target" / "debug" / "vibrotribo"))


def chromium():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


@pytest.fixture(scope="session")
def artefacts():
    d = pathlib.Path(os.environ.get("BROWSER_ARTEFACTS", ROOT / "target" / "browser-artefacts"))
    d.mkdir(parents=True, exist_ok=True)
    return d


@pytest.fixture(scope="session")
def browser():
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    path = chromium()
    if path is None:
        pytest.skip("no chromium on this machine (Debian: apt-get install chromium)")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=path, args=["--no-sandbox"])
        yield b
        b.close()


@pytest.fixture()
def server():
    proc = subprocess.Popen(
        [binary(), "serve", "--port", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    line = proc.stdout.readline()
    if "http://" not in line:
        proc.kill()
        raise RuntimeError(f"vibrotribo serve did not start: {line!r} {proc.stderr.read()}")
    url = "http" + line.split("http", 1)[1].split()[0]
    yield url
    proc.terminate()
    proc.wait(timeout=30)


@pytest.fixture()
def page(browser, server):
    context = browser.new_context(accept_downloads=True, viewport={"width": 1500, "height": 1200})
    pg = context.new_page()
    pg.set_default_timeout(60_000)
    pg.goto(server)
    yield pg
    context.close()


def cli_power(*args):
    """Average power (W) of `vibrotribo simulate ARGS` from its summary.json."""
    with tempfile.TemporaryDirectory() as out:
        subprocess.run([binary(), "simulate", "-q", "--out", out, *args], check=True, capture_output=True)
        return json.loads((pathlib.Path(out) / "summary.json").read_text())["average_power_w"]
