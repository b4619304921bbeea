"""The example notebooks (``*.ipynb``) from their sources (``*.py`` in the "percent" cell
format: ``# %%`` starts a code cell, ``# %% [markdown]`` a text cell of ``# `` lines).

    python python/examples/build_notebooks.py

The tests check that every notebook holds the cells of its source, execute the notebooks
(nbclient) and type-check the sources (mypy), so that neither can rot."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any, Dict, List, Tuple

HERE = Path(__file__).resolve().parent
EXAMPLES = ["paper_study", "harvester_design", "bifurcation"]


def cells(text: str) -> List[Tuple[str, str]]:
    """The (kind, source) cells of a percent-format source."""
    out: List[Tuple[str, List[str]]] = []
    for line in text.splitlines():
        if line.startswith("# %%"):
            out.append(("markdown" if "[markdown]" in line else "code", []))
        elif out:
            kind, body = out[-1]
            body.append(line[2:] if kind == "markdown" and line.startswith("# ") else ("" if kind == "markdown" and line == "#" else line))
    return [(kind, "\n".join(body).strip("\n")) for kind, body in out]


def notebook(text: str) -> Dict[str, Any]:
    """A notebook (nbformat 4) of the cells of ``text``, without outputs."""
    nb_cells = []
    for j, (kind, source) in enumerate(cells(text)):
        cell: Dict[str, Any] = {"cell_type": kind, "id": f"cell-{j}", "metadata": {}, "source": source}
        if kind == "code":
            cell.update(execution_count=None, outputs=[])
        nb_cells.append(cell)
    return {
        "cells": nb_cells,
        "metadata": {
            "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
            "language_info": {"name": "python"},
        },
        "nbformat": 4,
        "nbformat_minor": 5,
    }


def main() -> int:
    for name in EXAMPLES:
        nb = notebook((HERE / f"{name}.py").read_text())
        (HERE / f"{name}.ipynb").write_text(json.dumps(nb, indent=1, ensure_ascii=False) + "\n")
        print(f"wrote {HERE / (name + '.ipynb')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
