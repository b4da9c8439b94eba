"""Fuzz ``LagrangianSystem.simulate`` and ``LagrangianSystem.linearize`` (issue 26): each call
is accepted with a result that passes its own check (the constraint residual and the Jacobi
integral; eigenvalues in closed form), refused naming the argument, or fails as a documented
:class:`~poinsot.SimulationError` (:mod:`fuzzing`)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from fuzzing import FEW, MANY, finite, number, odd_objects, outcome, sometimes
from hypothesis import event, given
from hypothesis import strategies as st
from sympy.physics.mechanics import dynamicsymbols

from poinsot import models
from poinsot.lagrange import LagrangianSystem

MODELS = {"polar": models.pendulum_polar(), "cartesian": models.pendulum_cartesian()}
SIM_ARGS = ["t_span", "q0", "qd0", "params", "method", "dt", "rtol", "atol", "t_eval",
            "stabilization", "baumgarte", "max_steps", "guess", "inputs", "engine"]  # fmt: skip
ODD_KEYS = st.sampled_from(["theta", "z", sp.Symbol("x"), dynamicsymbols("z"), 3, None])


def _dict_of(good: dict, values):
    """``good`` ({key: value}) with its values replaced from ``values``, and sometimes a key
    dropped or an unknown key added."""
    return st.fixed_dictionaries({k: values for k in good}).flatmap(
        lambda d: sometimes(st.just(d), st.just(dict(list(d.items())[1:])),
                            ODD_KEYS.map(lambda k: {**d, k: 1.0}), odd_objects))  # fmt: skip


@st.composite
def lagrangian_runs(draw):
    name = draw(st.sampled_from(sorted(MODELS)))
    model = MODELS[name]
    s = model.symbols
    g, l = draw(st.floats(0.5, 20.0)), draw(st.floats(0.2, 3.0))
    params = {s["m"]: draw(st.floats(0.1, 5.0)), s["g"]: g, s["l"]: l}
    params = draw(sometimes(st.just(params), _dict_of(params, number(st.floats(0.1, 5.0)))))
    theta = draw(st.floats(-3.0, 3.0))
    if name == "polar":
        q0 = {s["theta"]: theta}
        qd0 = {s["theta"]: draw(st.floats(-3.0, 3.0))}
    else:  # on the circle of the rod (given both, or x alone: y is solved for)
        q0 = draw(st.sampled_from([{s["x"]: l * math.sin(theta), s["y"]: -l * math.cos(theta)},
                                   {s["x"]: l * math.sin(theta) * 0.999}]))  # fmt: skip
        qd0 = {}
    q0 = draw(sometimes(st.just(q0), _dict_of(q0, number(finite))))
    qd0 = draw(sometimes(st.just(qd0), _dict_of(q0 if isinstance(q0, dict) else {},
                                                number(finite)), share=0.2))  # fmt: skip
    T = draw(st.floats(0.05, 10.0))
    kw = {"q0": q0, "qd0": qd0, "params": params}
    kw["method"] = draw(sometimes(st.sampled_from(["dop853", "rk4"]),
                                  st.sampled_from(["rkmk4", "euler", 7])))  # fmt: skip
    if kw["method"] == "rk4" or draw(st.booleans()):
        kw["dt"] = draw(sometimes(st.floats(1e-3, 0.2), number(st.floats(1e-3, 0.2)), st.none()))
    if draw(st.booleans()):
        kw["rtol"] = draw(number(st.floats(1e-12, 1e-3)))
    if draw(st.booleans()):
        kw["stabilization"] = draw(sometimes(st.sampled_from(["baumgarte", "projection", None]),
                                             odd_objects))  # fmt: skip
    if draw(st.booleans()):
        kw["baumgarte"] = draw(sometimes(st.tuples(st.floats(0, 50), st.floats(0, 50)),
                                         number(finite), odd_objects))  # fmt: skip
    if draw(st.booleans()):
        n = draw(st.integers(0, 5))
        grid = sorted(draw(st.lists(st.floats(0.0, T), min_size=n, max_size=n, unique=True)))
        kw["t_eval"] = draw(sometimes(st.just(grid), st.just([np.inf]), odd_objects))
    if draw(st.booleans()):
        kw["max_steps"] = draw(sometimes(st.integers(1, 10**5), number(st.integers(1, 5))))
    t_span = draw(sometimes(st.just((0.0, T)), st.tuples(number(finite), number(finite))))
    return name, t_span, kw


def _accurate(kw) -> bool:
    if kw["method"] == "dop853":
        return (kw.get("rtol") or 1e-10) <= 1e-7
    return kw.get("dt") is not None and kw["dt"] <= 0.01


def _lagrangian(case):
    name, t_span, kw = case
    model = MODELS[name]

    def check(sol):
        t_eval = kw.get("t_eval")
        expected = np.linspace(*map(float, t_span), 201) if t_eval is None else t_eval
        np.testing.assert_allclose(sol.t, np.asarray(expected, dtype=float), rtol=0, atol=0)
        assert np.isfinite(sol.q).all() and np.isfinite(sol.qd).all()
        if len(sol.t) < 2 or not _accurate(kw):
            return
        event("residual and energy checked")
        stabilised = kw.get("stabilization", "baumgarte") is not None
        gains = kw.get("baumgarte") or (10.0, 10.0)  # None: the default gains
        if name == "cartesian" and stabilised and min(gains) > 0:
            assert np.abs(sol.constraint_residual).max() < 1e-4
        if name == "polar" or (stabilised and min(gains) > 0):
            # the Jacobi integral h (no force, fixed constraints), evaluated from its
            # expression at the samples, on the scale of its terms
            (h,) = [i for i in sol.invariants if i.symbol == "h"]
            assert np.abs(h.values - h.values[0]).max() <= 1e-3 * h.scale

    kw.setdefault("max_steps", 10**5)  # bounded, and quick enough for a fuzz test
    outcome(lambda: model.system.simulate(t_span, **kw), check, SIM_ARGS,
            what=f"{name}.simulate({t_span!r}, {kw!r})")  # fmt: skip


@FEW
@given(lagrangian_runs())
def test_lagrangian_simulate(case):
    _lagrangian(case)


@pytest.mark.slow
@MANY
@given(lagrangian_runs())
def test_lagrangian_simulate_many(case):
    _lagrangian(case)


# ----------------------------------------------------------------- linearize
_x, _F = dynamicsymbols("x F")
_m, _k = sp.symbols("m k", positive=True)
CART = LagrangianSystem([_x], kinetic=_m * _x.diff() ** 2 / 2, potential=_k * _x**2 / 2,
                        forces=[{_x: _F}])  # fmt: skip


@st.composite
def linearizations(draw):
    which = draw(st.sampled_from(["pendulum", "cart"]))
    if which == "pendulum":
        model = MODELS["polar"]
        th = model.symbols["theta"]
        params = {"m": draw(st.floats(0.1, 5)), "g": draw(st.floats(0.5, 20)),
                  "l": draw(st.floats(0.2, 3))}  # fmt: skip
        k = draw(st.integers(-2, 2))
        point = {th: k * math.pi}
        speeds_key = th.diff()
        system, inputs = model.system, None
    else:
        params = {"m": draw(st.floats(0.1, 5)), "k": draw(st.floats(0.1, 50))}  # positive
        point = {_x: 0.0}
        speeds_key = _x.diff()
        system = CART
        inputs = draw(sometimes(st.just({"F": 0.0}), st.just({}), st.just({"G": 1.0})))
    point = draw(sometimes(st.just(point), _dict_of(point, number(finite)),
                           st.just({**point, speeds_key: 0.0}),
                           st.just({**point, speeds_key: 0.5}),
                           ODD_KEYS.map(lambda key: {**point, key: 0.0})))  # fmt: skip
    params = draw(sometimes(st.just(params), _dict_of(params, number(st.floats(0.1, 5)))))
    speeds = draw(sometimes(st.none(), st.just({speeds_key: 0.0}), odd_objects,
                            ODD_KEYS.map(lambda key: {key: 0.0})))  # fmt: skip
    t = draw(sometimes(st.just(0.0), number(finite)))
    return which, system, point, params, speeds, inputs, t


def _linearize(case):
    which, system, point, params, speeds, inputs, t = case
    kw = {"speeds": speeds, "t": t}
    if inputs is not None:
        kw["inputs"] = inputs

    def check(lin):
        """The closed forms: the pendulum ±i√(g/l) hanging, ±√(g/l) upside down; the cart
        ±i√(k/m) with B = (0, 1/m)."""
        eig = np.sort_complex(lin.eigenvalues)
        if which == "pendulum":
            rate = math.sqrt(params["g"] / params["l"])
            theta = next(iter(lin.equilibrium.values()))
            up = round(theta / math.pi) % 2 == 1
            want = np.array([-rate, rate]) if up else np.array([-1j * rate, 1j * rate])
        else:
            rate = math.sqrt(params["k"] / params["m"])
            want = np.array([-1j * rate, 1j * rate])
            np.testing.assert_allclose(lin.input_matrix[:, 0], [0, 1 / params["m"]], rtol=1e-12)
        # central differences of step 1e-6: an absolute accuracy for rates below 1 rad/s
        np.testing.assert_allclose(eig, np.sort_complex(want), rtol=1e-6,
                                   atol=1e-6 * max(rate, 1.0))  # fmt: skip

    outcome(lambda: system.linearize(point, params=params, **kw), check,
            ["equilibrium", "speeds", "params", "inputs", "t"],
            what=f"{which}.linearize({point!r}, params={params!r}, {kw!r})")  # fmt: skip


@FEW
@given(linearizations())
def test_linearize(case):
    _linearize(case)


@pytest.mark.slow
@MANY
@given(linearizations())
def test_linearize_many(case):
    _linearize(case)
