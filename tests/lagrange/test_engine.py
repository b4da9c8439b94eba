"""The compiled engine (the model's M, f, G, b, γ, g, h as machine code in the core, with the
core's KKT solve, stabilisation and projection) against the reference oracle (``oracle.py``:
SymPy's lambdify, NumPy's solve, SciPy's integrator): the same equations to round-off, the
same motion, constraints, inputs and parameter sweeps included; and what the compiled engine
promises of its cost (no Python per step, one compilation per model, none again for a model
seen before)."""

from __future__ import annotations

import numpy as np
import oracle
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
    """One evaluation of ẏ (Baumgarte terms included, at states off the constraints), of the
    physical (q̈, λ) and of every part: the core against SymPy's lambdify with NumPy's solve."""
    mdl = models.MODELS[name]()
    system = mdl.system
    engine = compile_system(system)
    num = oracle.Lambdified(system, mdl.params)
    p = engine.parameter_vector(mdl.params)
    rhs = num.rhs("baumgarte", (3.0, 7.0))
    rng = np.random.default_rng(7)
    n, m = system.n_coordinates, system.n_constraints
    u = np.zeros(0)
    for _ in range(5):
        y = rng.uniform(-1, 1, 2 * n) + 0.3
        out = engine.model.rhs(0.37, y, p, u, 3.0, 7.0)
        ref = rhs(0.37, y)
        np.testing.assert_allclose(out, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
        qdd, lam = engine.model.accelerations(0.37, y[:n], y[n:], p, u)
        qdd_ref, lam_ref = num.accelerations(0.37, y[:n], y[n:])
        scale = max(np.abs(qdd_ref).max(), np.abs(lam_ref).max(initial=0.0))
        np.testing.assert_allclose(qdd, qdd_ref, rtol=1e-12, atol=1e-12 * scale)
        np.testing.assert_allclose(lam, lam_ref, rtol=1e-12, atol=1e-12 * scale)
        M, f, G, b, gamma, g, h = engine.model.parts(0.37, y[:n], y[n:], p, u)
        np.testing.assert_allclose(M, num.mat(num.M, y[:n], y[n:], 0.37, (n, n)), rtol=1e-13,
                                   atol=1e-14)  # fmt: skip
        np.testing.assert_allclose(f, num.mat(num.f, y[:n], y[n:], 0.37, (n,)), rtol=1e-12,
                                   atol=1e-13 * max(1.0, np.abs(f).max()))  # fmt: skip
        if m:
            for got, fn, shape in ((G, num.G, (m, n)), (b, num.b, (m,)),
                                   (gamma, num.gamma, (m,))):  # fmt: skip
                want = num.mat(fn, y[:n], y[n:], 0.37, shape)
                np.testing.assert_allclose(got, want, rtol=1e-12,
                                           atol=1e-13 * max(1.0, np.abs(want).max()))  # fmt: skip
        if system.n_holonomic:
            want = num.mat(num.g, y[:n], y[n:], 0.37, (system.n_holonomic,))
            np.testing.assert_allclose(g, want, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(h, num.mat(num.energy, y[:n], y[n:], 0.37, ()), rtol=1e-12)


@pytest.mark.parametrize("name", ["double-pendulum", "atwood", "rolling-disk", "bead-on-hoop"])
@pytest.mark.parametrize("stabilization", ["baumgarte", "projection"])
def test_compiled_runs_equal_the_lambdify_path(name, stabilization):
    """Fixed steps: the same steps on right-hand sides equal to round-off give the same motion
    to round-off. Adaptive steps: round-off may change a step size, so they agree to the
    tolerance."""
    mdl = models.MODELS[name]()
    t = np.linspace(0, 1, 11)
    kw = {"t_eval": t, "stabilization": stabilization}
    a = oracle.simulate(mdl, (0, 1), method="rk4", dt=1e-3, **kw)
    b = mdl.simulate((0, 1), method="rk4", dt=1e-3, **kw)
    np.testing.assert_allclose(b.q, a.q, rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(b.multipliers, a.multipliers, rtol=1e-10, atol=1e-11)
    np.testing.assert_allclose(b.energy, a.energy, rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(b.constraint_residual, a.constraint_residual, atol=1e-12)
    a = oracle.simulate(mdl, (0, 1), **kw)
    b = mdl.simulate((0, 1), **kw)
    np.testing.assert_allclose(b.q, a.q, rtol=1e-8, atol=1e-9)


def test_a_compiled_run_calls_no_python_per_step(monkeypatch):
    """The core steps the compiled model: the Python right-hand sides are never called (they
    raise here). An input given as a Python function is called back from the core (the slow
    path) and gives the same motion, bit for bit, as the same input given as a number."""
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols

    from poinsot.lagrange import LagrangianSystem, numeric

    mdl = models.atwood_machine()
    t = np.linspace(0, 2, 9)
    calls = []
    for name in ("accelerations", "mat", "project"):
        original = getattr(numeric._EngineNumeric, name)

        def counted(*args, _f=original, **kwargs):
            calls.append(1)
            return _f(*args, **kwargs)

        monkeypatch.setattr(numeric._EngineNumeric, name, counted)
    short = mdl.simulate((0, 2), t_eval=t, method="rk4", dt=1e-2)
    before = len(calls)  # the start's checks (the consistent initial state)
    long = mdl.simulate((0, 2), t_eval=t, method="rk4", dt=1e-4)
    assert len(calls) == 2 * before, "Python evaluations grew with the steps"
    assert np.abs(long.q - short.q).max() < 1e-6
    monkeypatch.undo()

    x, F = dynamicsymbols("x F")
    m, k = sp.symbols("m k", positive=True)
    spring = LagrangianSystem([x], kinetic=m * x.diff() ** 2 / 2, potential=k * x**2 / 2,
                              forces=[{x: F}])  # fmt: skip
    kw = {"q0": {x: 0.1}, "params": {"m": 2, "k": 8}, "t_eval": t}
    calls = []
    fast = spring.simulate((0, 2), inputs={F: 4.0}, **kw)
    slow = spring.simulate((0, 2), inputs={F: lambda tt: calls.append(tt) or 4.0}, **kw)
    assert np.array_equal(fast.q, slow.q) and fast.nfev == slow.nfev
    assert len(calls) >= fast.nfev  # called back at every evaluation (and at the samples)


def test_inputs_as_expressions_run_compiled_and_match_the_python_functions():
    """A SymPy input (a function of t and the state: feedback) is compiled with the model; it
    gives the motion of the same input written as a Python function, and of the closed form of
    a driven, damped oscillator."""
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols

    from poinsot.lagrange import LagrangianSystem

    x, F = dynamicsymbols("x F")
    t = sp.Symbol("t")
    spring = LagrangianSystem([x], kinetic=x.diff() ** 2 / 2, potential=x**2 / 2,
                              forces=[{x: F}])  # fmt: skip
    ts = np.linspace(0, 5, 21)
    kw = {"q0": {x: 0.0}, "qd0": {x: 0.0}, "t_eval": ts, "rtol": 1e-12, "atol": 1e-13}
    # ẍ + x = cos(2t) − 0 ẋ: x = (cos t − cos 2t)/3 from rest
    expr = spring.simulate((0, 5), inputs={F: sp.cos(2 * t)}, **kw)
    func = spring.simulate((0, 5), inputs={F: lambda tt: np.cos(2 * tt)}, **kw)
    np.testing.assert_allclose(expr.q[:, 0], (np.cos(ts) - np.cos(2 * ts)) / 3, atol=1e-10)
    np.testing.assert_allclose(expr.q, func.q, atol=1e-12)
    # feedback on the speed: F = −ẋ damps the motion (energy decays)
    damped = spring.simulate((0, 5), inputs={F: -x.diff(t)}, q0={x: 1.0}, t_eval=ts)
    assert np.all(np.diff(damped.energy) < 0)
    with pytest.raises(ValueError, match=r"inputs\[F\].*found k"):
        spring.simulate((0, 5), inputs={F: sp.Symbol("k") * t}, **kw)


def test_one_compilation_serves_a_parameter_sweep(monkeypatch, tmp_path):
    """Counted: one program (one derivation, one lowering) and no lambdify for a sweep of
    compiled runs and ensembles over the parameters."""
    import sympy

    from poinsot.lagrange import engine as engine_module

    monkeypatch.setenv("POINSOT_CACHE_DIR", str(tmp_path))  # a model never seen
    monkeypatch.setattr(engine_module, "_MODELS", {})

    mdl = models.pendulum_on_cart()
    s = mdl.symbols
    calls = {"program": 0, "lambdify": 0}
    program, lambdify = engine_module._program, sympy.lambdify

    def count_program(*args):
        calls["program"] += 1
        return program(*args)

    def count_lambdify(*args, **kwargs):
        calls["lambdify"] += 1
        return lambdify(*args, **kwargs)

    monkeypatch.setattr(engine_module, "_program", count_program)
    monkeypatch.setattr(sympy, "lambdify", count_lambdify)
    for mass in (0.5, 2.0, 8.0):
        mdl.simulate((0, 1), params={**mdl.params, s["M"]: mass})
    mdl.system.simulate_ensemble((0, 1), q0=mdl.q0, qd0=mdl.qd0,
                                 params={**mdl.params, s["m"]: [0.5, 1.0, 2.0]})  # fmt: skip
    assert calls == {"program": 1, "lambdify": 0}
    monkeypatch.undo()
    compiled = compile_system(mdl.system)
    assert [str(p) for p in compiled.parameters] == ["M", "g", "l", "m"]
    t = np.linspace(0, 2, 11)
    for mass in (0.5, 2.0, 8.0):
        params = {**mdl.params, s["M"]: mass}
        a = oracle.simulate(mdl, (0, 2), t_eval=t, params=params)
        b = mdl.simulate((0, 2), t_eval=t, params=params)
        np.testing.assert_allclose(b.q, a.q, rtol=1e-9, atol=1e-11)
        assert compile_system(mdl.system) is compiled  # the same compiled model
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
    sol = spring.simulate((0, 3), **kw)
    np.testing.assert_allclose(sol.q[:, 0], 0.5 * (1 - np.cos(2 * t)), atol=1e-9)
    with pytest.raises(ValueError, match="`engine` must be 'compiled'"):
        spring.simulate((0, 3), engine="cython", **kw)
    with pytest.raises(ValueError, match=r"engine='numpy'` was removed.*tests/lagrange/oracle"):
        spring.simulate((0, 3), engine="numpy", **kw)


def test_a_new_process_loads_the_model_from_the_disk_cache(tmp_path):
    """The first process derives the model and keeps its program; the second finds it by the
    model's hash (it derives nothing: `_program` raises there) and gives the same motion."""
    import os
    import subprocess
    import sys

    run = ("import numpy as np; from poinsot import models; m = models.atwood_machine(); "
           "s = m.simulate((0, 1), t_eval=np.linspace(0, 1, 5)); "
           "print(repr(float(s.q[-1, 0])))")  # fmt: skip
    again = ("from poinsot.lagrange import engine\n"
             "def refuse(*a): raise AssertionError('derived again')\n"
             "engine._program = refuse\n" + run.replace("; ", "\n"))  # fmt: skip
    env = {**os.environ, "POINSOT_CACHE_DIR": str(tmp_path)}
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                           timeout=300) for code in (run, again)]  # fmt: skip
    for done in runs:
        assert done.returncode == 0, done.stderr[-2000:]
    assert runs[0].stdout == runs[1].stdout
    assert len(list((tmp_path / "lagrange").glob("model_*.npz"))) == 1


def test_a_model_seen_before_is_not_derived_again(tmp_path, monkeypatch):
    """A second system object of the same model (a new script run) finds the compiled model
    by the model's hash: its equations of motion are not derived; a changed model is."""
    from poinsot.lagrange import engine as engine_module

    monkeypatch.setenv("POINSOT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(engine_module, "_MODELS", {})
    first = models.double_pendulum().system
    key = compile_system(first).key
    calls = []
    program = engine_module._program
    monkeypatch.setattr(engine_module, "_program", lambda s: calls.append(s) or program(s))
    monkeypatch.setattr(engine_module, "_MODELS", {})  # a new process: only the disk is left
    again = models.double_pendulum().system
    assert compile_system(again).key == key and calls == []
    assert "mass_matrix" not in again.__dict__ and "forcing" not in again.__dict__
    other = models.pendulum_polar().system  # another model: derived and compiled
    assert compile_system(other).key != key and calls == [other]


def test_a_corrupt_or_foreign_cache_entry_is_derived_again(tmp_path, monkeypatch):
    from poinsot.lagrange import engine as engine_module

    monkeypatch.setenv("POINSOT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(engine_module, "_MODELS", {})
    system = models.atwood_machine().system
    key = engine_module._model_key(system)
    folder = tmp_path / "lagrange"
    folder.mkdir()
    (folder / f"model_{key}.npz").write_bytes(b"not a program")
    sol = models.atwood_machine().simulate((0, 1), t_eval=[0, 1])
    assert np.isfinite(sol.q).all()
    with np.load(folder / f"model_{key}.npz") as data:  # rewritten whole
        assert len(data["codes"]) == len(data["values"]) > 0


def test_bad_model_programs_are_refused_by_the_core():
    from poinsot import _core

    with pytest.raises(ValueError, match="malformed"):
        _core.LagrangianModel(np.array([1, 4]), np.array([0.0, 0.0]), 1, 0, 0, 0, 0)
    with pytest.raises(ValueError, match="holonomic"):
        _core.LagrangianModel(np.zeros(0, np.int64), np.zeros(0), 1, 0, 1, 0, 0)
