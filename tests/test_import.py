"""`import poinsot` stays light: heavy dependencies load only when used."""

from __future__ import annotations

import subprocess
import sys

HEAVY = ("numba", "sympy", "matplotlib", "scipy", "trimesh", "plotly", "xarray", "dask")


def test_import_does_not_load_heavy_modules():
    code = f"import sys, poinsot; print(','.join(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"imported at `import poinsot`: {out.stdout.strip()}"


def test_lazy_names_resolve():
    import poinsot

    assert poinsot.RigidBody.__name__ == "RigidBody"
    assert set(poinsot.__all__) <= set(dir(poinsot))
    for name in poinsot.__all__:
        assert getattr(poinsot, name) is not None
