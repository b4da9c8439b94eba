"""The layering of the package, as declared once: the import-linter ``layers`` contract in
``pyproject.toml`` (application, presentation, models, front-ends, vocabulary, integrators,
helpers, the core's layouts, the bindings; top to bottom), its ``forbidden`` contracts, and the
nevers import-linter cannot state (``[tool.poinsot.nevers]``: the bindings are a compiled
module, outside its import graph).

The tests read those contracts (nothing here restates which module is in which layer) and
check them on the source with an AST walk that needs nothing installed:

* every module of the package belongs to a layer;
* no module imports a layer above its own, nor an independent sibling (``|``) of its layer;
* no module imports what a ``forbidden`` contract or a never forbids it;
* the only import by name at run time is the display registry's backend, the presentation;
* the layouts (``poinsot.layout``) import the standard library, NumPy and the bindings only;
* ``import poinsot`` exposes the library only.

:func:`test_import_linter_contracts` runs ``lint-imports`` on the same contracts when
import-linter is installed.
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

import poinsot

PACKAGE = Path(poinsot.__file__).parent
ROOT = PACKAGE.parent.parent
PYPROJECT = ROOT / "pyproject.toml"
LAYOUT = PACKAGE / "layout.py"
ALLOWED_IN_LAYOUT = {"numpy", "__future__", "typing"}

pytestmark = pytest.mark.skipif(
    not PYPROJECT.exists(), reason="the contract lives in the checkout's pyproject.toml"
)


@dataclass(frozen=True)
class Layer:
    index: int  # 0 is the top
    modules: frozenset[str]  # names under the container: "app", "viz", "bodies", ...
    independent: bool  # siblings separated by "|": they may not import each other
    optional: frozenset[str]  # declared "(name)": need not exist as Python source


def _parse_layer(index: int, raw: str) -> Layer:
    """One entry of ``layers``, with import-linter's syntax: ``a | b`` independent siblings,
    ``a : b`` siblings that may import each other, ``(a)`` optional."""
    has_pipe, has_colon = "|" in raw, ":" in raw
    assert not (has_pipe and has_colon), f"layer {raw!r} mixes '|' and ':'"
    parts = [p.strip() for p in raw.split(":" if has_colon else "|")]
    names, optional = set(), set()
    for part in parts:
        assert part, f"empty name in layer {raw!r}"
        if part.startswith("(") and part.endswith(")"):
            part = part[1:-1].strip()
            optional.add(part)
        names.add(part)
    return Layer(index, frozenset(names), not has_colon, frozenset(optional))


def _contract():
    """``(container, [Layer, ...])`` from the one ``layers`` contract in pyproject.toml."""
    config = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["tool"]["importlinter"]
    contracts = [c for c in config["contracts"] if c["type"] == "layers"]
    assert len(contracts) == 1, "pyproject.toml declares exactly one `layers` contract"
    contract = contracts[0]
    assert contract.get("containers") == [config["root_package"]] == ["poinsot"]
    assert contract.get("exhaustive") is True
    return "poinsot", [_parse_layer(i, raw) for i, raw in enumerate(contract["layers"])]


CONTAINER, LAYERS = _contract()
LAYER_OF = {name: layer for layer in LAYERS for name in layer.modules}


@dataclass(frozen=True)
class Never:
    name: str
    sources: frozenset[str]  # children of the container: "app", "viz", ...
    forbidden: frozenset[str]
    ignored: frozenset[tuple[str, str]]  # (importer, imported), full dotted names


def _nevers() -> list[Never]:
    """The ``forbidden`` contracts of import-linter and ``[tool.poinsot.nevers]``."""
    config = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))
    out = []
    for c in config["tool"]["importlinter"]["contracts"]:
        if c["type"] != "forbidden":
            continue
        strip = lambda names: frozenset(n.split(".", 1)[1] for n in names)  # noqa: E731
        ignored = frozenset(
            tuple(part.strip() for part in rule.split("->")) for rule in c.get("ignore_imports", [])
        )
        out.append(Never(c["name"], strip(c["source_modules"]), strip(c["forbidden_modules"]),
                         ignored))  # fmt: skip
    for name, rule in config["tool"]["poinsot"]["nevers"].items():
        sources = set(rule["source"])
        if "*" in sources:  # every child of the container, less those excepted
            sources = (sources - {"*"}) | set(LAYER_OF)
        sources -= set(rule.get("except", ()))
        out.append(Never(name, frozenset(sources), frozenset(rule["forbidden"]), frozenset()))
    return out


NEVERS = _nevers()


def _top(name: str) -> str | None:
    """The child of the container that ``name`` (a dotted module name) lies in, or None for the
    container itself or a module outside it."""
    parts = name.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == CONTAINER else None


def _module_name(path: Path, package: Path = PACKAGE) -> str:
    parts = path.relative_to(package.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, package: Path = PACKAGE):
    """``(absolute module name, line)`` of every import in ``path``: relative ones resolved,
    and ``from module import name`` read also as an import of ``module.name`` (which may be a
    submodule)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    here = ".".join(path.relative_to(package.parent).with_suffix("").parts[:-1])
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here.split(".")
                base = base[: len(base) - node.level + 1]
                module = ".".join([*base, node.module] if node.module else base)
            else:
                module = node.module or ""
            yield module, node.lineno
            yield from ((f"{module}.{a.name}", node.lineno) for a in node.names)


