"""Constrained systems in Lagrangian mechanics (docs/theory.md §3).

:class:`LagrangianSystem` derives the equations of motion with multipliers symbolically (SymPy);
``system.simulate`` integrates them with poinsot's integrators and reports multipliers,
generalized constraint forces, constraint residuals and energy; ``system.equilibria`` and
``system.linearize`` give equilibria, natural frequencies and stability.
"""

from .linear import Linearization, equilibria, linearize
from .numeric import LagrangianSolution, simulate
from .system import LagrangianSystem, PointMass

__all__ = [
    "LagrangianSolution",
    "LagrangianSystem",
    "Linearization",
    "PointMass",
    "equilibria",
    "linearize",
    "simulate",
]
