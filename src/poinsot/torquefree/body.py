"""The torque-free body: its principal moments, frames, invariants (30)–(31), cone (32) and the
feasibility condition (33) (``docs/theory.md`` §1, "Torque-free body").

:class:`FreeRigidBody` gathers the concepts of this package: the exact solution
(:mod:`~poinsot.torquefree.solution`), fixed points (:mod:`~poinsot.torquefree.stability`) and
polhodes (:mod:`~poinsot.torquefree.polhodes`), each a part of its interface written in its own
module.
"""

from __future__ import annotations

import math

import numpy as np

from .._bindings import inertia as core_inertia
from .._bindings import torquefree as core_torquefree
from .._validation import _real_array, as_array, as_scalar
from ..display import Displayable
from .polhodes import PolhodeMixin
from .solution import SolutionMixin
from .stability import StabilityMixin

__all__ = [
    "SYMMETRY_RTOL",
    "FreeRigidBody",
    "energy_ellipsoid_semi_axes",
    "momentum_ellipsoid_semi_axes",
]

#: Moments closer than this (relative to I3) are treated as equal (symmetric body); the same
#: tolerance as :attr:`poinsot.bodies.RigidBody.symmetry`: the core's own value.
SYMMETRY_RTOL = core_inertia.SYMMETRY_RTOL


def energy_ellipsoid_semi_axes(moments, energy) -> np.ndarray:
    """Semi-axes ``√(2k/I_i)`` (3,) of the energy (Poinsot) ellipsoid ``Σ I_i ω_i² = 2k``,
    eq. (30), along the axes of the principal ``moments`` (3,) (``freebody.rs``).

    >>> energy_ellipsoid_semi_axes((1.0, 2.0, 4.0), 1.0)
    array([1.41421356, 1.        , 0.70710678])
    """
    moments = as_array(moments, "moments", shape=(3,))
    return core_torquefree.energy_ellipsoid_semi_axes(moments, as_scalar(energy, "energy"))


def momentum_ellipsoid_semi_axes(moments, momentum) -> np.ndarray:
    """Semi-axes ``a/I_i`` (3,) of the momentum ellipsoid ``Σ I_i² ω_i² = a²``, eq. (31), along
    the axes of the principal ``moments`` (3,) (``freebody.rs``).

    >>> momentum_ellipsoid_semi_axes((1.0, 2.0, 4.0), 2.0)
    array([2. , 1. , 0.5])
    """
    moments = as_array(moments, "moments", shape=(3,))
    return core_torquefree.momentum_ellipsoid_semi_axes(moments, as_scalar(momentum, "momentum"))


