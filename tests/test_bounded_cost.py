"""Issue 44, a bounded cost for every path: adaptive runs estimate their steps from the pace
of their own first steps (and again each time the steps double) and stop, with the estimate,
as soon as they cannot end within ``max_steps``; their samples are checked against the memory
available before they grow; ensembles estimate their members before any chunk runs. The
campaign's reproducers each ran for minutes, or out of memory; here each is refused with its
estimate (the deadlines only catch a hang: they are far above what the refusals take)."""

from __future__ import annotations

import re

import numpy as np
import pytest

import poinsot._resources
from bounded import deadline
from poinsot import RigidBody, models, simulate
from poinsot.dynamics import RigidBodySystem
from poinsot.ensemble import simulate_ensemble
from poinsot.integrate.driver import estimate_steps, estimate_steps_by_spans
from poinsot.integrate.solve import SimulationError, StepBudgetError
from poinsot.lagrange import simulate_ensemble as lagrange_ensemble
from poinsot.relative import Carrier, simulate_relative

BOX = RigidBody.box(2.0, (1, 2, 3))
W0 = (0.1, 1.0, 0.2)


def estimate_in(message: str) -> float:
    """The estimated steps a refusal states."""
    return float(re.search(r"needs about ([0-9.e+]+) (more )?steps", message).group(1))


def test_an_adaptive_run_over_1e300_is_stopped_with_its_estimate():
    """It ran 119 s, then failed with `MemoryError: Unable to allocate 9.00 GiB`."""
    with deadline(30), pytest.raises(SimulationError) as err:
        simulate(BOX, (0, 1e300), omega0=W0)
    message = str(err.value)
    assert "`max_steps` = 100000000" in message and estimate_in(message) > 1e299
    assert len(err.value.trajectory.t) > 1  # the samples computed before the refusal


def test_a_lagrangian_run_over_1e300_is_stopped_with_its_estimate():
    """It ran about 7 min."""
    with deadline(30), pytest.raises(SimulationError, match="needs about") as err:
        models.pendulum_cartesian().simulate((0, 1e300))
    assert estimate_in(str(err.value)) > 1e299


def test_a_carrier_singular_in_the_span_is_stopped():
    """``euler_angles = ['1/(t - 0.5)', '0.1', '0']`` ran about 13 min: the steps shrink
    towards t = 0.5 and the pace says the run cannot end (here its samples would not fit)."""
    carrier = Carrier(euler_angles=["1/(t - 0.5)", "0.1", "0"])
    with deadline(60), pytest.raises(SimulationError, match="the run was stopped") as err:
        simulate_relative(BOX, (0, 1), carrier=carrier, omega_r0=W0)
    assert "at t = 0.49" in str(err.value)


def test_a_carrier_run_over_1e300_is_stopped():
    with deadline(30), pytest.raises(SimulationError, match="needs about"):
        simulate_relative(BOX, (0, 1e300), carrier=Carrier(omega_e=(0, 0, 1)), omega_r0=W0)


def test_the_hodograph_scenario_with_an_absurd_atol_is_stopped():
    """``atol = 9007199254740993`` stalled at t = 3.1165."""
    from importlib.resources import files

    from poinsot.app.scenario import load_scenario

    text = (files("poinsot.app") / "scenarios" / "hodograph-bound.toml").read_text()
    scenario = load_scenario(text.replace("atol = 1e-13", "atol = 9007199254740993"))
    with deadline(60), pytest.raises(SimulationError, match="needs about"):
        scenario.simulate()


def test_an_adaptive_ensemble_is_estimated_before_it_runs():
    """A 10⁶-member dop853 ensemble over [0, 1e9] gave no result in 90 s."""
    omega0 = np.tile(W0, (10**6, 1))
    with deadline(30), pytest.raises(StepBudgetError, match="member 0 of 1000000") as err:
        simulate_ensemble(BOX, (0, 1e9), omega0=omega0, method="dop853")
    assert err.value.needed > 1e9 and err.value.budget == 10**8


def test_a_lagrangian_ensemble_is_estimated_before_it_runs():
    mdl = models.pendulum_polar()
    q0 = {mdl.symbols["theta"]: np.linspace(0.1, 1.0, 50)}
    with deadline(30), pytest.raises(StepBudgetError, match="of 50") as err:
        lagrange_ensemble(mdl.system, (0, 1e300), params=mdl.params, q0=q0)
    assert err.value.needed > 1e299


