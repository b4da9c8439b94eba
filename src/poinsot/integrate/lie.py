"""Lie-group integrators: Runge–Kutta–Munthe-Kaas on R⁹ × SO(3).

The attitude is advanced as ``Q = Q_n exp(θ̂)`` with ``θ`` solving the ODE in the Lie algebra
``θ̇ = dexp⁻¹_{−θ}(ω)`` (from ``Q̇ = QΩ``), integrated by an explicit Runge–Kutta tableau, while
``R, V, ω`` follow the same tableau in their vector space. Every ``Q`` it produces is a product of
exact rotations, so ``QᵀQ = I`` holds to round-off (Munthe-Kaas 1999, BIT 39; Iserles et al.
2000, Acta Numerica §5).
"""

from __future__ import annotations

import numpy as np

from ..kernels import rigid
from ..kernels.so3 import dexpinv, exp_so3
from .base import register
from .rk import RK4, ExplicitRungeKutta

__all__ = ["RKMK4", "MuntheKaas"]


class MuntheKaas(ExplicitRungeKutta):
    """RKMK with the tableau of the subclass, on the rigid-body state ``[R, V, Q, ω]``."""

    requires = "rigid"
    conserves = frozenset({"orthogonality"})

    def _step_impl(self, t, y, h):
        A, B, C = self.A, self.B, self.C
        s = len(B)
        Q = y[6:15].reshape(3, 3)
        z = np.concatenate([y[0:6], y[15:18]])  # R, V, ω
        kz = np.empty((s, 9))
        kth = np.empty((s, 3))
        for i in range(s):
            theta = h * (A[i, :i] @ kth[:i]) if i else np.zeros(3)
            zi = z + h * (A[i, :i] @ kz[:i]) if i else z
            Qi = Q @ exp_so3(theta) if i else Q
            yi = rigid.pack_state(zi[0:3], zi[3:6], Qi, zi[6:9])
            dy = self.fun(t + C[i] * h, yi)
            kz[i, 0:6] = dy[0:6]
            kz[i, 6:9] = dy[15:18]
            kth[i] = dexpinv(-theta, zi[6:9])
        theta = h * (B @ kth)
        z_new = z + h * (B @ kz)
        return rigid.pack_state(z_new[0:3], z_new[3:6], Q @ exp_so3(theta), z_new[6:9])


@register
class RKMK4(MuntheKaas):
    """Fourth-order Runge–Kutta–Munthe-Kaas (classical RK4 tableau in the Lie algebra)."""

    name = "rkmk4"
    order = 4
    A, B, C = RK4.A, RK4.B, RK4.C
