"""The heavy symmetric top: a symmetric body on a fixed tip under uniform gravity.

What a top is known for, as numbers: the tilt θ(t) of its symmetry axis with its nutation band,
the precession ψ(t) with its mean rate, and the rates it would precess at steadily — the
gyroscopic estimate ``M g l / (C ω₃)`` and the two exact steady precessions, roots of
``A cos θ Ω² − C ω₃ Ω + M g l = 0`` (Goldstein, Poole & Safko, *Classical Mechanics*, 3rd ed.,
§5.7; the formulas live once in ``crates/core/src/tops.rs``).

* :func:`steady_precession_rates`, :func:`gyroscopic_precession_rate` — the rates;
* :func:`heavy_top` — whether a body, a pivot and forces make a heavy symmetric top, and its
  ``A``, ``C``, ``M g l`` and axis (or None);
* :func:`top_motion` — the angles of a simulated top and the numbers above for its run;
* :func:`exact_motion` — the same, from the closed form of Lagrange's top (θ by Jacobi
  functions, ψ and φ by elliptic integrals of the third kind; ``crates/core/src/heavy_top.rs``,
  ``docs/theory.md`` §6): the exact reference a simulated top is graded against;
* :func:`exact_derivatives` — that closed form's exact derivatives along ``A``, ``C``,
  ``M g l`` and the initial state (:class:`TopDerivatives`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._bindings import inertia as core_inertia
from ._bindings import invariants as core_invariants
from ._bindings import tops as core_tops
from ._validation import as_scalar

__all__ = [
    "HeavyTop",
    "TopDerivatives",
    "TopMotion",
    "exact_derivatives",
    "exact_motion",
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
    return core_tops.steady_precession_rates(*args)


def gyroscopic_precession_rate(C, mgl, spin) -> float:
    """The gyroscopic estimate ``Ω = M g l / (C ω₃)`` (rad/s) of a fast top's precession rate
    (Goldstein §5.7): the torque ``M g l sin θ`` turns the spin angular momentum ``C ω₃``,
    whose horizontal part is ``C ω₃ sin θ``. Arguments as for :func:`steady_precession_rates`.

    >>> round(gyroscopic_precession_rate(0.045, 4.905, 100.0), 6)
    1.09
    """
    return core_tops.gyroscopic_precession_rate(as_scalar(C, "C"), as_scalar(mgl, "mgl"),
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

    def __post_init__(self):
        """Checked once, for a top built by hand too: positive ``A``, ``C``, ``mgl``; ``axis``
        and ``up`` unit vectors (a longer axis would scale the Euler angles' frame)."""
        for name in ("A", "C", "mgl"):
            value = as_scalar(getattr(self, name), f"HeavyTop.{name}")
            if not value > 0:
                raise ValueError(f"`HeavyTop.{name}` must be positive, found {value}")
            object.__setattr__(self, name, value)
        for name in ("axis", "up"):
            v = np.asarray(getattr(self, name), dtype=float)
            if v.shape != (3,) or not np.isfinite(v).all():
                raise ValueError(f"`HeavyTop.{name}` must be 3 finite numbers, found {v!r}")
            if abs(np.linalg.norm(v) - 1.0) > 1e-9:
                raise ValueError(f"`HeavyTop.{name}` must be a unit vector, found one of "
                                 f"length {np.linalg.norm(v):.6g}")  # fmt: skip
            object.__setattr__(self, name, v)

    def frame(self) -> np.ndarray:
        """Body axes (columns, body components) whose third is :attr:`axis`: the axes whose
        z-x-z Euler angles are the top's precession ψ, nutation θ and spin φ."""
        return _axes_with_z(self.axis)

    def space(self) -> np.ndarray:
        """A rotation (3, 3) taking :attr:`up` to +z (space components → the top's space
        axes, z up)."""
        return _axes_with_z(self.up).T


def _axes_with_z(a) -> np.ndarray:
    """A right-handed orthonormal basis (columns) whose third vector is the unit vector ``a``:
    the cyclic permutation of the coordinate axes whose third is the one ``a`` lies nearest,
    tilted onto ``a`` (the first vector is the next coordinate axis made perpendicular to
    ``a``). For ``a`` = +z it is the identity, so that a top whose symmetry axis is body z,
    under gravity along −z, has the z-x-z Euler angles of the trajectory itself; for ``a`` = +x
    it is (y, z, x)."""
    a = np.asarray(a, dtype=float)
    k = int(np.argmax(np.abs(a)))
    nxt = np.eye(3)[(k + 1) % 3]
    x = nxt - (nxt @ a) * a  # |a_{k+1}|² ≤ 2/3: never degenerate
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
    moments, E = core_inertia.principal_decomposition(J)
    sym = core_invariants.symmetric_top_axis(moments.tolist(), E.tolist(), c.tolist(), TOP_RTOL)
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

    ``t`` (n,) [s]; ``theta``, ``psi`` (n,) [rad]: the z-x-z Euler angles of the symmetry
    axis in the top's space axes (:attr:`space_axes`, z up): θ the tilt of the axis from the
    upward vertical, ψ the precession angle (unwrapped), the azimuth of the line of nodes
    from the space x axis about the vertical; the axis itself points at azimuth ψ − π/2.
    When gravity is along −z and the symmetry axis is body z, these are the trajectory's own
    :meth:`~poinsot.trajectory.Trajectory.euler_angles`. ``singular`` (n,) bool (θ = 0 or π, where ψ
    is undefined); ``spin`` ω₃ [rad/s] (its value at the start; constant for a top);
    ``theta_band`` (min, max) θ [rad]; ``mean_precession_rate`` the least-squares slope of
    ψ(t) [rad/s]; ``gyroscopic_rate`` ``M g l / (C ω₃)``; ``steady_rates`` (slow, fast) at
    the mean θ [rad/s]; ``theta_mean`` [rad]; ``phi`` (n,) the spin angle [rad] (unwrapped),
    ``Q`` (n, 3, 3) and ``omega`` (n, 3) the body's attitude and angular velocity (body
    components), as the trajectory has them; ``nutation_period`` [s] (the closed form's;
    NaN for a simulated top, infinite without nutation).

    :func:`exact_motion` gives the theta band and the mean precession rate exactly (the
    turning points of ``cos θ`` and ψ's advance over a nutation period), :func:`top_motion`
    from the samples (their extremes and the least-squares slope of ψ).

    Through a vertical (the band reaching θ = 0 or π) ψ and φ step by ±π, and the side is
    undefined where the vertical and axial momenta are equal there: the closed form takes
    +π, the limit of a small positive spin, and its mean precession rate counts π per
    passage. A top released from rest with no spin swings in one plane, which stands still,
    yet "precesses" at π per nutation period by this convention; a simulated run's ψ steps
    by ±π as round-off decides, so its least-squares rate means little there.
    :meth:`angle_errors` compares ψ and φ modulo 2π in that case.
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
    phi: np.ndarray | None = None
    Q: np.ndarray | None = None
    omega: np.ndarray | None = None
    nutation_period: float = float("nan")
    #: the top's space axes (rows: x, y, z in the run's space components; z is up): the
    #: identity under gravity along −z
    space_axes: np.ndarray | None = None
    #: for a simulated top, the closed form from its initial state (:func:`exact_motion`) at
    #: the same times, or None (an axis started on the vertical)
    exact: TopMotion | None = None

    def psi_reference(self) -> str:
        """Words for what ψ is measured from, for labels: ``"line of nodes from +x about +z;
        the axis's azimuth is ψ − 90°"`` for the usual space axes."""
        S = np.eye(3) if self.space_axes is None else self.space_axes
        x, z = _axis_name(S[0]), _axis_name(S[2])
        return f"line of nodes from {x} about {z}; the axis's azimuth is ψ − 90°"

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
            "nutation_period": self.nutation_period,
            **(self._against_exact() if self.exact is not None else {}),
        }

    def angle_errors(self) -> dict:
        """``|θ − θ_exact|``, ``|ψ − ψ_exact|``, ``|φ − φ_exact|`` (n,) each [rad], against
        :attr:`exact`. Where the exact motion passes through a vertical (a swing with no spin
        in one plane, or over the top), ψ and φ step by ±π there, the side a matter of
        round-off: they are then compared as angles, modulo 2π."""
        e = self.exact
        through = e.theta_band[0] == 0.0 or e.theta_band[1] == np.pi

        def error(name):
            d = getattr(self, name) - getattr(e, name)
            if through and name != "theta":
                d = np.remainder(d + np.pi, 2 * np.pi) - np.pi
            return np.abs(d)

        return {name: error(name) for name in ("theta", "psi", "phi")}

    def _against_exact(self) -> dict:
        """The closed form's band, period and mean rate, and the largest differences of θ, ψ
        and φ from it over the samples."""
        e = self.exact
        errors = self.angle_errors()
        return {
            "exact": {
                "theta_min": e.theta_band[0],
                "theta_max": e.theta_band[1],
                "nutation_period": e.nutation_period,
                "mean_precession_rate": e.mean_precession_rate,
                **{f"max_{name}_error": float(err.max()) for name, err in errors.items()},
            }
        }


