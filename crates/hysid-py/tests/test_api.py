"""The package's API carries its own types: every public function and method has runtime
annotations (no hand-kept stub beside the code), the family names are the registry's, and
the compiled module's stub ``_hysid.pyi`` names the functions and arguments it has."""

import ast
import inspect
import pathlib
import typing

import hysid
import pytest

PACKAGE = pathlib.Path(hysid.__file__).parent


def _public_callables():
    for name in hysid.__all__:
        obj = getattr(hysid, name)
        if inspect.isfunction(obj):
            yield name, obj
        elif inspect.isclass(obj) and obj.__module__.startswith("hysid."):
            for attr, member in vars(obj).items():
                if attr.startswith("_") and attr != "__init__":
                    continue
                if isinstance(member, (classmethod, staticmethod)):
                    member = member.__func__
                if isinstance(member, property):
                    member = member.fget
                if inspect.isfunction(member):
                    yield f"{name}.{attr}", member


CALLABLES = dict(_public_callables())


def test_every_public_name_is_importable():
    for name in hysid.__all__:
        assert hasattr(hysid, name), name
    assert "identify_operator" in CALLABLES and "Result.report" in CALLABLES


@pytest.mark.parametrize("name", sorted(CALLABLES))
def test_annotations_resolve_at_run_time(name):
    f = CALLABLES[name]
    hints = typing.get_type_hints(f)
    params = [p for p in inspect.signature(f).parameters if p not in ("self", "cls")]
    missing = [p for p in params if p not in hints and not p.startswith("*")]
    assert not missing, f"{name}: parameters without annotation: {missing}"
    assert "return" in hints, f"{name}: no return annotation"


def test_family_literal_is_the_registry():
    registry = tuple(name for name, _ in hysid._hysid.families())
    assert typing.get_args(hysid.FamilyName) == registry
    assert hysid.FAMILIES == registry


def test_no_stub_beside_the_python_code():
    stubs = sorted(p.name for p in PACKAGE.glob("*.pyi"))
    assert stubs == ["_hysid.pyi"], stubs


def test_compiled_stub_names_the_module_functions():
    """``_hysid.pyi`` lists exactly the extension's functions, with their argument names."""
    tree = ast.parse((PACKAGE / "_hysid.pyi").read_text(encoding="utf-8"))
    stub = {
        n.name: [a.arg for a in n.args.args + n.args.kwonlyargs] for n in tree.body if isinstance(n, ast.FunctionDef)
    }
    compiled = {
        name: list(inspect.signature(f).parameters)
        for name, f in vars(hysid._hysid).items()
        if callable(f) and not inspect.isclass(f) and not name.startswith("_")
    }
    assert stub == compiled
