"""The compiled module's stub, src/poinsot/_core.pyi, names what the built module has: every
public name of `poinsot._core` (its classes' members too) is in the stub, and every name the
stub defines is in the module, as the same kind of thing (a class, a function, a value). The
signatures and types are mypy's stubtest's to check (.ci/run); this test needs no mypy, so a
name added to the bindings without its stub entry fails the test suite too."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import pytest

from poinsot import _core

STUB = Path(_core.__file__).with_name("_core.pyi")


def _is_dunder(name: str) -> bool:
    return name.startswith("__") and name.endswith("__")


def _stub_only(name: str) -> bool:
    """The stub's own helpers (type aliases such as `_F64`), which the module does not have."""
    return name.startswith("_") and not _is_dunder(name)


def _defined(body: list[ast.stmt]) -> dict[str, ast.stmt]:
    """The names a stub's block defines (functions, classes, annotated or assigned names), by
    name; blocks under `if` (version checks) are read too. Imports define nothing here."""
    names: dict[str, ast.stmt] = {}
    for node in body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names[node.name] = node
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names[node.target.id] = node
        elif isinstance(node, ast.Assign):
            for target in node.targets:
                if isinstance(target, ast.Name):
                    names[target.id] = node
        elif isinstance(node, ast.If):
            names.update(_defined(node.body))
            names.update(_defined(node.orelse))
    return names


@pytest.fixture(scope="module")
def stub() -> ast.Module:
    assert STUB.is_file(), f"no stub of the compiled module at {STUB}"
    return ast.parse(STUB.read_text(encoding="utf-8"), filename=str(STUB))


def _public(names) -> set[str]:
    return {n for n in names if not _is_dunder(n)}


def test_every_name_of_the_module_is_in_the_stub(stub):
    missing = _public(dir(_core)) - set(_defined(stub.body))
    assert not missing, f"names of poinsot._core missing from {STUB.name}: {sorted(missing)}"


def test_every_name_of_the_stub_is_in_the_module(stub):
    extra = {n for n in _defined(stub.body) if not _stub_only(n) and not hasattr(_core, n)}
    assert not extra, f"names in {STUB.name} that poinsot._core lacks: {sorted(extra)}"


def test_the_stub_lists_the_module_s_all(stub):
    node = _defined(stub.body).get("__all__")
    assert node is not None, f"{STUB.name} has no __all__ (the module has one)"
    value = node.value if isinstance(node, ast.Assign | ast.AnnAssign) else None
    assert value is not None, f"{STUB.name}'s __all__ has no value"
    listed = set(ast.literal_eval(value))
    runtime = set(_core.__all__)
    assert listed == runtime, (
        f"__all__: only in the module {sorted(runtime - listed)}, "
        f"only in the stub {sorted(listed - runtime)}"
    )


def test_each_name_is_the_same_kind_of_thing(stub):
    wrong = []
    for name, node in _defined(stub.body).items():
        if _stub_only(name) or not hasattr(_core, name):
            continue
        value = getattr(_core, name)
        if isinstance(node, ast.ClassDef):
            ok = inspect.isclass(value)
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            ok = callable(value) and not inspect.isclass(value)
        else:
            ok = not callable(value)
        if not ok:
            wrong.append(f"{name}: {type(node).__name__} in the stub, {type(value).__name__}")
    assert not wrong, f"{STUB.name} and poinsot._core disagree: {wrong}"


def test_the_classes_members_match(stub):
    classes = {
        n: c
        for n, c in _defined(stub.body).items()
        if isinstance(c, ast.ClassDef) and not _stub_only(n)
    }
    assert classes, f"{STUB.name} defines no class"
    problems = []
    for name, node in classes.items():
        runtime = _public(vars(getattr(_core, name)))
        stubbed = {n for n in _public(_defined(node.body)) if not _stub_only(n)}
        if runtime - stubbed:
            problems.append(f"{name} lacks {sorted(runtime - stubbed)} in the stub")
        if stubbed - runtime:
            problems.append(f"{name} has {sorted(stubbed - runtime)} only in the stub")
    assert not problems, "; ".join(problems)
