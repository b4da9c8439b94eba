"""The torque-free motion in closed form: ω(t), Q(t), periods, flips, families
(``docs/theory.md`` §1, eqs (20)–(33); ``docs/torque_free.md``).

Every method takes one initial condition ``omega0`` (3,) or many (N, 3) (body frame) and
evaluates the closed form in the compiled core (``poinsot._core``: the Rust crate
``poinsot-core``, modules ``torque_free`` and ``freebody``; the loop over members runs there,
without the GIL, thirty-two members at a time in SIMD lanes on every core), so millions of exact
solutions need no integrator. With one initial
condition the result has the
shapes of a single motion (``exact_omega``: (n, 3)) and undefined quantities raise; with many,
a leading member axis is added (``(N, n, 3)``) and undefined quantities are NaN, so that one
fixed point does not stop a sweep.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validation
from .._bindings import torquefree as core_torquefree
from .._validation import _real_array, as_rotation_matrices, as_times, as_vector3, as_vectors

__all__ = ["MAX_PHASE", "ExactDerivatives", "SolutionMixin"]

#: The largest angle ``|ω| |t|`` (rad) at which the closed forms are evaluated: 2⁵², where the
#: spacing of doubles reaches 1 (the phase of the motion is then lost to rounding); the heavy
#: top's closed form (:mod:`poinsot.tops`) keeps the same limit.
MAX_PHASE = _validation.MAX_PHASE
#: Offsets of the regime row (``poinsot._core.torque_free_regimes``): ``"case"``, ``"u0"``,
#: ``"lam"``, … and ``"size"``.
REGIME = core_torquefree.REGIME_OFFSETS
#: The polhode family of each case code, as :meth:`SolutionMixin.classify` names it.
CASE_NAMES = tuple(core_torquefree.TORQUE_FREE_CASE_NAMES)


@dataclass(frozen=True)
class ExactDerivatives:
    """The exact derivatives of a torque-free motion
    (:meth:`SolutionMixin.exact_derivatives`), body frame; the moments are the principal
    moments in ascending order (``principal_moments``), their axes held.

    Attributes
    ----------
    t : (n,)
    omega : (n, 3)
        ω(t).
    d_omega_d_omega0 : (n, 3, 3)
        ``∂ω_i(t)/∂ω0_j``.
    d_omega_d_moments : (n, 3, 3)
        ``∂ω_i(t)/∂I_k``.
    attitude : (n, 3, 3)
        Q(t) (body → space) from ``Q(0) = Q0``.
    d_attitude_d_omega0 : (n, 3, 3, 3)
        ``∂Q_rc(t)/∂ω0_j``.
    d_attitude_d_moments : (n, 3, 3, 3)
        ``∂Q_rc(t)/∂I_k``.
    period, flip_interval : float
        ``4K(m)/λ`` and ``2K(m)/λ``.
    d_period_d_omega0, d_period_d_moments, d_flip_d_omega0, d_flip_d_moments : (3,)
        Their gradients.
    """

    t: np.ndarray
    omega: np.ndarray
    d_omega_d_omega0: np.ndarray
    d_omega_d_moments: np.ndarray
    attitude: np.ndarray
    d_attitude_d_omega0: np.ndarray
    d_attitude_d_moments: np.ndarray
    period: float
    d_period_d_omega0: np.ndarray
    d_period_d_moments: np.ndarray
    flip_interval: float
    d_flip_d_omega0: np.ndarray
    d_flip_d_moments: np.ndarray


class SolutionMixin:
    """The exact solution of :class:`~poinsot.torquefree.FreeRigidBody` (a part of its
    interface, in a module of its own)."""

    # ----------------------------------------------------------------- inputs
    def _initial(self, omega0, name="omega0"):
        """``(W, single)``: body-frame ω (N, 3) (:meth:`_spin`) and whether one (3,) was
        given."""
        W = as_vectors(omega0, name)
        single = np.ndim(_real_array(omega0, name)) == 1
        # only where some component is zero or subnormal: the rows with a subnormal component
        # (elementwise: NumPy's reduction over three columns costs 70 ms per 10⁶ rows), then
        # those whose largest component is subnormal
        A, tiny = np.abs(W), np.finfo(float).tiny
        bad = ()
        if A.size and A.min() < tiny:
            rows = np.flatnonzero((A < tiny) & (A > 0)) // 3
            if len(rows):
                rows = np.unique(rows)
                bad = rows[A[rows].max(axis=1) < tiny]
        if len(bad):
            self._spin(W[bad[0]], name if single else f"{name}[{int(bad[0])}]")
        return np.ascontiguousarray(W), single

    @staticmethod
    def _spin(omega, name):
        """A body-frame ω (3,), finite, zero or with a normal number among its components:
        an ω whose components are all subnormal (below 2.2e-308, where the compiled core
        flushes them to zero) is refused."""
        w = as_vector3(omega, name)
        big = float(np.abs(w).max())
        if 0 < big < np.finfo(float).tiny:
            raise ValueError(
                f"`{name}` = {w.tolist()} is below the range of double precision: its largest "
                "component is subnormal (< 2.2e-308); choose other units, or give 0"
            )
        return w

    @staticmethod
    def _resolved(W, t, name="t"):
        """Refuse times at which the motion has turned so far that double precision no longer
        resolves its phase: ``|ω| |t|`` beyond :data:`MAX_PHASE` radians (the rounding error
        of the angle exceeds a radian; the closed forms would return noise or NaN)."""
        if not len(W) or not len(t):
            return
        with np.errstate(over="ignore"):
            # max |ω| as max(max ω, −min ω): no temporary array of |ω|
            phase = max(float(W.max()), -float(W.min())) * float(np.abs(t).max()) * math.sqrt(3)
        if phase > MAX_PHASE:
            k = int(np.argmax(np.abs(t)))
            raise ValueError(
                f"`{name}` = {t[k]:g} is beyond what double precision resolves for this motion: "
                f"|ω| |t| ≈ {phase:.3g} rad, at most {MAX_PHASE:.3g} rad (the rounding error of "
                "the angle would exceed a radian)"
            )

    @staticmethod
    def _times(t):
        """Times (n,): one finite number or a 1-D array of them; empty gives empty results
        (:func:`poinsot._validation.as_times`)."""
        return np.ascontiguousarray(as_times(t, "t"))

    def _regimes(self, W):
        """The regime rows (N, ``REGIME["size"]``) of the body-frame ω ``W`` (N, 3)."""
        return core_torquefree.torque_free_regimes(self._In, self._S, self._symmetry_code, W)

    def _families(self, W):
        """``(case, period, flip interval)`` (N, 3) of the body-frame ω ``W`` (N, 3)."""
        return core_torquefree.torque_free_families(self._In, self._S, self._symmetry_code, W)

    # ----------------------------------------------------------------- invariants
    def invariants(self, omega):
        """``(k, a)``: rotational kinetic energy ``2k = Σ I_i ω_i²`` (30) and ``a = |L|`` (31);
        floats for one ω (3,), arrays (N,) for many (N, 3).

        Examples
        --------
        >>> from poinsot import FreeRigidBody
        >>> FreeRigidBody((1, 2, 3)).invariants((1, 0, 0))
        (0.5, 1.0)
        """
        W, single = self._initial(omega, "omega")
        with np.errstate(over="ignore"):  # beyond ~1e308 they are inf: not representable
            k, a = core_torquefree.principal_invariants(self._I, np.ascontiguousarray(W @ self._S))
        return (float(k[0]), float(a[0])) if single else (k, a)

    # ----------------------------------------------------------------- families and times
    def classify(self, omega0):
        """The polhode family of ``omega0``: ``"around e1"``, ``"around e3"``,
        ``"separatrix"``, ``"fixed point"``, ``"symmetric"`` or ``"spherical"`` (an array of
        names for (N, 3))."""
        W, single = self._initial(omega0)
        cases = self._families(W)[:, 0].astype(int)
        names = np.array(CASE_NAMES)[cases]
        return str(names[0]) if single else names

    def period(self, omega0):
        """Period of ω(t): ``4K(m)/λ`` (three distinct moments), ``2π/|ν|`` (symmetric);
        ``inf`` on the separatrix. At a fixed point, where ω is constant, one ``omega0`` raises
        ``ValueError`` and an array gives NaN."""
        W, single = self._initial(omega0)
        out = self._families(W)[:, 1]
        if single and math.isnan(out[0]):
            raise ValueError("`omega0` is a fixed point: ω(t) is constant and has no period")
        return float(out[0]) if single else out

    def flip_interval(self, omega0):
        """Time between successive flips (sign changes of ω2) of the intermediate-axis motion:
        ``2K(m)/λ`` — the tennis-racket / Dzhanibekov time; ``inf`` on the separatrix.

        A flip is undefined for symmetric or spherical bodies (no intermediate axis) and at
        fixed points (ω2 never changes sign): one ``omega0`` raises ``ValueError`` there, an
        array gives NaN.
        """
        W, single = self._initial(omega0)
        if self.symmetry != "asymmetric" and single:
            raise ValueError(
                f"flip_interval needs three distinct `moments`; this body is {self.symmetry}"
            )
        out = self._families(W)[:, 2]
        if single and math.isnan(out[0]):
            raise ValueError("`omega0` is a fixed point: ω2 never changes sign, no flips")
        return float(out[0]) if single else out

    # ----------------------------------------------------------------- the motion
    def exact_omega(self, omega0, t) -> np.ndarray:
        """ω(t), body frame, from ``ω(0) = omega0``: the exact solution of (20); (n, 3) for
        one ``omega0`` (3,), (N, n, 3) for many (N, 3).

        Asymmetric bodies: Jacobi elliptic functions, ``a²/2k > I2`` (around e3):
        ``ω = (α1 cn u, ±α2 sn u, ±α3 dn u)``; ``a²/2k < I2`` (around e1):
        ``ω = (±α1 dn u, ±α2 sn u, α3 cn u)``; on the separatrix (m = 1) the same with
        ``sn = tanh``, ``cn = dn = sech``. ``u = u0 + λt``; the parameter's complement
        ``1 − m`` is formed without cancellation, so the solution stays accurate arbitrarily
        close to the separatrix. Symmetric bodies: ``π = Aω`` turns about the symmetry axis at
        the rate ``−ν``, ``ν = (1/I_s − 1/I⊥) π_s``. Spherical: ω constant.

        Examples
        --------
        >>> from poinsot import FreeRigidBody
        >>> body = FreeRigidBody((1.0, 2.0, 3.0))
        >>> w = body.exact_omega([(1e-3, 1.0, 1e-3), (0.1, 1.0, 0.1)], [0.0, 5.0])
        >>> w.shape
        (2, 2, 3)
        """
        W, single = self._initial(omega0)
        t = self._times(t)
        self._resolved(W, t)
        out = core_torquefree.torque_free_omegas(self._In, self._S, self._symmetry_code, W, t)
        return out[0] if single else out

    def exact_derivatives(self, omega0, t, Q0=None) -> ExactDerivatives:
        """The exact derivatives of ω(t), of Q(t), of the period and of the flip interval
        with respect to ``omega0`` (body frame) and the principal moments, from the closed
        form itself (:class:`ExactDerivatives`); ``Q(0) = Q0`` (default identity) is held.

        The regime's algebra (amplitudes, rate, parameter m, the initial argument u0) runs in
        the core on dual numbers; the elliptic functions carry their known derivatives in u
        and, through the amplitude, in m (Carlson's ``R_D``: no cancellation as m → 1), so
        the derivatives stay accurate arbitrarily close to the separatrix, where they grow as
        ``1/(1 − m)``. The attitude is the engine's own formula on the same dual numbers:
        θ and φ from ``π = Iω``, and ψ's third-kind integral ``Π(u)`` differentiated through
        Carlson's duplication (``crates/core/src/torque_free/derivatives.rs``). A body with
        three distinct moments, off the fixed points and the separatrix itself; one
        ``omega0``.

        Examples
        --------
        How the tennis-racket flip interval of a box depends on its moments:

        >>> from poinsot import FreeRigidBody
        >>> body = FreeRigidBody((1.0, 2.0, 3.0))
        >>> d = body.exact_derivatives((0.01, 1.0, 0.01), [0.0, 1.0])
        >>> round(d.flip_interval, 4), d.d_flip_d_moments.round(3).tolist()
        (19.5529, [18.686, 4.331, -9.116])
        >>> d.d_attitude_d_omega0.shape
        (2, 3, 3, 3)
        """
        W, single = self._initial(omega0)
        if not single:
            raise ValueError("`omega0` must be one angular velocity (3,) for exact_derivatives")
        if self.symmetry != "asymmetric":
            raise ValueError("exact_derivatives needs three distinct `moments`; this body is "
                             f"{self.symmetry}")  # fmt: skip
        Q = np.eye(3) if Q0 is None else as_rotation_matrices(Q0, "Q0", 1)[0]
        t = self._times(t)
        self._resolved(W, t)
        S = self._S
        scale = self._In / self._I  # the core's moments are scaled by a power of two
        w, D, Qs, DQ, period, flip = core_torquefree.torque_free_derivatives(
            self._In, S.T @ W[0], Q @ S, t
        )
        dw = np.einsum("ij,njk,lk->nil", S, D[:, :, 3:], S)
        dI = np.einsum("ij,njk->nik", S, D[:, :, :3]) * scale
        # Q(t) = Q_sorted(t) Sᵀ, ω0_sorted = Sᵀ ω0
        dQw = np.einsum("nrak,ca,lk->nrcl", DQ[..., 3:], S, S)
        dQI = np.einsum("nrak,ca->nrck", DQ[..., :3], S) * scale
        return ExactDerivatives(
            t, w @ S.T, dw, dI, Qs @ S.T, dQw, dQI,
            float(period[0]), S @ period[4:], period[1:4] * scale,
            float(flip[0]), S @ flip[4:], flip[1:4] * scale,
        )  # fmt: skip

    def exact_attitude(self, omega0, t, Q0=None) -> np.ndarray:
        """Attitude ``Q(t)`` (body → space) of the torque-free motion from ``ω(0) = omega0``
        and ``Q(0) = Q0`` (default identity; one rotation or one per member), exactly; (n, 3, 3)
        for one ``omega0``, (N, n, 3, 3) for many.

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
        W, single = self._initial(omega0)
        Q = np.eye(3)[None] if Q0 is None else as_rotation_matrices(Q0, "Q0", len(W))
        t = self._times(t)
        self._resolved(W, t)
        out = core_torquefree.torque_free_attitudes(
            self._In, self._S, self._symmetry_code, W, np.ascontiguousarray(Q), t
        )
        return out[0] if single else out

    def describe(self, omega0) -> dict:
        """A JSON-ready summary of the motion from ``omega0``: family, invariants, period,
        flip interval (``"inf"`` on the separatrix; absent where undefined) and fixed points.

        With a flip interval, also whether the body really flips (:meth:`flips`):
        ``e2_swing`` and ``flips``; and the periodic motion's stability, ``floquet_drift``:
        every Floquet multiplier is 1 and a deviation moves by ``‖M − I‖`` per period, ``M``
        the monodromy matrix (:meth:`floquet`, from the closed form's exact derivatives)."""
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
        if "flip_interval" in out and out["family"] in ("around e1", "around e3"):
            out.update(self.flips(omega0))
            out["floquet_drift"] = self.floquet(omega0).drift
        return out

    def flips(self, omega0) -> dict:
        """Whether the motion from ``omega0`` flips — the tennis racket: the body's intermediate
        axis e₂ turns over against the angular momentum L every half period — or only wobbles
        about the stable axis it circles, while ω·e₂ changes sign all the same.

        From the exact polhode: ``e2_swing = max |e₂·L| / |L|`` over the motion (``L·e_k =
        I_k ω_k``), and ``flips`` when e₂ comes within 45° of ±L (``e2_swing > cos 45°``).

        Examples
        --------
        >>> from poinsot.torquefree import FreeRigidBody
        >>> body = FreeRigidBody((1.0, 2.0, 3.0))
        >>> body.flips((1e-3, 1.0, 1e-3))["flips"], body.flips((0.01, 0.0, 1.0))["flips"]
        (True, False)
        """
        pts = self.principal_components(self.polhode(omega0).points)
        L = pts * self._I
        swing = float(np.max(np.abs(L[:, 1]) / np.linalg.norm(L, axis=1)))
        return {"e2_swing": swing, "flips": bool(swing > math.cos(math.pi / 4))}

    # ----------------------------------------------------------------- oracle
    def error_series(self, trajectory) -> dict:
        """Per-sample errors of a numerical torque-free :class:`~poinsot.trajectory.Trajectory`
        against the exact solution from its first sample: ``"omega"`` max-abs ``|Δω|``
        (rad/s), ``"attitude"`` max-abs ``|ΔQ|`` (dimensionless), ``"energy"`` and
        ``"momentum"`` relative errors of ``k`` and ``|L|``; each an array (n,). The trajectory
        must be torque-free about its centre of mass."""
        tr = trajectory
        if getattr(tr.system, "pivot", None) is not None and np.any(tr.system.c):
            raise ValueError("`trajectory` turns about a pivot away from its centre of mass")
        t = tr.t - tr.t[0]
        w = self.exact_omega(tr.omega[0], t)
        Q = self.exact_attitude(tr.omega[0], t, tr.Q[0])
        k0, a0 = self.invariants(tr.omega[0])
        omega = np.ascontiguousarray(tr.omega, dtype=float)
        ks, As = core_torquefree.rotational_energies_and_momenta(
            np.ascontiguousarray(self.inertia), omega
        )
        return {
            "omega": np.abs(tr.omega - w).max(axis=1),
            "attitude": np.abs(tr.Q - Q).max(axis=(1, 2)),
            "energy": np.abs(ks / k0 - 1),
            "momentum": np.abs(As / a0 - 1),
        }

    def trajectory_error(self, trajectory) -> dict:
        """The largest of :meth:`error_series` over the run: max |Δω|, max |ΔQ|, relative
        energy and |L| errors."""
        return {k: float(v.max()) for k, v in self.error_series(trajectory).items()}
