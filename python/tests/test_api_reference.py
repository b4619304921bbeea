"""The guide's Python API reference is what the docstrings say today
(``python python/tools/api_reference.py`` writes it, or ``VIBROTRIBO_BLESS=1`` with this
test), and every public function, class, method and property has a docstring."""

import importlib.util
import inspect
import os
import pathlib

import vibrotribo
import vibrotribo.dask

TOOL = pathlib.Path(__file__).resolve().parents[1] / "tools" / "api_reference.py"


def _tool():
    spec = importlib.util.spec_from_file_location("api_reference", TOOL)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_public_name_has_a_docstring():
    tool = _tool()
    missing = []
    for module in (vibrotribo, vibrotribo.dask):
        for name in module.__all__:
            obj = getattr(module, name)
            if not (inspect.isclass(obj) or callable(obj)):
                continue
            if not inspect.getdoc(obj):
                missing.append(f"{module.__name__}.{name}")
            if inspect.isclass(obj):
                for m in tool.public_members(obj):
                    member = vars(obj)[m]
                    if not inspect.getdoc(member):
                        missing.append(f"{module.__name__}.{name}.{m}")
    assert not missing, f"no docstring: {missing}"


def test_the_python_api_page_is_up_to_date():
    tool = _tool()
    text = tool.render()
    if os.environ.get("VIBROTRIBO_BLESS") == "1":
        tool.PAGE.write_text(text)
    current = tool.PAGE.read_text() if tool.PAGE.exists() else ""
    assert current == text, (
        f"{tool.PAGE} is not what the docstrings say: run `python python/tools/api_reference.py` "
        "(or this test with VIBROTRIBO_BLESS=1)"
    )
