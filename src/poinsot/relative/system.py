"""The relative-motion system the integrators step (``docs/relative.md``).

:class:`RelativeMotionSystem` holds no formula: it lowers the forces once (through
:class:`~poinsot.dynamics.RigidBodySystem`, the body's principal frame) and hands the compiled
core the carrier as it evaluates it (:attr:`~poinsot.relative.Carrier.engine`: piecewise
polynomials, compiled expressions, or a Python callable on the slow path). The relative
equation (11)–(12) itself is ``poinsot_core::relative``.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from .. import layout
from .._bindings import relative as core_relative
from .._bindings import rigid as core_rigid
from .._bindings import sensitivity as core_sensitivity
from ..dynamics import RigidBodySystem
from ..sensitivity import SensitiveSystem

__all__ = ["RELATIVE_SLICES", "RelativeMotionSystem", "RelativeSensitiveSystem"]

#: Named blocks of the relative state (``poinsot_core::relative``).
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
    #: The structure the integrators may use: none beyond a vector field.
    structure: ClassVar[str] = "vector field"

    def __init__(self, body, carrier, forces=(), *, balance_transport=False, hold_com=False):
        self.rigid = RigidBodySystem(body, forces)
        self.body = body
        self.carrier = carrier
        self.forces = self.rigid.forces
        self.balance_transport = bool(balance_transport)
        self.hold_com = bool(hold_com)
        self.principal_axes = self.rigid.principal_axes
        self.principal_inertia = np.diag(self.rigid.principal_moments)

    @property
    def compiled(self) -> bool:
        """True when the whole run is compiled code (built-in forces, no Python carrier)."""
        return self.rigid.compiled and self.carrier.compiled

    @property
    def python_forces(self):
        """What keeps the run on the slow path: Python forces, and a carrier given by Python
        callables."""
        out = self.rigid.python_forces
        if not self.carrier.compiled:
            out = (*out, self.carrier)
        return out

    # ----------------------------------------------------------------- frames
    def to_internal(self, y) -> np.ndarray:
        """Relative states (n, 33) (or one) from the body frame to the principal frame (only
        Q_r and ω_r change)."""
        return self._frames(y, inverse=False)

    def from_internal(self, z) -> np.ndarray:
        """Relative states (or their derivatives) from the principal frame to the body frame."""
        return self._frames(z, inverse=True)

    def _frames(self, y, inverse):
        y = np.array(y, dtype=float)
        Y = np.atleast_2d(y).copy()
        n = layout.STATE_SIZE
        Y[:, :n] = core_rigid.states_principal(
            self.principal_axes, np.ascontiguousarray(Y[:, :n]), inverse
        )
        return Y.reshape(y.shape)

    # ----------------------------------------------------------------- the core
    def _data(self, y0):
        body, kinds, params, axes, user = self.rigid.native(np.zeros(layout.STATE_SIZE))
        return (body, kinds, params, axes, user, self.carrier.engine, self.balance_transport,
                self.hold_com)  # fmt: skip

    def problem(self, y0):
        """The system as the compiled core integrates it
        (:class:`~poinsot.integrate.problem.NativeProblem`): any vector-field method."""
        from ..integrate.problem import GENERAL_METHODS, NativeProblem

        slow = tuple(f.name for f in self.rigid.python_forces)
        if not self.carrier.compiled:
            slow = (*slow, f"{self.carrier.name} (a Python callable)")
        return NativeProblem(
            core_relative.integrate_relative, self._data(y0), GENERAL_METHODS, slow
        )

    def rhs(self, t, y) -> np.ndarray:
        """``ẏ`` of a body-frame relative state (33,): eqs (11)–(12) and the kinematics."""
        z = np.ascontiguousarray(self.to_internal(y))
        return self.from_internal(core_relative.relative_rhs(*self._data(z), float(t), z))


class RelativeSensitiveSystem(SensitiveSystem):
    """A relative run with its sensitivities, as the run contract takes a system: the
    augmented state ``[y (33), S (33 × P, row-major)]``, the relative state's frames outside
    the core, the principal frame inside."""

    state_slices = RELATIVE_SLICES
    size = 33
    structure = "vector field"

    def problem(self, y0):
        from ..integrate.problem import NativeProblem
        from ..sensitivity import SENSITIVE_METHODS

        system, d = self.system, self.directions
        body, kinds, params, _, _ = system.rigid.native(np.zeros(layout.STATE_SIZE))
        data = (body, kinds, params, system.carrier.engine, system.balance_transport,
                system.hold_com, np.ascontiguousarray(d.moment_seeds),
                np.ascontiguousarray(d.force_seeds), self.control_all)  # fmt: skip
        slow = () if system.carrier.compiled else (f"{system.carrier.name} (a Python callable)",)
        return NativeProblem(core_sensitivity.integrate_relative_sensitivities, data,
                             SENSITIVE_METHODS, slow)  # fmt: skip

    def to_internal(self, y0) -> np.ndarray:
        """The augmented initial state (principal frame) of a relative state ``y0`` (33,)."""
        system, d = self.system, self.directions
        y0 = np.asarray(y0, dtype=float)[: self.size]
        body = system.rigid.native(np.zeros(layout.STATE_SIZE))[0]
        return core_sensitivity.relative_sensitivity_start(
            body, np.ascontiguousarray(system.principal_axes, dtype=float),
            np.ascontiguousarray(system.to_internal(y0)), d.kinds, d.components,
        )  # fmt: skip