def _children(package: Path = PACKAGE):
    """The children of the container: its modules and subpackages, by name."""
    names = set()
    for path in package.iterdir():
        if path.name.startswith((".", "__pycache__")) or path.name == "__init__.py":
            continue
        if path.is_dir():
            if (path / "__init__.py").exists():
                names.add(path.name)
        elif path.suffix == ".py":
            names.add(path.stem)
        elif path.suffix in (".so", ".pyd"):
            names.add(path.name.split(".")[0])  # the compiled bindings
    return names


def _upward_imports(package: Path = PACKAGE) -> list[str]:
    """Every import in the source under ``package`` of a layer above the importer's own, or of
    an independent sibling in its layer."""
    found = []
    for path in sorted(package.rglob("*.py")):
        own = _top(_module_name(path, package))
        if own is None:  # the container's __init__: test_import_poinsot_exposes_the_library
            continue
        layer = LAYER_OF[own]
        for module, line in _imports(path, package):
            target = _top(module)
            if target is None or target == own or target not in LAYER_OF:
                continue  # outside, the container itself, or a name imported from a module
            other = LAYER_OF[target]
            where = f"{path.relative_to(package)}:{line} imports {module}"
            if other.index < layer.index:
                found.append(f"{where}: {own} (layer {layer.index}) may not import {target}, "
                             f"in layer {other.index} above it")  # fmt: skip
            elif other is layer and layer.independent:
                found.append(f"{where}: {own} and {target} are independent siblings ('|')")
    return found


def _forbidden_imports(package: Path = PACKAGE, nevers=NEVERS) -> list[str]:
    """Every import in the source under ``package`` that a never forbids."""
    found = []
    for path in sorted(package.rglob("*.py")):
        importer = _module_name(path, package)
        own = _top(importer)
        for never in nevers:
            if own not in never.sources:
                continue
            for module, line in _imports(path, package):
                target = _top(module)
                if target not in never.forbidden:
                    continue
                real = ".".join(module.split(".")[:2]) if target == "_core" else module
                if any(importer == a and real.startswith(b) for a, b in never.ignored):
                    continue
                found.append(f"{path.relative_to(package)}:{line} imports {module}: "
                             f"{never.name}")  # fmt: skip
    return found


def test_no_module_imports_what_a_never_forbids():
    found = _forbidden_imports()
    assert not found, "\n".join(found)


def test_the_nevers_catch_the_breaks_they_name(tmp_path):
    """Each never, on a small tree: the application importing the bindings or the
    integrators, and the presentation importing the bindings, are caught."""
    package = tmp_path / CONTAINER
    for sub in ("app", "viz", "integrate"):
        (package / sub).mkdir(parents=True)
        (package / sub / "__init__.py").write_text("")
    (package / "__init__.py").write_text("")
    (package / "app" / "runs.py").write_text("from .. import _core\nfrom ..integrate import x\n")
    (package / "viz" / "report.py").write_text("from .._core import equivalent_box\n")
    found = "\n".join(_forbidden_imports(package))
    assert "app/runs.py:1 imports poinsot._core: app or viz -> the bindings" in found
    assert "app/runs.py:2 imports poinsot.integrate.x: Never: app -> the integrators" in found
    assert "viz/report.py:1 imports poinsot._core.equivalent_box" in found


