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


MODELS = ["double-pendulum", "atwood", "rolling-disk", "rolling-coin", "pendulum-cartesian",
          "bead-on-hoop", "knife-edge", "heavy-top-euler"]  # fmt: skip


@pytest.mark.parametrize("name", MODELS)
def test_compiled_rhs_equals_the_lambdify_path_to_round_off(name):
    """One evaluation of ẏ (Baumgarte terms included, at states off the constraints) and of the
    physical (q̈, λ): the generated module against SymPy's lambdify with NumPy's solve."""
    from poinsot.lagrange.numeric import _ODE, _numeric

    mdl = models.MODELS[name]()
    system = mdl.system
    engine = compile_system(system)
    num = _numeric(system, mdl.params)
    p = engine.parameter_vector(mdl.params)
    ode = _ODE(num, "baumgarte", (3.0, 7.0))
    rng = np.random.default_rng(7)
    n = system.n_coordinates
    for _ in range(5):
        y = rng.uniform(-1, 1, 2 * n) + 0.3
        out = np.empty(2 * n)
        engine.module.rhs(0.37, y, p, np.zeros(0), 3.0, 7.0, out)
        ref = ode.rhs(0.37, y)
        np.testing.assert_allclose(out, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
        qdd, lam = engine.module.accelerations(0.37, y[:n], y[n:], p, np.zeros(0))
        qdd_ref, lam_ref = num.accelerations(0.37, y[:n], y[n:])
        scale = max(np.abs(qdd_ref).max(), np.abs(lam_ref).max(initial=0.0))
        np.testing.assert_allclose(qdd, qdd_ref, rtol=1e-12, atol=1e-12 * scale)
        np.testing.assert_allclose(lam, lam_ref, rtol=1e-12, atol=1e-12 * scale)


def test_the_stepped_vector_field_is_the_generated_rhs():
    """The compiled drivers' vector field (through the entry point's address) returns what
    the generated module's rhs returns, bit for bit."""
    from numba import njit

    from poinsot.kernels.systems import native_vector_field

    mdl = models.rolling_coin()
    engine = compile_system(mdl.system)
    p = engine.parameter_vector(mdl.params)
    system = engine.native_system(p, np.zeros(0), (4.0, 5.0))
    field = njit(lambda s, t, y, out: native_vector_field(s, t, y, out))
    y = np.linspace(-0.7, 0.9, 10)
    a, b = np.empty(10), np.empty(10)
    field(system, 0.25, y, a)
    engine.module.rhs(0.25, y, p, np.zeros(0), 4.0, 5.0, b)
    assert np.array_equal(a, b)


@pytest.mark.parametrize("name", ["double-pendulum", "atwood", "rolling-disk", "bead-on-hoop"])
@pytest.mark.parametrize("stabilization", ["baumgarte", "projection"])
def test_compiled_runs_equal_the_lambdify_path(name, stabilization):
    """Fixed steps: the same steps on right-hand sides equal to round-off give the same motion
    to round-off. Adaptive steps: round-off may change a step size, so they agree to the
    tolerance."""
    mdl = models.MODELS[name]()
    t = np.linspace(0, 1, 11)
    kw = {"t_eval": t, "stabilization": stabilization}
    a = mdl.simulate((0, 1), method="rk4", dt=1e-3, **kw)
    b = mdl.simulate((0, 1), method="rk4", dt=1e-3, engine="compiled", **kw)
    np.testing.assert_allclose(b.q, a.q, rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(b.multipliers, a.multipliers, rtol=1e-10, atol=1e-11)
    np.testing.assert_allclose(b.energy, a.energy, rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(b.constraint_residual, a.constraint_residual, atol=1e-12)
    a = mdl.simulate((0, 1), **kw)
    b = mdl.simulate((0, 1), engine="compiled", **kw)
    np.testing.assert_allclose(b.q, a.q, rtol=1e-8, atol=1e-9)


def test_a_compiled_run_calls_no_python_per_step(monkeypatch):
    """The compiled drivers step the generated entry points: the Python right-hand sides are
    never called (they raise here), and the Python backend of the same system — the driver's
    twin calling the generated rhs from Python — gives the same motion."""
    from poinsot.integrate.driver import integrate
    from poinsot.lagrange import numeric

    mdl = models.atwood_machine()
    t = np.linspace(0, 2, 9)
    ref = mdl.simulate((0, 2), t_eval=t, engine="compiled")

    def refuse(*args, **kwargs):
        raise AssertionError("Python called per step")

    monkeypatch.setattr(numeric._ODE, "rhs", refuse)
    monkeypatch.setattr(numeric._NativePython, "vector_field", refuse)
    sol = mdl.simulate((0, 2), t_eval=t, engine="compiled")
    assert np.array_equal(sol.q, ref.q)
    monkeypatch.undo()
    engine = compile_system(mdl.system)
    num = numeric._EngineNumeric(mdl.system, mdl.params, engine)
    ode = numeric._NativeODE(num, "baumgarte", (10.0, 10.0), engine, np.zeros(0))
    y0 = np.concatenate([ref.q[0], ref.qd[0]])
    fast = integrate(ode, "dop853", (0, 2), y0, t_eval=t, rtol=1e-10, atol=1e-12)
    slow = integrate(ode, "dop853", (0, 2), y0, t_eval=t, rtol=1e-10, atol=1e-12,
                     backend="python")  # fmt: skip
    assert (fast.backend, slow.backend) == ("compiled", "python")
    np.testing.assert_allclose(fast.y, slow.y, rtol=1e-13, atol=1e-14)
    assert fast.nfev == slow.nfev


def test_one_compilation_serves_a_parameter_sweep(monkeypatch, tmp_path):
    """Counted: one generated source (one derivation, one code generation) and no lambdify
    for a sweep of compiled runs and ensembles over the parameters."""
    import sympy

    from poinsot.lagrange import engine as engine_module

    monkeypatch.setenv("POINSOT_CACHE_DIR", str(tmp_path))  # a model never seen

    mdl = models.pendulum_on_cart()
    s = mdl.symbols
    calls = {"source": 0, "lambdify": 0}
    source, lambdify = engine_module._source, sympy.lambdify

    def count_source(*args):
        calls["source"] += 1
        return source(*args)

    def count_lambdify(*args, **kwargs):
        calls["lambdify"] += 1
        return lambdify(*args, **kwargs)

    monkeypatch.setattr(engine_module, "_source", count_source)
    monkeypatch.setattr(sympy, "lambdify", count_lambdify)
    for mass in (0.5, 2.0, 8.0):
        mdl.simulate((0, 1), params={**mdl.params, s["M"]: mass}, engine="compiled")
    mdl.system.simulate_ensemble((0, 1), q0=mdl.q0, qd0=mdl.qd0,
                                 params={**mdl.params, s["m"]: [0.5, 1.0, 2.0]})  # fmt: skip
    assert calls == {"source": 1, "lambdify": 0}
    monkeypatch.undo()
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


def test_a_model_seen_before_is_not_derived_again(tmp_path, monkeypatch):
    """A second system object of the same model (a new script run) finds the generated module
    by the model's hash: its equations of motion are not derived; a changed model is."""
    from poinsot.lagrange import engine as engine_module

    monkeypatch.setenv("POINSOT_CACHE_DIR", str(tmp_path))
    first = models.double_pendulum().system
    path = compile_system(first).path
    calls = []
    source = engine_module._source
    monkeypatch.setattr(engine_module, "_source", lambda s: calls.append(s) or source(s))
    again = models.double_pendulum().system
    assert compile_system(again).path == path and calls == []
    assert "mass_matrix" not in again.__dict__ and "forcing" not in again.__dict__
    other = models.pendulum_polar().system  # another model: derived and generated
    assert compile_system(other).path != path and calls == [other]
