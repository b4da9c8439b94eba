"""An operating point must lie on the constraints as an initial state must; coordinates are
given by symbol or by name on every path; a ``guess`` has an effect or is refused, and a failed
solve says where it started."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from poinsot import models


@pytest.fixture(scope="module")
def cartesian():
    return models.pendulum_cartesian()


@pytest.fixture(scope="module")
def coin():
    return models.rolling_coin()


def _residual(expressions, values):
    """max |expression| at ``values`` by SymPy (the independent route)."""
    return max(abs(float(sp.sympify(e).subs(values))) for e in expressions)


# --- F1: linearize refuses a point off the constraints --------------------------------------


def test_linearize_refuses_coordinates_off_the_holonomic_constraints(cartesian):
    """(0, −1.3) is not on the rod of length 1: the linearisation there was another
    pendulum's (√(g/1.3) = 2.747 rad/s, "spectrally stable"); it is refused, with the
    violation, as ``simulate`` refuses the same point."""
    x, y = cartesian.system.coordinates
    point = {x: 0.0, y: -1.3}
    size = _residual(cartesian.system.holonomic, {**point, **cartesian.params})
    assert size == pytest.approx(0.69)
    refused = r"`equilibrium`: inconsistent operating point: the holonomic constraints are "
    with pytest.raises(ValueError, match=refused + r"violated by max \|g\(q\)\| = 0\.69"):
        cartesian.system.linearize(point, params=cartesian.params)
    with pytest.raises(ValueError, match=r"`q0`: inconsistent initial conditions: .* = 0\.69"):
        cartesian.system.simulate((0, 1), q0=point, params=cartesian.params)
    # on the rod to within round-off it is accepted: ±i√(g/l)
    lin = cartesian.system.linearize({x: 0.0, y: -1.0 - 1e-12}, params=cartesian.params)
    rate = math.sqrt(9.81 / 1.0)
    np.testing.assert_allclose(np.sort(lin.eigenvalues.imag), [-rate, rate], rtol=1e-9)


def test_linearize_refuses_a_radial_velocity_as_a_velocity_constraint(cartesian):
    """A velocity along the rod breaks 2x ẋ + 2y ẏ = 0: it was refused as "not a steady
    motion: accelerations [...]", which named the wrong rule."""
    x, y = cartesian.system.coordinates
    point, speeds = {x: 0.0, y: -1.0}, {y: 0.5}
    rates = {x.diff(): 0.0, y.diff(): 0.5}
    size = _residual([sp.diff(cartesian.system.holonomic[0], cartesian.system.t)],
                     {**rates, **point, **cartesian.params})  # fmt: skip
    assert size == pytest.approx(1.0)
    with pytest.raises(ValueError, match=r"`speeds`: inconsistent operating point: the velocity "
                       r"constraints are violated by max \|G q̇ \+ b\| = 1\b"):  # fmt: skip
        cartesian.system.linearize(point, params=cartesian.params, speeds=speeds)
    # the same velocity in the operating point itself names that argument
    with pytest.raises(ValueError, match=r"`equilibrium`: inconsistent operating point: .*G q̇"):
        cartesian.system.linearize({**point, y.diff(): 0.5}, params=cartesian.params)


def test_linearize_refuses_velocities_that_break_the_rolling_constraint(coin):
    """Upright rolling at spin Ω needs ẋ = r Ω cos ψ, ẏ = r Ω sin ψ (solved by SymPy here):
    any other ẋ was accepted and echoed in ``lin.speeds``."""
    s = coin.symbols
    p = {str(k): v for k, v in coin.params.items()}
    spin = 2 * math.sqrt(p["g"] / (3 * p["r"]))
    point = {s[k]: 0.0 for k in ("x", "y", "psi", "theta", "phi")}
    vx, vy = sp.symbols("v_x v_y")
    rates = {s["x"].diff(): vx, s["y"].diff(): vy, s["psi"].diff(): 0, s["theta"].diff(): 0,
             s["phi"].diff(): spin}  # fmt: skip
    rows = [sp.sympify(c).subs(rates).subs(point).subs(coin.params)
            for c in coin.system.nonholonomic]  # fmt: skip
    v = sp.solve(rows, [vx, vy])
    rolling = float(v[vx])
    assert rolling == pytest.approx(p["r"] * spin)
    lin = coin.system.linearize(point, params=coin.params,
                                speeds={s["phi"]: spin, s["x"]: rolling})  # fmt: skip
    assert lin.speeds[s["x"]] == rolling
    for wrong in (-rolling, 5.0):
        size = abs(wrong - rolling)
        with pytest.raises(ValueError, match=rf"`speeds`: inconsistent operating point: .* = "
                           rf"{size:.3g}"):  # fmt: skip
            coin.system.linearize(point, params=coin.params,
                                  speeds={s["phi"]: spin, s["x"]: wrong})  # fmt: skip
    # an omitted velocity is zero, and said to be when that breaks the constraints
    with pytest.raises(ValueError, match=r"velocities not given are zero: x\(t\), y\(t\), "):
        coin.system.linearize(point, params=coin.params, speeds={s["phi"]: spin})


# --- F2: coordinates by name on every path --------------------------------------------------


