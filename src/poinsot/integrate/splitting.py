"""Explicit symplectic splitting for rigid bodies: exact free-rotor flows composed with kicks.

The Hamiltonian splits into the free rotor ``T = Σ π_i²/(2 I_i)`` (plus ``|P|²/2M`` for the
centre of mass) and the potential of the forces. Each part is solved exactly: the free rotor by
the exact flow of a symmetric rotor or the symmetric composition of rotations about the
principal axes (McLachlan 1993, *Phys. Rev. Lett.* 71; Dullweber, Leimkuhler & McLachlan 1997,
*J. Chem. Phys.* 107 — the core's ``free_rotor_step``), the forces as
momentum kicks. The Strang composition ``kick(h/2) ∘ drift(h) ∘ kick(h/2)`` is second order and
symplectic; torque-free it keeps ``|L|`` and the spatial ``L`` to round-off, and ``Q`` on SO(3).

Structure required (declared, checked before a run): a rigid-body system whose forces are all
``position_only`` — they depend on ``(t, R, Q)`` only, like uniform gravity, springs without
damping, the heavy top's weight, central gravity.
"""

from __future__ import annotations

from .base import Solver, register

__all__ = ["Splitting"]


@register
class Splitting(Solver):
    """Second-order symplectic splitting (free rotor ∘ kicks), fixed step; the core steps
    the body momentum π in place of ω (``splitting_step``)."""

    name = "splitting"  # order, kind, invariants, kicks: the core's registry (spec.rs)
