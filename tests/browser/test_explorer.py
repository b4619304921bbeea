"""The explorer page as a person uses it: the power shown is the command line's, a changed Ω
is followed, an orbit diagram region is recomputed, a clicked value loads into the run view,
the exported configuration runs to the same power."""

from conftest import cli_power


def shown_power(page):
    return float(page.get_by_test_id("power-value").get_attribute("data-value"))


def wait_power(page, previous=None):
    """Waits until the page shows a power (different from `previous`) and is idle."""
    page.wait_for_function(
        """prev => {
            const v = document.querySelector('[data-testid="power-value"]').dataset.value;
            const idle = document.querySelector('[data-testid="status"]').dataset.state === 'idle';
            return v !== '' && idle && Number(v) !== prev;
        }""",
        arg=previous,
    )
    return shown_power(page)


def test_power_shown_is_the_cli_power(page, artefacts):
    power = wait_power(page)
    assert power == cli_power(), f"page {power!r} W, CLI {cli_power()!r} W"
    for view in ("run-view", "orbit-diagram", "basins-view", "map-view"):
        assert page.get_by_test_id(view).is_visible()
    page.screenshot(path=str(artefacts / "default.png"), full_page=True)


def test_changing_omega_follows_the_cli(page, artefacts):
    before = wait_power(page)
    field = page.get_by_test_id("param-excitation.omega_ratio")
    field.fill("0.8")
    field.press("Enter")
    after = wait_power(page, before)
    assert after == cli_power("--set", "excitation.omega_ratio=0.8")
    assert "0.8" in page.url or "omega_ratio" in page.url  # the state is in the URL
    page.screenshot(path=str(artefacts / "omega-0.8.png"), full_page=True)


def test_invalid_value_shows_the_engine_error_and_runs_nothing(page):
    before = wait_power(page)
    field = page.get_by_test_id("param-oscillator.restitution")
    field.fill("1.7")
    field.press("Enter")
    error = page.get_by_test_id("error-oscillator.restitution")
    error.wait_for()
    page.wait_for_function(
        "() => document.querySelector('[data-testid=\"error-oscillator.restitution\"]').textContent.length > 0"
    )
    assert "restitution" in error.text_content()
    assert shown_power(page) == before


def orbit_points(page):
    return int(page.locator("#chart-orbit").get_attribute("data-points") or 0)


def wait_orbit_done(page):
    page.wait_for_function(
        "() => document.querySelector('[data-testid=\"orbit-diagram\"]').dataset.state === 'idle'"
        " && /values in/.test(document.querySelector('[data-testid=\"orbit-progress\"]').textContent)"
    )


def test_orbit_diagram_zoom_and_click(page, artefacts):
    wait_power(page)
    page.get_by_test_id("orbit-steps").fill("24")
    page.get_by_test_id("orbit-transient").fill("40")
    page.get_by_test_id("orbit-recorded").fill("20")
    page.get_by_test_id("orbit-compute").click()
    wait_orbit_done(page)
    assert orbit_points(page) == 24
    page.screenshot(path=str(artefacts / "orbit.png"), full_page=True)
    # Drag a box over the middle: that region is computed anew (24 new values inside it).
    over = page.locator("#chart-orbit .u-over")
    over.scroll_into_view_if_needed()
    box = over.bounding_box()
    x0, x1 = box["x"] + box["width"] * 0.3, box["x"] + box["width"] * 0.6
    y0, y1 = box["y"] + 5, box["y"] + box["height"] - 5
    page.mouse.move(x0, y0)
    page.mouse.down()
    page.mouse.move((x0 + x1) / 2, (y0 + y1) / 2, steps=5)
    page.mouse.move(x1, y1, steps=5)
    page.mouse.up()
    page.wait_for_function(
        "() => Number(document.querySelector('[data-testid=\"orbit-from\"]').value) > 0.5"
    )
    wait_orbit_done(page)
    over.scroll_into_view_if_needed()
    box = over.bounding_box()
    lo = float(page.get_by_test_id("orbit-from").input_value())
    hi = float(page.get_by_test_id("orbit-to").input_value())
    assert 0.5 < lo < hi < 1.0, (lo, hi)
    assert orbit_points(page) == 24
    xs = page.evaluate("() => orbitPoints.map(p => p.x)")
    assert all(lo - 1e-12 <= x <= hi + 1e-12 for x in xs), xs
    page.screenshot(path=str(artefacts / "orbit-zoomed.png"), full_page=True)
    # Click a value: it loads into the run view, whose power is the CLI's at that value.
    before = shown_power(page)
    page.mouse.click(box["x"] + box["width"] * 0.5, box["y"] + box["height"] * 0.5)
    page.wait_for_function(
        "() => 'excitation.omega_ratio' in (JSON.parse(decodeURIComponent(location.hash.slice(1))).set || {})"
    )
    value = page.get_by_test_id("param-excitation.omega_ratio").input_value()
    assert float(value) in xs
    after = wait_power(page, before)
    assert after == cli_power("--set", f"excitation.omega_ratio={value}")
    page.screenshot(path=str(artefacts / "orbit-clicked.png"), full_page=True)


def test_exported_toml_runs_to_the_same_power(page, artefacts, tmp_path):
    before = wait_power(page)
    field = page.get_by_test_id("param-harvester.load_resistance")
    field.fill("3e6")
    field.press("Enter")
    power = wait_power(page, before)
    with page.expect_download() as download:
        page.get_by_test_id("export-toml").click()
    path = tmp_path / "exported.toml"
    download.value.save_as(path)
    assert power == cli_power(str(path))


def test_map_and_basins_paint(page, artefacts):
    wait_power(page)
    page.locator("#map-form [name=x_steps]").fill("4")
    page.locator("#map-form [name=y_steps]").fill("4")
    page.get_by_test_id("map-compute").click()
    page.wait_for_function("() => /points in/.test(document.querySelector('[data-testid=\"map-progress\"]').textContent)")
    assert page.locator("#chart-map").get_attribute("data-cells") == "16"
    page.locator("#basins-form [name=x_steps]").fill("4")
    page.locator("#basins-form [name=y_steps]").fill("4")
    page.locator("#basins-form [name=transient]").fill("60")
    page.get_by_test_id("basins-compute").click()
    page.wait_for_function(
        "() => /points in/.test(document.querySelector('[data-testid=\"basins-progress\"]').textContent)"
    )
    assert page.locator("#chart-basins").get_attribute("data-cells") == "16"
    assert "%" in page.get_by_test_id("basins-legend").text_content()
    page.screenshot(path=str(artefacts / "map-basins.png"), full_page=True)


def test_rapid_changes_show_the_latest_answer(page):
    wait_power(page)
    final = page.evaluate(
        """async () => {
            const f = document.querySelector('[data-testid="param-excitation.omega_ratio"]');
            for (let k = 0; k < 60; k++) {
                f.value = String(0.6 + 0.003 * k);
                f.dispatchEvent(new Event('change'));
                await new Promise(r => setTimeout(r, 3));
            }
            return f.value;
        }"""
    )
    expected = cli_power("--set", f"excitation.omega_ratio={final}")
    page.wait_for_function(
        """want => document.querySelector('[data-testid="status"]').dataset.state === 'idle'
            && Number(document.querySelector('[data-testid="power-value"]').dataset.value) === want""",
        arg=expected,
    )
    assert page.get_by_test_id("param-excitation.omega_ratio").input_value() == final
