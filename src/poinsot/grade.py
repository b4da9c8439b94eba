"""Grading another engine's motion against the exact one (``poinsot grade``).

Other engines integrate the free rigid body (and the heavy top) numerically, and their users
rarely know how far off they are: brax#156 (no tennis-racket effect), godot#50173,
JoltPhysics#803, Principia#2519 (an angular velocity that leaves its polhode). poinsot knows
the exact motion (``docs/theory.md`` §2 and §6): this module measures a trajectory from
anywhere against it, from the trajectory's own first sample.

* :func:`grade_free` — a torque-free body: the errors of ω and of the attitude against the
  closed form, the drift of the energy ``k`` and of ``|L|`` (30)–(31), the distance of ω from
  its exact polhode, the flips of the intermediate axis against the exact instants, and
  whether the motion stays in its polhode family;
* :func:`grade_top` — a heavy symmetric top: the errors of θ, ψ, φ, ω and Q against Lagrange's
  top in closed form (:func:`poinsot.tops.exact_motion`);
* :func:`read_motion` — a trajectory from a file: CSV through the column maps of
  ``poinsot identify`` (with ``columns.attitude``), or ``.npz`` with ``t``, ``omega`` and
  ``quaternion`` or ``Q`` (poinsot's own export).

Every number comes from the library: the closed forms and invariants are the core's; this
module only compares.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["Grade", "Motion", "grade_free", "grade_top", "read_motion"]


@dataclass(frozen=True)
class Motion:
    """A trajectory read from a file: ``t`` (n,) [s], ``omega`` (n, 3) body frame [rad/s],
    ``Q`` (n, 3, 3) body → space or None, ``source`` (the file), ``notes``."""

    t: np.ndarray
    omega: np.ndarray
    Q: np.ndarray | None
    source: str = ""
    notes: tuple = ()


def read_motion(path, log_map=None, **options) -> Motion:
    """A body's motion from a file.

    ``.npz``: arrays ``t`` (n,), ``omega`` (n, 3) (body frame, rad/s) and optionally the
    attitude, ``quaternion`` (n, 4: w, x, y, z, body → space) or ``Q`` (n, 3, 3) — what
    :meth:`poinsot.trajectory.Trajectory.to_npz` writes. Anything else is read as a CSV log
    by :func:`poinsot.identify.read_log` with ``log_map`` and ``options`` (``gyro`` the ω
    columns, ``attitude`` four quaternion or nine matrix columns).

    Raises
    ------
    poinsot.identify.LogMapError
        Naming the file and what is missing or malformed.
    """
    from .identify.log import LogMapError, read_log
    from .rotation import matrix_from_quat

    path = Path(path)
    if path.suffix.lower() != ".npz":
        given = options.get("attitude") or (log_map is not None and log_map.attitude)
        if not given:  # poinsot's own CSV export names its attitude columns
            found = _attitude_columns(path)
            if found:
                options = {**options, "attitude": found}
        log = read_log(path, log_map, **options)
        return Motion(log.t, log.omega, log.attitude, str(path), log.notes)
    if log_map is not None or any(v is not None for v in options.values()):
        raise LogMapError(f"{path}: a column map applies to CSV logs, not to .npz files")
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise LogMapError(f"{path}: not a readable .npz file ({exc})") from None
    with data:
        for key in ("t", "omega"):
            if key not in data.files:
                raise LogMapError(f"{path}: no array `{key}` (found {', '.join(data.files)})")
        t = np.asarray(data["t"], dtype=float)
        omega = np.asarray(data["omega"], dtype=float)
        Q = None
        if "Q" in data.files:  # the matrix as integrated: its drift off SO(3) is graded
            Q = np.asarray(data["Q"], dtype=float)
        elif "quaternion" in data.files:
            Q = matrix_from_quat(np.asarray(data["quaternion"], dtype=float))
    n = len(t)
    if t.ndim != 1 or omega.shape != (n, 3) or (Q is not None and Q.shape != (n, 3, 3)):
        raise LogMapError(f"{path}: expected t (n,), omega (n, 3) and an attitude of n "
                          f"samples, found {t.shape}, {omega.shape}"
                          + ("" if Q is None else f", {Q.shape}"))  # fmt: skip
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(omega))):
        raise LogMapError(f"{path}: t and omega must be finite")
    if n < 2 or np.any(np.diff(t) <= 0):
        raise LogMapError(f"{path}: t must hold two or more strictly increasing times")
    return Motion(t, omega, Q, str(path))


def _attitude_columns(path) -> tuple | None:
    """The attitude columns of poinsot's CSV export when the file's first line has them: the
    matrix ``Q_11 [1]`` … ``Q_33 [1]`` (row by row; as integrated, so its drift off SO(3) is
    graded), else the quaternion ``quaternion_w [1]`` … ``quaternion_z [1]`` (normalised when
    written: it hides that drift)."""
    try:
        with open(path, encoding="utf-8-sig") as fh:
            header = fh.readline()
    except (OSError, UnicodeDecodeError):
        return None  # read_log says what is wrong with the file
    names = [n.strip().strip('"') for n in header.split(",")]
    for wanted in (tuple(f"Q_{i}{j} [1]" for i in "123" for j in "123"),
                   tuple(f"quaternion_{c} [1]" for c in "wxyz")):  # fmt: skip
        if all(w in names for w in wanted):
            return wanted
    return None


@dataclass(frozen=True)
class Grade:
    """How far a trajectory is from the exact motion from its first sample.

    Attributes
    ----------
    kind : str
        ``"free body"`` or ``"heavy top"``.
    t : ndarray (n,)
        The trajectory's times [s].
    omega_error : ndarray (n,)
        ``|ω − ω_exact|`` [rad/s].
    attitude_error : ndarray (n,) or None
        ``max |Q − Q_exact|`` over the entries (dimensionless; about the angle between them
        when small), None without an attitude.
    orthogonality_error : ndarray (n,) or None
        ``max |QᵀQ − I|``: how far the engine's attitude is from a rotation.
    energy_error, momentum_error : ndarray (n,) or None
        Free body: ``|k/k₀ − 1|`` and ``||L|/|L₀| − 1|`` (both conserved exactly).
    polhode_distance : ndarray (n,) or None
        Free body: the distance of ω from the exact polhode through ω₀ [rad/s].
    family : str
        Free body: the polhode family of ω₀ (:meth:`FreeRigidBody.classify`).
    family_left_at : float or None
        The first time ω is in another family, or None when it never is.
    wrong_family_fraction : float
        The fraction of the samples in another family.
    flips, exact_flips : ndarray
        Free body, three distinct moments: the instants where ω·e₂ changes sign, measured
        (linear between samples) and exact (over the same span).
    angle_errors : dict or None
        Heavy top: ``"theta"``, ``"psi"``, ``"phi"`` → ``|angle − angle_exact|`` (n,) [rad].
    omega_exact, Q_exact : ndarray
        The exact motion at the same times.
    gyro_mismatch : float or None
        How far the attitude's steps are from the gyro's (:func:`gyro_attitude_mismatch`):
        above :data:`FOLLOW_RTOL` the columns are likely mislabelled; ``gyro_verdict`` says
        what the steps match instead, if anything.
    """

    kind: str
    t: np.ndarray
    omega_error: np.ndarray
    attitude_error: np.ndarray | None
    orthogonality_error: np.ndarray | None
    omega_exact: np.ndarray
    Q_exact: np.ndarray | None
    energy_error: np.ndarray | None = None
    momentum_error: np.ndarray | None = None
    polhode_distance: np.ndarray | None = None
    family: str = ""
    family_left_at: float | None = None
    wrong_family_fraction: float = 0.0
    flips: np.ndarray = field(default_factory=lambda: np.zeros(0))
    exact_flips: np.ndarray = field(default_factory=lambda: np.zeros(0))
    flip_interval: float = math.nan
    angle_errors: dict | None = None
    #: the exact polhode through ω₀ (m, 3), body frame (free body)
    polhode: np.ndarray | None = None
    omega: np.ndarray | None = None
    gyro_mismatch: float | None = None
    gyro_verdict: str = ""

    def flip_errors(self) -> np.ndarray:
        """``|t_measured − t_exact|`` of the flips, paired in order (as many as both have)."""
        n = min(len(self.flips), len(self.exact_flips))
        return np.abs(self.flips[:n] - self.exact_flips[:n])

    def summary(self) -> dict:
        """The largest errors, JSON-ready, each with its unit in the key's ``units`` map."""

        def peak(a):
            return None if a is None else float(np.max(a))

        out = {
            "kind": self.kind,
            "samples": len(self.t),
            "t_start": float(self.t[0]),
            "t_end": float(self.t[-1]),
            "max_omega_error": peak(self.omega_error),
            "max_attitude_error": peak(self.attitude_error),
            "max_orthogonality_error": peak(self.orthogonality_error),
            "gyro_attitude_mismatch": self.gyro_mismatch,
            "gyro_attitude_verdict": self.gyro_verdict,
        }
        units = {"t_start": "s", "t_end": "s", "max_omega_error": "rad/s",
                 "max_attitude_error": "1", "max_orthogonality_error": "1",
                 "gyro_attitude_mismatch": "1 (relative)"}  # fmt: skip
        if self.kind == "free body":
            flips = self.flip_errors()
            out |= {
                "family": self.family,
                "family_kept": self.family_left_at is None,
                "family_left_at": self.family_left_at,
                "wrong_family_fraction": self.wrong_family_fraction,
                "max_energy_error": peak(self.energy_error),
                "max_momentum_error": peak(self.momentum_error),
                "max_polhode_distance": peak(self.polhode_distance),
                "flips": len(self.flips),
                "exact_flips": len(self.exact_flips),
                "flip_interval": self.flip_interval,
                "max_flip_time_error": float(flips.max()) if len(flips) else None,
            }
            units |= {"family_left_at": "s", "wrong_family_fraction": "1",
                      "max_energy_error": "1 (relative)", "max_momentum_error": "1 (relative)",
                      "max_polhode_distance": "rad/s", "flip_interval": "s",
                      "max_flip_time_error": "s"}  # fmt: skip
        else:
            for name, err in (self.angle_errors or {}).items():
                out[f"max_{name}_error"] = peak(err)
                units[f"max_{name}_error"] = "rad"
        out["units"] = units
        return out


