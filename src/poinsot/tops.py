"""The heavy symmetric top: a symmetric body on a fixed tip under uniform gravity.

What a top is known for, as numbers: the tilt θ(t) of its symmetry axis with its nutation band,
the precession ψ(t) with its mean rate, and the rates it would precess at steadily — the
gyroscopic estimate ``M g l / (C ω₃)`` and the two exact steady precessions, roots of
``A cos θ Ω² − C ω₃ Ω + M g l = 0`` (Goldstein, Poole & Safko, *Classical Mechanics*, 3rd ed.,
§5.7; the formulas live once in ``crates/core/src/tops.rs``).

* :func:`steady_precession_rates`, :func:`gyroscopic_precession_rate` — the rates;
* :func:`heavy_top` — whether a body, a pivot and forces make a heavy symmetric top, and its
  ``A``, ``C``, ``M g l`` and axis (or None);
* :func:`top_motion` — the angles of a simulated top and the numbers above for its run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from ._validation import as_scalar

__all__ = [
    "HeavyTop",
    "TopMotion",
    "gyroscopic_precession_rate",
    "heavy_top",
    "steady_precession_rates",
    "top_motion",
]


def steady_precession_rates(A, C, mgl, theta, spin) -> tuple[float, float]:
    """The slow and fast rates Ω (rad/s) of steady precession of a heavy symmetric top.

    The roots of ``A cos θ Ω² − C ω₃ Ω + M g l = 0`` (θ̇ = 0 in Lagrange's equation for θ;
    Goldstein §5.7), formed without cancellation in the compiled core. For a fast top the slow
    root tends to :func:`gyroscopic_precession_rate`.

    Parameters
    ----------
    A : float
        Moment of inertia about an axis through the tip perpendicular to the symmetry axis
        [kg·m²].
    C : float
        Moment about the symmetry axis [kg·m²].
    mgl : float
        ``M g l``: weight times the distance from the tip to the centre of mass [N·m].
    theta : float
        Angle of the symmetry axis (tip → centre of mass) from the upward vertical [rad].
    spin : float
        ``ω₃ = φ̇ + ψ̇ cos θ``, the spin about the symmetry axis [rad/s].

    Returns
    -------
    (slow, fast) : floats
        NaN, NaN when the top spins too slowly to precess steadily at θ
        (``C² ω₃² < 4 A M g l cos θ``); ``fast`` is infinite for a horizontal axis.

    Examples
    --------
    >>> slow, fast = steady_precession_rates(0.2758, 0.045, 4.905, 0.6, 100.0)
    >>> round(slow, 4), round(fast, 2), round(gyroscopic_precession_rate(0.045, 4.905, 100.0), 4)
    (1.1578, 18.61, 1.09)
    """
    args = [as_scalar(v, name) for v, name in ((A, "A"), (C, "C"), (mgl, "mgl"),
                                              (theta, "theta"), (spin, "spin"))]  # fmt: skip
    if not (args[0] > 0 and args[1] > 0):
        raise ValueError(f"`A` and `C` must be positive, found {args[0]}, {args[1]}")
    return _core.steady_precession_rates(*args)


def gyroscopic_precession_rate(C, mgl, spin) -> float:
    """The gyroscopic estimate ``Ω = M g l / (C ω₃)`` (rad/s) of a fast top's precession rate
    (Goldstein §5.7): the torque ``M g l sin θ`` turns the spin angular momentum ``C ω₃``,
    whose horizontal part is ``C ω₃ sin θ``. Arguments as for :func:`steady_precession_rates`.

    >>> round(gyroscopic_precession_rate(0.045, 4.905, 100.0), 6)
    1.09
    """
    return _core.gyroscopic_precession_rate(as_scalar(C, "C"), as_scalar(mgl, "mgl"),
                                            as_scalar(spin, "spin"))  # fmt: skip


@dataclass(frozen=True)
class HeavyTop:
    """A heavy symmetric top: ``A``, ``C`` about the tip [kg·m²], ``mgl`` [N·m], ``axis`` the
    symmetry axis from the tip towards the centre of mass (body components, unit), ``up`` the
    upward vertical (space, unit: ``−g/|g|``), ``length`` l [m]."""

    A: float
    C: float
    mgl: float
    axis: np.ndarray
    up: np.ndarray
    length: float

    def frame(self) -> np.ndarray:
        """Body axes (columns, body components) whose third is :attr:`axis`: the axes whose
        z-x-z Euler angles are the top's precession ψ, nutation θ and spin φ."""
        return _axes_with_z(self.axis)

    def space(self) -> np.ndarray:
        """A rotation (3, 3) taking :attr:`up` to +z (space components → the top's space
        axes, z up)."""
        return _axes_with_z(self.up).T


def _axes_with_z(a) -> np.ndarray:
    """A right-handed orthonormal basis (columns) whose third vector is the unit vector ``a``;
    the first is perpendicular to ``a`` and to the coordinate axis least aligned with it."""
    helper = np.eye(3)[int(np.argmin(np.abs(a)))]
    x = np.cross(helper, a)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(a, x), a])


