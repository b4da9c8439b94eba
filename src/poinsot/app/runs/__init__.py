"""One run object per kind of scenario, all with the interface of :class:`Run`: simulate,
summarise, write data, figures and the report, and what the command line prints.

:func:`run_for` chooses the run once, by the scenario's type (:data:`RUNS`);
:func:`poinsot.app.job.run_scenario` then runs any of them the same way.
"""

from __future__ import annotations

from ..scenario import EnsembleScenario, LagrangianScenario, RelativeScenario, Scenario
from .base import Run
from .ensemble import EnsembleRun
from .lagrangian import LagrangianRun
from .relative import RelativeRun
from .rigid import RigidRun

__all__ = ["RUNS", "EnsembleRun", "LagrangianRun", "RelativeRun", "RigidRun", "Run", "run_for"]

#: The run of each type of scenario (a subclass of a type listed here runs as that type).
RUNS: dict[type, type[Run]] = {
    Scenario: RigidRun,
    EnsembleScenario: EnsembleRun,
    RelativeScenario: RelativeRun,
    LagrangianScenario: LagrangianRun,
}


def run_for(scenario) -> Run:
    """The run of ``scenario``: the entry of :data:`RUNS` for its type, or its nearest base."""
    for kind in type(scenario).__mro__:
        if kind in RUNS:
            return RUNS[kind](scenario)
    raise TypeError(f"no run for a scenario of type {type(scenario).__name__}")
