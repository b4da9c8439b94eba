"""The compiled engine (generated, numba-compiled M, f, G, γ with runtime parameters) gives
the NumPy path's motion to round-off, constraints, inputs and parameter sweeps included."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import models
from poinsot.lagrange.engine import compile_system


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("POINSOT_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "engine"))


@pytest.mark.parametrize("name", ["double-pendulum", "atwood", "rolling-disk"])
def test_compiled_engine_agrees_with_numpy(name):
    mdl = models.MODELS[name]()
    t = np.linspace(0, 2, 21)
    a = mdl.simulate((0, 2), t_eval=t)
    b = mdl.simulate((0, 2), t_eval=t, engine="compiled")
    np.testing.assert_allclose(b.q, a.q, rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(b.multipliers, a.multipliers, rtol=1e-8, atol=1e-10)


def test_one_compilation_serves_a_parameter_sweep():
    mdl = models.pendulum_on_cart()
    s = mdl.symbols
    compiled = compile_system(mdl.system)
    assert [str(p) for p in compiled.parameters] == ["M", "g", "l", "m"]
    t = np.linspace(0, 2, 11)
    for mass in (0.5, 2.0, 8.0):
        params = {**mdl.params, s["M"]: mass}
        a = mdl.simulate((0, 2), t_eval=t, params=params)
        b = mdl.simulate((0, 2), t_eval=t, params=params, engine="compiled")
        np.testing.assert_allclose(b.q, a.q, rtol=1e-9, atol=1e-11)
        assert compile_system(mdl.system) is compiled  # the same compiled module
    with pytest.raises(ValueError, match="missing m"):
        compiled.parameter_vector({s["M"]: 1.0, s["g"]: 9.81, s["l"]: 1.0})


def test_compiled_engine_takes_inputs_and_refuses_unknown_engines():
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols

    from poinsot.lagrange import LagrangianSystem

    x, F = dynamicsymbols("x F")
    m, k = sp.symbols("m k", positive=True)
    spring = LagrangianSystem([x], kinetic=m * x.diff() ** 2 / 2, potential=k * x**2 / 2,
                              forces=[{x: F}])  # fmt: skip
    t = np.linspace(0, 3, 31)
    kw = {"q0": {x: 0}, "params": {"m": 2, "k": 8}, "inputs": {F: 4.0}, "t_eval": t}
    sol = spring.simulate((0, 3), engine="compiled", **kw)
    np.testing.assert_allclose(sol.q[:, 0], 0.5 * (1 - np.cos(2 * t)), atol=1e-9)
    with pytest.raises(ValueError, match="`engine` must be 'numpy' or 'compiled'"):
        spring.simulate((0, 3), engine="cython", **kw)


def test_a_new_process_loads_the_compiled_module_from_the_disk_cache(tmp_path):
    import os
    import subprocess
    import sys

    code = ("import numpy as np; from poinsot import models; m = models.atwood_machine(); "
            "s = m.simulate((0, 1), t_eval=np.linspace(0, 1, 5), engine='compiled'); "
            "print(repr(float(s.q[-1, 0])))")  # fmt: skip
    env = {**os.environ, "POINSOT_CACHE_DIR": str(tmp_path)}
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                           timeout=300) for _ in range(2)]  # fmt: skip
    for done in runs:
        assert done.returncode == 0, done.stderr[-2000:]
    assert runs[0].stdout == runs[1].stdout  # the second run loads the first one's cache
    assert list((tmp_path / "lagrange").glob("__pycache__/*.nbi"))  # numba's cache index
