"""examples/python/quickstart.py (the paper's Fig. 22) runs and writes its picture
(scripts/test installs matplotlib into its environment; elsewhere the test needs it)."""

import runpy

import pytest

from conftest import ROOT


def test_quickstart_draws_fig22(tmp_path):
    pytest.importorskip("matplotlib")
    example = runpy.run_path(str(ROOT / "examples" / "python" / "quickstart.py"))
    out = tmp_path / "fig22.png"
    example["main"](str(out), periods=40)
    assert out.stat().st_size > 10_000
