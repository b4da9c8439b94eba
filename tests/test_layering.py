"""Layering contracts (like poliastro's import-linter contract "core does not import astropy").

* the kernel layer (``poinsot.kernels``) imports the standard library, NumPy, numba and its own
  modules only;
* the library (bodies, forces, dynamics, integrators, torque-free and Lagrangian analysis)
  never imports the presentation (``plotting``, ``report``) or the application (``scenario``,
  ``job``, ``cli``), and the presentation never imports the application.

The AST check below needs nothing installed; the same contracts are declared for import-linter
in ``pyproject.toml`` and run by :func:`test_import_linter_contracts` when it is installed.
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import poinsot

PACKAGE = Path(poinsot.__file__).parent
KERNELS = PACKAGE / "kernels"
ALLOWED_IN_KERNELS = {
    "numpy",
    "numba",
    "llvmlite",  # numba's own code generator: calls by address (kernels/native.py)
    "math",
    "__future__",
    "typing",
    "functools",
    "importlib",
    "collections",
    "hashlib",
    "inspect",
    "types",
    "pathlib",
    "warnings",
}
LIBRARY = {
    "bodies",
    "mesh",
    "rotation",
    "forces",
    "dynamics",
    "integrate",
    "trajectory",
    "simulation",
    "torquefree",
    "ensemble",
    "relative",
    "elliptic",
    "lagrange",
    "models",
    "_validation",
    "_io",
    "layout",
    "conservation",
    "expressions",
}
PRESENTATION = {"plotting", "report", "numbers"}
APPLICATION = {"scenario", "scenario_reference", "job", "cli", "__main__"}


def _imports(path: Path):
    """``(absolute module name, line)`` of every import in ``path`` (relative ones resolved)."""
    tree = ast.parse(path.read_text())
    package = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts[:-1])
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                module = ".".join([*base, node.module] if node.module else base)
                names = [f"{module}.{a.name}" for a in node.names] if not node.module else []
                yield module, node.lineno
                yield from ((n, node.lineno) for n in names)
            else:
                yield node.module or "", node.lineno


def _top_of(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == "poinsot" else None


def _files(names):
    for name in sorted(names):
        target = PACKAGE / name
        yield from sorted(target.rglob("*.py")) if target.is_dir() else [target.with_suffix(".py")]


def test_kernels_import_only_numpy_numba_stdlib_and_each_other():
    files = sorted(KERNELS.glob("*.py"))
    assert files
    for path in files:
        for module, line in _imports(path):
            if module.startswith("poinsot."):
                assert module.startswith("poinsot.kernels"), f"{path.name}:{line} imports {module}"
            else:
                assert module.split(".")[0] in ALLOWED_IN_KERNELS, (
                    f"{path.name}:{line} imports {module!r}: kernels may import only numpy, "
                    "numba, the standard library and poinsot.kernels"
                )


@pytest.mark.parametrize(
    ("sources", "forbidden"),
    [(LIBRARY, PRESENTATION | APPLICATION), (PRESENTATION, APPLICATION)],
    ids=["library", "presentation"],
)
def test_lower_layers_never_import_higher_ones(sources, forbidden):
    for path in _files(sources):
        if not path.exists():
            continue
        for module, line in _imports(path):
            assert _top_of(module) not in forbidden, (
                f"{path.relative_to(PACKAGE)}:{line} imports {module}: the "
                f"{'library' if sources is LIBRARY else 'presentation'} must not import "
                f"{sorted(forbidden)}"
            )


def test_every_module_belongs_to_a_layer():
    known = LIBRARY | PRESENTATION | APPLICATION | {"kernels", "__init__", "scenarios", "_core"}
    for path in PACKAGE.iterdir():
        if path.name.startswith(".") or path.name in ("py.typed", "__pycache__"):
            continue
        assert path.name.split(".")[0] in known, (
            f"{path.name}: add it to a layer in tests/test_layering.py"
        )


def test_import_linter_contracts():
    exe = shutil.which("lint-imports")
    if exe is None:
        pytest.skip("import-linter is not installed")
    root = PACKAGE.parent.parent
    if not (root / "pyproject.toml").exists():  # pragma: no cover - installed, not a checkout
        pytest.skip("the contracts live in the checkout's pyproject.toml")
    done = subprocess.run(
        [
            sys.executable,
            "-c",
            "from importlinter.cli import lint_imports_command; lint_imports_command()",
        ],
        cwd=root,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stdout + done.stderr
