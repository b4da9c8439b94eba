"""Constrained systems: a model's compiled expressions and the Lagrangian model with its run
(``crates/core/src/expressions.rs``, ``lagrange/``).
"""

from .._core import (
    Expressions,
    LagrangianModel,
    LagrangianTangent,
    integrate_lagrange,
    integrate_lagrange_sensitivities,
    lagrange_sensitivity_start,
)

__all__ = [
    "Expressions",
    "LagrangianModel",
    "LagrangianTangent",
    "integrate_lagrange",
    "integrate_lagrange_sensitivities",
    "lagrange_sensitivity_start",
]
