"""Parameter ensembles of Lagrangian systems: every member is the single run with its own
parameters (same compiled driver), whatever the chunking or threads; closed forms across the
members; clear refusals."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import models


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("POINSOT_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "engine"))


def test_members_are_the_single_runs_whatever_the_chunks():
    mdl = models.pendulum_on_cart()
    s = mdl.symbols
    masses = np.array([0.5, 1.0, 2.0, 4.0, 8.0])
    angles = np.linspace(0.2, 1.4, 5)
    t = np.linspace(0, 2, 11)
    kw = {"qd0": mdl.qd0, "t_eval": t}
    params = {**mdl.params, s["M"]: masses}
    ens = mdl.system.simulate_ensemble((0, 2), q0={s["x"]: 0.0, s["theta"]: angles},
                                       params=params, **kw)  # fmt: skip
    assert ens.success.all() and ens.q.shape == (5, 11, 2) and len(ens) == 5
    for i in (0, 4):
        one = mdl.simulate((0, 2), q0={s["x"]: 0.0, s["theta"]: angles[i]}, t_eval=t,
                           params={**mdl.params, s["M"]: masses[i]}, engine="compiled")  # fmt: skip
        assert np.array_equal(ens.q[i], one.q)  # the same compiled driver, the same steps
        np.testing.assert_allclose(ens.energy[i], one.energy, rtol=1e-14)
    for threads, chunk in ((1, None), (2, 1), (2, 3)):
        other = mdl.system.simulate_ensemble((0, 2), q0={"x": 0.0, "theta": angles},
                                             params=params, threads=threads, chunk_size=chunk,
                                             **kw)  # fmt: skip
        assert np.array_equal(other.q, ens.q)
    np.testing.assert_array_equal(ens.parameters[s["M"]], masses)


def test_small_oscillation_periods_across_lengths():
    """θ(t) = θ0 cos(√(g/l) t) for small θ0: every member against its closed form."""
    mdl = models.pendulum_polar()
    th, l, g = (mdl.symbols[k] for k in ("theta", "l", "g"))
    lengths = np.linspace(0.2, 3.0, 40)
    t = np.linspace(0, 3, 31)
    ens = mdl.system.simulate_ensemble((0, 3), q0={th: 1e-4}, t_eval=t,
                                       params={**mdl.params, l: lengths})  # fmt: skip
    exact = 1e-4 * np.cos(np.sqrt(mdl.params[g] / lengths)[:, None] * t)
    np.testing.assert_allclose(ens[th], exact, atol=1e-11)  # amplitude correction ~ θ0³


def test_constrained_members_solve_their_dependent_coordinates_and_keep_the_constraints():
    """The Atwood machine with per-member masses: dependent coordinates and velocities solved
    for each member; the acceleration a = (m1 − m2) g / (m1 + m2 + I/r²) in closed form, and the
    multipliers the tensions of the single runs."""
    mdl = models.atwood_machine()
    s, p = mdl.symbols, mdl.params
    m1 = np.array([1.0, 2.0, 3.0])
    ens = mdl.system.simulate_ensemble((0, 1), q0={s["y1"]: 0.0}, params={**p, s["m1"]: m1},
                                       stabilization="projection", t_eval=[0, 1])  # fmt: skip
    assert ens.success.all()
    for i in range(3):
        one = mdl.simulate((0, 1), params={**p, s["m1"]: m1[i]}, t_eval=[0, 1],
                           stabilization="projection", engine="compiled")  # fmt: skip
        np.testing.assert_allclose(ens.q[i], one.q, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(ens.samples(i)["lam"], one.multipliers, rtol=1e-12)
        res = ens.samples(i)["g"]
        assert np.abs(res).max() < 1e-12


def test_fixed_step_ensembles_and_failed_members():
    """RK4 members; a member whose run becomes non-finite gets NaN samples and its status,
    its neighbours their own results."""
    from poinsot._core import FINISHED, NONFINITE

    mdl = models.pendulum_polar()
    th, g, l, m = (mdl.symbols[k] for k in ("theta", "g", "l", "m"))
    # member 1: θ̈ = −(g/l) sin θ with g/l = 1e310 overflows once θ leaves 0
    params = {g: [9.81, 1e160, 9.81], l: [1.0, 1e-150, 1.0], m: 1.0}
    ens = mdl.system.simulate_ensemble((0, 1), q0={th: [0.1, 0.0, 0.3]}, qd0={th: [0, 1, 0]},
                                       method="rk4", dt=1e-3, t_eval=[0, 1],
                                       params=params)  # fmt: skip
    assert ens.status.tolist() == [FINISHED, NONFINITE, FINISHED]
    assert np.isnan(ens.q[1]).all() and np.isfinite(ens.q[[0, 2]]).all()
    one = mdl.simulate((0, 1), q0={th: 0.3}, method="rk4", dt=1e-3, t_eval=[0, 1],
                       engine="compiled")  # fmt: skip
    assert np.array_equal(ens.q[2], one.q)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        (
            {"params": {"l": [1.0, 2.0]}, "q0": {"theta": [0.1, 0.2, 0.3]}},
            ValueError,
            r"one length, found params\[l\]: 2, q0\[theta\]: 3",
        ),
        ({"params": {"zeta": 1.0}}, ValueError, r"`params`: 'zeta' is not one of g, l, m"),
        ({"params": {"l": 1.0}}, ValueError, "`params` must give every parameter: missing g, m"),
        ({"params": {"l": [[1.0]]}}, ValueError, r"`params\[l\]` must be a number or a 1-D"),
        ({"params": {"l": [1.0, np.nan]}}, ValueError, r"`params\[l\]\[1\]` must be finite"),
        ({"q0": {"theta": lambda t: t}}, TypeError, "takes numbers"),
        ({"q0": {"phi": 0.1}}, ValueError, r"`q0`: 'phi' is not one of theta"),
        ({"params": {"m": [1.0, 0.0]}}, ValueError, r"`params\[m\]` must be positive .*member 1"),
        ({"threads": 0}, ValueError, "`threads` must be a positive integer"),
        ({"method": "rk4"}, ValueError, "`dt` must be given"),
        ({"method": "splitting"}, ValueError, "integrates rigid bodies"),
    ],
)
def test_bad_input_is_refused_named(kwargs, error, match):
    mdl = models.pendulum_polar()
    base = {"q0": {"theta": 0.1}, "params": {"g": 9.81, "l": 1.0, "m": 1.0}}
    given = kwargs.pop("params", {})
    params = {"l": 1.0} if "missing" in match else {**base["params"], **given}
    call = {**base, "params": params, **kwargs}
    with pytest.raises(error, match=match):
        mdl.system.simulate_ensemble((0, 1), **call)


def test_an_inconsistent_member_is_named():
    mdl = models.pendulum_cartesian()
    x, y = mdl.symbols["x"], mdl.symbols["y"]
    with pytest.raises(ValueError, match="member 2: `q0`: inconsistent initial conditions"):
        mdl.system.simulate_ensemble((0, 1), q0={x: [0.0, 0.6, 0.9], y: [-1.0, -0.8, -0.9]},
                                     params=mdl.params)  # fmt: skip


def test_an_adaptive_member_stops_at_the_step_budget(monkeypatch):
    """The budget holds for adaptive members too: an ensemble whose members' estimated steps
    exceed ``max_steps`` is refused before it runs (issue 44), and a member that still
    reaches it (the estimate skipped here) stops there (status 0, NaN samples); with room
    enough the same ensemble finishes."""
    from poinsot.integrate.solve import StepBudgetError
    from poinsot.lagrange import ensemble
    from poinsot.models import pendulum_polar

    mdl = pendulum_polar()
    th, l = mdl.symbols["theta"], mdl.symbols["l"]
    kw = {"q0": {th: 1.0}, "params": {**mdl.params, l: [0.5, 1.0]}}
    with pytest.raises(StepBudgetError, match="member 0 of 2") as err:
        mdl.system.simulate_ensemble((0, 50), max_steps=20, **kw)
    assert err.value.needed > 20
    with monkeypatch.context() as m:
        m.setattr(ensemble, "_check_members_budget", lambda *a: None)
        cut = mdl.system.simulate_ensemble((0, 50), max_steps=20, **kw)
    assert (cut.status == 0).all() and np.isnan(cut.q).all() and (cut.nsteps == 20).all()
    done = mdl.system.simulate_ensemble((0, 50), **kw)
    assert done.success.all() and np.isfinite(done.q).all()


@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_one_sided_constraints_let_go_in_ensembles_as_in_single_runs(method):
    # sliding ladders from three angles: each member's wall lets go where its reaction
    # vanishes (cos θ = ⅔ cos θ0, Kleppner & Kolenkow 7.9), located inside the core's time
    # loop, and each member equals its single run bit for bit (release instant, samples,
    # multipliers, evaluations), whatever the chunking and the threads
    mdl = models.sliding_ladder()
    system, th = mdl.system, mdl.symbols["theta"]
    th0 = np.array([0.3, 0.5, 0.7])
    run = dict(t_eval=np.linspace(0, 0.85, 86), method=method)
    if method == "rk4":
        run["dt"] = 1e-3
    singles = [mdl.simulate((0, 0.85), q0={th: a}, **run) for a in th0]
    # the single runs' completed initial states (the set-up's Newton iterations start from
    # different guesses, and may differ by an ulp)
    q0 = {c: np.array([s.q[0, j] for s in singles]) for j, c in enumerate(system.coordinates)}
    qd0 = {c: np.array([s.qd[0, j] for s in singles]) for j, c in enumerate(system.coordinates)}
    ens = system.simulate_ensemble((0, 0.85), q0=q0, qd0=qd0, params=mdl.params, **run)
    alone = system.simulate_ensemble((0, 0.85), q0=q0, qd0=qd0, params=mdl.params,
                                     chunk_size=1, threads=1, **run)  # fmt: skip
    assert ens.success.all()
    wall = list(mdl.reactions).index("wall reaction N_wall")
    for i, single in enumerate(singles):
        ((t_r, _, state),) = single.releases
        assert ens.releases[i, 0] == t_r == alone.releases[i, 0]
        np.testing.assert_array_equal(ens.q[i], single.q)
        np.testing.assert_array_equal(ens.qd[i], single.qd)
        np.testing.assert_array_equal(alone.q[i], single.q)
        assert ens.nfev[i] == single.nfev
        samples = ens.samples(i)
        np.testing.assert_array_equal(samples["lam"], single.multipliers)
        np.testing.assert_array_equal(samples["g"], single.constraint_residual)
        after = single.t >= t_r
        assert np.all(samples["lam"][after, wall] == 0) and after.any()
        assert np.cos(state[2]) == pytest.approx(2 / 3 * np.cos(th0[i]), rel=1e-7)
    with pytest.raises(ValueError, match="event_resolution"):
        system.simulate_ensemble((0, 0.85), q0=q0, qd0=qd0, params=mdl.params,
                                 event_resolution=np.nan, **run)  # fmt: skip


def test_an_adaptive_members_first_step_is_dt_as_in_a_single_run():
    """``dt`` with the adaptive method is its first step, in an ensemble as in a single run
    (it was ignored by ensembles): a member equals its single run bit for bit, and another
    first step gives other steps."""
    mdl = models.pendulum_on_cart()
    s = mdl.symbols
    t = np.linspace(0, 1, 6)
    angles = np.array([0.3, 0.9])
    q0 = {s["x"]: 0.0, s["theta"]: angles}
    runs = {}
    for first in (1e-6, 0.1):
        ens = mdl.system.simulate_ensemble((0, 1), q0=q0, qd0=mdl.qd0, params=mdl.params,
                                           t_eval=t, dt=first)  # fmt: skip
        one = mdl.simulate((0, 1), q0={s["x"]: 0.0, s["theta"]: angles[1]}, t_eval=t, dt=first)
        assert np.array_equal(ens.q[1], one.q) and ens.nfev[1] == one.nfev
        runs[first] = ens
    assert not np.array_equal(runs[1e-6].nfev, runs[0.1].nfev)


@pytest.mark.parametrize("bad", [-1, 0, 1, 2.5, 1e300, float("nan"), True, "many"])
def test_event_resolution_is_an_integer_from_two(bad):
    """``event_resolution`` is checked by name in every front-end (it was cast with int() and
    clamped, or ran into a memory error at 1e300)."""
    from poinsot import RigidBody, simulate

    mdl = models.sliding_ladder()
    th = mdl.symbols["theta"]
    match = "`event_resolution` must be an integer from 2"
    with pytest.raises(ValueError, match=match):
        mdl.simulate((0, 0.5), q0={th: 0.3}, event_resolution=bad)
    with pytest.raises(ValueError, match=match):
        mdl.system.simulate_ensemble((0, 0.5), q0={th: [0.3]}, params=mdl.params,
                                     event_resolution=bad)  # fmt: skip
    with pytest.raises(ValueError, match=match):
        simulate(RigidBody.box(1.0, (1, 2, 3)), (0, 1), omega0=(0, 1, 0),
                 events=lambda t, y: t - 0.5, event_resolution=bad)  # fmt: skip


def test_a_prepared_ensemble_runs_other_members_without_lowering_again(monkeypatch):
    """``system.prepare_ensemble`` checks the run and compiles the model once; its ``run``
    takes any members (parameters, initial states), each bit for bit the one-call ensemble's,
    and lowers nothing again (neither the compiler nor the settings' check is called)."""
    from poinsot.lagrange import engine
    from poinsot.lagrange import ensemble as lagrange_ensemble

    mdl = models.pendulum_on_cart()
    s = mdl.symbols
    t = np.linspace(0, 1, 6)
    sets = [{"q0": {s["x"]: 0.0, s["theta"]: np.linspace(0.2, 0.6, len(masses))},
             "qd0": mdl.qd0, "params": {**mdl.params, s["M"]: masses}}
            for masses in ([0.5, 1.0], [2.0, 4.0, 8.0])]  # fmt: skip
    once = [mdl.system.simulate_ensemble((0, 1), t_eval=t, **members) for members in sets]
    prepared = mdl.system.prepare_ensemble((0, 1), t_eval=t)

    def refuse(*args, **kwargs):
        raise AssertionError("lowered or checked again")

    monkeypatch.setattr(engine, "compile_system", refuse)
    monkeypatch.setattr(lagrange_ensemble, "check_settings", refuse)
    for members, expected in zip(sets, once, strict=True):
        ens = prepared.run(**members)
        assert np.array_equal(ens.q, expected.q) and len(ens) == len(expected)
    with pytest.raises(AssertionError, match="lowered or checked again"):
        mdl.system.simulate_ensemble((0, 1), t_eval=t, **sets[0])  # the patch is in effect
    monkeypatch.undo()
    with pytest.raises(ValueError, match="`threads` must be a positive integer"):
        mdl.system.prepare_ensemble((0, 1), threads=0)