def _attitude_errors(Q, R) -> np.ndarray:
    """``max |Q − R|`` over the entries, per sample (n,): the measure poinsot's own method
    comparisons use (about the angle between them when small; defined for a ``Q`` that has
    drifted off SO(3), as an integrator's may)."""
    return np.abs(Q - R).max(axis=(1, 2))


#: Above this median relative mismatch, the attitude does not follow the gyro.
FOLLOW_RTOL = 0.05


def gyro_attitude_mismatch(t, omega, Q) -> tuple[float | None, str]:
    """Whether the attitude ``Q`` (n, 3, 3) follows the body-frame ``omega`` (n, 3): the
    median over the steps of ``|log(Q_kᵀQ_{k+1}) − ½(ω_k + ω_{k+1})Δt| / |½(ω_k +
    ω_{k+1})Δt|`` (Q̇ = Q ω̂ over one step), and what the increments match when they do not:
    ``"space"`` (``log(Q_{k+1}Q_kᵀ)``: ω in the space frame), ``"transposed"`` (``log(Q_k
    Q_{k+1}ᵀ)``: a space → body matrix, or a conjugate quaternion), ``"degrees"`` (``ω·π/180``:
    a gyro in deg/s), or ``""``. ``(None, "")`` where the attitude turns more than 1 rad a
    step (its steps are then ambiguous), or the gyro too little to tell."""
    from .rotation import rotvec_from_matrix

    if Q is None or len(t) < 3:
        return None, ""
    step = 0.5 * (omega[1:] + omega[:-1]) * np.diff(t)[:, None]
    size = np.linalg.norm(step, axis=1)
    turning = size > 1e-9
    if turning.sum() < 2:
        return None, ""
    step, size = step[turning], size[turning]
    a, b = Q[:-1][turning], Q[1:][turning]
    body = rotvec_from_matrix(np.swapaxes(a, 1, 2) @ b)
    if np.median(np.linalg.norm(body, axis=1)) > 1.0:
        return None, ""

    def mismatch(increment, scale=1.0):
        return float(np.median(np.linalg.norm(increment - scale * step, axis=1) / (scale * size)))

    first = mismatch(body)
    if first <= FOLLOW_RTOL:
        return first, ""
    for verdict, increment, scale in (
        ("space", rotvec_from_matrix(b @ np.swapaxes(a, 1, 2)), 1.0),
        ("transposed", rotvec_from_matrix(a @ np.swapaxes(b, 1, 2)), 1.0),
        ("degrees", body, math.pi / 180),
    ):
        if mismatch(increment, scale) <= FOLLOW_RTOL:
            return first, verdict
    return first, ""


