"""Layering contract: the kernel layer imports nothing from the layers above it.

Like poliastro's import-linter contract ("poliastro.core does not import astropy.units"):
``poinsot.kernels`` may import the standard library, NumPy, numba and its own modules only.
"""

from __future__ import annotations

import ast
from pathlib import Path

import poinsot

KERNELS = Path(poinsot.__file__).parent / "kernels"
ALLOWED_THIRD_PARTY = {"numpy", "numba", "math", "__future__", "typing", "functools", "importlib"}


def _imports(path: Path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, 0
        elif isinstance(node, ast.ImportFrom):
            yield node.module or "", node.level


def test_kernels_import_only_numpy_numba_and_each_other():
    files = sorted(KERNELS.glob("*.py"))
    assert files
    for path in files:
        for module, level in _imports(path):
            top = module.split(".")[0]
            if level == 1:  # from .x import — inside kernels
                continue
            assert level == 0, f"{path.name}: relative import above kernels: {'.' * level}{module}"
            assert top in ALLOWED_THIRD_PARTY or module.startswith("poinsot.kernels"), (
                f"{path.name} imports {module!r}: kernels may import only numpy, numba, the "
                "standard-library math helpers and poinsot.kernels"
            )
