"""Constrained systems: a model's compiled expressions and the Lagrangian model with its run
(``crates/core/src/expressions.rs``, ``lagrange/``).
"""

from .._core import (
    Expressions,
    LagrangianModel,
    integrate_lagrange,
)

__all__ = [
    "Expressions",
    "LagrangianModel",
    "integrate_lagrange",
]
