"""The Lagrangian front-ends' boundary (issue 26): an operating point holding speeds is honoured
as ``speeds=`` is, every dict argument names its unknown keys, the Baumgarte gains are checked
like the tolerances, and every run (ensembles included) is refused up front when its step count
exceeds the budget."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from poinsot import models


def _upright_rolling(mdl, spin):
    """Upright rolling of the coin at spin rate ``spin``: its coordinates and the velocities
    the rolling constraints require (solved by SymPy)."""
    s = mdl.symbols
    point = {s[k]: 0.0 for k in ("x", "y", "psi", "theta", "phi")}
    vx, vy = sp.symbols("v_x v_y")
    rates = {s["x"].diff(): vx, s["y"].diff(): vy, s["psi"].diff(): 0, s["theta"].diff(): 0,
             s["phi"].diff(): spin}  # fmt: skip
    rows = [sp.sympify(c).subs(rates).subs(point).subs(mdl.params) for c in mdl.system.nonholonomic]
    v = sp.solve(rows, [vx, vy])
    return point, {s["x"]: float(v[vx]), s["y"]: float(v[vy]), s["phi"]: spin}


@pytest.fixture(scope="module")
def coin():
    return models.rolling_coin()


def test_speeds_in_the_operating_point_are_honoured_as_speeds_are(coin):
    """The coin rolling upright at 1.4× its critical spin √(g/3r) is stable and its lean wobbles
    at ω² = (4/5)(3Ω² − g/r) (Greenwood, Advanced Dynamics, §6.3). One operating-point dict
    holding q and q̇ (SymPy's ``op_point``) says so, as ``speeds=`` does; before issue 26 the
    speeds in it were dropped and the disc linearised at rest ("unstable")."""
    p = {str(k): v for k, v in coin.params.items()}
    spin = 1.4 * np.sqrt(p["g"] / p["r"] / 3)
    point, speeds = _upright_rolling(coin, spin)
    by_speeds = coin.system.linearize(point, params=coin.params, speeds=speeds)
    op = {**point, **{q.diff(): v for q, v in speeds.items()}}
    by_op = coin.system.linearize(op, params=coin.params)
    assert by_op.reduced_verdict == by_speeds.reduced_verdict == "spectrally stable"
    np.testing.assert_array_equal(by_op.matrix, by_speeds.matrix)
    wobble = np.sqrt(0.8 * (3 * spin**2 - p["g"] / p["r"]))
    assert by_op.frequencies.max() == pytest.approx(wobble, rel=1e-6)
    assert by_op.speeds == by_speeds.speeds and set(by_op.equilibrium) == set(point)
    # speeds= keyed by the speeds themselves, and both ways at once when they agree
    keyed = {q.diff(): v for q, v in speeds.items()}
    again = coin.system.linearize(point, params=coin.params, speeds=keyed)
    np.testing.assert_array_equal(again.matrix, by_speeds.matrix)
    both = coin.system.linearize(op, params=coin.params, speeds=speeds)
    np.testing.assert_array_equal(both.matrix, by_speeds.matrix)


def test_unknown_and_conflicting_operating_point_keys_are_refused_by_name(coin):
    s = coin.symbols
    point = {s[k]: 0.0 for k in ("x", "y", "psi", "theta", "phi")}
    other = sp.Function("z")(sp.Symbol("t"))
    for key in ("omega", sp.Symbol("x"), other, other.diff()):
        with pytest.raises(ValueError, match=r"`equilibrium`: .* is neither a coordinate"):
            coin.system.linearize({**point, key: 0.0}, params=coin.params)
        with pytest.raises(ValueError, match=r"`speeds`: .* is neither a coordinate"):
            coin.system.linearize(point, params=coin.params, speeds={key: 0.0})
    with pytest.raises(ValueError, match=r"velocity of phi\(t\) is given twice"):
        coin.system.linearize({**point, s["phi"].diff(): 3.0}, params=coin.params,
                              speeds={s["phi"]: 4.0})  # fmt: skip
    with pytest.raises(ValueError, match=r"must give every coordinate: missing theta\(t\)"):
        coin.system.linearize({k: v for k, v in point.items() if k != s["theta"]},
                              params=coin.params)  # fmt: skip
    with pytest.raises(TypeError, match=r"`equilibrium\[theta\(t\)\]` must be a real number"):
        coin.system.linearize({**point, s["theta"]: "0"}, params=coin.params)
    with pytest.raises(TypeError, match=r"`equilibrium` must be a dict"):
        coin.system.linearize([0.0] * 5, params=coin.params)
    with pytest.raises(ValueError, match=r"`params`: 'G' is not a parameter"):
        coin.system.linearize(point, params={**coin.params, "G": 1.0})


def test_equilibria_bounds_are_checked_by_name():
    mdl = models.pendulum_polar()
    th = mdl.symbols["theta"]
    found = mdl.system.equilibria(mdl.params, bounds={th: (-1.0, 4.0)})
    angles = np.array([e[th] for e in found])  # sin θ = 0 at a pendulum's equilibria
    np.testing.assert_allclose(np.sin(angles), 0.0, atol=1e-9)
    assert {round(a % (2 * np.pi), 6) % round(2 * np.pi, 6) for a in angles} == {0.0, 3.141593}
    finite = r"bounds\[theta\(t\)\]\[1\]` must be finite"
    for bounds, match in (({th.diff(): (0, 1)}, "is not a coordinate"),
                          ({th: 3.0}, r"`bounds\[theta\(t\)\]` must be a pair"),
                          ({th: (1.0, -1.0)}, "low < high"),
                          ({th: (0.0, np.inf)}, finite)):  # fmt: skip
        with pytest.raises(ValueError, match=match):
            mdl.system.equilibria(mdl.params, bounds=bounds)


BAD_GAINS = [
    (10.0, TypeError, "found float"),
    ("10", TypeError, "found str"),
    (complex(10, 1), TypeError, "found complex"),
    ((10, complex(0, 1)), TypeError, r"`baumgarte\[1\]` must be a real number"),
    ((10,), ValueError, "found 1 values"),
    ((-1.0, 10.0), ValueError, r"`baumgarte\[0\]` must be non-negative"),
    ((np.nan, 10.0), ValueError, r"`baumgarte\[0\]` must be finite"),
]


@pytest.mark.parametrize(("gains", "error", "match"), BAD_GAINS)
def test_baumgarte_gains_are_checked_like_the_tolerances(gains, error, match):
    mdl = models.pendulum_cartesian()
    with pytest.raises(error, match=match):
        mdl.simulate((0, 0.1), baumgarte=gains)
    with pytest.raises(error, match=match):
        mdl.system.simulate_ensemble((0, 0.1), q0=mdl.q0, params=mdl.params, baumgarte=gains)


def test_accepted_gains_are_the_gains_used():
    """A list, an array and the default tuple give the same run; zero gains switch the
    stabilisation off (the residual drifts more than with the critically damped default)."""
    mdl = models.pendulum_cartesian()
    ref = mdl.simulate((0, 2), method="rk4", dt=1e-2)
    for gains in ([10, 10], np.array([10.0, 10.0])):
        np.testing.assert_array_equal(mdl.simulate((0, 2), method="rk4", dt=1e-2,
                                                   baumgarte=gains).q, ref.q)  # fmt: skip
    off = mdl.simulate((0, 2), method="rk4", dt=1e-2, baumgarte=(0, 0))
    assert np.abs(off.constraint_residual).max() > np.abs(ref.constraint_residual).max()


@pytest.mark.parametrize(("t_span", "dt"), [((0, 0.5), 1e-300), ((0, 9.2e18), 1e-3)])
def test_lagrangian_runs_and_ensembles_refuse_an_impossible_step_count(t_span, dt):
    mdl = models.pendulum_cartesian()
    with pytest.raises(ValueError, match=r"the run needs .* steps of dt .* `max_steps` = "):
        mdl.simulate(t_span, method="rk4", dt=dt)
    with pytest.raises(ValueError, match=r"the run needs .* steps of dt .* `max_steps` = "):
        mdl.system.simulate_ensemble(t_span, q0=mdl.q0, params=mdl.params, method="rk4", dt=dt)
    with pytest.raises(ValueError, match="needs 50 steps"):
        mdl.system.simulate_ensemble((0, 0.5), q0=mdl.q0, params=mdl.params, method="rk4",
                                     dt=1e-2, max_steps=49)  # fmt: skip


def test_a_first_step_of_1e_300_is_harmless():
    """``dt`` is only the first step of an adaptive method: the issue's run of the Lagrangian
    pendulum with ``dt = 1e-300`` ends promptly, on the rod."""
    from bounded import deadline

    with deadline(120, "pendulum_cartesian().simulate((0, 0.5), dt=1e-300)"):
        sol = models.pendulum_cartesian().simulate((0, 0.5), dt=1e-300)
    assert np.abs(sol.constraint_residual).max() < 1e-8


def test_parameters_keep_their_declared_sign():
    """The equations were derived with m, g, l > 0 (SymPy simplifies √(l²) to l): a value of
    the other sign is refused by name, in a run and in an ensemble; an unknown symbol too."""
    mdl = models.pendulum_polar()
    l = mdl.symbols["l"]
    for bad in (0.0, -1.0):
        with pytest.raises(ValueError, match=r"`params\[l\]` must be positive"):
            mdl.simulate((0, 1), params={**mdl.params, l: bad})
        with pytest.raises(ValueError, match=r"`params\[l\]` must be positive"):
            mdl.system.simulate_ensemble((0, 1), q0=mdl.q0,
                                         params={**mdl.params, l: [1.0, bad]})  # fmt: skip
    with pytest.raises(ValueError, match=r"`params`: L is not a parameter"):
        mdl.simulate((0, 1), params={**mdl.params, sp.Symbol("L"): 1.0})
    # a symbol without the assumption, of the same name, means the parameter (once)
    others = {k: v for k, v in mdl.params.items() if k != l}
    sol = mdl.simulate((0, 1), params={**others, sp.Symbol("l"): 2.0}, t_eval=[1.0])
    assert sol.params[l] == 2.0
    with pytest.raises(ValueError, match=r"`params`: l is given twice with two values"):
        mdl.simulate((0, 1), params={**mdl.params, sp.Symbol("l"): 2.0})