def _axis_name(v) -> str:
    """``+x``, ``−z``… for a coordinate axis, the components otherwise."""
    v = np.asarray(v, float)
    k = int(np.argmax(np.abs(v)))
    if abs(abs(v[k]) - 1) < 1e-12:
        return ("+" if v[k] > 0 else "−") + "xyz"[k]
    return "(" + ", ".join(f"{c:.4g}" for c in v) + ")"


def top_motion(traj, top: HeavyTop) -> TopMotion:
    """The top's precession ψ(t) and nutation θ(t) along ``traj`` (a
    :class:`~poinsot.trajectory.Trajectory` of the body of ``top``), its nutation band, mean
    precession rate (the least-squares slope of the unwrapped ψ(t) over the samples where it
    is defined) and the predicted rates: the gyroscopic estimate and the steady precessions at
    the mean θ (:func:`steady_precession_rates`)."""
    from .rotation import euler_series

    top = _check_top(top)
    if len(traj.t) == 0:
        raise ValueError("`traj` has no samples: run it with sample times (`t_eval`) to see its "
                         "precession and nutation")  # fmt: skip
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
        phi=series.angles[:, 2],
        Q=traj.Q,
        omega=traj.omega,
        space_axes=S,
        exact=_exact_or_none(top, traj),
    )


