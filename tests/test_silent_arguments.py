"""Issue 44, no argument without effect: a tolerance given to a fixed-step method was ignored
without a word; it is refused, naming the argument and the methods that use it. ``dt`` given
to the adaptive method is its first step (as SciPy's ``first_step``): it has an effect."""

from __future__ import annotations

import re

import numpy as np
import pytest

from poinsot import RigidBody, simulate
from poinsot.app.scenario import ScenarioError, load_scenario
from poinsot.ensemble import simulate_ensemble

BOX = RigidBody.box(1.0, (1, 2, 3))


@pytest.mark.parametrize("method", ["rk4", "rkmk4", "splitting", "exact-splitting4"])
@pytest.mark.parametrize("name", ["rtol", "atol"])
def test_a_tolerance_given_to_a_fixed_step_method_is_refused(method, name):
    with pytest.raises(ValueError, match=rf"`{name}` has no effect on the fixed-step method "
                                         rf"'{method}'.*'dop853'"):  # fmt: skip
        simulate(BOX, (0, 1), omega0=(0, 1, 0.1), method=method, dt=0.01, **{name: 1e-6})
    with pytest.raises(ValueError, match=rf"`{name}` has no effect"):
        simulate_ensemble(BOX, (0, 1), omega0=np.ones((4, 3)), method=method, dt=0.01,
                          **{name: 1e-6})  # fmt: skip


def test_dt_is_the_adaptive_methods_first_step():
    """The first step is what ``dt`` says: a tiny one costs steps, and the result is the same
    motion to the tolerance."""
    a = simulate(BOX, (0, 1), omega0=(0, 1, 0.1), t_eval=[0, 1])
    b = simulate(BOX, (0, 1), omega0=(0, 1, 0.1), dt=1e-9, t_eval=[0, 1])
    assert b.nsteps > a.nsteps
    np.testing.assert_allclose(a.omega, b.omega, atol=1e-9)


def test_the_same_rule_holds_for_scenario_keys():
    text = ('[body]\ntype = "box"\nmass = 1.0\nsize = [1.0, 2.0, 3.0]\n[initial]\n'
            'omega = [0.0, 1.0, 0.1]\n[integrator]\nmethod = "rk4"\ndt = 0.01\nrtol = 1e-6\n'
            "[time]\nspan = [0.0, 1.0]\n")  # fmt: skip
    with pytest.raises(ScenarioError, match=r"`rtol` has no effect on the fixed-step method"):
        load_scenario(text)


@pytest.mark.parametrize("name", ["rtol", "atol"])
def test_a_lagrangian_run_refuses_tolerances_for_a_fixed_step_method(name):
    """Its tolerances defaulted to numbers, so a fixed-step run could not tell them given."""
    from poinsot.models import pendulum_cartesian

    with pytest.raises(ValueError, match=rf"`{name}` has no effect on the fixed-step method"):
        pendulum_cartesian().simulate((0, 0.5), method="rk4", dt=0.01, **{name: 1e-6})
    pendulum_cartesian().simulate((0, 0.5), method="rk4", dt=0.01)  # no tolerance: it runs


@pytest.mark.parametrize("atol", [1.0, 1e300])
def test_a_lagrangian_solution_off_its_constraints_warns(atol):
    """``atol = 1e300`` left a residual of 3.1e11 without a word; ``atol = 1`` left 0.20."""
    import warnings

    from poinsot.lagrange import ConstraintDriftWarning
    from poinsot.models import pendulum_cartesian

    given = re.escape(f"{atol:g}")
    with pytest.warns(ConstraintDriftWarning, match=rf"max \|g\(q, t\)\| = .*atol = {given}"):
        sol = pendulum_cartesian().simulate((0, 2), atol=atol)
    assert np.abs(sol.constraint_residual).max() > 1e-6
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the defaults hold the constraints: no warning
        sol = pendulum_cartesian().simulate((0, 2))
    assert np.abs(sol.constraint_residual).max() < 1e-9


def test_event_resolution_without_events_is_refused():
    """It was accepted at −1, 0 and 2.5 with no event to watch, and at 1e300 it stalled."""
    from poinsot.models import pendulum_cartesian, sliding_ladder

    for value in (-1, 0, 2.5, 1e300, 2001):
        with pytest.raises(ValueError, match="`event_resolution` has no effect: this run "
                                             "watches no events"):  # fmt: skip
            simulate(BOX, (0, 1), omega0=(0, 1, 0.1), event_resolution=value)
        with pytest.raises(ValueError, match="`event_resolution` has no effect"):
            pendulum_cartesian().simulate((0, 0.5), event_resolution=value)
    event = lambda t, y: t - 0.5  # noqa: E731
    with pytest.raises(ValueError, match=r"`event_resolution` must be an integer from 2 to "
                                         r"1e\+07, found 1e\+300"):  # fmt: skip
        simulate(BOX, (0, 1), omega0=(0, 1, 0.1), events=event, event_resolution=1e300)
    traj = simulate(BOX, (0, 1), omega0=(0, 1, 0.1), events=event, event_resolution=11)
    assert traj.t_events[0] == pytest.approx([0.5])
    ladder = sliding_ladder()  # one-sided: the release is watched on the grid
    assert ladder.simulate((0, 1), event_resolution=101).t[-1] == 1.0