def _follows(t, omega, Q) -> dict:
    """The Grade's ``gyro_mismatch`` and ``gyro_verdict``."""
    mismatch, verdict = gyro_attitude_mismatch(t, omega, Q)
    return {"gyro_mismatch": mismatch, "gyro_verdict": verdict}


def _crossings(t, x) -> np.ndarray:
    """The instants where ``x`` (n,) changes sign, linear between samples."""
    s = np.signbit(x)
    k = np.flatnonzero(s[1:] != s[:-1])
    return t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])


def _check(t, omega, Q, name="omega"):
    from ._validation import as_array

    t = as_array(t, "t", (None,))
    omega = as_array(omega, name, (len(t), 3))
    if len(t) < 2 or np.any(np.diff(t) <= 0):
        raise ValueError("`t` must hold two or more strictly increasing times")
    if Q is not None:
        Q = as_array(Q, "Q", (len(t), 3, 3))  # as the engine left it, on SO(3) or not
    return t, omega, Q


def grade_free(t, omega, inertia, Q=None) -> Grade:
    """Grade a torque-free body's trajectory against the exact motion from its first sample.

    Parameters
    ----------
    t : array_like (n,)
        Strictly increasing times [s].
    omega : array_like (n, 3)
        Angular velocity in the body frame [rad/s].
    inertia : array_like (3,) or (3, 3)
        The principal moments along the body axes, or the inertia tensor about the centre of
        mass in the body frame [kg·m²] (only its ratios matter).
    Q : array_like (n, 3, 3), optional
        The attitude, body → space.

    Returns
    -------
    Grade

    Examples
    --------
    >>> import numpy as np
    >>> from poinsot import FreeRigidBody
    >>> t = np.linspace(0.0, 50.0, 1001)
    >>> w = FreeRigidBody((1.0, 2.0, 3.0)).exact_omega((0.01, 1.0, 0.01), t)
    >>> g = grade_free(t, w + 1e-6, (1.0, 2.0, 3.0))  # every sample off by 1e-6 rad/s
    >>> g.family, g.family_left_at, len(g.flips), len(g.exact_flips)
    ('around e3', None, 2, 2)
    >>> f"{g.polhode_distance.max():.1e}", f"{g.omega_error.max():.1e}"
    ('2.5e-06', '5.3e-04')

    The offset ω₀ starts a motion on a neighbouring polhode with another period: ω stays
    within 2.5e-6 rad/s of the true curve but runs ahead along it, by 5.3e-4 rad/s after 50 s.
    """
    from .bodies import RigidBody
    from .conservation import angular_momentum_body, orthogonality_error, rotational_energy
    from .torquefree import FreeRigidBody

    t, omega, Q = _check(t, omega, Q)
    J = np.asarray(inertia, dtype=float)
    J = np.diag(J) if J.shape == (3,) else J
    free = FreeRigidBody.from_body(RigidBody(1.0, J))
    w0 = omega[0]
    k0, a0 = free.invariants(w0)
    if not k0 > 0:
        raise ValueError("`omega` starts at rest: there is no motion to grade")
    tau = t - t[0]
    w_exact = free.exact_omega(w0, tau)
    Q_exact = None if Q is None else free.exact_attitude(w0, tau, Q[0])
    ks = rotational_energy(free.inertia, omega)  # (30)
    As = np.hypot.reduce(angular_momentum_body(free.inertia, omega), axis=1)  # (31)
    family = free.classify(w0)
    families = free.classify(omega)
    wrong = families != family
    distance = curve = None
    if family not in ("fixed point", "spherical"):
        curve = free.polhode(w0, n=2000).points
        period = free.period(w0) if family != "separatrix" else math.inf
        distance = _distance_to_polhode(omega, lambda s: free.exact_omega(w0, s), period, curve)
    flips = exact = np.zeros(0)
    interval = math.nan
    if free.symmetry == "asymmetric" and family in ("around e1", "around e3"):
        e2 = free.principal_axes[:, 1]
        flips = _crossings(t, omega @ e2)
        interval = free.flip_interval(w0)
        exact = t[0] + _exact_flips(lambda s: free.exact_omega(w0, s) @ e2, tau[-1], interval)
    return Grade(
        kind="free body",
        t=t,
        omega=omega,
        omega_error=np.linalg.norm(omega - w_exact, axis=1),
        attitude_error=None if Q is None else _attitude_errors(Q, Q_exact),
        orthogonality_error=None if Q is None else orthogonality_error(Q),
        omega_exact=w_exact,
        Q_exact=Q_exact,
        energy_error=np.abs(ks / k0 - 1),
        momentum_error=np.abs(As / a0 - 1),
        polhode_distance=distance,
        polhode=curve,
        family=family,
        family_left_at=float(t[np.argmax(wrong)]) if wrong.any() else None,
        wrong_family_fraction=float(wrong.mean()),
        flips=flips,
        exact_flips=exact,
        flip_interval=interval,
        **_follows(t, omega, Q),
    )