class FreeRigidBody(SolutionMixin, StabilityMixin, PolhodeMixin, Displayable):
    """A torque-free rigid body given by its principal moments.

    Parameters
    ----------
    moments : array_like (3,)
        Principal moments along the body's x, y, z axes, in any order, all > 0, satisfying the
        triangle inequalities (no moment exceeds the sum of the other two).
    allow_unphysical : bool
        Accept moments that break the triangle inequality, with a warning: Euler's equation is
        still well posed (the source notebook's example (3, 3, 9) is such a case).

    Notes
    -----
    Any scale of the moments and of ω is taken (the closed forms run on moments scaled to
    I3 ~ 1). Times must be finite, and within what double precision resolves for the motion:
    ``|ω| |t|`` at most :data:`~poinsot.torquefree.solution.MAX_PHASE` = 2⁵² rad (beyond, the
    angle's rounding error exceeds a radian). An empty array of times gives empty results.

    Examples
    --------
    The tennis-racket (Dzhanibekov) flip:

    >>> import numpy as np
    >>> body = FreeRigidBody((1.0, 2.0, 3.0))
    >>> round(body.flip_interval((1e-3, 1.0, 1e-3)), 6)
    27.530841
    >>> w = body.exact_omega((1e-3, 1.0, 1e-3), [0.0, 27.530840553491])
    >>> np.round(w[:, 1], 3).tolist()   # ω2 has flipped
    [1.0, -1.0]

    Many initial conditions at once, in compiled code:

    >>> body.flip_interval([(1e-3, 1.0, 1e-3), (1e-2, 1.0, 1e-2)]).round(3).tolist()
    [27.531, 19.553]
    """

    def __init__(self, moments, *, allow_unphysical: bool = False):
        I = as_array(moments, "moments", (3,))
        if np.any(I <= 0):
            k = int(np.argmax(I <= 0))
            raise ValueError(
                f"`moments[{k}]` must be positive, found {I[k]} (a degenerate body, all mass on "
                "a line, has no torque-free dynamics about that line)"
            )
        from ..bodies import check_inertia

        # the core's one check of an inertia (the triangle inequality, here)
        check_inertia(np.diag(I), "moments", rtol=1e-12, allow_unphysical=allow_unphysical)
        self._setup(I, np.eye(3))

    def _setup(self, moments, body_axes):
        """``moments`` along the columns of ``body_axes`` (principal axes in body coordinates)."""
        self.moments = np.array(moments, dtype=float)
        order = np.argsort(self.moments, kind="stable")
        S = body_axes[:, order].copy()
        if np.linalg.det(S) < 0:
            S[:, 2] = -S[:, 2]
        self._S = np.ascontiguousarray(S)  # sorted principal axes (columns), right-handed
        self._I = np.ascontiguousarray(self.moments[order])
        # the closed forms run on moments scaled by a power of two (exactly) to I3 ~ 1: they
        # hold products such as I1 I2 I3, which would leave the double range for moments
        # beyond 1e±103; times and ω are unchanged by this scaling (ω̇ = −I⁻¹(ω × Iω))
        self._In = np.ldexp(self._I, -int(np.frexp(self._I[2])[1]))
        self._symmetry_code = int(core_inertia.symmetry_code(self._I, SYMMETRY_RTOL))
        self.symmetry = core_inertia.SYMMETRY_CLASSES[self._symmetry_code]
        self.inertia = body_axes @ np.diag(moments) @ body_axes.T

    @classmethod
    def from_body(cls, body) -> FreeRigidBody:
        """The torque-free motion of a :class:`~poinsot.bodies.RigidBody` about its centre of
        mass; inputs and outputs are in the body's own frame."""
        self = cls.__new__(cls)
        if body.is_degenerate:
            raise ValueError(
                "`body` is degenerate (all mass on a line): its torque-free spin about that line "
                "is undefined"
            )
        self._setup(body.principal_moments, body.principal_axes)
        return self

    def __repr__(self):
        return f"FreeRigidBody(moments={self.moments.tolist()}, symmetry={self.symmetry!r})"

    @property
    def principal_moments(self) -> np.ndarray:
        """Sorted moments ``(I1, I2, I3)``."""
        return self._I.copy()

    @property
    def principal_axes(self) -> np.ndarray:
        """The sorted principal axes (columns, body coordinates, right-handed), (3, 3)."""
        return self._S.copy()

    # ----------------------------------------------------------------- frames
    def principal_components(self, vectors) -> np.ndarray:
        """The components ``(v·e1, v·e2, v·e3)`` along the sorted principal axes of body-frame
        vectors (..., 3): what the figures plot, so that a curve "around e1" circles the axis
        labelled e₁ whatever the body's own axes are.

        >>> import numpy as np
        >>> from poinsot.models import notebook_body
        >>> free = FreeRigidBody.from_body(notebook_body())  # e1 is the body's z axis
        >>> free.principal_components([0.0, 0.0, 2.0]).round(12).tolist()
        [2.0, 0.0, 0.0]
        """
        return np.asarray(vectors, dtype=float) @ self._S

    def _to_sorted(self, omega):
        return np.asarray(omega, dtype=float) @ self._S  # Sᵀ ω for row vectors

    def _from_sorted(self, w):
        return np.asarray(w) @ self._S.T

    # ----------------------------------------------------------------- the cone
    def cone_coefficients(self, energy, momentum) -> np.ndarray:
        """Coefficients ``b_i = I_i (a²/(2k) − I_i)`` of the cone (32) ``Σ b_i ω_i² = 0``, along
        the sorted principal axes e1, e2, e3 (erratum: ``a²/(2k)``, not ``a²/2·k``).

        Examples
        --------
        >>> FreeRigidBody((1, 2, 3)).cone_coefficients(0.5, 2 ** 0.5).round(12).tolist()
        [1.0, 0.0, -3.0]
        """
        self.check_feasible(energy, momentum)
        return core_torquefree.cone_coefficients(self._I, float(energy), float(momentum))

    def cone_matrix(self, energy, momentum) -> np.ndarray:
        """The cone (32) as a quadratic form in the body frame: ``ωᵀ C ω = 0``, (3, 3)."""
        return self._S @ np.diag(self.cone_coefficients(energy, momentum)) @ self._S.T

    def check_feasible(self, energy, momentum) -> float:
        """Return ``D = a²/(2k)`` after checking condition (33) ``I1 ≤ a²/(2k) ≤ I3``."""
        k = as_scalar(energy, "energy")
        a = as_scalar(momentum, "momentum")
        if not k > 0:
            raise ValueError(f"`energy` must be a positive number, found {energy}")
        if not a >= 0:
            raise ValueError(f"`momentum` must be a non-negative number, found {momentum}")
        self.check_energy_range(k)
        # a²/(2k) as (a/√(2k))²: a² alone leaves the double range long before the ratio does
        # (a = 1e300); a product that overflows is inf, which the check below refuses
        s = a / math.sqrt(2 * k)
        D = s * s
        I1, _, I3 = self._I
        if D < I1 * (1 - 1e-12) or D > I3 * (1 + 1e-12):
            raise ValueError(
                f"infeasible invariants `energy` = {k:.6g}, `momentum` = {a:.6g}: every motion "
                "has I1 ≤ a²/(2k) ≤ I3 (33), found "
                f"I1 = {I1:.6g}, a²/(2k) = {D:.6g}, I3 = {I3:.6g}"
            )
        return min(max(D, I1), I3)

    def check_energy_range(self, energy) -> float:
        """Refuse an energy whose polhodes leave the double range: the ellipsoid's points
        ``ω = √(2k/I)`` and momenta ``a = √(2kI)`` must stay finite and nonzero."""
        k = as_scalar(energy, "energy")
        I1, I3 = self._I[0], self._I[2]
        with np.errstate(over="ignore", under="ignore"):
            values = (2 * k * I3, 2 * k / I1, 2 * k * I1, 2 * k / I3)
        if not all(np.isfinite(v) and v > 1e-300 for v in values):
            raise ValueError(
                f"`energy` = {k:.3g} with moments {I1:.3g} … {I3:.3g} is out of range: 2k·I3 and "
                "2k/I1 must lie within 1e-300 … 1e308 (choose other units)"
            )
        return k

    def euler_rhs(self, omega) -> np.ndarray:
        """``ω̇`` from Euler's equation (20) in principal components (27)–(29), for ω (..., 3)
        in the body frame."""
        raw = _real_array(omega, "omega")
        if raw.ndim == 0 or raw.shape[-1] != 3:
            raise ValueError(f"`omega` must have shape (..., 3), found shape {raw.shape}")
        w = as_array(raw, "omega", (None,) * (raw.ndim - 1) + (3,))
        S = self._S
        w_sorted = np.ascontiguousarray(w.reshape(-1, 3) @ S)
        return (core_torquefree.euler_omega_dot_free(self._I, w_sorted) @ S.T).reshape(w.shape)