def test_save_every_with_t_eval_is_refused():
    """The run keeps the states at `t_eval`; `save_every = 10` was ignored without a word."""
    with pytest.raises(ValueError, match="`save_every` = 10 has no effect with `t_eval`"):
        simulate(BOX, (0, 1), omega0=(0, 1, 0.1), t_eval=[0, 0.5, 1], save_every=10)
    assert len(simulate(BOX, (0, 1), omega0=(0, 1, 0.1), save_every=10, method="rk4",
                        dt=0.01).t) == 11  # fmt: skip


def test_threads_with_a_dask_client_is_refused():
    """The Dask workers run the chunks: `threads` was ignored. Refused before the client is
    even looked at."""
    with pytest.raises(ValueError, match="`threads` has no effect with `client`"):
        simulate_ensemble(BOX, (0, 1), omega0=np.ones((4, 3)), dt=0.01, threads=2,
                          client=object())  # fmt: skip


def test_baumgarte_gains_without_baumgarte_stabilisation_are_refused():
    from poinsot.models import pendulum_cartesian

    with pytest.raises(ValueError, match="`baumgarte` has no effect with "
                                         "stabilization='projection'"):  # fmt: skip
        pendulum_cartesian().simulate((0, 0.5), stabilization="projection", baumgarte=(1, 1))
    a = pendulum_cartesian().simulate((0, 0.5), baumgarte=(1, 1), t_eval=[0.5])
    b = pendulum_cartesian().simulate((0, 0.5), t_eval=[0.5])
    assert not np.array_equal(a.q, b.q)  # the gains have an effect where they apply


def test_a_whole_initial_state_is_checked_and_replaces_the_other_arguments():
    """``run(y0=...)`` had ignored ``omega0`` and ``Q0`` given beside it, taken a Q with
    det 8, and named a wrong shape only by a reshape's message."""
    from poinsot import Gravity
    from poinsot.simulation import prepare

    top = RigidBody(1.0, np.diag([0.02, 0.03, 0.04]), (0, 0, 0.2))
    run = prepare(top, (0, 0.1), forces=[Gravity()], pivot=(0, 0, 0), method="rk4", dt=0.01)
    y0 = run.initial_state(omega0=(0.3, 0.1, 5.0))
    a, b = run.run(y0=y0), run.run(omega0=(0.3, 0.1, 5.0))
    np.testing.assert_array_equal(a.omega, b.omega)
    for kw in ({"omega0": (5, 5, 5)}, {"Q0": np.eye(3)}, {"R0": (0, 0, 1)}):
        name = next(iter(kw))
        with pytest.raises(ValueError, match=rf"give `y0` or `{name}`, not both"):
            run.run(y0=y0, **kw)
    with pytest.raises(ValueError, match=r"`y0` must have shape \(18,\), found shape \(5,\)"):
        run.run(y0=y0[:5])
    bad = y0.copy()
    bad[17] = np.nan
    with pytest.raises(ValueError, match=r"`y0\[17\]` must be finite"):
        run.run(y0=bad)
    bad = y0.copy()
    bad[6:15] *= 2  # det 8
    with pytest.raises(ValueError, match=r"`y0\[6:15\] \(Q, row by row\)` is not a rotation"):
        run.run(y0=bad)
    bad = y0.copy()
    bad[3:6] += 1.0  # the centre of mass moving off the pivot's sphere
    with pytest.raises(ValueError, match=r"`y0\[3:6\]` \(V\): with a pivot the velocity follows"):
        run.run(y0=bad)
    with pytest.raises(ValueError, match="`omega_frame` has no effect with `y0`"):
        run.run(y0=y0, omega_frame="space")
    # with sensitivities it says the frame of the omega0 columns: accepted
    sens = prepare(top, (0, 0.1), forces=[Gravity()], pivot=(0, 0, 0), method="rk4", dt=0.01,
                   sensitivities="omega0")  # fmt: skip
    assert sens.run(y0=y0, omega_frame="space").sensitivity("omega", "omega0").shape[1:] == (3, 3)
