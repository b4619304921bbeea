"""The example notebooks (python/examples/*.ipynb) hold the cells of their sources
(python/examples/*.py), run to the end in a fresh kernel (nbclient), and their sources
type-check (mypy), so that neither the examples nor the API they show can rot."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ROOT = EXAMPLES.parents[1]
sys.path.insert(0, str(EXAMPLES))
from build_notebooks import EXAMPLES as NAMES, notebook  # noqa: E402


@pytest.mark.parametrize("name", NAMES)
def test_notebook_holds_its_source(name):
    committed = json.loads((EXAMPLES / f"{name}.ipynb").read_text())
    built = notebook((EXAMPLES / f"{name}.py").read_text())
    assert [c["source"] for c in committed["cells"]] == [c["source"] for c in built["cells"]], (
        f"{name}.ipynb differs from {name}.py: run python python/examples/build_notebooks.py"
    )


@pytest.mark.parametrize("name", NAMES)
def test_notebook_runs(name):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    nb = nbformat.reads((EXAMPLES / f"{name}.ipynb").read_text(), as_version=4)
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(ROOT)}})
    client.execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    assert any(o.get("output_type") == "stream" for o in outputs), f"{name}: printed nothing"


def test_examples_type_check():
    pytest.importorskip("mypy")
    sources = [str(EXAMPLES / f"{n}.py") for n in NAMES]
    p = subprocess.run(
        [sys.executable, "-m", "mypy", "--ignore-missing-imports", "--no-error-summary", *sources],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 0, p.stdout + p.stderr
