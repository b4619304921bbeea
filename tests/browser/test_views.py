"""The explorer's continuation overlay and exports: the branches drawn over the orbit diagram
are `vibrotribo continue`'s, the view's CSV and the shown CLI command reproduce the view, and a
link restores it."""

import csv
import io
import pathlib
import shlex
import subprocess

from conftest import binary, cli_power
from test_explorer import orbit_points, wait_orbit_done, wait_power


def read_rows(text):
    return list(csv.reader(io.StringIO(text)))


def download_text(page, testid, tmp_path):
    with page.expect_download() as download:
        page.get_by_test_id(testid).click()
    path = tmp_path / download.value.suggested_filename
    download.value.save_as(path)
    return path.read_text()


def fill_orbit(page, param, lo, hi, steps, transient="60", recorded="16"):
    page.get_by_test_id("orbit-param").fill(param)
    page.get_by_test_id("orbit-from").fill(lo)
    page.get_by_test_id("orbit-to").fill(hi)
    page.get_by_test_id("orbit-steps").fill(steps)
    page.get_by_test_id("orbit-transient").fill(transient)
    page.get_by_test_id("orbit-recorded").fill(recorded)


def test_continuation_branches_overlay_the_orbit_diagram(page, artefacts, tmp_path):
    wait_power(page)
    fill_orbit(page, "mass_ratio", "2.6", "3.0", "16")
    page.get_by_test_id("orbit-compute").click()
    wait_orbit_done(page)
    page.get_by_test_id("orbit-branches").click()
    page.wait_for_function(
        "() => document.querySelector('[data-testid=\"branches-progress\"]').dataset.state === 'idle'"
        " && /branch/.test(document.querySelector('[data-testid=\"branches-progress\"]').textContent)"
    )
    chart = page.locator("#chart-orbit")
    assert int(chart.get_attribute("data-branch-lines")) > 0
    assert int(chart.get_attribute("data-bifurcations")) > 0
    assert orbit_points(page) == 16  # the brute-force points are still drawn under the branches
    legend = page.locator("#chart-orbit .u-legend").text_content()
    assert "stable branch" in legend and "Neimark" in legend, legend
    page.screenshot(path=str(artefacts / "orbit-branches.png"), full_page=True)
    # The drawn branch is `vibrotribo continue`'s branch.csv, cell for cell.
    shown = read_rows(download_text(page, "export-branches-csv", tmp_path))
    out = tmp_path / "continue"
    subprocess.run(
        [binary(), "continue", "--param", "mass_ratio", "--from", "2.6", "--to", "3.0", "--out", str(out)],
        check=True, capture_output=True,
    )
    assert shown == read_rows((out / "branch.csv").read_text())
    # The link keeps the overlay: a new page draws it again.
    assert "branches" in page.url
    other = page.context.new_page()
    other.goto(page.url)
    other.wait_for_function(
        "() => Number(document.querySelector('#chart-orbit').dataset.branchLines || 0) > 0"
    )
    other.close()


def test_csv_command_and_link_reproduce_the_view(page, artefacts, tmp_path):
    before = wait_power(page)
    field = page.get_by_test_id("param-excitation.omega_ratio")
    field.fill("0.8")
    field.press("Enter")
    power = wait_power(page, before)
    fill_orbit(page, "excitation.omega_ratio", "0.6", "0.9", "5", "30", "12")
    page.get_by_test_id("orbit-compute").click()
    wait_orbit_done(page)
    # The run's samples as CSV: the power column is V·I of the run shown.
    run_rows = read_rows(download_text(page, "export-csv", tmp_path))
    assert run_rows[0][0] == "time_s" and "p_w" in run_rows[0] and len(run_rows) > 100
    # The command: each part run as shown reproduces its view.
    command = page.get_by_test_id("export-command").input_value()
    parts = [shlex.split(p) for p in command.split(" && ")]
    assert [p[:2] for p in parts] == [["vibrotribo", "simulate"], ["vibrotribo", "sweep"]], command
    assert "excitation.omega_ratio=0.8" in parts[0]
    for p in parts:
        subprocess.run([binary()] + p[1:] + ["-q"], cwd=tmp_path, check=True, capture_output=True)
    import json

    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["average_power_w"] == power == cli_power("--set", "excitation.omega_ratio=0.8")
    # The orbit diagram's CSV is the sweep's orbit.csv: the same x1 at t = nT, value by value.
    shown = read_rows(download_text(page, "export-orbit-csv", tmp_path))
    assert shown[0][:3] == ["excitation.omega_ratio", "period_index", "x1_m"], shown[0]
    cli = read_rows((tmp_path / "sweep" / "orbit.csv").read_text())
    h = cli[0]
    cli_pairs = [(float(r[h.index("param")]), float(r[h.index("x1_m")])) for r in cli[1:]]
    shown_pairs = [(float(r[0]), float(r[2])) for r in shown[1:]]
    assert shown_pairs == cli_pairs
    page.screenshot(path=str(artefacts / "exports.png"), full_page=True)
    # The link restores the view: the value, the orbit diagram's form and its points.
    other = page.context.new_page()
    other.goto(page.url)
    wait_power(other)
    assert other.get_by_test_id("param-excitation.omega_ratio").input_value() == "0.8"
    assert float(other.get_by_test_id("power-value").get_attribute("data-value")) == power
    assert other.get_by_test_id("orbit-steps").input_value() == "5"
    wait_orbit_done(other)
    assert orbit_points(other) == 5
    assert other.get_by_test_id("export-command").input_value() == command
    other.close()


def test_basins_are_coloured_by_the_classification(page, artefacts, tmp_path):
    wait_power(page)
    page.locator("#basins-form [name=x_steps]").fill("4")
    page.locator("#basins-form [name=y_steps]").fill("3")
    page.get_by_test_id("basins-compute").click()
    page.wait_for_function(
        "() => document.querySelector('[data-testid=\"basins-legend\"]').dataset.attractors > 0"
    )
    shown = read_rows(download_text(page, "export-basins-csv", tmp_path))
    command = page.get_by_test_id("export-command").input_value()
    basins = next(shlex.split(p) for p in command.split(" && ") if " basins " in p)
    subprocess.run([binary()] + basins[1:] + ["-q"], cwd=tmp_path, check=True, capture_output=True)
    cli = read_rows((tmp_path / "basins" / "basins.csv").read_text())
    assert [r[-1] for r in shown[1:]] == [r[2] for r in cli[1:]]
    assert [(float(r[0]), float(r[1])) for r in shown[1:]] == [(float(r[0]), float(r[1])) for r in cli[1:]]
    page.screenshot(path=str(artefacts / "basins.png"), full_page=True)
