"""The installed package: its type stubs and py.typed marker, and stubs that match the module."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import batten
from batten import _batten

PACKAGE = Path(batten.__file__).parent
STUBS = PACKAGE / "_batten.pyi"


def stub_functions() -> dict[str, ast.FunctionDef]:
    tree = ast.parse(STUBS.read_text())
    return {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}


def stub_classes() -> dict[str, ast.ClassDef]:
    tree = ast.parse(STUBS.read_text())
    return {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}


def test_the_wheel_ships_the_stubs_and_the_typed_marker():
    assert (PACKAGE / "py.typed").is_file()
    assert STUBS.is_file()
    # The extension itself sits beside them, as batten._batten.
    assert Path(_batten.__file__).parent == PACKAGE


def test_every_public_name_of_the_module_has_a_stub_and_the_reverse():
    module = {n for n in dir(_batten) if not n.startswith("__")}
    stubbed = set(stub_functions()) | set(stub_classes())
    # Private helpers the package uses are stubbed too (the bench's timer need not be).
    assert module - {"_rust_seconds_per_call"} == stubbed
    assert set(batten.__all__) <= stubbed | {"__version__"}


def test_stub_signatures_are_the_runtime_signatures():
    for name, node in stub_functions().items():
        runtime = inspect.signature(getattr(_batten, name))
        a = node.args
        stub_params = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
        if a.kwarg:
            stub_params.append(a.kwarg.arg)
        assert list(runtime.parameters) == stub_params, name
        # Defaults, as source text (None, False), for the parameters that have one.
        defaults = dict(zip([p.arg for p in a.args][len(a.args) - len(a.defaults):], a.defaults))
        for pname, default in defaults.items():
            assert ast.literal_eval(default) == runtime.parameters[pname].default, (name, pname)
        for pname, p in runtime.parameters.items():
            if p.default is not inspect.Parameter.empty:
                assert pname in defaults, (name, pname)


def test_stub_properties_exist_on_the_classes():
    for cname, node in stub_classes().items():
        cls = getattr(_batten, cname)
        for item in node.body:
            if isinstance(item, ast.FunctionDef) and not item.name.startswith("__"):
                assert hasattr(cls, item.name), f"{cname}.{item.name}"
