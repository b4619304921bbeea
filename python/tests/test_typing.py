"""The package type-checks: mypy on ``vibrotribo`` itself (its annotations against the stub
of the compiled module ``_vibrotribo.pyi``), every function annotated and every body checked,
so that a signature and the code calling it cannot drift apart."""

import pathlib
import subprocess
import sys

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "vibrotribo"

FLAGS = [
    "--ignore-missing-imports",  # pandas and dask ship without type information
    "--check-untyped-defs",
    "--disallow-untyped-defs",
    "--disallow-incomplete-defs",
    "--no-implicit-optional",
    "--warn-redundant-casts",
    "--no-error-summary",
]


def test_the_package_type_checks():
    pytest.importorskip("mypy")
    p = subprocess.run(
        [sys.executable, "-m", "mypy", *FLAGS, str(PACKAGE)],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 0, p.stdout + p.stderr
