"""Short text and HTML views of result objects: a line per field with its shape, never the
arrays themselves, so that a result at the end of a notebook cell prints in a few lines."""

from __future__ import annotations

import dataclasses
import html
from typing import Any, List, Tuple

import numpy as np

_WIDTH = 60


def summarize(value: Any) -> str:
    """A few words for ``value``: a number as it is, an array as its shape and dtype, a table
    as its rows and columns, a container as its length."""
    if isinstance(value, np.ndarray):
        if value.size <= 4 and value.ndim <= 1:
            return np.array2string(value, precision=6, separator=", ")
        return f"array{value.shape} {value.dtype}"
    if isinstance(value, (bool, int, np.integer)):
        return str(value)
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.6g}"
    if isinstance(value, str):
        return repr(value) if len(value) <= _WIDTH else repr(value[: _WIDTH - 3] + "...")
    if value is None:
        return "None"
    if hasattr(value, "rows") and hasattr(value, "columns"):
        return f"Table({value.rows} rows × {len(value.columns)} columns)"
    if isinstance(value, dict):
        return f"{{{len(value)} keys}}"
    if isinstance(value, (list, tuple)):
        return f"[{len(value)} items]"
    name = type(value).__name__
    return f"{name}(…)"


class Display:
    """A mixin for dataclass results: a short ``repr`` and an HTML table for notebooks."""

    def _fields(self) -> List[Tuple[str, str]]:
        out = []
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            out.append((f.name, summarize(getattr(self, f.name))))
        return out

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={v}" for k, v in self._fields())
        return f"{type(self).__name__}({inner})"

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><td style='text-align:left'><code>{html.escape(k)}</code></td>"
            f"<td style='text-align:left'>{html.escape(v)}</td></tr>"
            for k, v in self._fields()
        )
        return f"<b>{html.escape(type(self).__name__)}</b><table>{rows}</table>"
