"""Polhodes, separatrix arcs and herpolhodes of the torque-free body (``docs/theory.md`` §1,
"Polhodes", eqs (30)–(33)).

A polhode is the path of ω on the energy ellipsoid ``Σ I_i ω_i² = 2k`` (30), where it meets the
momentum ellipsoid ``Σ I_i² ω_i² = a²`` (31): on the cone (32). Here they are traced exactly,
from the closed-form ω(t) over one period; the herpolhode is ω seen in space, in the invariable
plane on which Poinsot's ellipsoid rolls.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._validation import as_count, as_positive_scalar
from .solution import REGIME

__all__ = ["Polhode", "PolhodeMixin"]

#: The most levels a polhode family draws, and the most points of one polhode.
MAX_LEVELS = 1000
MAX_POINTS = 10**7


@dataclass
class Polhode:
    """A polhode: the path of ω on the energy ellipsoid (body frame).

    ``points`` (n, 3); ``family`` is ``"around e1"``, ``"around e3"``, ``"separatrix"``,
    ``"fixed point"``, ``"symmetric"`` (a circle of a symmetric body) or ``"spherical"``;
    ``energy`` k (``2k = Σ I ω²``), ``momentum`` a = ``|L|``, ``period`` of ω(t) (inf on the
    separatrix), ``t`` the times of the points from ``omega0``.
    """

    points: np.ndarray
    family: str
    energy: float
    momentum: float
    period: float
    t: np.ndarray = field(repr=False, default=None)


class PolhodeMixin:
    """The polhodes of :class:`~poinsot.torquefree.FreeRigidBody` (a part of its interface,
    in a module of its own)."""

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
        n = as_count(n, "n", 2, MAX_POINTS)
        w_body = self._spin(omega0, "omega0")
        k, a = self.invariants(w_body)
        family = self.classify(w_body)
        if family in ("fixed point", "spherical"):
            return Polhode(w_body[None, :], "fixed point", k, a, math.inf, np.zeros(1))
        if family == "separatrix":
            reg = self._regimes(w_body[None, :])[0]
            T = (abs(reg[REGIME["u0"]]) + math.log(4e6)) / reg[REGIME["lam"]]
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
        w1sq = 2 * k * (I3 - D) / (I1 * (I3 - I1))
        w3sq = 2 * k * (D - I1) / (I3 * (I3 - I1))
        if self.symmetry == "asymmetric" and abs(D - I2) <= 1e-12 * I3:
            eps = 1e-3  # a point on the separatrix arc, near e2
            w2 = math.sqrt(2 * k / I2) * math.sqrt(1 - eps**2)
            r = 2 * k - I2 * w2 * w2  # remaining energy split between ω1 and ω3 on the cone
            b1, b3 = I1 * (I2 - I1), I3 * (I3 - I2)  # cone (32) at D = I2: b1 ω1² = b3 ω3²
            w3 = math.sqrt(r / (I3 + I1 * b3 / b1))
            w1 = math.sqrt(b3 / b1) * w3
            return self._from_sorted(np.array([w1, w2, w3]))
        w = np.array([math.sqrt(max(w1sq, 0)), 0.0, math.sqrt(max(w3sq, 0))])
        if D > I2 or self.symmetry == "oblate":
            w[2] *= sign
        else:
            w[0] *= sign
        return self._from_sorted(w)

    def polhode_family(self, energy=0.5, *, levels=9, n=400) -> list[Polhode]:
        """Every kind of polhode on the energy ellipsoid of ``energy`` (the notebook's sweep,
        done exactly): ``levels`` values of a²/2k strictly between I1 and I3, on both branches,
        the separatrix arcs (asymmetric bodies) and the fixed points. For three distinct moments
        half the levels are around e1 (evenly between I1 and I2) and half around e3 (between
        I2 and I3), so that both families show however close I2 is to I1 or I3 (a tennis
        racket's I2 is within 7 % of I3)."""
        I1, I2, I3 = self._I
        k = self.check_energy_range(as_positive_scalar(energy, "energy"))
        levels = as_count(levels, "levels", 1, MAX_LEVELS)
        n = as_count(n, "n", 2, MAX_POINTS)
        out = []
        if self.symmetry == "spherical":
            return [Polhode(np.zeros((0, 3)), "spherical", k, math.sqrt(2 * k * I1), math.inf)]
        if self.symmetry == "asymmetric":  # both families, whatever the gaps I2 − I1, I3 − I2
            low, high = (levels + 1) // 2, levels // 2
            Ds = np.concatenate(
                [
                    I1 + (I2 - I1) * np.arange(1, low + 1) / (low + 1),
                    I2 + (I3 - I2) * np.arange(1, high + 1) / (high + 1),
                ]
            )
        else:
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

    def separatrix_arcs(self, energy=0.5, *, n=400, reach=1e-6) -> list[Polhode]:
        """The four heteroclinic arcs at ``a² = 2k I2`` joining the unstable points ±√(2k/I2) e2,
        in closed form: ``ω = (σ1 α1 sech u, σ1σ3 α2 tanh u, σ3 α3 sech u)``,
        ``α1² = 2k(I3 − I2)/(I1(I3 − I1))``, ``α2² = 2k/I2``, ``α3² = 2k(I2 − I1)/(I3(I3 − I1))``,
        ``u = λt``, ``λ² = (I3 − I2)(I2 − I1)·2k/(I1 I2 I3)``; ``u`` spans the arc until the
        sech terms fall to ``reach``."""
        if self.symmetry != "asymmetric":
            raise ValueError(
                f"a separatrix needs three distinct `moments`; this body is {self.symmetry}"
            )
        n = as_count(n, "n", 2, MAX_POINTS)
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
        on which Poinsot's ellipsoid rolls. ``t``: one time or an array (n,) of finite times
        (empty: an empty result, (0, 3)).

        Examples
        --------
        >>> import numpy as np
        >>> from poinsot import FreeRigidBody
        >>> body = FreeRigidBody((1.0, 2.0, 3.0))
        >>> h = body.herpolhode((0.1, 1.0, 0.1), [0.0, 1.0, 2.0])
        >>> k, a = body.invariants((0.1, 1.0, 0.1))
        >>> bool(np.allclose(h[:, 2], 2 * k / a)), body.herpolhode((0.1, 1.0, 0.1), []).shape
        (True, (0, 3))
        """
        w_body = self._spin(omega0, "omega0")
        if not np.any(w_body):
            raise ValueError("`omega0` must not be zero: a body at rest has no herpolhode")
        Q = self.exact_attitude(w_body, t, Q0)
        w = self.exact_omega(w_body, t)
        space = np.einsum("nij,nj->ni", Q, w)
        Q_start = np.eye(3) if Q0 is None else self.exact_attitude(w_body, 0.0, Q0)[0]
        L = Q_start @ (self.inertia @ w_body)  # conserved: the invariable frame of any t
        L = L / np.abs(L).max()  # scaled first: |L| of a tiny ω underflows
        ez = L / np.linalg.norm(L)
        ex = np.cross([0.0, 0, 1] if abs(ez[2]) < 0.9 else [1.0, 0, 0], ez)
        ex /= np.linalg.norm(ex)
        ey = np.cross(ez, ex)
        return space @ np.column_stack([ex, ey, ez])
