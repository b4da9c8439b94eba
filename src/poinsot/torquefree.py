"""The torque-free rigid body solved exactly (THEORY.md §1, "Torque-free body", eqs (19)–(33)).

:class:`FreeRigidBody` holds the principal moments and answers everything Euler's equation
``A ω̇ + ω × Aω = 0`` (20) allows in closed form: the invariants (30)–(31), the cone (32), the
feasibility condition (33), fixed points and their stability, ω(t) by Jacobi elliptic functions,
the attitude Q(t) by Euler angles about the angular momentum with the incomplete elliptic
integral of the third kind, periods, flip intervals, polhodes and herpolhodes.

Frames. ``FreeRigidBody(moments)`` takes the moments along the body's x, y, z axes (any order):
the body frame *is* the principal frame. :meth:`FreeRigidBody.from_body` takes a
:class:`~poinsot.bodies.RigidBody` and works in its principal frame, mapping every input and
result to and from the body frame. Internally the moments are sorted, ``I1 ≤ I2 ≤ I3``, in a
right-handed frame ``S`` (columns: the sorted axes in body coordinates).

The formulas (Landau & Lifshitz, *Mechanics*, §37; Whittaker, *Analytical Dynamics*, §69)
were re-derived and are verified in the tests by differentiation and against DOP853, because
published versions contain sign errors.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import elliptic
from ._validation import as_array, as_vector3
from .kernels import freebody
from .kernels import inertia as kin_inertia
from .kernels.rigid import angular_momentum_body, euler_omega_dot, rotational_energy
from .kernels.so3 import exp_so3

__all__ = ["FixedPointSet", "FreeRigidBody", "Polhode", "Stability"]

#: Moments closer than this (relative to I3) are treated as equal (symmetric body); the same
#: tolerance as :attr:`poinsot.bodies.RigidBody.symmetry`.
SYMMETRY_RTOL = kin_inertia.SYMMETRY_RTOL
#: ω within this relative distance of the intermediate axis is taken as that fixed point.
NEAR_UNSTABLE_AXIS = 1e-140


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


@dataclass
class Polhode:
    """A polhode: the path of ω on the energy ellipsoid (body frame).

    ``points`` (n, 3); ``family`` is ``"around e1"``, ``"around e3"``, ``"separatrix"``,
    ``"fixed point"``, ``"symmetric"`` (a circle of a symmetric body) or ``"spherical"``;
    ``energy`` k (``2k = Σ I ω²``), ``momentum`` a = |L|, ``period`` of ω(t) (inf on the
    separatrix), ``t`` the times of the points from ``omega0``.
    """

    points: np.ndarray
    family: str
    energy: float
    momentum: float
    period: float
    t: np.ndarray = field(repr=False, default=None)


class FreeRigidBody:
    """A torque-free rigid body given by its principal moments.

    Parameters
    ----------
    moments : array_like (3,)
        Principal moments along the body's x, y, z axes, in any order, all > 0, satisfying the
        triangle inequalities (no moment exceeds the sum of the other two).
    allow_unphysical : bool
        Accept moments that break the triangle inequality, with a warning: Euler's equation is
        still well posed (the source notebook's example (3, 3, 9) is such a case).

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
    """

    def __init__(self, moments, *, allow_unphysical: bool = False):
        I = as_array(moments, "moments", (3,))
        if np.any(I <= 0):
            k = int(np.argmax(I <= 0))
            raise ValueError(
                f"`moments[{k}]` must be positive, found {I[k]} (a degenerate body, all mass on "
                "a line, has no torque-free dynamics about that line)"
            )
        s = np.sort(I)
        if s[0] + s[1] < s[2] * (1 - 1e-12):
            message = (
                "principal moments must satisfy I1 + I2 ≥ I3, found "
                f"{s[0]:.6g} + {s[1]:.6g} < {s[2]:.6g}"
            )
            if not allow_unphysical:
                raise ValueError(message + " (allow_unphysical=True to study the equation anyway)")
            warnings.warn(message + ": no mass distribution has these moments", stacklevel=2)
        self._setup(I, np.eye(3))

    def _setup(self, moments, body_axes):
        """``moments`` along the columns of ``body_axes`` (principal axes in body coordinates)."""
        self.moments = np.array(moments, dtype=float)
        order = np.argsort(self.moments, kind="stable")
        S = body_axes[:, order].copy()
        if np.linalg.det(S) < 0:
            S[:, 2] = -S[:, 2]
        self._S = S  # sorted principal axes (columns) in body coordinates, right-handed
        self._I = self.moments[order]
        code = kin_inertia.symmetry_code(self._I, SYMMETRY_RTOL)
        self.symmetry = kin_inertia.SYMMETRY_CLASSES[code]
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

    # ----------------------------------------------------------------- frames
    def _to_sorted(self, omega):
        return np.asarray(omega, dtype=float) @ self._S  # Sᵀ ω for row vectors

    def _from_sorted(self, w):
        return np.asarray(w) @ self._S.T

    def _omega(self, omega0, name="omega0"):
        w = as_vector3(omega0, name)
        return w, self._to_sorted(w)

    # ----------------------------------------------------------------- invariants
    def invariants(self, omega) -> tuple[float, float]:
        """``(k, a)``: rotational kinetic energy ``2k = Σ I_i ω_i²`` (30) and ``a = |L|`` (31).

        Examples
        --------
        >>> FreeRigidBody((1, 2, 3)).invariants((1, 0, 0))
        (0.5, 1.0)
        """
        _, w = self._omega(omega, "omega")
        k, a = freebody.invariants(self._I, w)
        return float(k), float(a)

    def cone_coefficients(self, energy, momentum) -> np.ndarray:
        """Coefficients ``b_i = I_i (a²/(2k) − I_i)`` of the cone (32) ``Σ b_i ω_i² = 0``, along
        the sorted principal axes e1, e2, e3 (THEORY.md erratum: ``a²/(2k)``, not ``a²/2·k``).

        Examples
        --------
        >>> FreeRigidBody((1, 2, 3)).cone_coefficients(0.5, 2 ** 0.5).round(12).tolist()
        [1.0, 0.0, -3.0]
        """
        self.check_feasible(energy, momentum)
        return freebody.cone_coefficients(self._I, float(energy), float(momentum))

    def cone_matrix(self, energy, momentum) -> np.ndarray:
        """The cone (32) as a quadratic form in the body frame: ``ωᵀ C ω = 0``, (3, 3)."""
        return self._S @ np.diag(self.cone_coefficients(energy, momentum)) @ self._S.T

    def check_feasible(self, energy, momentum) -> float:
        """Return ``D = a²/(2k)`` after checking condition (33) ``I1 ≤ a²/(2k) ≤ I3``."""
        k = float(energy)
        a = float(momentum)
        if not (np.isfinite(k) and k > 0):
            raise ValueError(f"`energy` must be a positive number, found {energy}")
        if not (np.isfinite(a) and a >= 0):
            raise ValueError(f"`momentum` must be a non-negative number, found {momentum}")
        D = a * a / (2 * k)
        I1, _, I3 = self._I
        if D < I1 * (1 - 1e-12) or D > I3 * (1 + 1e-12):
            raise ValueError(
                "infeasible invariants: every motion has I1 ≤ a²/(2k) ≤ I3 (33), found "
                f"I1 = {I1:.6g}, a²/(2k) = {D:.6g}, I3 = {I3:.6g}"
            )
        return min(max(D, I1), I3)

    def euler_rhs(self, omega) -> np.ndarray:
        """``ω̇`` from Euler's equation (20) in principal components (27)–(29), for ω (..., 3)
        in the body frame."""
        w = np.asarray(omega, dtype=float)
        S = self._S
        w_sorted = w @ S
        return euler_omega_dot(self._I, w_sorted, np.zeros_like(w_sorted)) @ S.T

    # ----------------------------------------------------------------- fixed points
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
        w = as_vector3(omega, "omega")
        Aw = self.inertia @ w
        return bool(
            np.linalg.norm(np.cross(w, Aw))
            <= rtol * max(np.linalg.norm(w) * np.linalg.norm(Aw), 1e-300)
        )

    def jacobian(self, omega) -> np.ndarray:
        """``∂ω̇/∂ω = A⁻¹(hat(Aω) − hat(ω) A)`` (3, 3), body frame."""
        w = as_vector3(omega, "omega")
        return freebody.euler_jacobian(np.ascontiguousarray(self.inertia), w)

    def stability(self, omega) -> Stability:
        """Linear stability of the fixed point ``omega`` (body frame); see :class:`Stability`."""
        w = as_vector3(omega, "omega")
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
        w = as_vector3(omega, "omega")
        if not self.is_fixed_point(w):
            raise ValueError(f"`omega` = {w.tolist()} is not a fixed point: ω × Aω ≠ 0")
        t = np.atleast_1d(np.asarray(t, dtype=float))
        Q0 = np.eye(3) if Q0 is None else _rotation(Q0)
        if method == "rodrigues":
            return Q0 @ exp_so3(t[:, None] * w)
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

    # ----------------------------------------------------------------- exact solution
    def _regime(self, w):
        """Classify the sorted ω and return the parameters of its exact solution."""
        I1, I2, I3 = self._I
        w1, w2, w3 = w
        a2 = float(np.sum((self._I * w) ** 2))
        k2 = float(np.sum(self._I * w * w))
        if self.symmetry != "asymmetric" or a2 == 0:
            return {"case": "symmetric"}
        # cancellation-free combinations of the invariants (see module docstring)
        P3 = I1 * (I3 - I1) * w1 * w1 + I2 * (I3 - I2) * w2 * w2  # 2k I3 − a² ≥ 0
        P1 = I2 * (I2 - I1) * w2 * w2 + I3 * (I3 - I1) * w3 * w3  # a² − 2k I1 ≥ 0
        D2 = I3 * (I3 - I2) * w3 * w3 - I1 * (I2 - I1) * w1 * w1  # a² − 2k I2
        base = {"a": math.sqrt(a2), "k": 0.5 * k2}
        if max(abs(w1), abs(w3)) <= NEAR_UNSTABLE_AXIS * abs(w2):
            # Within 1e-140 of the unstable axis the motion is its fixed point: leaving it
            # takes longer than ln(1e140)/σ ≈ 322/σ, and the invariants' differences that set
            # the orbit underflow in double precision.
            return base | {"case": "fixed", "axis": 1}
        if P3 == 0:
            return base | {"case": "fixed", "axis": 2}
        if P1 == 0:
            return base | {"case": "fixed", "axis": 0}
        if D2 >= 0:  # around e3, or the separatrix (D2 = 0)
            alpha = np.array(
                [
                    math.sqrt(P3 / (I1 * (I3 - I1))),
                    math.sqrt(P3 / (I2 * (I3 - I2))),
                    math.sqrt(P1 / (I3 * (I3 - I1))),
                ]
            )
            lam = math.sqrt((I3 - I2) * P1 / (I1 * I2 * I3))
            m = (I2 - I1) * P3 / ((I3 - I2) * P1)
            m1 = (I3 - I1) * D2 / ((I3 - I2) * P1)
            pole = 2
        else:  # around e1
            alpha = np.array(
                [
                    math.sqrt(P3 / (I1 * (I3 - I1))),
                    math.sqrt(P1 / (I2 * (I2 - I1))),
                    math.sqrt(P1 / (I3 * (I3 - I1))),
                ]
            )
            lam = math.sqrt((I2 - I1) * P3 / (I1 * I2 * I3))
            m = (I3 - I2) * P1 / ((I2 - I1) * P3)
            m1 = (I3 - I1) * (-D2) / ((I2 - I1) * P3)
            pole = 0
        m, m1 = min(max(m, 0.0), 1.0), min(max(m1, 0.0), 1.0)
        if m1 < 1e-300:  # subnormal: the separatrix is the orbit to within O(m1)
            m, m1 = 1.0, 0.0
        s1 = 1.0 if w1 > 0 else -1.0
        s3 = 1.0 if w3 > 0 else -1.0
        # Signs: the ODE needs σ1 = σ2 σ3. Off the separatrix cn takes both signs, so the sign
        # of the cn-component is +1 (absorbed in the phase); on the separatrix cn = sech u > 0
        # and each of the four arcs keeps the signs of both ω1 and ω3.
        if pole == 2:
            s1 = s1 if m1 == 0 else 1.0
            signs = np.array([s1, s1 * s3, s3])
            sn0, cn0 = signs[1] * w2 / alpha[1], signs[0] * w1 / alpha[0]
        else:
            s3 = s3 if m1 == 0 else 1.0
            signs = np.array([s1, s1 * s3, s3])
            sn0, cn0 = signs[1] * w2 / alpha[1], signs[2] * w3 / alpha[2]
        u0 = elliptic.first_kind_from_sn_cn(sn0, cn0, m, m1)
        case = "separatrix" if m1 == 0 else ("around e3" if pole == 2 else "around e1")
        return base | {
            "case": case,
            "alpha": alpha,
            "lam": lam,
            "m": m,
            "m1": m1,
            "signs": signs,
            "u0": u0,
            "pole": pole,
        }

    def _symmetric_parts(self, w):
        """For a symmetric body: symmetry axis index ``s`` (sorted frame), transverse moment
        ``I`` and the body-frame precession rate ``ν = (1/I_s − 1/I) π_s``."""
        I = self._I
        if self.symmetry == "spherical":
            return 2, I[0], 0.0
        s, Iperp = (2, I[0]) if self.symmetry == "oblate" else (0, I[2])
        return s, Iperp, (1.0 / I[s] - 1.0 / Iperp) * I[s] * w[s]

    def _exact_sorted(self, w, t):
        """ω(t) (n, 3) in the sorted frame and the regime parameters."""
        reg = self._regime(w)
        case = reg["case"]
        if case == "fixed":
            return np.tile(w, (len(t), 1)), reg
        if case == "symmetric":
            s, _, nu = self._symmetric_parts(w)
            pi = np.einsum("nij,j->ni", exp_so3(-np.outer(t, nu * np.eye(3)[s])), self._I * w)
            return pi / self._I, reg
        sn, cn, dn = elliptic.jacobi(reg["u0"] + reg["lam"] * t, reg["m"], reg["m1"])
        alpha, signs = reg["alpha"], reg["signs"]
        if reg["pole"] == 2:
            out = np.column_stack(
                [signs[0] * alpha[0] * cn, signs[1] * alpha[1] * sn, signs[2] * alpha[2] * dn]
            )
        else:
            out = np.column_stack(
                [signs[0] * alpha[0] * dn, signs[1] * alpha[1] * sn, signs[2] * alpha[2] * cn]
            )
        return out, reg

    def exact_omega(self, omega0, t) -> np.ndarray:
        """ω(t) (n, 3), body frame, from ``ω(0) = omega0``: the exact solution of (20).

        Asymmetric bodies: Jacobi elliptic functions, ``a²/2k > I2`` (around e3):
        ``ω = (α1 cn u, ±α2 sn u, ±α3 dn u)``; ``a²/2k < I2`` (around e1):
        ``ω = (±α1 dn u, ±α2 sn u, α3 cn u)``; on the separatrix (m = 1) the same with
        ``sn = tanh``, ``cn = dn = sech``. ``u = u0 + λt``; the parameter's complement
        ``1 − m`` is formed without cancellation, so the solution stays accurate arbitrarily
        close to the separatrix. Symmetric bodies: ``π = Aω`` turns about the symmetry axis at
        the rate ``−ν``, ``ν = (1/I_s − 1/I⊥) π_s``. Spherical: ω constant.
        """
        _, w = self._omega(omega0)
        t = np.atleast_1d(as_array(t, "t", (None,)) if np.ndim(t) else np.array([float(t)]))
        out, _ = self._exact_sorted(w, t)
        return self._from_sorted(out)

    def classify(self, omega0) -> str:
        """The polhode family of ``omega0``: ``"around e1"``, ``"around e3"``,
        ``"separatrix"``, ``"fixed point"``, ``"symmetric"`` or ``"spherical"``."""
        _, w = self._omega(omega0)
        case = self._regime(w)["case"]
        if case == "symmetric":
            if self.symmetry == "spherical":
                return "spherical"
            s, _, nu = self._symmetric_parts(w)
            return "fixed point" if nu == 0 or np.allclose(np.delete(w, s), 0) else "symmetric"
        return "fixed point" if case == "fixed" else case

    def period(self, omega0) -> float:
        """Period of ω(t): ``4K(m)/λ`` (asymmetric), ``2π/|ν|`` (symmetric); ``inf`` on the
        separatrix. Raises ``ValueError`` at a fixed point, where ω is constant."""
        _, w = self._omega(omega0)
        reg = self._regime(w)
        case = reg["case"]
        if case == "fixed" or self.classify(omega0) in ("fixed point", "spherical"):
            raise ValueError("`omega0` is a fixed point: ω(t) is constant and has no period")
        if case == "symmetric":
            _, _, nu = self._symmetric_parts(w)
            return 2 * math.pi / abs(nu)
        if case == "separatrix":
            return math.inf
        return 4 * elliptic.ellipk(reg["m1"]) / reg["lam"]

    def flip_interval(self, omega0) -> float:
        """Time between successive flips (sign changes of ω2) of the intermediate-axis motion:
        ``2K(m)/λ`` — the tennis-racket / Dzhanibekov time. ``inf`` on the separatrix.

        Raises ``ValueError`` where a flip is undefined: symmetric or spherical bodies (no
        intermediate axis) and fixed points (ω2 never changes sign).
        """
        _, w = self._omega(omega0)
        if self.symmetry != "asymmetric":
            raise ValueError(
                f"flip_interval needs three distinct moments; this body is {self.symmetry}"
            )
        reg = self._regime(w)
        if reg["case"] == "fixed":
            raise ValueError("`omega0` is a fixed point: ω2 never changes sign, no flips")
        if reg["case"] == "separatrix":
            return math.inf
        return 2 * elliptic.ellipk(reg["m1"]) / reg["lam"]

    def exact_attitude(self, omega0, t, Q0=None) -> np.ndarray:
        """Attitude ``Q(t)`` (n, 3, 3) (body → space) of the torque-free motion from
        ``ω(0) = omega0`` and ``Q(0) = Q0`` (default identity), exactly.

        Asymmetric bodies: z-x-z Euler angles ``(ψ, θ, φ)`` of the body relative to the
        invariable frame (z along L), with pole the axis the polhode circles (e3, or e1 via the
        right-handed relabelling ``(e3, −e2, e1)``); ``cos θ = π_pole/a``,
        ``tan φ = π_1'/π_2'`` and
        ``ψ(t) = a t/I_p + a (I_p − I_q)/(I_p I_q λ) [Π(n; am u | m) − Π(n; am u0 | m)]``
        (evaluated as ``∫ du/(1 − n sn² u)`` in u, never through the amplitude, which rounds
        to ±π/2 while the body lingers by its unstable axis),
        ``n = −I_p (I2 − I1)/(I1 (I3 − I2))`` (pole e3; swap 1 ↔ 3 for pole e1), n < 0, so the
        third-kind integral has no pole. Symmetric bodies:
        ``Q(t) = exp(t L̂/I⊥) Q0 exp(ν t ê_s)``; fixed points: ``Q0 exp(Ω t)``.
        """
        omega_body, w = self._omega(omega0)
        t = np.atleast_1d(np.asarray(t, dtype=float))
        Q0 = np.eye(3) if Q0 is None else _rotation(Q0)
        S = self._S
        Q0s = Q0 @ S  # sorted-principal frame → space
        omega_s, reg = self._exact_sorted(w, t)
        case = reg["case"]
        if case == "fixed" or (case == "symmetric" and self.classify(omega0) != "symmetric"):
            return Q0 @ exp_so3(t[:, None] * omega_body)
        if case == "symmetric":
            s, Iperp, nu = self._symmetric_parts(w)
            L = Q0s @ (self._I * w)
            Qs = exp_so3(np.outer(t, L / Iperp)) @ Q0s @ exp_so3(np.outer(t, nu * np.eye(3)[s]))
            return Qs @ S.T
        I1, I2, I3 = self._I
        a, lam, m, m1 = reg["a"], reg["lam"], reg["m"], reg["m1"]
        if reg["pole"] == 2:
            B = np.eye(3)
            Ip, Iq = I3, I1
            n = -I3 * (I2 - I1) / (I1 * (I3 - I2))
        else:  # relabel (e1', e2', e3') = (e3, −e2, e1): right-handed, pole e1
            B = np.array([[0.0, 0, 1], [0, -1, 0], [1, 0, 0]])
            Ip, Iq = I1, I3
            n = -I1 * (I3 - I2) / (I3 * (I2 - I1))
        pi_b = (omega_s * self._I) @ B.T  # body momentum in the relabelled frame
        theta = np.arctan2(np.hypot(pi_b[:, 0], pi_b[:, 1]), pi_b[:, 2])
        phi = np.arctan2(pi_b[:, 0], pi_b[:, 1])
        u0 = reg["u0"]
        Pi = elliptic.third_kind_u(n, u0 + lam * t, m, m1) - elliptic.third_kind_u(n, u0, m, m1)
        psi = a * t / Ip + a * (Ip - Iq) / (Ip * Iq * lam) * Pi  # ψ(0) = 0
        R_inv = _zxz(psi, theta, phi)  # relabelled body → invariable frame
        # Q(t) = P0 R_inv(t) B, with P0 (invariable → space) fixed by Q(0) = Q0:
        # P0 = Q0s Bᵀ R_inv(0)ᵀ, R_inv(0) from ω(0) with ψ = 0
        pi0 = (w * self._I) @ B.T
        R0 = _zxz(
            np.zeros(1),
            np.arctan2(np.hypot(pi0[:1], pi0[1:2]), pi0[2:3]),
            np.arctan2(pi0[:1], pi0[1:2]),
        )[0]
        P0 = Q0s @ B.T @ R0.T
        return P0 @ R_inv @ B @ S.T

    # ----------------------------------------------------------------- polhodes
    def polhode(self, omega0=None, *, energy=None, momentum=None, n=400) -> Polhode:
        """The polhode through ``omega0`` — or the one with the given ``energy`` k and
        ``momentum`` a (the branch with positive component along its pole) — exactly, as
        ``n`` points over one period of ω(t) (a separatrix arc: ``n`` points over t ∈ [−T, T]
        with T long enough to approach the unstable points within 1e-6 relative).
        """
        if omega0 is None:
            if energy is None or momentum is None:
                raise ValueError("give `omega0`, or both `energy` and `momentum`")
            omega0 = self.point_on_polhode(energy, momentum)
        w_body, w = self._omega(omega0)
        k, a = self.invariants(w_body)
        family = self.classify(w_body)
        if family in ("fixed point", "spherical"):
            return Polhode(w_body[None, :], "fixed point", k, a, math.inf, np.zeros(1))
        if family == "separatrix":
            reg = self._regime(w)
            T = (abs(reg["u0"]) + math.log(4e6)) / reg["lam"]
            t = np.linspace(-T, T, n)
        else:
            t = np.linspace(0.0, self.period(w_body), n)
        pts = self.exact_omega(w_body, t)
        return Polhode(pts, family, k, a, self.period(w_body), t)

    def point_on_polhode(self, energy, momentum, sign=1.0) -> np.ndarray:
        """A point ω (body frame) with the given ``energy`` k and ``momentum`` a: where the
        polhode crosses ω2 = 0 (on its pole's side ``sign``); on the separatrix, a point near
        the unstable axis on the arc with ω1, ω3 > 0."""
        D = self.check_feasible(energy, momentum)
        k = float(energy)
        I1, I2, I3 = self._I
        if self.symmetry == "spherical":
            return self._from_sorted(np.array([0, 0, sign * math.sqrt(2 * k / I3)]))
        # solve I1 w1² + I3 w3² = 2k, I1² w1² + I3² w3² = 2kD (ω2 = 0)
        if I3 - I1 > 0:
            w1sq = 2 * k * (I3 - D) / (I1 * (I3 - I1))
            w3sq = 2 * k * (D - I1) / (I3 * (I3 - I1))
        else:  # pragma: no cover - spherical handled above
            w1sq, w3sq = 0.0, 2 * k / I3
        if self.symmetry == "asymmetric" and abs(D - I2) <= 1e-12 * I3:
            eps = 1e-3  # a point on the separatrix arc, near e2
            w2 = math.sqrt(2 * k / I2) * math.sqrt(1 - eps**2)
            r = 2 * k - I2 * w2 * w2  # remaining energy split between ω1 and ω3 on the cone
            b1, b3 = I1 * (I2 - I1), I3 * (I3 - I2)  # cone (32) at D = I2: b1 ω1² = b3 ω3²
            w3 = math.sqrt(r / (I3 + I1 * b3 / b1))
            w1 = math.sqrt(b3 / b1) * w3
            return self._from_sorted(np.array([w1, w2, w3]) * np.array([1, 1, 1]))
        w = np.array([math.sqrt(max(w1sq, 0)), 0.0, math.sqrt(max(w3sq, 0))])
        if D > I2 or self.symmetry == "oblate":
            w[2] *= sign
        else:
            w[0] *= sign
        return self._from_sorted(w)

    def polhode_family(self, energy=0.5, *, levels=9, n=400) -> list[Polhode]:
        """Every kind of polhode on the energy ellipsoid of ``energy`` (the notebook's sweep,
        done exactly): ``levels`` values of a²/2k strictly between I1 and I3, on both branches,
        the separatrix arcs (asymmetric bodies) and the fixed points."""
        I1, I2, I3 = self._I
        k = float(energy)
        out = []
        if self.symmetry == "spherical":
            return [Polhode(np.zeros((0, 3)), "spherical", k, math.sqrt(2 * k * I1), math.inf)]
        Ds = I1 + (I3 - I1) * (np.arange(1, levels + 1) / (levels + 1))
        for D in Ds:
            if self.symmetry == "asymmetric" and abs(D - I2) < 1e-9 * I3:
                continue
            a = math.sqrt(2 * k * D)
            for sgn in (1.0, -1.0):
                out.append(self.polhode(self.point_on_polhode(k, a, sgn), n=n))
        if self.symmetry == "asymmetric":
            out.extend(self.separatrix_arcs(k, n=n))
        for fp in self.fixed_points():
            if fp.kind == "axis":
                e = fp.basis[:, 0]
                w = e * math.sqrt(2 * k / fp.moment)
                for sgn in (1.0, -1.0):
                    out.append(
                        Polhode(
                            (sgn * w)[None, :],
                            "fixed point",
                            k,
                            math.sqrt(2 * k * fp.moment),
                            math.inf,
                            np.zeros(1),
                        )
                    )
        return out

    def describe(self, omega0) -> dict:
        """A JSON-ready summary of the motion from ``omega0``: family, invariants, period,
        flip interval (``"inf"`` on the separatrix; absent where undefined) and fixed points."""
        k, a = self.invariants(omega0)
        out = {
            "family": self.classify(omega0),
            "energy": k,
            "momentum": a,
            "fixed_points": [{"set": fp.label, "stable": fp.stable} for fp in self.fixed_points()],
        }
        for name, fn in (("period", self.period), ("flip_interval", self.flip_interval)):
            try:
                value = fn(omega0)
            except ValueError:
                continue
            out[name] = value if math.isfinite(value) else "inf"
        return out

    def separatrix_arcs(self, energy=0.5, *, n=400, reach=1e-6) -> list[Polhode]:
        """The four heteroclinic arcs at ``a² = 2k I2`` joining the unstable points ±√(2k/I2) e2,
        in closed form: ``ω = (σ1 α1 sech u, σ1σ3 α2 tanh u, σ3 α3 sech u)``,
        ``α1² = 2k(I3 − I2)/(I1(I3 − I1))``, ``α2² = 2k/I2``, ``α3² = 2k(I2 − I1)/(I3(I3 − I1))``,
        ``u = λt``, ``λ² = (I3 − I2)(I2 − I1)·2k/(I1 I2 I3)``; ``u`` spans the arc until the
        sech terms fall to ``reach``."""
        if self.symmetry != "asymmetric":
            raise ValueError(
                f"a separatrix needs three distinct moments; this body is {self.symmetry}"
            )
        I1, I2, I3 = self._I
        k = float(energy)
        alpha = np.sqrt(
            [2 * k * (I3 - I2) / (I1 * (I3 - I1)), 2 * k / I2, 2 * k * (I2 - I1) / (I3 * (I3 - I1))]
        )
        lam = math.sqrt((I3 - I2) * (I2 - I1) * 2 * k / (I1 * I2 * I3))
        U = math.acosh(1 / reach)
        u = np.linspace(-U, U, n)
        sech, tanh = 1 / np.cosh(u), np.tanh(u)
        arcs = []
        for s1 in (1.0, -1.0):
            for s3 in (1.0, -1.0):
                w = np.column_stack(
                    [s1 * alpha[0] * sech, s1 * s3 * alpha[1] * tanh, s3 * alpha[2] * sech]
                )
                arcs.append(
                    Polhode(
                        self._from_sorted(w),
                        "separatrix",
                        k,
                        math.sqrt(2 * k * I2),
                        math.inf,
                        u / lam,
                    )
                )
        return arcs

    def herpolhode(self, omega0, t, Q0=None) -> np.ndarray:
        """The herpolhode: ω in space, in the invariable frame (z along L), (n, 3).

        Its z-component is the constant ``2k/a`` (the invariable plane); (x, y) trace the curve
        on which Poinsot's ellipsoid rolls.
        """
        w_body = as_vector3(omega0, "omega0")
        Q = self.exact_attitude(w_body, t, Q0)
        w = self.exact_omega(w_body, t)
        space = np.einsum("nij,nj->ni", Q, w)
        L = Q[0] @ (self.inertia @ w[0])
        ez = L / np.linalg.norm(L)
        ex = np.cross([0.0, 0, 1] if abs(ez[2]) < 0.9 else [1.0, 0, 0], ez)
        ex /= np.linalg.norm(ex)
        ey = np.cross(ez, ex)
        return space @ np.column_stack([ex, ey, ez])

    # ----------------------------------------------------------------- oracle
    def trajectory_error(self, trajectory) -> dict:
        """Errors of a numerical torque-free :class:`~poinsot.trajectory.Trajectory` against
        the exact solution from its first sample: max |Δω|, max |ΔQ|, relative energy and |L|
        errors. The trajectory must be torque-free about its centre of mass."""
        tr = trajectory
        if getattr(tr.system, "pivot", None) is not None and np.any(tr.system.c):
            raise ValueError("`trajectory` turns about a pivot away from its centre of mass")
        t = tr.t - tr.t[0]
        w = self.exact_omega(tr.omega[0], t)
        Q = self.exact_attitude(tr.omega[0], t, tr.Q[0])
        k0, a0 = self.invariants(tr.omega[0])
        omega = np.ascontiguousarray(tr.omega)
        ks = rotational_energy(self.inertia, omega)
        As = np.linalg.norm(angular_momentum_body(self.inertia, omega), axis=1)
        return {
            "omega": float(np.abs(tr.omega - w).max()),
            "attitude": float(np.abs(tr.Q - Q).max()),
            "energy": float(np.abs(ks / k0 - 1).max()),
            "momentum": float(np.abs(As / a0 - 1).max()),
        }


def _rotation(Q0):
    from ._validation import as_rotation_matrix

    return as_rotation_matrix(Q0, "Q0")


def _zxz(psi, theta, phi):
    """``Rz(ψ) Rx(θ) Rz(φ)`` for arrays of angles, (n, 3, 3)."""
    cps, sps = np.cos(psi), np.sin(psi)
    ct, st = np.cos(theta), np.sin(theta)
    cph, sph = np.cos(phi), np.sin(phi)
    R = np.empty((len(psi), 3, 3))
    R[:, 0, 0] = cps * cph - sps * ct * sph
    R[:, 0, 1] = -cps * sph - sps * ct * cph
    R[:, 0, 2] = sps * st
    R[:, 1, 0] = sps * cph + cps * ct * sph
    R[:, 1, 1] = -sps * sph + cps * ct * cph
    R[:, 1, 2] = -cps * st
    R[:, 2, 0] = st * sph
    R[:, 2, 1] = st * cph
    R[:, 2, 2] = ct
    return R
