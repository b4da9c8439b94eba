"""Constrained systems in Lagrangian mechanics (docs/theory.md §3).

:class:`LagrangianSystem` derives the equations of motion with multipliers symbolically (SymPy);
``system.simulate`` integrates them with poinsot's integrators and reports multipliers,
generalized constraint forces, constraint residuals and energy (the default
``engine="compiled"``: the model's expressions compiled to machine code in the core in
milliseconds, stepped by the core's integrators); ``system.simulate_ensemble``
runs parameter ensembles (``system.prepare_ensemble`` checks and lowers one once, for any
members); ``system.equilibria`` and ``system.linearize`` give equilibria,
natural frequencies and stability; ``system.reaction_forces`` gives the forces of the
constraints that minimal coordinates hide (:mod:`~poinsot.lagrange.reactions`).
"""

from .ensemble import (
    LagrangianEnsemble,
    PreparedLagrangianEnsemble,
    prepare_ensemble,
    simulate_ensemble,
)
from .linear import Linearization, equilibria, linearize
from .numeric import ConstraintDriftWarning, simulate
from .reactions import HiddenConstraint
from .solution import LagrangianSolution
from .system import LagrangianSystem, PointMass

__all__ = [
    "ConstraintDriftWarning",
    "HiddenConstraint",
    "LagrangianEnsemble",
    "LagrangianSolution",
    "LagrangianSystem",
    "Linearization",
    "PointMass",
    "PreparedLagrangianEnsemble",
    "equilibria",
    "linearize",
    "prepare_ensemble",
    "simulate",
    "simulate_ensemble",
]
