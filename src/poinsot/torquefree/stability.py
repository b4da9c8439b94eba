"""Fixed points of Euler's equation (20) and their stability (``docs/theory.md`` §1,
"Stationary rotations", eqs (22)–(26)).

A fixed point is an ω with ``ω × Aω = 0``: an eigenvector of the inertia. Three distinct
moments give three axes (the intermediate one unstable, a saddle with growth rate σ); two equal
moments a plane and an axis; three equal moments make every ω a fixed point. The linear
stability comes from the eigenvalues of the Jacobian ``A⁻¹(hat(Aω) − hat(ω) A)``
(``poinsot._core.euler_jacobian``, the Rust core's ``freebody::euler_jacobian``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._bindings import torquefree as core_torquefree
from ..sensitivity import Floquet

__all__ = ["FixedPointSet", "Floquet", "Stability", "StabilityMixin"]

#: The tolerances of :meth:`StabilityMixin.floquet`'s DOP853 run unless it is given others.
_FLOQUET_RTOL, _FLOQUET_ATOL = 1e-13, 1e-15


@dataclass(frozen=True)
class Stability:
    """Linear stability of a fixed point ``ω*`` of Euler's equation.

    Attributes
    ----------
    eigenvalues : ndarray (3,) complex
        Of the Jacobian ``J = A⁻¹(hat(Aω*) − hat(ω*) A)``.
    stable : bool
        Lyapunov stability (for the axes of largest and smallest moment it follows from the
        two conservation laws, not only from the linearisation).
    kind : str
        ``"center"`` (purely imaginary pair), ``"saddle"`` (real pair ±σ),
        ``"degenerate"`` (all eigenvalues zero: a Jordan block, perturbations grow linearly in t,
        as in the plane of fixed points of a symmetric body), or ``"trivial"`` (J = 0).
    growth_rate : float
        σ > 0 for a saddle (intermediate axis): ``σ = |ω| √((I2−I1)(I3−I2)/(I1 I3))``; else 0.
    wobble_frequency : float
        ν for a center: ``|ω| √((I2−I1)(I3−I1)/(I2 I3))`` about e1,
        ``|ω| √((I3−I1)(I3−I2)/(I1 I2))`` about e3; else 0.
    """

    eigenvalues: np.ndarray
    stable: bool
    kind: str
    growth_rate: float = 0.0
    wobble_frequency: float = 0.0


@dataclass(frozen=True)
class FixedPointSet:
    """A set of fixed points of Euler's equation: an axis, a plane, or every ω.

    ``basis`` (3, d) spans it in the body frame (d = 1 axis, 2 plane, 3 all); ``moment`` is the
    moment about it (for a plane, the repeated moment); ``stable`` as in :class:`Stability`.
    """

    kind: str
    basis: np.ndarray
    moment: float
    stable: bool
    label: str


class StabilityMixin:
    """The fixed points of :class:`~poinsot.torquefree.FreeRigidBody` (a part of its
    interface, in a module of its own)."""

    def fixed_points(self) -> list[FixedPointSet]:
        """The fixed points of Euler's equation, by symmetry case, with their stability.

        Three distinct moments: the three principal axes (e2 unstable). Two equal: the plane of
        the repeated moment (unstable: a perturbation off the plane makes ω precess round it)
        and the remaining axis (stable). All equal: every ω (stable: ω is constant).
        """
        S, I = self._S, self._I
        if self.symmetry == "spherical":
            return [FixedPointSet("all", S.copy(), float(I[0]), True, "every ω")]
        if self.symmetry == "asymmetric":
            return [
                FixedPointSet("axis", S[:, [0]], float(I[0]), True, "e1 (smallest moment)"),
                FixedPointSet("axis", S[:, [1]], float(I[1]), False, "e2 (intermediate)"),
                FixedPointSet("axis", S[:, [2]], float(I[2]), True, "e3 (largest moment)"),
            ]
        if self.symmetry == "oblate":
            return [
                FixedPointSet("plane", S[:, [0, 1]], float(I[0]), False, "plane e1–e2"),
                FixedPointSet("axis", S[:, [2]], float(I[2]), True, "e3 (symmetry axis)"),
            ]
        return [
            FixedPointSet("axis", S[:, [0]], float(I[0]), True, "e1 (symmetry axis)"),
            FixedPointSet("plane", S[:, [1, 2]], float(I[1]), False, "plane e2–e3"),
        ]

    def is_fixed_point(self, omega, rtol=1e-10) -> bool:
        """True when ``ω × Aω = 0`` (ω is an eigenvector of A)."""
        w = self._spin(omega, "omega")
        big = float(np.abs(w).max())
        if big == 0:
            return True
        u = w / big  # scale-free: a tiny or huge ω is judged by its direction
        Au = self.inertia @ u / np.abs(self.inertia).max()
        return bool(
            np.linalg.norm(np.cross(u, Au)) <= rtol * np.linalg.norm(u) * np.linalg.norm(Au)
        )

    def jacobian(self, omega) -> np.ndarray:
        """``∂ω̇/∂ω = A⁻¹(hat(Aω) − hat(ω) A)`` (3, 3), body frame."""
        w = self._spin(omega, "omega")
        return core_torquefree.euler_jacobian(np.ascontiguousarray(self.inertia, dtype=float), w)

    def stability(self, omega) -> Stability:
        """Linear stability of the fixed point ``omega`` (body frame); see :class:`Stability`."""
        w = self._spin(omega, "omega")
        if not self.is_fixed_point(w):
            raise ValueError(f"`omega` = {w.tolist()} is not a fixed point: ω × Aω ≠ 0")
        J = self.jacobian(w)
        eig = np.linalg.eigvals(J)
        speed = float(np.linalg.norm(w))
        I1, I2, I3 = self._I
        scale = max(speed * I3 / I1, 1e-300)
        if np.abs(J).max() <= 1e-12 * scale:
            return Stability(eig, True, "trivial")
        if np.abs(eig).max() <= 1e-7 * scale:
            return Stability(eig, False, "degenerate")
        if np.abs(eig.real).max() > 1e-9 * scale:
            sigma = speed * math.sqrt((I2 - I1) * (I3 - I2) / (I1 * I3))
            return Stability(eig, False, "saddle", growth_rate=sigma)
        ws = self._to_sorted(w)
        if abs(ws[0]) >= abs(ws[2]):  # about e1
            nu = speed * math.sqrt((I2 - I1) * (I3 - I1) / (I2 * I3))
        else:
            nu = speed * math.sqrt((I3 - I1) * (I3 - I2) / (I1 * I2))
        if self.symmetry != "asymmetric":
            nu = float(np.abs(eig.imag).max())
        return Stability(eig, True, "center", wobble_frequency=nu)

    def fixed_point_attitude(self, omega, t, Q0=None, *, method="rodrigues") -> np.ndarray:
        """``Q(t) = Q0 exp(Ω t)`` at a fixed point (ω constant), (n, 3, 3).

        ``method="rodrigues"`` uses Rodrigues' formula; ``"jordan"`` the notebook's real Jordan
        form (22)–(23): ``Ω = P J Pᵀ`` with ``P = [u, v, ω/|ω|]`` orthonormal and
        ``exp(J t)`` a plane rotation by ``|ω| t`` — an independent cross-check.
        """
        from .._validation import as_rotation_matrix

        w = self._spin(omega, "omega")
        if not self.is_fixed_point(w):
            raise ValueError(f"`omega` = {w.tolist()} is not a fixed point: ω × Aω ≠ 0")
        t = self._times(t)
        self._resolved(w[None], t)
        Q0 = np.eye(3) if Q0 is None else as_rotation_matrix(Q0, "Q0")
        if method == "rodrigues":
            return core_torquefree.fixed_point_attitudes(
                w, np.ascontiguousarray(Q0, dtype=float), t
            )
        if method != "jordan":
            raise ValueError(f"`method` must be 'rodrigues' or 'jordan', found {method!r}")
        speed = np.linalg.norm(w)
        if speed == 0:
            return np.broadcast_to(Q0, (len(t), 3, 3)).copy()
        n = w / speed
        u = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
        u /= np.linalg.norm(u)
        P = np.column_stack([u, np.cross(n, u), n])
        c, s = np.cos(speed * t), np.sin(speed * t)
        E = np.zeros((len(t), 3, 3))
        E[:, 0, 0] = E[:, 1, 1] = c
        E[:, 0, 1], E[:, 1, 0] = -s, s
        E[:, 2, 2] = 1.0
        return Q0 @ P @ E @ P.T

    def floquet(self, omega0, period=None, *, rtol=None, atol=None) -> Floquet:
        """The :class:`~poinsot.sensitivity.Floquet` picture of the motion from ``omega0``
        (body frame) over one ``period`` (default: :meth:`period`; at a fixed point, where every
        time is a period, one turn ``2π/|ω|``): ``M = ∂ω(T)/∂ω0``.

        A periodic torque-free motion has every multiplier 1: the energy and the momentum are
        conserved and the flow is volume preserving, so ``det M = 1``, ``M`` fixes the velocity
        ``ω̇(0)`` and ``(M − I)²`` vanishes (one Jordan block: a neighbour on another polhode
        has another period and drifts linearly in phase). Differentiating
        ``ω(T(ω0); ω0) = ω0`` gives ``M − I = −ω̇(0) ∇T(ω0)ᵀ``: the drift ``‖M − I‖`` is the
        period's sensitivity, and grows as ``1/(1 − m)`` near the separatrix. At a fixed point
        on the intermediate axis every ``T`` is a period and the largest exponent is the growth
        rate ``σ = |ω| √((I2 − I1)(I3 − I2)/(I1 I3))``.

        Over the motion's own period of a body with three distinct moments, the monodromy
        matrix ``∂ω(T)/∂ω0`` is the closed form's exact derivative
        (:meth:`exact_derivatives`: accurate arbitrarily close to the separatrix); otherwise
        (a fixed point, a symmetric body, another ``period``) the forward sensitivity of a
        DOP853 run at ``rtol``, ``atol`` (default ``1e-13``, ``1e-15``;
        :mod:`poinsot.sensitivity`: the variational equations integrated with the motion in
        the compiled core). The closed form integrates nothing, so a tolerance given there
        would have no effect and is refused; every argument is checked first, on either path.

        Examples
        --------
        The tennis-racket motion: a neighbour's phase drifts, nothing grows.

        >>> from poinsot import FreeRigidBody
        >>> body = FreeRigidBody((1.0, 2.0, 3.0))
        >>> f = body.floquet((0.1, 1.0, 0.1))
        >>> np.round(np.abs(f.multipliers), 6).tolist()
        [1.0, 1.0, 1.0]

        On the intermediate axis the deviations grow at ``σ``:

        >>> f = body.floquet((0.0, 1.0, 0.0))
        >>> round(float(f.exponents[0]), 9), round(body.stability((0, 1, 0)).growth_rate, 9)
        (0.577350269, 0.577350269)
        """
        from .. import layout
        from .._validation import as_scalar
        from ..bodies import RigidBody
        from ..dynamics import RigidBodySystem
        from ..integrate.driver import integrate
        from ..integrate.solve import check_tolerances
        from ..sensitivity import SensitiveSystem, check_returned, directions, split

        # every argument checked here, whichever path follows
        w = self._spin(omega0, "omega0")
        rtol_given, atol_given = check_tolerances(rtol, atol)
        own = period is None
        if period is not None:
            period = as_scalar(period, "period")
            if not period > 0:
                raise ValueError(f"`period` must be a positive finite time, found {period}")
        closed_form = own and self.symmetry == "asymmetric" and not self.is_fixed_point(w)
        if closed_form:
            for name, value in (("rtol", rtol), ("atol", atol)):
                if value is not None:
                    raise ValueError(f"`{name}` has no effect here: over the motion's own "
                                     "period the monodromy is the closed form's exact "
                                     f"derivative, nothing is integrated; drop `{name}`, or "
                                     "give `period` for a DOP853 run")  # fmt: skip
        if period is None:
            if self.is_fixed_point(w):
                speed = float(np.linalg.norm(w))
                if speed == 0:
                    raise ValueError("`omega0` is zero: the body is at rest, nothing moves")
                period = 2 * math.pi / speed
            else:
                period = float(self.period(w))
            if not (math.isfinite(period) and period > 0):
                raise ValueError(f"`omega0` has no period, found {period} (the separatrix "
                                 "has none): give `period`")  # fmt: skip
        if closed_form:
            M = self.exact_derivatives(w, [period]).d_omega_d_omega0[-1]
            method = "closed form"
        else:
            rtol = _FLOQUET_RTOL if rtol_given is None else rtol_given
            atol = _FLOQUET_ATOL if atol_given is None else atol_given
            system = RigidBodySystem(RigidBody(1.0, self.inertia, allow_unphysical=True))
            dirs = directions(system, "omega0")
            y0 = system.initial_state(omega0=w)
            result = integrate(SensitiveSystem(system, dirs), "dop853", (0.0, period), y0,
                               t_eval=[period], rtol=rtol, atol=atol)  # fmt: skip
            y, sens = split(result.y, dirs)
            if not self.is_fixed_point(w):  # a fixed point returns whatever the time
                hint = (
                    f"; its own period is {float(self.period(w)):.9g} s"
                    if self.symmetry == "asymmetric"
                    else ""
                )
                check_returned(y[-1, layout.STATE_SLICES["omega"]], w,
                               float(np.abs(w).max()), period, "ω", hint)  # fmt: skip
            M = sens.of("omega", "omega0")[-1]
            method = "dop853"
        return Floquet.of(M, period, method)