def _exact_flips(component, span, interval) -> np.ndarray:
    """The exact zeros of ω·e₂ over ``[0, span]``: the first found by bisection on the closed
    form within one flip interval, the rest a whole number of intervals later (ω·e₂ ∝ sn u)."""
    probe = np.linspace(0.0, min(span, 1.01 * interval), 64)
    x = component(probe)
    s = np.signbit(x)
    k = np.flatnonzero(s[1:] != s[:-1])
    if not len(k):
        return np.zeros(0)
    lo, hi = probe[k[0]], probe[k[0] + 1]
    flo = x[k[0]]
    for _ in range(60):  # to the last bit of the time
        mid = 0.5 * (lo + hi)
        fm = component(np.array([mid]))[0]
        if np.signbit(fm) == np.signbit(flo):
            lo, flo = mid, fm
        else:
            hi = mid
        if hi - lo <= 4 * np.spacing(hi):
            break
    first = 0.5 * (lo + hi)
    count = math.floor((span - first) / interval) + 1 if first <= span else 0
    return first + interval * np.arange(count)


def _distance_to_polhode(points, exact, period, curve) -> np.ndarray:
    """The distance of each ω (n, 3) from the exact polhode: the nearest of ``exact(s)`` over
    one period ``s ∈ [0, period)`` (the closed form along the curve), found on a grid of 2048
    times and refined by golden-section search between the grid's neighbours, so that it is
    the distance to the curve itself, not to a polyline (zero, to round-off, for the exact
    motion). On the separatrix (infinite period) the polyline ``curve`` (m, 3) is used."""
    if not math.isfinite(period):
        return _distance_to_polyline(points, curve)
    grid = np.linspace(0.0, period, 2049)[:-1]
    ref = exact(grid)
    step = grid[1] - grid[0]
    nearest = np.empty(len(points))
    coarse = np.empty(len(points))
    for i in range(0, len(points), 256):  # (256, 2048) distances at a time
        d2 = ((points[i : i + 256, None, :] - ref[None, :, :]) ** 2).sum(-1)
        nearest[i : i + 256] = grid[np.argmin(d2, axis=1)]
        coarse[i : i + 256] = np.sqrt(d2.min(axis=1))
    lo, hi = nearest - step, nearest + step
    golden = (math.sqrt(5.0) - 1.0) / 2.0

    def dist(s):
        return np.linalg.norm(points - exact(s), axis=1)

    a, b = hi - golden * (hi - lo), lo + golden * (hi - lo)
    fa, fb = dist(a), dist(b)
    for _ in range(90):  # the bracket shrinks by 0.618 a round: to round-off of the time
        left = fa < fb
        hi, lo = np.where(left, b, hi), np.where(left, lo, a)
        a, b = hi - golden * (hi - lo), lo + golden * (hi - lo)
        fa, fb = dist(a), dist(b)
        if np.all(hi - lo <= 4 * np.spacing(np.maximum(np.abs(hi), period))):
            break
    return np.minimum(np.minimum(fa, fb), coarse)


