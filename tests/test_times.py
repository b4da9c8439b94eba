"""Times everywhere (issue 26): every public function that takes times refuses NaN and ±inf by
name, and an empty array of times gives empty results, the same way in every function: the
closed forms evaluate at no time, and a run with an empty ``t_eval`` is integrated to its end
(its failures and counters are those of the run) and keeps none of its states
(``docs/reliability.md``)."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import FreeRigidBody, RigidBody, simulate
from poinsot.ensemble import simulate_ensemble
from poinsot.models import pendulum_cartesian, pendulum_polar
from poinsot.relative import Carrier, simulate_relative

FREE = FreeRigidBody((1.0, 2.0, 3.0))
W0 = (0.1, 1.0, 0.1)
BOX = RigidBody.box(1.0, (1.0, 2.0, 3.0))
CARRIERS = {
    "constant": Carrier(omega_e=(0, 0, 1)),
    "expressions": Carrier(omega_e=["0", "0", "sin(t)"]),
    "python": Carrier(omega_e=lambda t: (0, 0, t), epsilon_e=lambda t: (0, 0, 1)),
    "euler angles": Carrier(euler_angles=["t", "0", "0"]),
}

#: name → (function of t, the shape of one time's result)
EVALUATORS = {
    "exact_omega": (lambda t: FREE.exact_omega(W0, t), (3,)),
    "exact_omega (many)": (lambda t: FREE.exact_omega([W0, W0], t)[0], (3,)),
    "exact_attitude": (lambda t: FREE.exact_attitude(W0, t), (3, 3)),
    "herpolhode": (lambda t: FREE.herpolhode(W0, t), (3,)),
    "fixed_point_attitude": (lambda t: FREE.fixed_point_attitude((0, 1, 0), t), (3, 3)),
    "fixed_point_attitude (jordan)": (
        lambda t: FREE.fixed_point_attitude((0, 1, 0), t, method="jordan"), (3, 3)),
    **{f"carrier motions, {k}": (c.motions, (9,)) for k, c in CARRIERS.items()},
    "carrier omega_e": (lambda t: CARRIERS["expressions"].omega_e(t), (3,)),
    "carrier attitude": (lambda t: CARRIERS["euler angles"].attitude(np.atleast_1d(t)), (3, 3)),
}  # fmt: skip


@pytest.mark.parametrize("name", sorted(EVALUATORS))
@pytest.mark.parametrize("bad", [np.inf, -np.inf, np.nan, [0.0, 1.0, np.inf], [np.nan]])
def test_non_finite_times_are_refused_by_name(name, bad):
    fn, _ = EVALUATORS[name]
    with pytest.raises(ValueError, match=r"`t(\[\d\])?` must be finite, found"):
        fn(bad)


@pytest.mark.parametrize("name", sorted(EVALUATORS))
def test_empty_times_give_empty_results_and_times_are_evaluated_one_by_one(name):
    fn, shape = EVALUATORS[name]
    assert fn([]).shape == (0, *shape)
    assert fn(np.array([])).shape == (0, *shape)
    t = np.array([0.0, 0.4, 1.7])
    many = fn(t)
    assert many.shape == (3, *shape)
    for k, tk in enumerate(t):  # the same numbers, time by time
        np.testing.assert_allclose(fn([tk])[0], many[k], rtol=1e-13, atol=1e-13)


def test_the_herpolhode_lies_on_the_invariable_plane():
    """Its z-component is 2k/a at every time (Poinsot), however the times are given."""
    k, a = FREE.invariants(W0)
    h = FREE.herpolhode(W0, np.linspace(5.0, 30.0, 7))
    np.testing.assert_allclose(h[:, 2], 2 * k / a, rtol=1e-12)
    with pytest.raises(ValueError, match="`omega0` must not be zero"):
        FREE.herpolhode((0, 0, 0), [0.0])


def _runs(t_eval):
    """Every front-end that integrates, with the given sample times: name → (result, samples
    of the result, something the run itself decides)."""
    stop = lambda t, y: y[2] + 100.0  # noqa: E731 - an event that never fires
    pend, polar = pendulum_cartesian(), pendulum_polar()
    out = {}
    tr = simulate(BOX, (0, 1), omega0=(0, 1, 1), t_eval=t_eval)
    out["simulate"] = (tr, tr.t, tr.nfev)
    tr = simulate(BOX, (0, 1), omega0=(0, 1, 1), method="rk4", dt=0.01, t_eval=t_eval)
    out["simulate rk4"] = (tr, tr.t, tr.nsteps)
    tr = simulate(BOX, (0, 1), omega0=(0, 1, 1), t_eval=t_eval, events=stop)
    out["simulate with events"] = (tr, tr.t, tr.t_events[0].shape + tr.y_events[0].shape)
    rel = simulate_relative(BOX, (0, 1), omega_r0=(0, 1, 0), carrier=CARRIERS["constant"],
                            t_eval=t_eval)  # fmt: skip
    out["simulate_relative"] = (rel, rel.t, rel.nfev)
    ens = simulate_ensemble(BOX, (0, 1), omega0=[(0, 1, 1), (0.1, 1, 0)], dt=0.01,
                            t_eval=t_eval)  # fmt: skip
    out["simulate_ensemble"] = (ens, ens.t, tuple(ens.final_state.ravel()))
    sol = pend.simulate((0, 1), t_eval=t_eval)
    out["LagrangianSystem.simulate"] = (sol, sol.t, sol.nfev)
    lens = polar.system.simulate_ensemble((0, 1), q0=polar.q0, params=polar.params,
                                          t_eval=t_eval)  # fmt: skip
    out["LagrangianSystem.simulate_ensemble"] = (lens, lens.t, tuple(lens.nfev))
    return out


def test_an_empty_t_eval_runs_to_the_end_and_keeps_no_samples():
    empty, end = _runs([]), _runs([1.0])
    for name, (result, t, decided) in empty.items():
        assert t.shape == (0,), name
        assert decided == end[name][2], name  # the same run, integrated to t1
        repr(result)  # every result prints
    tr = empty["simulate"][0]
    assert tr.omega.shape == (0, 3) and tr.Q.shape == (0, 3, 3) and tr.energy_drift.shape == (0,)
    s = tr.summary()
    assert s["samples"] == 0 and s["t_start"] is None and np.isnan(s["diagnostics"]["energy_drift"])
    assert empty["simulate_ensemble"][0].omega.shape == (2, 0, 3)
    assert empty["LagrangianSystem.simulate"][0].q.shape == (0, 2)
    assert np.isnan(empty["simulate_relative"][0].hodograph_ratio())
    with pytest.raises(ValueError, match="`reductions` are evaluated at the samples"):
        simulate_ensemble(BOX, (0, 1), omega0=[(0, 1, 1)], dt=0.01, t_eval=[],
                          reductions={"f": lambda chunk: chunk.omega[:, 0, 0]})  # fmt: skip


@pytest.mark.parametrize("bad", [[0.0, np.inf], [np.nan], [0.5, np.nan, 0.7]])
def test_every_run_refuses_non_finite_sample_times_by_name(bad):
    pend = pendulum_cartesian()
    calls = [
        lambda: simulate(BOX, (0, 1), omega0=(0, 1, 1), t_eval=bad),
        lambda: simulate_relative(BOX, (0, 1), omega_r0=(0, 1, 0), carrier=CARRIERS["constant"],
                                  t_eval=bad),
        lambda: simulate_ensemble(BOX, (0, 1), omega0=[(0, 1, 1)], dt=0.01, t_eval=bad),
        lambda: pend.simulate((0, 1), t_eval=bad),
        lambda: pend.system.simulate_ensemble((0, 1), q0=pend.q0, params=pend.params,
                                              t_eval=bad),
    ]  # fmt: skip
    for call in calls:
        with pytest.raises(ValueError, match=r"`t_eval\[\d\]` must be finite"):
            call()


def test_an_event_that_never_fires_leaves_empty_logs():
    """``y_events`` of an event without zeros is (0, 18) (it raised a reshape error)."""
    tr = simulate(BOX, (0, 1), omega0=(0, 1, 1), events=lambda t, y: y[2] + 100.0)
    assert tr.t_events[0].shape == (0,) and tr.y_events[0].shape == (0, 18)


@pytest.mark.parametrize("name", ["exact_omega", "exact_attitude", "herpolhode"])
def test_times_beyond_what_double_precision_resolves_are_refused(name):
    """|ω| |t| beyond 2⁵² rad: the phase is lost to rounding (a spin of 1e300 rad/s gave NaN
    attitudes at t = 1, and t = 1e100 gave noise); the same motion at resolvable times is
    finite and keeps its invariants."""
    fn = getattr(FREE, name)
    for w, t in (((0.0, 0.0, 1e300), 1.0), (W0, 1e100), (W0, [0.0, -1e17])):
        with pytest.raises(ValueError, match=r"`t` = .* is beyond what double precision"):
            fn(w, t)
    fast = np.array([0.0, 0.0, 1e300])
    out = fn(fast, [0.0, 1e-300, 2e-300])
    assert np.isfinite(out).all()
    with pytest.raises(ValueError, match="beyond what double precision"):
        FREE.fixed_point_attitude(fast, 1.0)


@pytest.mark.parametrize("scale", [1e-300, 1e-150, 1.0, 1e150, 1e300])
def test_fixed_points_and_the_herpolhode_are_judged_at_any_scale(scale):
    """ω × Aω = 0 is a property of ω's direction: a spin of 1e-300 rad/s off the axes is not a
    fixed point (every tiny ω was one), and the invariable plane of a tiny ω exists."""
    assert FREE.is_fixed_point(np.array([0.0, 1.0, 0.0]) * scale)
    assert not FREE.is_fixed_point(np.array(W0) * scale)
    w = np.array(W0) * scale
    h = FREE.herpolhode(w, np.array([0.0, 1.0]) / scale)
    assert np.isfinite(h).all()
    k, a = FREE.invariants(W0)
    np.testing.assert_allclose(h[:, 2] / scale, 2 * k / a, rtol=1e-12)
