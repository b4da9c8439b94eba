"""Events (solve_ivp's contract) on Lagrangian and rigid-body runs, and one-sided
constraints that let go when their reaction vanishes, against closed forms."""

from __future__ import annotations

import numpy as np
import oracle
import pytest

from poinsot import Gravity, RigidBody, models, simulate
from poinsot.integrate.events import EventError, integrate_with_events


def test_sliding_ladder_leaves_the_wall_at_two_thirds_of_its_height():
    # from rest at θ0 (from the wall), the wall's reaction vanishes at cos θ = ⅔ cos θ0
    # (Kleppner & Kolenkow, An Introduction to Mechanics, problem 7.9)
    mdl = models.sliding_ladder()
    s = mdl.symbols
    for th0 in (0.3, 0.7):
        sol = mdl.simulate((0, 0.85), q0={s["theta"]: th0}, t_eval=np.linspace(0, 0.85, 86))
        ((t_r, constraint, state),) = sol.releases
        assert "x_c" in constraint
        assert np.cos(state[2]) == pytest.approx(2 / 3 * np.cos(th0), rel=1e-8)
        after = sol.t > t_r
        wall = list(mdl.reactions).index("wall reaction N_wall")
        assert np.all(sol.multipliers[after, wall] == 0)
        assert np.all(sol.multipliers[~after, wall] >= -1e-9)  # it pushed until it let go
        # no horizontal force after the release: ẋ_c stays what it was
        np.testing.assert_allclose(sol.qd[after, 0], state[3], rtol=1e-8)
        gap = sol.q[after, 0] - np.sin(sol.q[after, 2])  # x_top = x_c − (L/2) sin θ, L = 2
        assert np.all(gap > 0)  # the top moves away from the wall
        assert np.all(np.isnan(sol.constraint_residual[after, 1]))


def test_lagrangian_events_terminal_and_directional():
    mdl = models.pendulum_polar()
    s = mdl.symbols
    th0 = 0.3

    def through_bottom(t, y):
        return y[0]

    through_bottom.direction = -1  # falling through θ = 0 only

    def stop_at_turn(t, y):
        return y[1]

    stop_at_turn.terminal = True
    stop_at_turn.direction = 1  # θ̇ rising through zero: the far turning point

    sol = mdl.simulate((0, 10), q0={s["theta"]: th0}, t_eval=np.linspace(0, 10, 101),
                       events=[through_bottom, stop_at_turn])  # fmt: skip
    # the bob passes the bottom going left at T/4 and turns at T/2; T by the elliptic integral
    from scipy.special import ellipk

    T = 4 * ellipk(np.sin(th0 / 2) ** 2) / np.sqrt(9.81)
    np.testing.assert_allclose(sol.t_events[0], [T / 4], rtol=1e-8)
    np.testing.assert_allclose(sol.t_events[1], [T / 2], rtol=1e-8)
    assert sol.terminated and sol.t[-1] == pytest.approx(T / 2, rel=1e-10)
    assert sol.q[-1, 0] == pytest.approx(-th0, rel=1e-7)


def test_rigid_body_events_ballistic_landing_and_refusals():
    body = RigidBody.box(1.0, (0.2, 0.2, 0.2))

    def ground(t, y):
        return y[2]  # R_z

    ground.terminal, ground.direction = True, -1
    tr = simulate(body, (0, 5), omega0=(0, 0, 1), R0=(0, 0, 10), V0=(0, 0, 5),
                  forces=[Gravity((0, 0, -9.81))], events=ground)  # fmt: skip
    t_land = (5 + np.sqrt(25 + 2 * 9.81 * 10)) / 9.81
    np.testing.assert_allclose(tr.t_events[0], [t_land], rtol=1e-12)
    assert tr.t[-1] == pytest.approx(t_land) and abs(tr.R[-1, 2]) < 1e-9
    with pytest.raises(TypeError, match=r"`events\[0\]` must be a function g\(t, y\)"):
        simulate(body, (0, 1), omega0=(0, 0, 1), events=[3])


def test_non_terminal_events_count_every_crossing():
    # t ↦ sin t on a trivial segment: zeros at π, 2π, 3π
    def segment(ta, ya, tb, times):
        return np.array([[np.sin(t)] for t in times])

    def g(t, y):
        return y[0]

    t, _, log = integrate_with_events(segment, g, 0.0, [0.0], 10.0, np.linspace(0, 10, 11),
                                      resolution=101)  # fmt: skip
    np.testing.assert_allclose(log.t_events[0], [np.pi, 2 * np.pi, 3 * np.pi], rtol=1e-12)
    assert log.terminated_by is None and len(t) == 11


