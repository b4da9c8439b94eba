"""Explicit symplectic splitting for rigid bodies: exact free-rotor flows composed with kicks.

The Hamiltonian splits into the free rotor ``T = Σ π_i²/(2 I_i)`` (plus ``|P|²/2M`` for the
centre of mass) and the potential of the forces. Each part is solved exactly: the free rotor by
the exact flow of a symmetric rotor or the symmetric composition of rotations about the
principal axes (McLachlan 1993, *Phys. Rev. Lett.* 71; Dullweber, Leimkuhler & McLachlan 1997,
*J. Chem. Phys.* 107 — :func:`poinsot.kernels.rigid.free_rotor_step_into`), the forces as
momentum kicks. The Strang composition ``kick(h/2) ∘ drift(h) ∘ kick(h/2)`` is second order and
symplectic; torque-free it keeps ``|L|`` and the spatial ``L`` to round-off, and ``Q`` on SO(3).

Structure required (declared, checked before a run): a rigid-body system whose forces are all
``position_only`` — they depend on ``(t, R, Q)`` only, like uniform gravity, springs without
damping, the heavy top's weight, central gravity.
"""

from __future__ import annotations

import numpy as np

from .base import Solver, SolverState, _kernel_for, register

__all__ = ["Splitting"]


@register
class Splitting(Solver):
    """Second-order symplectic splitting (free rotor ∘ kicks), fixed step; its state carries
    the body momentum π in place of ω (:func:`poinsot.kernels.steppers.solver_init_into`)."""

    name = "splitting"
    order = 2
    requires = "rigid"
    conserves = frozenset({"orthogonality", "angular_momentum", "symplectic"})
    kind = "splitting"
    driver = "run_splitting"
    #: the structure it needs: every force a kick (position-only)
    needs_position_only_forces = True

    def step(self, system, state, h, controller=None):
        from ..kernels import steppers as _st

        z = state.z
        out = np.empty_like(z)
        split = _kernel_for(_st.splitting_step, system)
        split(system, state.t, z, float(h), np.empty_like(z), np.empty((3, 3)),
              np.empty((3, 3)), out)  # fmt: skip
        return SolverState(state.t + h, out), None