def test_the_library_reaches_the_bindings_only_through_their_facades(tmp_path):
    """The never that keeps a binding's name in one place is not vacuous: a library module
    importing ``poinsot._core`` (as a module, or a name from it) is caught, and a facade is
    not."""
    package = tmp_path / CONTAINER
    (package / "_bindings").mkdir(parents=True)
    for path in (package / "__init__.py", package / "_bindings" / "__init__.py"):
        path.write_text("")
    (package / "bodies.py").write_text("from . import _core\nfrom ._core import box_inertia\n")
    (package / "_bindings" / "inertia.py").write_text("from .._core import box_inertia\n")
    found = "\n".join(_forbidden_imports(package))
    never = "the library -> the bindings, past their facades"
    assert f"bodies.py:1 imports poinsot._core: {never}" in found
    assert f"bodies.py:2 imports poinsot._core.box_inertia: {never}" in found
    assert "_bindings" not in found


def _facade_names() -> dict[str, list[str]]:
    """``{facade module: the bindings it names}``: every ``from .._core import ...`` of the
    ``_bindings`` modules and every ``_core.NAME`` that ``layout.py`` reads."""
    names = {}
    for path in sorted((PACKAGE / "_bindings").glob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        names[f"_bindings.{path.stem}"] = [
            alias.name
            for node in ast.walk(tree)
            if isinstance(node, ast.ImportFrom) and node.module == "_core"
            for alias in node.names
        ]
    tree = ast.parse(LAYOUT.read_text(encoding="utf-8"))
    names["layout"] = sorted(
        {
            node.attr
            for node in ast.walk(tree)
            if isinstance(node, ast.Attribute) and getattr(node.value, "id", "") == "_core"
        }
    )
    return names


def test_every_binding_has_exactly_one_facade():
    """The facades partition the bindings by concept: each name of ``poinsot._core`` is named
    by exactly one facade (so a new binding must be given a concept), and each facade names
    only bindings that exist."""
    from poinsot import _core

    bindings = {name for name in dir(_core) if not name.startswith("__")}
    owners: dict[str, list[str]] = {}
    for facade, names in _facade_names().items():
        for name in names:
            assert name in bindings, f"{facade} names {name}, which poinsot._core lacks"
            owners.setdefault(name, []).append(facade)
    twice = {name: where for name, where in owners.items() if len(where) > 1}
    assert not twice, f"named by two facades: {twice}"
    assert not sorted(bindings - set(owners)), "bindings with no facade (give each a concept)"


def test_the_facades_hold_no_code():
    """A facade module is thin: a docstring, the import of its bindings, and ``__all__``,
    which lists exactly what it imports."""
    for path in sorted((PACKAGE / "_bindings").glob("*.py")):
        body = ast.parse(path.read_text(encoding="utf-8")).body
        kinds = [type(node).__name__ for node in body]
        if path.stem == "__init__":
            assert kinds == ["Expr"], f"{path.name}: {kinds}"
            continue
        assert kinds == ["Expr", "ImportFrom", "Assign"], f"{path.name}: {kinds}"
        imported = [alias.name for alias in body[1].names]
        listed = ast.literal_eval(body[2].value)
        assert sorted(listed) == sorted(set(imported)), f"{path.name}: __all__"


def test_the_only_import_by_name_is_the_display_backend():
    """``importlib.import_module`` (or ``__import__``) hides an arrow from every import graph:
    the package uses it twice, each time for a declared target: the container's lazy map of
    its public names (``_LAZY``, which :func:`test_import_poinsot_exposes_the_library`
    holds to the library), and the display registry's backend, a module of the presentation
    loaded on the first display (as pandas finds its plotting backend)."""
    calls = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call):
                f = node.func
                name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
                if name in ("import_module", "__import__"):
                    calls.append(path.relative_to(PACKAGE).as_posix())
    assert calls == ["__init__.py", "display.py"], calls
    from poinsot import display

    assert _top(display.backend) == "viz" and LAYER_OF["viz"].index < LAYER_OF["display"].index