def _exact_or_none(top, traj):
    """The closed form of the run's top from its first sample, or None where the axis starts
    on the vertical (Euler angles undefined); any other refusal of :func:`exact_motion` (a
    first attitude that is not a rotation, times beyond double precision's phases) is
    raised, saying it is the closed form's."""
    from dataclasses import replace

    try:
        exact = exact_motion(top, traj.omega[0], traj.Q[0], traj.t - traj.t[0])
    except VerticalAxisError:
        return None
    except ValueError as exc:
        raise ValueError(f"the closed form from the first sample: {exc}") from None
    return replace(exact, t=traj.t)


class VerticalAxisError(ValueError):
    """A top whose axis starts on the vertical, where its Euler angles are undefined."""


def _check_top(top) -> HeavyTop:
    """``top`` checked: what :func:`heavy_top` returns for a symmetric top (it returns None for
    any other body, pivot or forces)."""
    if not isinstance(top, HeavyTop):
        raise TypeError(f"`top` must be the HeavyTop that heavy_top(body, pivot, forces) "
                        f"returns, found {top!r} (heavy_top gives None unless the body is "
                        "symmetric about a pivot on its axis, under uniform gravity "
                        "alone)")  # fmt: skip
    return top


def _refuse_unresolved_phases(times, w, periods_and_rates) -> None:
    """Refuse times at which double precision no longer resolves the motion's phases (the
    nutation's ``2π t/T``, the spin's and the precession's, bounded by ``(|ω₀| + |Ω|) |t|``):
    beyond :data:`~poinsot.torquefree.solution.MAX_PHASE` radians, as the torque-free closed
    form refuses them (``docs/reliability.md``)."""
    from ._validation import MAX_PHASE

    if not len(times):
        return
    span = float(np.abs(times).max())
    for k, ((period, rate), wk) in enumerate(zip(periods_and_rates, w, strict=True)):
        frequency = max(2 * np.pi / period if np.isfinite(period) else 0.0,
                        float(np.linalg.norm(wk)) + abs(rate))  # fmt: skip
        if frequency * span > MAX_PHASE:
            member = "" if len(w) == 1 else f" of member {k}"
            raise ValueError(f"`t` reaches {span:g} s, where the motion{member} has turned by "
                             f"{frequency * span:.3g} rad: beyond 2⁵² rad double precision no "
                             "longer resolves its phase")  # fmt: skip