def test_the_estimate_is_the_steps_the_run_takes():
    """A second route: the estimate from the first 1000 steps against the steps of the whole
    run (a torque-free box keeps a steady pace)."""
    system = RigidBodySystem(BOX)
    y0 = system.initial_state(omega0=W0)
    run = simulate(BOX, (0, 2000), omega0=W0, t_eval=[2000])
    assert estimate_steps(system, "dop853", (0, 2000), y0) == pytest.approx(run.nsteps, rel=0.05)
    short = simulate(BOX, (0, 10), omega0=W0, t_eval=[10])
    assert estimate_steps(system, "dop853", (0, 10), y0) == short.nsteps  # ends in the pilot
    with pytest.raises(ValueError, match="'rk4' is fixed-step: its steps need no estimate"):
        estimate_steps(system, "rk4", (0, 10), y0, dt=0.1)


def test_the_estimate_by_spans_of_a_steady_pace():
    steps = estimate_steps_by_spans(lambda t, cap: (min(round(t), cap), t <= cap), 0.0, 1e12)
    assert steps == pytest.approx(1e12, rel=1e-3)
    assert estimate_steps_by_spans(lambda t, cap: (3, None), 0.0, 1.0) == 0.0  # a failure


def test_a_run_within_its_budget_is_not_refused():
    """The budget just above the steps the run takes: it runs to its end."""
    run = simulate(BOX, (0, 2000), omega0=W0, t_eval=[2000])
    again = simulate(BOX, (0, 2000), omega0=W0, t_eval=[2000], max_steps=int(run.nsteps * 1.1))
    assert again.nsteps == run.nsteps
    np.testing.assert_array_equal(again.omega, run.omega)
    with pytest.raises(SimulationError, match="needs about"):
        simulate(BOX, (0, 2000), omega0=W0, t_eval=[2000], max_steps=run.nsteps // 2)


def test_samples_that_would_not_fit_in_memory_are_refused(monkeypatch):
    """Memory as a machine with little left would report it (and every size checked: runs
    below 64 MB of samples do not read the system's memory figures)."""
    from poinsot.integrate import driver

    monkeypatch.setattr(driver, "SMALL_BYTES", 0)
    monkeypatch.setattr(poinsot._resources, "available_memory", lambda: 50_000_000)
    with pytest.raises(ValueError, match=r"would keep 10000003 samples .* available .*save_every"):
        simulate(BOX, (0, 1e3), omega0=W0, method="rk4", dt=1e-4)
    simulate(BOX, (0, 1e3), omega0=W0, method="rk4", dt=1e-4, save_every=1000)  # fits
    with pytest.raises(SimulationError, match=r"would take about .* available .*save_every"):
        simulate(BOX, (0, 1e6), omega0=W0, max_steps=10**9)  # an adaptive run's samples
    monkeypatch.setattr(poinsot._resources, "available_memory", lambda: 200_000)
    with pytest.raises(SimulationError, match=r"would need .* to grow") as err:
        simulate(BOX, (0, 100), omega0=W0)  # refused when the output would double
    assert len(err.value.trajectory.t) > 100


def test_an_ensemble_member_stops_at_its_budget():
    """The core's members honour ``max_steps`` (they had no limit): status 0, said so."""
    import dataclasses

    from poinsot.ensemble import prepare_ensemble

    run = prepare_ensemble(BOX, (0, 10), method="rk4", dt=0.01)
    tight = dataclasses.replace(run, spec=dataclasses.replace(run.spec, max_steps=5))
    res = tight.run(omega0=[W0, W0])
    assert list(res.nsteps) == [5, 5] and not res.success.any()
    assert list(res.messages) == ["stopped at `max_steps`"] * 2
    assert res.summary()["failed"] == {"stopped at `max_steps`": 2}
    assert np.isnan(res.omega).all()


def test_a_member_that_fails_in_the_estimate_fails_alone():
    """The estimate's short run of a member that blows up is not the run: the ensemble runs,
    and that member alone reports its failure, as before the estimate existed."""
    omega0 = np.array([[1e300, 1e300, 0.0], W0])
    res = simulate_ensemble(BOX, (0, 10), omega0=omega0, method="dop853")
    assert list(res.success) == [False, True]
    assert res.messages[0] in ("step size too small", "non-finite state")
    system = RigidBodySystem(BOX)
    y0 = system.initial_state(omega0=omega0[0])
    assert estimate_steps(system, "dop853", (0, 10), y0) == 0.0