def test_the_contract_declares_each_module_once():
    declared = [name for layer in LAYERS for name in layer.modules]
    assert len(declared) == len(set(declared)), f"declared twice: {declared}"


def test_every_module_belongs_to_a_layer():
    children = _children()
    undeclared = sorted(children - set(LAYER_OF))
    assert not undeclared, (
        f"{undeclared}: add them to a layer of the `layers` contract in pyproject.toml"
    )
    missing = sorted(
        name for name in set(LAYER_OF) - children if name not in LAYER_OF[name].optional
    )
    assert not missing, f"the contract names modules that do not exist: {missing}"


def test_no_module_imports_a_layer_above_its_own():
    found = _upward_imports()
    assert not found, "\n".join(found)


def test_the_check_catches_an_upward_import_and_a_sibling_import(tmp_path):
    """The walk is not vacuous: on a small tree laid out as the contract says, a module of the
    lowest layer importing the top layer is caught, and so is an independent sibling."""
    top, bottom = LAYERS[0], LAYERS[-1]
    package = tmp_path / CONTAINER
    package.mkdir()
    (package / "__init__.py").write_text("")
    high, low = sorted(top.modules)[0], sorted(bottom.modules)[0]
    (package / f"{high}.py").write_text("")
    (package / f"{low}.py").write_text(f"from . import {high}\n")
    assert any(f"may not import {high}" in f for f in _upward_imports(package))
    independent = next(
        (layer for layer in LAYERS if layer.independent and len(layer.modules) > 1), None
    )
    if independent is None:  # the contract declares no independent siblings today
        return
    a, b = sorted(independent.modules)[:2]
    (package / f"{low}.py").write_text("")
    (package / f"{a}.py").write_text(f"from .{b} import x\n")
    (package / f"{b}.py").write_text("")
    assert any("independent siblings" in f for f in _upward_imports(package))


def test_import_poinsot_exposes_the_library():
    """The container's ``__init__`` (its type-checking names and lazy map included) names only
    the library and what lies below it, never the presentation or the application."""
    library = LAYER_OF["simulation"]
    path = PACKAGE / "__init__.py"
    named = {module for module, _ in _imports(path)}
    lazy = next(
        node.value
        for node in ast.parse(path.read_text(encoding="utf-8")).body
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "_LAZY"
    )
    named |= set(ast.literal_eval(lazy).values())
    for module in named:
        target = _top(module)
        if target in LAYER_OF:
            assert LAYER_OF[target].index >= library.index, f"poinsot/__init__.py names {module}"


def test_the_layouts_import_only_numpy_the_stdlib_and_the_bindings():
    for module, line in _imports(LAYOUT):
        if module.startswith("poinsot"):
            assert module in ("poinsot", "poinsot._core"), f"layout.py:{line} imports {module}"
        else:
            assert module.split(".")[0] in ALLOWED_IN_LAYOUT, (
                f"layout.py:{line} imports {module!r}: the layouts may import only numpy, the "
                "standard library and poinsot._core"
            )


def test_numba_is_gone():
    """No module of the package imports numba (a user's own numba function is called, never
    imported by poinsot), and it is no dependency."""
    for path in sorted(PACKAGE.rglob("*.py")):
        for module, line in _imports(path):
            assert module.split(".")[0] != "numba" or path.name == "tasks.py", (
                f"{path.relative_to(PACKAGE)}:{line} imports numba"
            )
    deps = tomllib.loads(PYPROJECT.read_text())["project"]["dependencies"]
    assert not [d for d in deps if d.lower().startswith("numba")]


def test_import_linter_contracts():
    if shutil.which("lint-imports") is None:
        pytest.skip("import-linter is not installed")
    done = subprocess.run(
        [
            sys.executable,
            "-c",
            "from importlinter.cli import lint_imports_command; lint_imports_command()",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    contracts = tomllib.loads(PYPROJECT.read_text())["tool"]["importlinter"]["contracts"]
    assert f"{len(contracts)} kept, 0 broken" in done.stdout, done.stdout