@pytest.mark.parametrize("direction", [0, 1, -1])
def test_an_event_evaluated_on_the_grid_at_once_finds_what_the_pointwise_event_finds(direction):
    # sin t and cos 3t on a trivial segment, each event given pointwise and with `batch`:
    # the same zeros, in the event's direction (sin: π, 2π, 3π; cos 3t: every π/3 from π/6)
    def segment(ta, ya, tb, times):
        return np.array([[np.sin(t), np.cos(3 * t)] for t in times])

    def pointwise(c):
        def g(t, y):
            return y[c]

        g.direction = direction
        return g

    def batched(c):
        g = pointwise(c)
        calls = []

        def many(t, Y):
            calls.append(len(t))
            return Y[:, c]

        g.batch = many
        return g, calls

    times = np.linspace(0, 10, 11)
    plain = integrate_with_events(segment, [pointwise(0), pointwise(1)], 0.0, [0.0, 1.0], 10.0,
                                  times, resolution=201)  # fmt: skip
    (g0, c0), (g1, c1) = batched(0), batched(1)
    fast = integrate_with_events(segment, [g0, g1], 0.0, [0.0, 1.0], 10.0, times,
                                 resolution=201)  # fmt: skip
    assert c0 == c1 == [201]  # the grid in one call each
    for k in range(2):
        np.testing.assert_array_equal(plain[2].t_events[k], fast[2].t_events[k])
    zeros_sin = np.pi * np.arange(1, 4)
    zeros_cos = np.pi / 6 + np.pi / 3 * np.arange(10)
    zeros_cos = zeros_cos[zeros_cos < 10]
    # sin falls through zero at odd multiples of π; cos 3t falls at π/6 + 2kπ/3
    want_sin = {0: zeros_sin, 1: zeros_sin[1::2], -1: zeros_sin[::2]}[direction]
    want_cos = {0: zeros_cos, 1: zeros_cos[1::2], -1: zeros_cos[::2]}[direction]
    np.testing.assert_allclose(fast[2].t_events[0], want_sin, rtol=1e-12)
    np.testing.assert_allclose(fast[2].t_events[1], want_cos, rtol=1e-12)


@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_the_core_locates_a_release_where_the_oracle_does(method):
    # the ladder's release located inside the core's time loop (compiled engine) and by the
    # reference oracle (SymPy's lambdify, NumPy's solve, SciPy's DOP853 and its event search,
    # the released system derived again): the same instant, the same state, and the same
    # motion after it
    mdl = models.sliding_ladder()
    th = mdl.symbols["theta"]
    run = dict(q0={th: 0.3}, t_eval=np.linspace(0, 0.85, 86), method=method)
    if method == "rk4":
        run["dt"] = 1e-3
    core = mdl.simulate((0, 0.85), **run)
    numpy = oracle.simulate(mdl, (0, 0.85), **run)
    ((t_core, name, y_core),), ((t_np, name_np, y_np),) = core.releases, numpy.releases
    assert name == name_np
    tol = 1e-9 if method == "dop853" else 1e-7
    assert t_core == pytest.approx(t_np, rel=tol)
    np.testing.assert_allclose(y_core, y_np, rtol=tol, atol=tol)
    np.testing.assert_allclose(core.q, numpy.q, rtol=1e-6, atol=1e-6)
    # Kleppner & Kolenkow 7.9: cos θ = ⅔ cos θ0 at the release
    assert np.cos(y_core[2]) == pytest.approx(2 / 3 * np.cos(0.3), rel=tol)