def heavy_top(body, pivot, forces) -> HeavyTop | None:
    """The heavy symmetric top that ``body`` held at ``pivot`` (body frame) under ``forces``
    is, or None when it is not one: the body must be symmetric (oblate or prolate) about an
    axis through the pivot and its centre of mass, the pivot away from the centre of mass, and
    the only force uniform gravity.

    Examples
    --------
    >>> from poinsot import Gravity, RigidBody
    >>> top = heavy_top(RigidBody.cylinder(1.0, 0.3, 0.2), (0, 0, -0.5), [Gravity()])
    >>> round(top.A, 6), round(top.C, 6), round(top.mgl, 4), top.axis.tolist()
    (0.275833, 0.045, 4.905, [0.0, 0.0, 1.0])
    """
    from .conservation import TOP_RTOL
    from .forces import Gravity

    if pivot is None or len(forces) != 1 or type(forces[0]) is not Gravity:
        return None
    g = np.asarray(forces[0].g, dtype=float)
    c = np.asarray(body.center_of_mass, float) - np.asarray(pivot, float)
    length = float(np.linalg.norm(c))
    if not (length > 0 and np.linalg.norm(g) > 0):
        return None
    J = body.inertia_about(pivot)
    moments, E = _core.principal_decomposition(J)
    sym = _core.symmetric_top_axis(moments.tolist(), E.tolist(), c.tolist(), TOP_RTOL)
    if sym is None:  # not symmetric about the pivot, or the centre of mass off the axis
        return None
    axis = c / length
    C = float(axis @ J @ axis)
    perp = _axes_with_z(axis)[:, 0]  # any direction across the axis: the moments are equal
    A = float(perp @ J @ perp)
    up = -g / np.linalg.norm(g)
    return HeavyTop(A, C, float(body.mass * np.linalg.norm(g) * length), axis, up, length)


@dataclass(frozen=True)
class TopMotion:
    """A simulated top's angles and rates (:func:`top_motion`).

    ``t`` (n,) [s]; ``theta``, ``psi`` (n,) [rad]: the tilt of the axis from the upward
    vertical and its azimuth about it (unwrapped); ``singular`` (n,) bool (θ = 0 or π, where ψ
    is undefined); ``spin`` ω₃ [rad/s] (its value at the start; constant for a top);
    ``theta_band`` (min, max) θ [rad]; ``mean_precession_rate`` the least-squares slope of
    ψ(t) [rad/s]; ``gyroscopic_rate`` ``M g l / (C ω₃)``; ``steady_rates`` (slow, fast) at
    the mean θ [rad/s]; ``theta_mean`` [rad].
    """

    t: np.ndarray
    theta: np.ndarray
    psi: np.ndarray
    singular: np.ndarray
    spin: float
    theta_band: tuple
    theta_mean: float
    mean_precession_rate: float
    gyroscopic_rate: float
    steady_rates: tuple

    def summary(self) -> dict:
        """The numbers, JSON-ready (radians, rad/s)."""
        return {
            "spin_omega3": self.spin,
            "theta_min": self.theta_band[0],
            "theta_max": self.theta_band[1],
            "theta_mean": self.theta_mean,
            "nutation_amplitude": 0.5 * (self.theta_band[1] - self.theta_band[0]),
            "mean_precession_rate": self.mean_precession_rate,
            "gyroscopic_precession_rate": self.gyroscopic_rate,
            "steady_precession_rate_slow": self.steady_rates[0],
            "steady_precession_rate_fast": self.steady_rates[1],
            "singular_samples": int(self.singular.sum()),
        }


def top_motion(traj, top: HeavyTop) -> TopMotion:
    """The top's precession ψ(t) and nutation θ(t) along ``traj`` (a
    :class:`~poinsot.trajectory.Trajectory` of the body of ``top``), its nutation band, mean
    precession rate (the least-squares slope of the unwrapped ψ(t) over the samples where it
    is defined) and the predicted rates: the gyroscopic estimate and the steady precessions at
    the mean θ (:func:`steady_precession_rates`)."""
    from .rotation import euler_series

    F = top.frame()
    S = top.space()
    series = euler_series(np.einsum("ij,njk,kl->nil", S, traj.Q, F), traj.omega @ F, traj.t)
    theta, psi = series.angles[:, 1], series.angles[:, 0]
    spin = float(traj.omega[0] @ top.axis)
    ok = ~series.singular
    rate = float(np.polyfit(traj.t[ok], psi[ok], 1)[0]) if ok.sum() >= 2 else float("nan")
    theta_mean = float(theta.mean())
    return TopMotion(
        t=traj.t,
        theta=theta,
        psi=psi,
        singular=series.singular,
        spin=spin,
        theta_band=(float(theta.min()), float(theta.max())),
        theta_mean=theta_mean,
        mean_precession_rate=rate,
        gyroscopic_rate=gyroscopic_precession_rate(top.C, top.mgl, spin) if spin else np.inf,
        steady_rates=steady_precession_rates(top.A, top.C, top.mgl, theta_mean, spin),
    )