def test_single_runs_take_coordinates_by_name_as_ensembles_do(cartesian):
    x, y = cartesian.system.coordinates
    run = {"params": cartesian.params, "t_eval": [0.0, 1.0]}
    by_symbol = cartesian.system.simulate((0, 1), q0={x: 0.6}, qd0={x: 0.1}, guess={y: -0.5},
                                          **run)  # fmt: skip
    by_name = cartesian.system.simulate((0, 1), q0={"x": 0.6}, qd0={"x": 0.1},
                                        guess={"y": -0.5}, **run)  # fmt: skip
    np.testing.assert_array_equal(by_name.q, by_symbol.q)
    np.testing.assert_array_equal(by_name.qd, by_symbol.qd)
    ens = cartesian.system.simulate_ensemble((0, 1), q0={"x": [0.6], "y": -0.8}, qd0={"x": 0.1},
                                             **run)  # fmt: skip
    np.testing.assert_allclose(ens.q[0], by_symbol.q, rtol=0, atol=1e-9)
    for call in (
        lambda: cartesian.system.simulate((0, 1), q0={"z": 0.6}, **run),
        lambda: cartesian.system.simulate((0, 1), q0={"x": 0.6}, guess={"z": 0}, **run),
        lambda: cartesian.system.simulate_ensemble((0, 1), q0={"z": [0.6]}, **run),
    ):
        with pytest.raises(ValueError, match=r"'z' is not .*'x', 'y'|'z' is not one of x, y"):
            call()


def test_linearize_takes_coordinates_by_name(cartesian, coin):
    x, y = cartesian.system.coordinates
    by_name = cartesian.system.linearize({"x": 0.0, "y": -1.0}, params=cartesian.params)
    by_symbol = cartesian.system.linearize({x: 0.0, y: -1.0}, params=cartesian.params)
    np.testing.assert_array_equal(by_name.matrix, by_symbol.matrix)
    assert by_name.equilibrium == by_symbol.equilibrium
    s = coin.symbols
    p = {str(k): v for k, v in coin.params.items()}
    spin = 2 * math.sqrt(p["g"] / (3 * p["r"]))
    point = {k: 0.0 for k in ("x", "y", "psi", "theta", "phi")}
    named = coin.system.linearize(point, params=coin.params,
                                  speeds={"phi": spin, "x": p["r"] * spin})  # fmt: skip
    symbols = coin.system.linearize({s[k]: 0.0 for k in point}, params=coin.params,
                                    speeds={s["phi"]: spin, s["x"]: p["r"] * spin})  # fmt: skip
    np.testing.assert_array_equal(named.matrix, symbols.matrix)
    with pytest.raises(ValueError, match=r"`equilibrium`: 'z' is neither a coordinate .*'x', 'y'"):
        cartesian.system.linearize({"x": 0.0, "z": -1.0}, params=cartesian.params)


# --- F3: the guess ---------------------------------------------------------------------------


def test_a_failed_solve_names_its_start_and_suggests_a_guess(cartesian):
    """x = 0.8 leaves y to solve from x² + y² = 1; Newton's method from y = 0, where ∂g/∂y = 0,
    cannot move: the message said "from `guess`" though none was given."""
    x, y = cartesian.system.coordinates
    with pytest.raises(ValueError, match=r"max \|g\(q0\)\| = 0\.36 \(y\(t\) solved for by "
                       r"Newton's method from the default start y\(t\) = 0, no `guess` "
                       r"given: pass `guess`"):  # fmt: skip
        cartesian.system.simulate((0, 2), q0={x: 0.8}, params=cartesian.params)
    with pytest.raises(ValueError, match=r"from `guess` y\(t\) = 0: pass another `guess`"):
        cartesian.system.simulate((0, 2), q0={x: 0.8}, guess={y: 0.0}, params=cartesian.params)
    sol = cartesian.system.simulate((0, 2), q0={x: 0.8}, guess={y: -0.1}, t_eval=[0, 2],
                                    params=cartesian.params)  # fmt: skip
    assert sol.q[0, 1] == pytest.approx(-0.6, abs=1e-14)


def test_a_guess_without_effect_is_refused(cartesian):
    x, y = cartesian.system.coordinates
    with pytest.raises(ValueError, match=r"`guess`: x\(t\) is given in `q0`"):
        cartesian.system.simulate((0, 1), q0={x: 0.8}, guess={x: 0.5, y: -0.5},
                                  params=cartesian.params)  # fmt: skip
    with pytest.raises(ValueError, match=r"`guess`: x\(t\), y\(t\) are given in `q0`"):
        cartesian.system.simulate((0, 1), q0={x: 0.6, y: -0.8}, guess={x: 0.5, y: -0.5},
                                  params=cartesian.params)  # fmt: skip
    polar = models.pendulum_polar()
    (th,) = polar.system.coordinates
    with pytest.raises(ValueError, match=r"`guess`: the system has no holonomic constraints"):
        polar.system.simulate((0, 1), q0={th: 0.1}, guess={th: 0.1}, params=polar.params)


def test_floquet_of_a_constrained_point_still_runs(cartesian):
    """The Floquet run from a constrained operating point passes a guess only for the
    coordinates it solves for."""
    x, y = cartesian.system.coordinates
    lin = cartesian.system.linearize({x: 0.0, y: -1.0}, params=cartesian.params)
    f = lin.floquet(period=0.5)
    expected = np.exp(lin.eigenvalues * 0.5)
    np.testing.assert_allclose(np.sort_complex(f.multipliers), np.sort_complex(expected),
                               atol=1e-9)  # fmt: skip


def test_a_model_guesses_only_the_coordinates_q0_leaves_out():
    """``Model.simulate`` passes its default ``guess`` for the coordinates ``q0`` omits: a user
    who gives every coordinate is not refused for a guess they never passed."""
    m = models.sliding_ladder()
    L, theta = float(m.params[m.symbols["L"]]), 0.3
    x_c, y_c = (L / 2) * math.sin(theta), (L / 2) * math.cos(theta)
    full = m.simulate((0, 0.2), q0={"x_c": x_c, "y_c": y_c, "theta": theta})
    part = m.simulate((0, 0.2))  # theta alone: x_c, y_c solved from the model's guess
    np.testing.assert_allclose(full.q, part.q, rtol=0, atol=1e-12)
