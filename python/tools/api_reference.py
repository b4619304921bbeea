"""Writes the guide's Python API reference (docs/guide/src/reference/python-api.md) from the
docstrings and signatures of the installed ``vibrotribo`` package: every name in
``vibrotribo.__all__`` and in ``vibrotribo.dask.__all__``, classes with their public methods
and properties.

    python python/tools/api_reference.py          # writes the page
    python python/tools/api_reference.py --check  # exit status 1 if the page is out of date

``python/tests/test_api_reference.py`` fails when the page is not what this writes."""

from __future__ import annotations

import inspect
import pathlib
import re
import sys
from typing import Any, List

PAGE = pathlib.Path(__file__).resolve().parents[2] / "docs" / "guide" / "src" / "reference" / "python-api.md"

HEADER = """# Python API

Generated from the docstrings of the `vibrotribo` package by `python/tools/api_reference.py`
(a test checks it is up to date). Units are SI unless a name or docstring says otherwise:
arrays of positions in m, velocities in m/s, times in s, power in W, energy in J. How to use
the package in notebooks: [Use vibrotribo from Python and notebooks](../how-to/notebooks.md).
"""


def markdown(doc: str) -> str:
    """A reStructuredText docstring as Markdown: roles and double back-quotes become code."""
    doc = re.sub(r":(?:func|class|meth|attr|mod|data|exc):`~?([^`]+)`", r"`\1`", doc)
    doc = doc.replace("``", "`")
    # A paragraph ending in "::" introduces an indented literal block: Markdown's is the same.
    doc = re.sub(r"::\n", ":\n", doc)
    return doc.strip()


def docstring(obj: Any) -> str:
    doc = inspect.getdoc(obj)
    return markdown(doc) if doc else ""


def signature(name: str, obj: Any) -> str:
    try:
        sig = str(inspect.signature(obj))
    except (TypeError, ValueError):
        sig = "(...)"
    return f"{name}{sig}"


def public_members(cls: type) -> List[str]:
    """Public methods and properties defined by the class itself, in source order."""
    names = []
    for name, member in vars(cls).items():
        if name.startswith("_") and name != "__init__":
            continue
        if name == "__init__":
            continue
        if isinstance(member, (property, staticmethod, classmethod)) or inspect.isfunction(member):
            names.append(name)
    return names


def entry(module: str, name: str, obj: Any) -> List[str]:
    out: List[str] = []
    if inspect.isclass(obj):
        kind = "exception" if issubclass(obj, BaseException) else "class"
        out += [f"## `{module}.{name}` ({kind})", ""]
        if kind == "class":
            out += ["```text", signature(name, obj), "```", ""]
        out += [docstring(obj), ""]
        for m in public_members(obj):
            member = vars(obj)[m]
            if isinstance(member, property):
                out += [f"### `{name}.{m}` (property)", "", docstring(member), ""]
            else:
                func = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
                out += [f"### `{name}.{m}`", "", "```text", signature(m, func), "```", "", docstring(func), ""]
    elif callable(obj):
        out += [f"## `{module}.{name}`", "", "```text", signature(name, obj), "```", "", docstring(obj), ""]
    return out


def render() -> str:
    import vibrotribo
    import vibrotribo.dask

    lines = [HEADER]
    for module in (vibrotribo, vibrotribo.dask):
        lines += [f"# `{module.__name__}`", "", docstring(module), ""]
        for name in module.__all__:
            lines += entry(module.__name__, name, getattr(module, name))
    text = "\n".join(lines)
    text = re.sub(r"\n{3,}", "\n\n", text)
    return text.rstrip() + "\n"


def main() -> int:
    text = render()
    if "--check" in sys.argv[1:]:
        current = PAGE.read_text() if PAGE.exists() else ""
        if current != text:
            print(f"{PAGE} is out of date: run python python/tools/api_reference.py", file=sys.stderr)
            return 1
        return 0
    PAGE.write_text(text)
    print(f"wrote {PAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
