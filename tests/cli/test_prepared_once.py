"""A scenario's run is checked and lowered once (the run contract): the loader prepares it
(:func:`poinsot.simulation.prepare`), the job runs what was prepared, and comparing methods on
the same problem reuses it. Counted on a spring: its numbers validated once (``Spring``'s
constructor, through the scalars it checks), checked against the body once (``Force.check``)
and lowered for the core once (``Spring.lower``), for the whole ``poinsot run``."""

from __future__ import annotations

import textwrap

import poinsot.forces as forces_module
from poinsot.app.cli import main

SCENARIO = textwrap.dedent("""
    name = "spring"
    [body]
    type = "box"
    mass = 2.0
    size = [0.2, 0.4, 0.6]
    [[forces]]
    type = "spring"
    point = [0.1, 0.0, 0.0]
    anchor = [0.0, 0.0, 1.0]
    stiffness = 40.0
    rest_length = 0.5
    [initial]
    omega = [0.1, 2.0, 0.3]
    [integrator]
    method = "rk4"
    dt = 0.001
    [time]
    span = [0, 2]
    samples = 51
""")


def test_a_spring_is_validated_checked_and_lowered_once(tmp_path, monkeypatch):
    calls = {"init": 0, "check": 0, "lower": 0}
    Spring = forces_module.Spring
    real_init, real_check, real_lower = Spring.__init__, Spring.check, Spring.lower

    def init(self, *args, **kwargs):
        calls["init"] += 1
        real_init(self, *args, **kwargs)

    def check(self, body):
        calls["check"] += 1
        real_check(self, body)

    def lower(self, frame):
        calls["lower"] += 1
        return real_lower(self, frame)

    monkeypatch.setattr(Spring, "__init__", init)
    monkeypatch.setattr(Spring, "check", check)
    monkeypatch.setattr(Spring, "lower", lower)
    (tmp_path / "s.toml").write_text(SCENARIO)
    assert main(["run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert calls == {"init": 1, "check": 1, "lower": 1}, calls
    assert (tmp_path / "o" / "trajectory.npz").exists()


def test_another_method_reuses_the_prepared_run(monkeypatch):
    """Comparing integrators on the scenario's problem (``[analysis]``'s comparison) runs the
    prepared run with each method: nothing is lowered or checked again."""
    from poinsot.app.scenario import load_scenario

    scenario = load_scenario(SCENARIO)
    calls = []
    for name in ("lower", "check"):
        real = getattr(forces_module.Spring, name)

        def counted(self, *a, real=real, name=name):
            calls.append(name)
            return real(self, *a)

        monkeypatch.setattr(forces_module.Spring, name, counted)
    first = scenario.simulate()
    other = scenario.simulate(method="rkmk4")
    assert calls == [] and (first.method, other.method) == ("rk4", "rkmk4")
    assert other.t.tolist() == first.t.tolist()
    assert abs(other.omega[-1] - first.omega[-1]).max() < 1e-6  # two 4th-order methods agree


def test_a_lagrangian_initial_state_is_made_consistent_once(tmp_path, monkeypatch):
    """A ``[model]`` scenario with a velocity omitted (solved from the constraint): the
    loader completes the state once, with the compiled engine, and the run starts from it
    (it only checks it: nothing left to solve)."""
    import numpy as np

    from poinsot.lagrange import arguments, numeric

    solved = []
    real = arguments.consistent_initial_state

    def counted(system, num, t0, q0, qd0, *args, **kwargs):
        solved.append(bool(np.isnan(q0).any() or np.isnan(qd0).any()))
        assert isinstance(num, numeric._EngineNumeric)
        return real(system, num, t0, q0, qd0, *args, **kwargs)

    monkeypatch.setattr(arguments, "consistent_initial_state", counted)  # the loader's
    monkeypatch.setattr(numeric, "consistent_initial_state", counted)  # the run's
    (tmp_path / "p.toml").write_text(
        textwrap.dedent("""
        name = "pendulum"
        [model]
        name = "pendulum-cartesian"
        params = { m = 1.0, g = 9.81, l = 1.0 }
        q0 = { x = 0.8660254037844386, y = -0.5 }
        qd0 = { x = 0.5 }  # the velocity of y is solved from the rod's constraint
        [time]
        span = [0.0, 1.0]
        samples = 11
    """)
    )
    assert main(["run", str(tmp_path / "p.toml"), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert solved == [True, False], solved  # completed at load, checked at the run