def _initial_angles(top: HeavyTop, w, Q):
    """The z-x-z Euler angles (N, 3) of the top's axis frame in its space axes and their rates
    (N, 3), from body ``w`` (N, 3) and ``Q`` (N, 3, 3) (body → space); refused with the axis on
    the vertical."""
    from .rotation import EULER_SINGULAR, euler_from_matrix, euler_rates_from_body

    F, S = top.frame(), top.space()
    angles = euler_from_matrix(np.einsum("ij,njk,kl->nil", S, Q, F), "ZXZ")
    vertical = np.flatnonzero(np.abs(np.sin(angles[:, 1])) < EULER_SINGULAR)
    if len(vertical):
        which = "" if len(Q) == 1 else f"[{vertical[0]}]"
        raise VerticalAxisError(f"`Q0{which}` puts the top's axis on the vertical, where ψ is "
                                "undefined: tilt it (a sleeping top is the limit of a small "
                                "tilt)")  # fmt: skip
    return angles, euler_rates_from_body(angles, w @ F)


def exact_motion(top: HeavyTop, omega0, Q0, t) -> TopMotion | list[TopMotion]:
    """The motion of the heavy symmetric top ``top`` (:func:`heavy_top`) from the body angular
    velocity ``omega0`` (3,) (body components) and attitude ``Q0`` (3, 3) (body → space), at
    the times ``t`` (n,), in closed form: the :class:`TopMotion` that :func:`top_motion` gives
    for a simulated run, field by field, exact.

    ``u = cos θ`` moves between two roots of the cubic ``u̇² = (α − βu)(1 − u²) − (b − au)²``
    as ``u₁ + (u₂ − u₁) sn²(τ | m)``; ψ and φ are elliptic integrals of the third kind
    (``docs/theory.md`` §6, eqs (T1)–(T3); Goldstein §5.7, Whittaker §71). Every regime is the
    same formula: nutation between two angles, cusps (a top released from rest), steady
    precession and the sleeping top (no nutation: θ constant, ψ and φ uniform), and swings
    through a vertical (no spin; a top thrown over the top), where ψ steps by π and the
    attitude and ω stay continuous (``docs/theory.md`` §6, (T5)–(T6)). Vectorised:
    ``omega0`` (N, 3) and ``Q0`` (N, 3, 3) give a list of N motions, from one call of the core.

    Examples
    --------
    >>> from poinsot import Gravity, RigidBody
    >>> from poinsot.rotation import matrix_from_euler
    >>> top = heavy_top(RigidBody.cylinder(1.0, 0.3, 0.2), (0, 0, -0.5), [Gravity()])
    >>> m = exact_motion(top, (0.0, 0.0, 100.0), matrix_from_euler([0.0, 0.6, 0.0]), [0.0, 1.0])
    >>> round(m.nutation_period, 6), round(m.mean_precession_rate, 4), round(m.gyroscopic_rate, 4)
    (0.433236, 1.1529, 1.09)

    Released from rest at θ = 0.6 rad, the axis falls to 0.69 rad and back every 0.43 s
    (cusps), precessing at 1.153 rad/s on average, 6 % above the gyroscopic estimate.
    """
    from ._validation import as_array, as_rotation_matrices, as_rotation_matrix
    from .rotation import EULER_SINGULAR, body_rates_from_euler, matrix_from_euler

    top = _check_top(top)
    single = np.ndim(omega0) == 1
    w = as_array(omega0, "omega0", (3,) if single else (None, 3)).reshape(-1, 3)
    if single:
        Q = as_rotation_matrix(as_array(Q0, "Q0", (3, 3)), "Q0")[None]
    else:
        Q = as_rotation_matrices(as_array(Q0, "Q0", (len(w), 3, 3)), "Q0", len(w))
    times = as_array(t, "t", (None,))
    F, S = top.frame(), top.space()
    angles, rates = _initial_angles(top, w, Q)
    motion, summary = core_tops.heavy_top_motions(top.A, top.C, top.mgl, angles, rates, times)
    _refuse_unresolved_phases(times, w, [(row[3], row[4]) for row in summary])
    out = []
    for m, (_, _, _, period, rate, spin, _, theta_min, theta_max) in zip(
        motion, summary, strict=True
    ):
        psi, theta, phi = m[:, 0], m[:, 1], m[:, 2]
        angles_t = m[:, :3]
        Q_t = np.einsum("ji,njk,lk->nil", S, matrix_from_euler(angles_t, "ZXZ"), F)
        omega_t = body_rates_from_euler(angles_t, m[:, 3:]) @ F.T
        # no samples, no mean θ: empty results (docs/reliability.md)
        theta_mean = float(theta.mean()) if len(theta) else float("nan")
        out.append(TopMotion(
            t=times, theta=theta, psi=psi,
            singular=np.abs(np.sin(theta)) < EULER_SINGULAR, spin=float(spin),
            theta_band=(float(theta_min), float(theta_max)),
            theta_mean=theta_mean, mean_precession_rate=float(rate),
            gyroscopic_rate=gyroscopic_precession_rate(top.C, top.mgl, spin) if spin else np.inf,
            steady_rates=(steady_precession_rates(top.A, top.C, top.mgl, theta_mean, spin)
                          if len(theta) else (float("nan"), float("nan"))),
            phi=phi, Q=Q_t, omega=omega_t, nutation_period=float(period), space_axes=S,
        ))  # fmt: skip
    return out[0] if single else out


