"""Every run has a bounded cost, or is refused up front (``poinsot.integrate.solve``): the step
budget ``max_steps`` for every front-end, and tolerances raised to what double precision
resolves."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from bounded import deadline
from poinsot import RigidBody, simulate
from poinsot.integrate.solve import DEFAULT_MAX_STEPS, RTOL_FLOOR, SimulationError, StepBudgetError
from poinsot.models import pendulum_cartesian
from poinsot.relative import Carrier, simulate_relative

BODY = RigidBody.box(1.0, (1.0, 2.0, 3.0))


@pytest.mark.parametrize(("t_span", "dt"), [((0, 1), 1e-300), ((0, 9.2e18), 1e-3), ((0, 1), 5e-9)])
def test_a_fixed_step_run_that_needs_too_many_steps_is_refused_with_the_count(t_span, dt):
    with pytest.raises(ValueError, match=r"the run needs .* steps of dt .* `max_steps` = "):
        simulate(BODY, t_span, omega0=(0, 1, 1), method="rk4", dt=dt)


def test_the_refusal_holds_for_every_front_end():
    with pytest.raises(ValueError, match="`max_steps`"):
        simulate_relative(BODY, (0, 1), omega_r0=(0, 1, 0), carrier=Carrier(omega_e=(0, 0, 1)),
                          method="rk4", dt=1e-300)  # fmt: skip
    with pytest.raises(ValueError, match="`max_steps`"):
        pendulum_cartesian().simulate((0, 0.5), q0={}, method="rk4", dt=1e-300)
    from poinsot.ensemble import simulate_ensemble

    with deadline(60, "simulate_ensemble"), pytest.raises(StepBudgetError, match="`max_steps`"):
        simulate_ensemble(BODY, (0, 1), omega0=[(0, 1, 1)] * 4, method="rk4", dt=1e-300)
    long = r"needs 9\.2e\+21 steps"
    with deadline(60, "simulate_ensemble"), pytest.raises(StepBudgetError, match=long):
        simulate_ensemble(BODY, (0, 9.2e18), omega0=[(0, 1, 1)], method="rkmk4", dt=1e-3)


def test_max_steps_is_an_option_and_its_default_documented():
    assert DEFAULT_MAX_STEPS >= 10**6
    assert "max_steps" in simulate.__doc__
    traj = simulate(BODY, (0, 1), omega0=(0, 1, 1), method="rk4", dt=0.01, max_steps=100)
    assert traj.nsteps == 100
    with pytest.raises(ValueError, match="needs 100 steps"):
        simulate(BODY, (0, 1), omega0=(0, 1, 1), method="rk4", dt=0.01, max_steps=99)
    for bad in (0, -3, 2.5, True, "10"):
        with pytest.raises(ValueError, match="`max_steps` must be a positive integer"):
            simulate(BODY, (0, 1), omega0=(0, 1, 1), max_steps=bad)


@pytest.mark.parametrize("front", ["simulate", "relative"])
def test_an_adaptive_run_stops_at_the_budget_with_its_samples(front):
    kw = {"rtol": 1e-12, "atol": 1e-14, "max_steps": 50}
    with pytest.raises(SimulationError, match="reached `max_steps` = 50 steps at t = ") as info:
        if front == "simulate":
            simulate(BODY, (0, 100), omega0=(0, 1, 1), **kw)
        else:
            simulate_relative(BODY, (0, 100), omega_r0=(0, 1, 1),
                              carrier=Carrier(omega_e=["0", "0", "sin(t)"]), **kw)  # fmt: skip
    partial = info.value.trajectory
    assert len(partial.t) > 1 and partial.t[-1] < 100


def test_tolerances_below_double_precision_are_raised_with_a_warning():
    with pytest.warns(UserWarning, match="below what double precision resolves"):
        traj = simulate(BODY, (0, 1), omega0=(0, 1, 1), rtol=1e-320)
    assert traj.success and np.all(np.isfinite(traj.omega))
    # an absolute tolerance far below round-off as well: a prompt, named stop, never a stall
    with pytest.warns(UserWarning), pytest.raises(SimulationError, match="tolerances too tight"):
        simulate(BODY, (0, 1), omega0=(0, 1, 1), rtol=1e-320, atol=1e-320)
    assert RTOL_FLOOR == pytest.approx(100 * np.finfo(float).eps)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(BODY, (0, 1), omega0=(0, 1, 1), rtol=1e-10)
