"""Explicit symplectic splitting for rigid bodies: exact free-rotor flows composed with kicks.

The Hamiltonian splits into the free rotor ``T = Σ π_i²/(2 I_i)`` (plus ``|P|²/2M`` for the
centre of mass) and the potential of the forces. Each part is solved exactly: the free rotor by
the symmetric composition of rotations about the principal axes (McLachlan 1993, *Phys. Rev.
Lett.* 71; Dullweber, Leimkuhler & McLachlan 1997, *J. Chem. Phys.* 107 — see
:func:`poinsot.kernels.rigid.free_rotor_strang`), the forces as momentum kicks. The Strang
composition ``kick(h/2) ∘ drift(h) ∘ kick(h/2)`` is second order and symplectic; torque-free it
keeps ``|L|`` and the spatial ``L`` to round-off, and ``Q`` on SO(3).

Structure required (declared, checked at construction): a rigid-body system whose forces are all
``position_only`` — they depend on ``(t, R, Q)`` only, like uniform gravity, springs without
damping, the heavy top's weight, central gravity.
"""

from __future__ import annotations

from ..kernels import rigid
from .base import Solver, register

__all__ = ["Splitting"]


@register
class Splitting(Solver):
    """Second-order symplectic splitting (free rotor ∘ kicks), fixed step."""

    name = "splitting"
    order = 2
    requires = "rigid"
    conserves = frozenset({"orthogonality", "angular_momentum", "symplectic"})
    _projects_itself = True

    def __init__(self, system, t0, y0, t_bound, *, dt=None, rtol=None, atol=None):
        bad = [f.name for f in getattr(system, "forces", ()) if not f.position_only]
        if bad:
            raise ValueError(
                "method 'splitting' needs forces that depend only on time, position and "
                f"attitude (kicks); these depend on velocities: {', '.join(bad)}"
            )
        super().__init__(system, t0, y0, t_bound, dt=dt, rtol=rtol, atol=atol)
        self._E = system.principal_axes
        self._moments = system.principal_moments
        self._load(self.y)

    def _load(self, y):
        """Internal state in the principal frame: momentum π_p and attitude Q_p = Q E.

        Carrying π (not ω) from step to step keeps |L| to round-off: converting ω ↔ π = Aω at
        every step would add a systematic A·A⁻¹ ≠ 1 bias.
        """
        R, V, Q, omega = rigid.unpack_state(y)
        self._R, self._V = R.copy(), V.copy()
        self._pi = self._E.T @ (self.system.inertia @ omega)
        self._Qp = Q @ self._E
        self._synced = y

    def _output(self):
        E = self._E
        y = rigid.pack_state(
            self._R, self._V, self._Qp @ E.T, self.system.inertia_inv @ (E @ self._pi)
        )
        if self._project is not None:
            y = self._project(y, self.t)
            self._R, self._V = y[0:3].copy(), y[3:6].copy()
        return y

    def _kick(self, t, h):
        sysm = self.system
        self.nfev += 1
        Q = self._Qp @ self._E.T
        omega = sysm.inertia_inv @ (self._E @ self._pi)
        F, tau = sysm.wrench(t, self._R, self._V, Q, omega)
        if sysm.pivot is None:
            self._V = self._V + h * F / sysm.mass
        self._pi = self._pi + h * (self._E.T @ tau)

    def _advance(self, h):
        if self.y is not self._synced:  # the state was changed from outside: re-read it
            self._load(self.y)
        h = self.dt if h is None else h
        h = min(h, self.t_bound - self.t)
        t = self.t
        self._kick(t, 0.5 * h)
        self._pi, self._Qp = rigid.free_rotor_step(self._moments, self._pi, self._Qp, h)
        if self.system.pivot is None:
            self._R = self._R + h * self._V
        else:  # the centre of mass follows the attitude: R = P + Q c
            self._output()
        self._kick(t + h, 0.5 * h)
        self.t = t + h
        self.y = self._output()
        self._synced = self.y
