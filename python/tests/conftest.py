"""Shared fixtures: the repository, its configuration files, and the `vibrotribo` program
the Python results are compared with (VIBROTRIBO_BIN, set by scripts/test; otherwise built
with cargo)."""

import csv
import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
CONFIGS = ROOT / "configs"


@pytest.fixture(scope="session")
def cli() -> Path:
    path = os.environ.get("VIBROTRIBO_BIN")
    if path:
        return Path(path)
    subprocess.run(
        ["cargo", "build", "--release", "--quiet", "-p", "vibrotribo-cli"], cwd=ROOT, check=True
    )
    return ROOT / "target" / "release" / "vibrotribo"


def run_cli(cli: Path, *args: str) -> None:
    """Runs the program; fails the test with its stderr if it fails."""
    p = subprocess.run([str(cli), *map(str, args), "--quiet"], capture_output=True, text=True)
    assert p.returncode == 0, f"vibrotribo {' '.join(map(str, args))} failed:\n{p.stderr}"


def read_csv(path: Path):
    """A CSV file written by the program as (header, {column: list of text cells})."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return header, {name: [r[j] for r in body] for j, name in enumerate(header)}


def numbers(cells) -> np.ndarray:
    """Cells as float64 (empty cells NaN). The program prints floats in Rust's shortest
    round-trip form, so parsing gives back the exact bits."""
    return np.array([float(c) if c != "" else np.nan for c in cells], dtype=np.float64)


def assert_bits(got: np.ndarray, expected: np.ndarray, what: str) -> None:
    """Equal shapes and bit-identical float64 values (NaN where NaN)."""
    got = np.asarray(got, dtype=np.float64)
    assert got.shape == expected.shape, f"{what}: shape {got.shape} != {expected.shape}"
    same = got.view(np.uint64) == expected.view(np.uint64)
    if not same.all():
        j = int(np.argmin(same))
        raise AssertionError(
            f"{what}: {int((~same).sum())} values differ; first at {j}: {got[j]!r} != {expected[j]!r}"
        )


def read_json(path: Path):
    return json.loads(Path(path).read_text())


def compare_tables(result_tables, directory, files):
    """Each table equals its CSV file: the same columns, text and flags equal, integers equal
    (an empty cell is -1), floats bit for bit (an empty cell is NaN)."""
    for table, file in zip(result_tables, files):
        header, cols = read_csv(directory / file)
        assert table.columns == header, f"{file}: {table.columns} != {header}"
        for name in header:
            got = table[name]
            cells = cols[name]
            if got.dtype == np.bool_:
                assert list(got) == [c == "true" for c in cells], f"{file} {name}"
            elif got.dtype.kind == "U":
                assert list(got) == cells, f"{file} {name}"
            elif got.dtype == np.int64:
                # Failed points leave the file's cell empty; the table holds -1.
                expected = [int(c) if c != "" else -1 for c in cells]
                assert got.tolist() == expected, f"{file} {name}"
            else:
                assert got.dtype == np.float64
                assert_bits(got, numbers(cells), f"{file} {name}")