def _distance_to_polyline(points, curve, chunk=512) -> np.ndarray:
    """The distance of each point (n, 3) from the closed polyline ``curve`` (m, 3)."""
    a = curve
    d = np.roll(curve, -1, axis=0) - a
    dd = np.einsum("ij,ij->i", d, d)
    dd = np.where(dd > 0, dd, 1.0)
    out = np.empty(len(points))
    for i in range(0, len(points), chunk):
        p = points[i : i + chunk, None, :]
        s = np.clip(np.einsum("nmj,mj->nm", p - a, d) / dd, 0.0, 1.0)
        nearest = a + s[..., None] * d
        out[i : i + chunk] = np.sqrt(np.einsum("nmj,nmj->nm", p - nearest, p - nearest).min(1))
    return out


def grade_top(t, omega, Q, top) -> Grade:
    """Grade a heavy symmetric top's trajectory (``omega`` (n, 3) body frame, ``Q`` (n, 3, 3)
    body → space) against Lagrange's top in closed form from its first sample
    (:func:`poinsot.tops.exact_motion`): the errors of ω, of the attitude and of the Euler
    angles θ (nutation), ψ (precession) and φ (spin) of the top's axis, measured as
    :func:`poinsot.tops.top_motion` measures a simulated top. ``top`` is a
    :class:`poinsot.tops.HeavyTop`."""
    from types import SimpleNamespace

    from .conservation import orthogonality_error
    from .tops import top_motion

    t, omega, Q = _check(t, omega, Q)
    if Q is None:
        raise ValueError("grading a top needs its attitude `Q`")
    motion = top_motion(SimpleNamespace(t=t, omega=omega, Q=Q), top)
    exact = motion.exact
    if exact is None:
        raise ValueError("the top starts with its axis on the vertical, where ψ is undefined")

    return Grade(
        kind="heavy top",
        t=t,
        omega=omega,
        omega_error=np.linalg.norm(omega - exact.omega, axis=1),
        attitude_error=_attitude_errors(Q, exact.Q),
        orthogonality_error=orthogonality_error(Q),
        omega_exact=exact.omega,
        Q_exact=exact.Q,
        angle_errors=motion.angle_errors(),
        **_follows(t, omega, Q),
    )