#: The directions of :class:`TopDerivatives`: the top's constants, then its initial z-x-z
#: angles and their rates.
TOP_DIRECTIONS = ("A", "C", "mgl", "psi0", "theta0", "phi0", "psi_dot0", "theta_dot0",
                  "phi_dot0")  # fmt: skip


@dataclass(frozen=True)
class TopDerivatives:
    """The exact derivatives of a heavy top's closed form (:func:`exact_derivatives`).

    Attributes
    ----------
    t : (n,)
    angles, rates : (n, 3)
        ``(ψ, θ, φ)`` and ``(ψ̇, θ̇, φ̇)`` [rad, rad/s], as :func:`exact_motion` has them.
    d_angles, d_rates : (n, 3, 9)
        Their derivatives along :data:`TOP_DIRECTIONS` (``directions``): ``A``, ``C``,
        ``M g l``, then the initial angles ``(ψ₀, θ₀, φ₀)`` and rates ``(ψ̇₀, θ̇₀, φ̇₀)``.
    cos_theta_band : (2,)
        The turning points ``(u₁, u₂)`` of ``cos θ``; ``d_cos_theta_band`` (2, 9).
    nutation_period, mean_precession_rate : float
        ``2K(m)/λ`` and ψ's advance over it divided by it; ``d_nutation_period``,
        ``d_mean_precession_rate`` (9,).
    rates0_d_omega0 : (3, 3)
        ``∂(ψ̇₀, θ̇₀, φ̇₀)/∂ω0`` at the initial attitude (the angles' rates are linear in the
        body ω): with it the derivatives along the body's ω0 (:meth:`d_angles_d_omega0`).
    Q, omega : (n, 3, 3), (n, 3)
        The body's attitude (body → space) and angular velocity (body components), as
        :func:`exact_motion` has them; ``d_Q`` (n, 3, 3, 9), ``d_omega`` (n, 3, 9) their
        derivatives along ``directions`` (:meth:`d_Q_d_omega0`, :meth:`d_omega_d_omega0`).
    """

    t: np.ndarray
    angles: np.ndarray
    rates: np.ndarray
    d_angles: np.ndarray
    d_rates: np.ndarray
    cos_theta_band: np.ndarray
    d_cos_theta_band: np.ndarray
    nutation_period: float
    d_nutation_period: np.ndarray
    mean_precession_rate: float
    d_mean_precession_rate: np.ndarray
    rates0_d_omega0: np.ndarray
    Q: np.ndarray
    d_Q: np.ndarray
    omega: np.ndarray
    d_omega: np.ndarray
    directions: tuple = TOP_DIRECTIONS

    @property
    def d_angles_d_omega0(self) -> np.ndarray:
        """``∂(ψ, θ, φ)(t)/∂ω0`` (n, 3, 3), the body's initial ω (body components) with its
        attitude held."""
        return self.d_angles[..., 6:] @ self.rates0_d_omega0

    @property
    def d_rates_d_omega0(self) -> np.ndarray:
        """``∂(ψ̇, θ̇, φ̇)(t)/∂ω0`` (n, 3, 3)."""
        return self.d_rates[..., 6:] @ self.rates0_d_omega0

    @property
    def d_Q_d_omega0(self) -> np.ndarray:
        """``∂Q_rc(t)/∂ω0_j`` (n, 3, 3, 3)."""
        return self.d_Q[..., 6:] @ self.rates0_d_omega0

    @property
    def d_omega_d_omega0(self) -> np.ndarray:
        """``∂ω_i(t)/∂ω0_j`` (n, 3, 3), body components."""
        return self.d_omega[..., 6:] @ self.rates0_d_omega0