@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_core_events_with_each_method_match_the_pendulums_closed_form(method):
    # the pendulum's bottom passages (T/4, 3T/4, ...) as a compiled expression and as a
    # Python function (the slow path, called back from the core), with the adaptive and a
    # fixed-step method: the zeros of the closed form, T by the elliptic integral
    from scipy.special import ellipk

    from poinsot.integrate.events import Event

    mdl = models.pendulum_polar()
    s = mdl.symbols
    th0 = 0.3
    T = 4 * ellipk(np.sin(th0 / 2) ** 2) / np.sqrt(9.81)
    options = {"dt": 1e-3} if method == "rk4" else {}
    sol = mdl.simulate((0, 5), q0={s["theta"]: th0}, method=method,
                       events=[Event(s["theta"]), lambda t, y: y[0]], **options)  # fmt: skip
    want = T / 4 + T / 2 * np.arange(int((5 - T / 4) // (T / 2)) + 1)
    tol = 1e-9 if method == "dop853" else 1e-10
    for k in range(2):
        np.testing.assert_allclose(sol.t_events[k], want, rtol=tol)
        np.testing.assert_allclose(sol.y_events[k][:, 0], 0, atol=1e-12)
    np.testing.assert_array_equal(sol.t_events[0], sol.t_events[1])
    assert not sol.terminated and sol.t[-1] == 5


def test_an_event_function_that_raises_stops_the_run_with_its_error():
    mdl = models.pendulum_polar()

    def broken(t, y):
        if t > 0.5:
            raise ZeroDivisionError("the user's event broke")
        return y[0] - 1.0

    with pytest.raises(EventError, match=r"`events\[0\]` raised ZeroDivisionError at "
                                         r"t = 0\.5.*: the user's event broke") as err:  # fmt: skip
        mdl.simulate((0, 1), events=broken)
    assert isinstance(err.value.__cause__, ZeroDivisionError)  # the user's own, kept
    # one that returns no number is named, among the run's events
    with pytest.raises(EventError, match=r"`events\[1\]` returned None at t = 0: an event "
                                         r"must return a number"):  # fmt: skip
        mdl.simulate((0, 1), events=[lambda t, y: y[0], lambda t, y: None])


@pytest.mark.parametrize("direction", [0, 1, -1])
def test_an_expression_event_is_compiled_and_finds_the_functions_zeros(direction):
    # the bob's horizontal offset l sin θ − 0.1 (a parameter in it), and θ̇: as SymPy
    # expressions compiled in the core, and as Python functions of y = [θ, θ̇]: the same zeros
    import sympy as sp

    from poinsot.integrate.events import Event

    mdl = models.pendulum_polar()
    s = mdl.symbols
    th, ell = s["theta"], s["l"]
    length = mdl.params[ell]

    def offset(t, y):
        return length * np.sin(y[0]) - 0.1

    def rate(t, y):
        return y[1]

    offset.direction = rate.direction = direction
    by_function = mdl.simulate((0, 6), events=[offset, rate])
    by_expression = mdl.simulate(
        (0, 6),
        events=[
            Event(ell * sp.sin(th) - sp.Rational(1, 10), direction=direction),
            Event(sp.diff(th), direction=direction),
        ],
    )
    for k in range(2):
        assert len(by_function.t_events[k]) >= 2
        np.testing.assert_allclose(by_expression.t_events[k], by_function.t_events[k],
                                   rtol=0, atol=1e-12)  # fmt: skip
        np.testing.assert_allclose(by_expression.y_events[k], by_function.y_events[k],
                                   rtol=0, atol=1e-10)  # fmt: skip
    # a terminal expression ends the run at its zero, as the function does
    stop = mdl.simulate((0, 6), events=Event(sp.diff(th), terminal=True, direction=1))
    assert stop.terminated and stop.t[-1] == pytest.approx(stop.t_events[0][0], abs=0)


def test_expression_events_are_refused_where_they_cannot_be_compiled():
    import sympy as sp

    from poinsot.integrate.events import Event

    mdl = models.pendulum_polar()
    stranger = sp.Symbol("stranger")
    with pytest.raises(ValueError, match=r"`events\[1\]` = stranger.*stranger"):
        mdl.simulate((0, 1), events=[lambda t, y: y[0], stranger])
    # a rigid body's run takes functions: an expression is refused, named, with the reason
    with pytest.raises(TypeError, match=r"`events\[0\]`.*constrained system"):
        simulate(RigidBody(1.0, np.eye(3)), (0, 1), omega0=(0, 0, 1), events=Event(stranger))
    with pytest.raises(TypeError, match=r"`events\[0\]` must be a function g\(t, y\) or an Event"):
        simulate(RigidBody(1.0, np.eye(3)), (0, 1), omega0=(0, 0, 1), events=[3.0])


def test_detection_points_within_long_steps_find_zeros_a_step_would_hide():
    # sin(20 t), an event in time alone, has a zero every π/20 s: the adaptive method's steps
    # on the pendulum at rtol 1e-6 are longer, so with detection at the step ends only
    # (event_resolution=2: one interval over the run) zeros pair up and vanish, while the
    # default detection points (no further apart than 2001 on the run) find every one, each
    # at kπ/20 to round-off (the event does not depend on the state's accuracy)
    import sympy as sp

    from poinsot.integrate.events import Event

    mdl = models.pendulum_polar()
    t = mdl.system.t
    run = dict(rtol=1e-6, atol=1e-8, events=Event(sp.sin(20 * t)))
    fine = mdl.simulate((0, 10), **run)
    coarse = mdl.simulate((0, 10), event_resolution=2, **run)
    want = np.pi / 20 * np.arange(1, 64)
    np.testing.assert_allclose(fine.t_events[0], want, rtol=0, atol=1e-12)
    assert len(coarse.t_events[0]) < len(want)
