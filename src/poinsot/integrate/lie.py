"""Lie-group integrators: Runge–Kutta–Munthe-Kaas on R⁹ × SO(3).

The attitude is advanced as ``Q = Q_n exp(θ̂)`` with ``θ`` solving the ODE in the Lie algebra
``θ̇ = dexp⁻¹_{−θ}(ω)`` (from ``Q̇ = QΩ``), integrated by an explicit Runge–Kutta tableau, while
``R, V, ω`` follow the same tableau in their vector space. Every ``Q`` it produces is a product of
exact rotations, so ``QᵀQ = I`` holds to round-off (Munthe-Kaas 1999, BIT 39; Iserles et al.
2000, Acta Numerica §5). The step is the core's ``rkmk_step``.
"""

from __future__ import annotations

from .base import register
from .rk import ExplicitRungeKutta

__all__ = ["RKMK4", "MuntheKaas"]


class MuntheKaas(ExplicitRungeKutta):
    """RKMK with the tableau of the subclass, on the rigid-body state ``[R, V, Q, ω]``."""

    requires = "rigid"
    conserves = frozenset({"orthogonality"})
    kind = "rkmk"


@register
class RKMK4(MuntheKaas):
    """Fourth-order Runge–Kutta–Munthe-Kaas (classical RK4 tableau in the Lie algebra)."""

    name = "rkmk4"  # order, kind, invariants and tableau (RK4's): the core's registry