def exact_derivatives(top: HeavyTop, omega0, Q0, t) -> TopDerivatives:
    """The exact derivatives of the heavy symmetric top's closed form (:func:`exact_motion`)
    along its constants ``A``, ``C``, ``M g l`` and its initial state, from the body angular
    velocity ``omega0`` (3,) and attitude ``Q0`` (3, 3) (body → space), at the times ``t``.

    The core runs the closed form's own algebra on dual numbers: the cubic's roots by the
    implicit function theorem, ``m``, ``λ``, the start ``τ₀`` (from ``u(τ₀) = u₀`` and
    ``u̇(τ₀) = −θ̇₀ sin θ₀`` together, so a top released from rest has them too), the Jacobi
    functions with their derivatives in ``τ`` and ``m``, and the third-kind integrals of ψ and
    φ through Carlson's duplication (``crates/core/src/heavy_top.rs``, ``TopTangent``).
    Refused, with the reason, where the closed form is not differentiable: a top that does not
    nutate (steady precession, the sleeping top: the turning points merge) or whose axis
    reaches the vertical.

    Examples
    --------
    How the nutation period of a top released from rest depends on its spin rate φ̇₀
    (seconds per rad/s):

    >>> from poinsot import Gravity, RigidBody
    >>> from poinsot.rotation import matrix_from_euler
    >>> top = heavy_top(RigidBody.cylinder(1.0, 0.3, 0.2), (0, 0, -0.5), [Gravity()])
    >>> d = exact_derivatives(top, (0.0, 0.0, 100.0), matrix_from_euler([0.0, 0.6, 0.0]), [1.0])
    >>> round(d.nutation_period, 6), round(float(d.d_nutation_period[8]), 6)
    (0.433236, -0.005407)
    """
    from ._validation import as_array, as_rotation_matrix, as_vector3

    top = _check_top(top)
    w = as_vector3(omega0, "omega0")
    Q = as_rotation_matrix(as_array(Q0, "Q0", (3, 3)), "Q0")
    times = as_array(t, "t", (None,))
    angles, rates = _initial_angles(top, w[None], Q[None])
    motion, d, summary, ds, R, dR, w_axis, dw_axis = core_tops.heavy_top_derivatives(
        top.A, top.C, top.mgl, angles[0], rates[0], times
    )
    # as exact_motion refuses them (it had returned numbers at t = 1e14, the phase 6e15 rad)
    _refuse_unresolved_phases(times, w[None], [(summary[2], summary[3])])
    F, S = top.frame(), top.space()  # body ← axis frame, and the space axes (rows)
    # the rates are linear in ω: their Jacobian is their value at the unit vectors
    _, J = _initial_angles(top, np.eye(3), np.repeat(Q[None], 3, axis=0))
    return TopDerivatives(
        t=times, angles=motion[:, :3], rates=motion[:, 3:], d_angles=d[:, :3],
        d_rates=d[:, 3:], cos_theta_band=summary[:2], d_cos_theta_band=ds[:2],
        nutation_period=float(summary[2]), d_nutation_period=ds[2],
        mean_precession_rate=float(summary[3]), d_mean_precession_rate=ds[3],
        rates0_d_omega0=J.T,
        Q=np.einsum("ji,njk,lk->nil", S, R, F), d_Q=np.einsum("ji,njkd,lk->nild", S, dR, F),
        omega=w_axis @ F.T, d_omega=np.einsum("ik,nkd->nid", F, dw_axis),
    )  # fmt: skip
