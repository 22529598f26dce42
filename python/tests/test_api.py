"""Every public name of the package has a docstring and a type stub (issue 35)."""

import ast
import inspect
import pathlib

import foldsynth
from foldsynth import _native

STUB = pathlib.Path(__file__).resolve().parents[1] / "foldsynth" / "_native.pyi"


def public(obj):
    return [n for n in dir(obj) if not n.startswith("_")]


def test_every_public_name_has_a_docstring():
    missing = []
    for name in foldsynth.__all__:
        if name == "__version__":
            continue
        obj = getattr(foldsynth, name)
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj):
            for member in public(obj):
                attr = inspect.getattr_static(obj, member)
                # NamedTuple fields are documented in the class's docstring.
                if isinstance(attr, (int, float, str)) or member in getattr(obj, "_fields", ()):
                    continue
                # What builtins (tuple, ValueError) give the class documents itself.
                if any(member in vars(b) for b in obj.__mro__ if b.__module__ == "builtins"):
                    continue
                if not (getattr(obj, member).__doc__ or "").strip():
                    missing.append(f"{name}.{member}")
    assert not missing, missing


def test_the_stub_names_every_native_name():
    tree = ast.parse(STUB.read_text(encoding="utf-8"))
    stubbed = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            stubbed[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        elif isinstance(node, ast.FunctionDef):
            stubbed[node.name] = set()
        elif isinstance(node, ast.AnnAssign):
            stubbed[node.target.id] = set()
    for name in public(_native) + ["__version__"]:
        assert name in stubbed, f"_native.{name} has no stub in {STUB.name}"
        obj = getattr(_native, name)
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            assert set(public(obj)) <= stubbed[name], (name, set(public(obj)) - stubbed[name])
