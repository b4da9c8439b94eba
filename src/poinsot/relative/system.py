"""The relative-motion system the integrators step (``docs/relative.md``).

:class:`RelativeMotionSystem` holds no formula: it lowers the forces once (through
:class:`~poinsot.dynamics.RigidBodySystem`, the body's principal frame), packs the carrier's
motion as data or as a compiled function, and hands the compiled engine the named tuple it
integrates (:class:`~poinsot.kernels.systems.RelativeSystem` or
:class:`~poinsot.kernels.systems.RelativeUserSystem`). Forces and carriers given by Python
callables run the same kernels from Python (the Python backend).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from ..dynamics import RigidBodySystem
from ..kernels import layout
from ..kernels.relative import (
    BALANCE_TRANSPORT,
    HOLD_COM,
    OPTIONS_SIZE,
    RELATIVE_STATE_SIZE,
    absolute_state_of,
    relative_rates,
)
from ..kernels.rigid import states_from_principal, states_to_principal
from ..kernels.systems import RelativeSystem, RelativeUserSystem

__all__ = ["RELATIVE_SLICES", "RelativeMotionSystem"]

#: Named blocks of the relative state (see :mod:`poinsot.kernels.relative`).
RELATIVE_SLICES = {
    "r": slice(0, 3),
    "v_r": slice(3, 6),
    "Q_r": slice(6, 15),
    "omega_r": slice(15, 18),
    "Q_carrier": slice(18, 27),
    "origin": slice(27, 30),
    "origin_velocity": slice(30, 33),
}


class RelativeMotionSystem:
    """A body moving relative to a :class:`~poinsot.relative.Carrier` under physical forces.

    Parameters
    ----------
    body : RigidBody
    carrier : Carrier
    forces : sequence of Force
        Physical forces, as for :func:`poinsot.simulate` (inertial frame).
    balance_transport : bool
        Add the physical moment ``J ε_e − Jω_e × ω_e`` that cancels the transport moment
        (case (16)).
    hold_com : bool
        Hold the centre of mass at its place in the carrier (a body mounted at its centre of
        mass, as in a gimbal); otherwise it moves under the forces and the inertia forces.
    """

    state_slices: ClassVar[dict[str, slice]] = RELATIVE_SLICES

    def __init__(self, body, carrier, forces=(), *, balance_transport=False, hold_com=False):
        self.rigid = RigidBodySystem(body, forces)
        self.body = body
        self.carrier = carrier
        self.forces = self.rigid.forces
        self.options = np.zeros(OPTIONS_SIZE)
        self.options[BALANCE_TRANSPORT] = 1.0 if balance_transport else 0.0
        self.options[HOLD_COM] = 1.0 if hold_com else 0.0
        self.principal_axes = self.rigid.principal_axes
        self.principal_inertia = np.diag(self.rigid.principal_moments)

    @property
    def compiled(self) -> bool:
        """True when the whole run is one compiled call (built-in forces, no Python carrier)."""
        return self.rigid.compiled and not self.rigid.jitted_forces and self.carrier.compiled

    @property
    def python_forces(self):
        """What keeps the run on the Python backend (named in the error for
        ``backend='compiled'``)."""
        out = self.rigid.python_forces + self.rigid.jitted_forces
        if not self.carrier.compiled:
            out = (*out, self.carrier)
        return out

    # ----------------------------------------------------------------- frames
    def to_internal(self, y) -> np.ndarray:
        """Relative states (n, 33) (or one) from the body frame to the principal frame (only
        Q_r and ω_r change)."""
        y = np.array(y, dtype=float)
        Y = np.atleast_2d(y).copy()
        n = layout.STATE_SIZE
        Y[:, :n] = states_to_principal(self.principal_axes, Y[:, :n].copy())
        return Y.reshape(y.shape)

    def from_internal(self, z) -> np.ndarray:
        """Relative states (or their derivatives) from the principal frame to the body frame."""
        z = np.array(z, dtype=float)
        Z = np.atleast_2d(z).copy()
        n = layout.STATE_SIZE
        Z[:, :n] = states_from_principal(self.principal_axes, Z[:, :n].copy())
        return Z.reshape(z.shape)

    # ----------------------------------------------------------------- engines
    def compiled_system(self, y0):
        """The named tuple of arrays the compiled engine integrates."""
        common = (
            self.rigid.body_parameters(),
            np.ascontiguousarray(self.principal_inertia),
            self.rigid.force_kind,
            self.rigid.force_params,
            self.options,
        )
        if self.carrier.kind == "ppoly":
            return RelativeSystem(*common, *self.carrier.ppoly)
        return RelativeUserSystem(*common, self.carrier.function)

    def python_system(self, y0):
        """The same physics with the Python forces and carrier evaluated from Python."""
        return _PythonRelativeSystem(self)

    def rhs(self, t, y) -> np.ndarray:
        """``ẏ`` of a body-frame relative state (33,): eqs (11)–(12) and the kinematics."""
        out = np.empty(RELATIVE_STATE_SIZE)
        self.python_system(y).vector_field(float(t), self.to_internal(y), out)
        return self.from_internal(out)


class _PythonRelativeSystem:
    """The relative system evaluated from Python (the Python backend): the carrier's and the
    forces' Python callables, the compiled kernels for the rest; the generic system interface
    of :mod:`poinsot.kernels.systems` as methods (no ``rates``: it steps as a general ODE)."""

    def __init__(self, owner: RelativeMotionSystem):
        self.owner = owner
        self.body = owner.rigid.body_parameters()
        self.forces = owner.rigid.python_system(np.zeros(layout.STATE_SIZE))
        self.inertia = np.ascontiguousarray(owner.principal_inertia)

    def state_size(self, y):
        return RELATIVE_STATE_SIZE

    def body_parameters(self):
        return self.body

    def vector_field(self, t, y, out):
        motion = self.owner.carrier.motion_tuple(t)
        s = np.array(absolute_state_of(y, motion))
        Fx, Fy, Fz, tx, ty, tz = self.forces.wrench(t, s)
        out[:] = relative_rates(self.body, self.inertia, self.owner.options, y, motion,
                                Fx, Fy, Fz, tx, ty, tz)  # fmt: skip

    def project(self, t, y):
        return False

    def potential(self, t, y):
        s = np.array(absolute_state_of(y, self.owner.carrier.motion_tuple(t)))
        return self.forces.potential(t, s)
