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


def test_a_carrier_given_as_text_does_not_load_the_spline_module():
    # scipy.interpolate costs most of a second of a cold start: only a spline carrier needs it
    code = (
        "import sys; from poinsot.relative import Carrier\n"
        "Carrier(omega_e=['0.02*cos(0.3*t)', '0', '0.4*sin(0.25*t)'])\n"
        "print('scipy.interpolate' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_a_spline_carrier_is_still_recognised():
    import numpy as np
    from scipy.interpolate import CubicSpline

    from poinsot.relative.carrier import _classify

    t = np.linspace(0, 1, 5)
    assert _classify(CubicSpline(t, np.c_[t, t, t]), "omega_e") == "spline"
    assert _classify(lambda t: (0, 0, t), "omega_e") == "python"
