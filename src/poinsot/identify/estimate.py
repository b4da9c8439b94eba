"""``identify``: a body's inertia from one gyro log (``docs/identify.md``).

The steps: check the input (every refusal names the argument); find the free flight
(:mod:`~poinsot.identify.flight`); estimate the inertia by equation error
(:mod:`~poinsot.identify.equation_error`); refine it, with the gyro bias and ω0, by output
error (:mod:`~poinsot.identify.output_error`); judge the fit (residuals against the gyro's
noise) and the identifiability (standard errors of every ratio and axis), and refuse what the
motion does not determine.
"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from .._bindings import inertia as core_inertia
from .._validation import as_array, as_positive_scalar, as_vector3
from .flight import find_free_flight
from .result import (
    IdentifyResult,
    ModelMismatchWarning,
    NotIdentifiableError,
    _robust_std,
    _total_noise,
)
from .signals import white_noise_std

__all__ = [
    "MAX_AXIS_STDERR_DEG",
    "MAX_RATIO_STDERR",
    "MAX_SAMPLES",
    "MAX_SEGMENTS",
    "MIN_ROTATION",
    "MIN_SAMPLES",
    "MISMATCH_RATIO",
    "identify",
]

#: Fewest samples in the window.
MIN_SAMPLES = 30
#: Most samples in the window: the fit's cost and memory grow with it (a free flight lasts
#: well under 2 s: 8000 samples at 4 kHz).
MAX_SAMPLES = 50_000
#: Most pieces the window is split into (each with its own initial ω).
MAX_SEGMENTS = 20
#: Least rotation in the window, ``∫|ω| dt`` [rad].
MIN_ROTATION = 1.0
#: A ratio whose standard error exceeds this is not identifiable.
MAX_RATIO_STDERR = 0.02
#: An axis whose standard error exceeds this [deg] is not identifiable.
MAX_AXIS_STDERR_DEG = 5.0
#: Below this ratio of the two smallest singular values the equation-error estimate is
#: ambiguous, and the output-error fit is started from several inertias.
AMBIGUOUS_GAP = 10.0
#: Iterations of each trial start.
TRIAL_NFEV = 10
#: Residuals this many times the gyro noise (RMS) flag the model as not explaining the motion.
MISMATCH_RATIO = 2.0


def _times(t) -> np.ndarray:
    t = as_array(t, "t", (None,))
    if len(t) < 2:
        raise ValueError(f"`t` must hold at least 2 samples, found {len(t)}")
    d = np.diff(t)
    if np.any(d <= 0):
        k = int(np.flatnonzero(d <= 0)[0]) + 1
        what = "repeats" if d[k - 1] == 0 else "goes back from"
        raise ValueError(
            f"`t` must increase strictly: t[{k}] = {float(t[k])!r} {what} t[{k - 1}] = "
            f"{float(t[k - 1])!r} "
            "(duplicate or out-of-order samples)"
        )
    return t


def _series(value, name: str, n: int, cols: int | None) -> np.ndarray:
    shape = (n,) if cols is None else (n, cols)
    arr = as_array(value, name, (None,) if cols is None else (None, cols), finite=False)
    if arr.shape != shape:
        raise ValueError(f"`{name}` must have shape {shape} (one row per time in `t`), "
                         f"found {arr.shape}")  # fmt: skip
    bad = ~np.isfinite(arr)
    if bad.any():
        k = int(np.flatnonzero(bad.reshape(n, -1).any(axis=1))[0])
        raise ValueError(f"`{name}` has a NaN or infinite sample at row {k} (t index {k}): "
                         "drop or fill the missing samples first")  # fmt: skip
    return arr


def _window(window, t) -> tuple[float, float] | None:
    if window is None:
        return None
    w = as_array(window, "window", (2,))
    a, b = float(w[0]), float(w[1])
    if not a < b:
        raise ValueError(f"`window` must be (start, end) with start < end, found ({a}, {b})")
    if a < t[0] or b > t[-1]:
        raise ValueError(
            f"`window` ({a:g}, {b:g}) s reaches outside the log, which runs from {t[0]:g} to "
            f"{t[-1]:g} s: the log is shorter than the window"
        )
    return a, b


def _cone_deg(w) -> float:
    """The largest angle [deg] between ω(t) and its mean direction."""
    norms = np.linalg.norm(w, axis=1)
    u = w[norms > 0] / norms[norms > 0, None]
    if len(u) == 0:
        return 0.0
    mean = u.mean(axis=0)
    if np.linalg.norm(mean) == 0:
        return 180.0
    mean /= np.linalg.norm(mean)
    return float(np.degrees(np.arccos(np.clip(u @ mean, -1.0, 1.0))).max())


def _rotor_inputs(rotor_speed, rotor_axis, rotor_inertia, n: int):
    """Check and convert the rotor's arguments: ``(speed (n,), unit axis, J)``, each None
    without a rotor (or without its ``J``)."""
    if rotor_speed is not None and rotor_axis is None:
        raise ValueError("`rotor_speed` was given without `rotor_axis`: give the rotor's axis "
                         "in the sensor frame")  # fmt: skip
    if rotor_axis is not None and rotor_speed is None:
        raise ValueError("`rotor_axis` was given without `rotor_speed`")
    if rotor_inertia is not None and rotor_speed is None:
        raise ValueError("`rotor_inertia` was given without `rotor_speed` and `rotor_axis`")
    speed = None if rotor_speed is None else _series(rotor_speed, "rotor_speed", n, None)
    axis = None
    if rotor_axis is not None:
        axis = as_vector3(rotor_axis, "rotor_axis")
        norm = float(np.linalg.norm(axis))
        if not norm > 0:
            raise ValueError("`rotor_axis` must be a nonzero vector")
        axis = axis / norm
    J = None if rotor_inertia is None else as_positive_scalar(rotor_inertia, "rotor_inertia")
    return speed, axis, J


def _fit_options(loss: str, segment, max_nfev) -> float:
    """Check the fit's options ``loss`` and ``max_nfev``; the ``segment`` length [s]."""
    from .output_error import LOSSES

    if loss not in LOSSES:
        raise ValueError(f"`loss` must be one of {LOSSES}, found {loss!r}")
    seg = as_positive_scalar(segment, "segment")
    if isinstance(max_nfev, bool) or not isinstance(max_nfev, int | np.integer) or max_nfev < 1:
        raise ValueError(f"`max_nfev` must be a positive integer, found {max_nfev!r}")
    return seg


def _check_flight(ts, ws, found_by: str, seg: float):
    """Refuse a free flight too short, too long, split into too many segments, turning too
    little or not at all: ``(where, cone, rotation)``, ``where`` naming the window."""
    m = len(ts)
    where = (f"the window t = {ts[0]:.4g} … {ts[-1]:.4g} s ({m} samples, found by the "
             f"{found_by})")  # fmt: skip
    if m < MIN_SAMPLES:
        raise NotIdentifiableError(
            f"`window`: {where} is too short: at least {MIN_SAMPLES} samples are needed; the "
            "ratios I1/I3, I2/I3 and the axes e1, e2, e3 are not identifiable from it",
            ("I1/I3", "I2/I3", "e1", "e2", "e3"),
        )
    if m > MAX_SAMPLES:
        raise ValueError(f"`window`: {where} holds more than {MAX_SAMPLES} samples: give the "
                         "free flight (a throw lasts well under 2 s)")  # fmt: skip
    pieces = int(np.ceil((ts[-1] - ts[0]) / seg - 1e-9))
    if pieces > MAX_SEGMENTS:
        raise ValueError(f"`segment` = {seg:g} s splits {where} into {pieces} pieces, each "
                         f"with its own initial ω; at most {MAX_SEGMENTS} are fitted")  # fmt: skip
    rotation = float(np.sum(0.5 * (np.linalg.norm(ws[1:], axis=1) + np.linalg.norm(ws[:-1], axis=1))
                            * np.diff(ts)))  # fmt: skip
    cone = _cone_deg(ws)
    if rotation < MIN_ROTATION:
        raise NotIdentifiableError(
            f"`omega`: too little rotation in {where}: the body turned {rotation:.3g} rad "
            f"(at least {MIN_ROTATION:g} is needed), so the ratios I1/I3, I2/I3 and the axes "
            "e1, e2, e3 are not identifiable; throw it with more spin or give a longer window",
            ("I1/I3", "I2/I3", "e1", "e2", "e3"),
        )
    if not np.ptp(ws, axis=0).max() > 0:
        raise NotIdentifiableError(
            f"`omega`: ω is constant over {where}, a steady spin about one axis that excites "
            "nothing else: the ratios I1/I3, I2/I3 and the axes e1, e2, e3 are not "
            "identifiable; throw it tumbling (spinning about a direction between the axes)",
            ("I1/I3", "I2/I3", "e1", "e2", "e3"),
        )
    return where, cone, rotation


def identify(
    t,
    omega,
    *,
    rotor_speed=None,
    rotor_axis=None,
    rotor_inertia=None,
    window=None,
    accel=None,
    saturation=None,
    loss: str = "linear",
    segment: float = 1.0,
    max_nfev: int = 300,
) -> IdentifyResult:
    """Identify a tumbling body's inertia from its gyro log.

    The body flies free (no torque but, optionally, that of a rotor it carries: a gyrostat,
    ``I ω̇ + ω × (I ω + h) + ḣ = 0`` with ``h = J ω_R a``; ``docs/theory.md`` §4). Its
    principal moments' ratios and principal axes come out of any tumble that excites them;
    the absolute scale only from a rotor of known inertia ``J``.

    Parameters
    ----------
    t : array_like (n,)
        Sample times [s], strictly increasing.
    omega : array_like (n, 3)
        Gyro readings [rad/s] in the sensor frame (a constant bias is fitted).
    rotor_speed : array_like (n,), optional
        The rotor's speed relative to the body [rad/s], at the times ``t``.
    rotor_axis : array_like (3,), optional
        Its axis in the sensor frame (normalised here); required with ``rotor_speed``.
    rotor_inertia : float, optional
        Its axial moment of inertia ``J`` [kg m²]: the inertia then comes out in kg m²
        (``absolute``). Without it ``J`` is fitted and only the ratios and axes come out.
    window : (float, float), optional
        The stretch of the log to use (or to search for the free flight in) [s].
    accel : array_like (n, 3), optional
        The accelerometer's specific force [m/s²], sensor frame, at the times ``t``: finds the
        free flight (the stretch a rigid lever arm explains; :mod:`poinsot.identify.flight`).
        Without it, the flight is ``window`` (default: the whole log) less any saturated
        samples.
    saturation : float, optional
        The gyro's range [rad/s]; default: recognised as a clipped plateau.
    loss : str
        The fit's loss, ``"linear"`` (least squares) or a robust one of
        :data:`poinsot.identify.output_error.LOSSES`, which down-weights residuals beyond the
        gyro's noise (estimated from the readings). With a robust loss the standard errors
        are the M-estimator's (Huber's sandwich covariance; ``poinsot.identify.output_error``),
        and the residuals are judged by their robust scale (``residual_scale``), not their
        RMS.
    segment : float
        Longest stretch [s] integrated from one initial ω (longer windows are split).
    max_nfev : int
        Bound on the optimiser's iterations.

    Returns
    -------
    IdentifyResult
        With ``flags`` (and a :class:`ModelMismatchWarning`) when the fitted model does not
        explain the readings: residuals more than :data:`MISMATCH_RATIO` times the noise (their
        RMS; with a robust loss their robust scale).

    Raises
    ------
    ValueError, TypeError
        Bad input, naming the argument: non-monotonic or duplicate times, NaN samples, a
        rotor speed without an axis (or the reverse), a window outside the log.
    NotIdentifiableError
        (a ValueError) when the motion does not determine a ratio or an axis: a spin about
        one principal axis, too short a window, too little rotation. The message says which.

    Examples
    --------
    A synthetic throw of a block with a logger whose flywheel spins up (0.5 s at 4 kHz, gyro
    noise 0.02 rad/s):

    >>> from poinsot.identify.synthetic import synthetic_throw
    >>> throw = synthetic_throw(seed=7)
    >>> res = identify(throw.t, throw.omega, **throw.kwargs())
    >>> bool(np.all(np.abs(res.ratios / throw.ratios - 1) < 0.005)), res.absolute
    (True, True)
    >>> bool(abs(res.trace / np.trace(throw.inertia) - 1) < 0.02)
    True
    """
    t = _times(t)
    n = len(t)
    w = _series(omega, "omega", n, 3)
    speed, axis, J = _rotor_inputs(rotor_speed, rotor_axis, rotor_inertia, n)
    win = _window(window, t)
    acc = None if accel is None else _series(accel, "accel", n, 3)
    sat = None if saturation is None else as_positive_scalar(saturation, "saturation")
    seg = _fit_options(loss, segment, max_nfev)

    flight = find_free_flight(t, w, acc, saturation=sat, window=win)
    sl = slice(flight.start, flight.stop)
    ts, ws = t[sl], w[sl]
    where, cone, rotation = _check_flight(ts, ws, flight.found_by, seg)
    sp = None if speed is None else speed[sl]
    try:
        oe, nfev = _fit(ts, ws, sp, axis, J, seg, loss, max_nfev)
        oe = replace(oe, nfev=oe.nfev + nfev)
    except (np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError) as exc:
        # a log so degenerate that the linear algebra of the fits breaks down
        raise NotIdentifiableError(
            f"`omega`: the readings in {where} do not determine the inertia (the fit broke "
            f"down: {exc}); the ratios I1/I3, I2/I3 and the axes e1, e2, e3 are not "
            "identifiable from them",
            ("I1/I3", "I2/I3", "e1", "e2", "e3"),
        ) from exc
    result = _result(oe, ts, ws, flight, speed is not None, J, loss)
    if not result.residual_ratio > MISMATCH_RATIO:
        # standard errors mean something only when the model explains the readings; when it
        # does not, the result is returned flagged (its standard errors inflated by the misfit)
        _refuse_unidentifiable(result, where, cone, rotation)
    for f in result.flags:
        warnings.warn(f, ModelMismatchWarning, stacklevel=2)
    return result


def _fit(ts, ws, sp, axis, J, seg, loss, max_nfev):
    """The equation-error fit, the output-error trials it leaves ambiguous, and the
    output-error fit: ``(fit, evaluations of the trials)``."""
    from .equation_error import equation_error
    from .output_error import output_error

    eq = equation_error(ts, ws, rotor_speed=sp, rotor_axis=axis, rotor_inertia=J)
    common = dict(rotor_speed=sp, rotor_axis=axis, rotor_inertia=J, segment=seg, loss=loss)
    start, start_J, w0 = eq.inertia, eq.rotor_inertia, None
    nfev = 0
    if not eq.physical or eq.gap < AMBIGUOUS_GAP:
        # the linear fit cannot choose: start the output-error fit briefly from each physical
        # inertia along its two most nearly null directions, and go on from the best
        trials = [(eq.inertia, eq.rotor_inertia)] if eq.physical else []
        trials += eq.candidates()
        best = None
        for I0, J0 in trials:
            if J is not None:  # the candidates have trace 1: scale to the known J
                continue
            fit = output_error(ts, ws, I0, initial_rotor_inertia=J0, max_nfev=TRIAL_NFEV,
                               **common)  # fmt: skip
            nfev += fit.nfev
            if best is None or fit.cost < best.cost:
                best = fit
        if best is not None:
            start = best.axes @ np.diag(best.moments) @ best.axes.T
            start_J, w0 = best.rotor_inertia, best.omega0
    oe = output_error(ts, ws, start, omega0=w0, initial_rotor_inertia=start_J,
                      max_nfev=max_nfev, **common)  # fmt: skip
    return oe, nfev


def _moments_stderr(oe, moments, ratios, absolute: bool):
    """The standard errors of the principal moments (3,) and of the trace, propagated from
    the covariance of the ratios (and of the scale ``η`` when ``absolute``)."""
    if absolute:
        # m = I3⁰ e^η (ρ1, ρ2, 1), expanded at η = 0: ∂m/∂(ρ1, ρ2, η)
        k = [oe.names.index(x) for x in ("rho1", "rho2", "eta")]
        C = oe.covariance[np.ix_(k, k)]
        I3 = moments[2]
        G = np.array([[I3, 0.0, moments[0]], [0.0, I3, moments[1]], [0.0, 0.0, I3]])
        g = G.sum(axis=0)  # ∂ trace
        with np.errstate(invalid="ignore"):  # an unidentifiable ratio: infinite variance
            var = np.diag(G @ C @ G.T)
            var_trace = float(g @ C @ g)
        dm = np.sqrt(np.where(np.isnan(var), np.inf, np.clip(var, 0.0, None)))
        dtrace = float(np.sqrt(max(var_trace, 0.0))) if not np.isnan(var_trace) else np.inf
    else:
        # trace 1: m_i = ρ_i/(1 + ρ1 + ρ2), m3 = 1/(1 + ρ1 + ρ2)
        k = [oe.names.index(x) for x in ("rho1", "rho2")]
        C = oe.covariance[np.ix_(k, k)]
        s = 1.0 + ratios.sum()
        G = np.array([[1.0 / s - ratios[0] / s**2, -ratios[0] / s**2],
                      [-ratios[1] / s**2, 1.0 / s - ratios[1] / s**2],
                      [-1.0 / s**2, -1.0 / s**2]])  # fmt: skip
        with np.errstate(invalid="ignore"):  # an unidentifiable ratio: infinite variance
            var = np.diag(G @ C @ G.T)
        dm = np.sqrt(np.where(np.isnan(var), np.inf, np.clip(var, 0.0, None)))
        dtrace = 0.0
    return dm, dtrace


def _misfit(oe, ws, robust: bool):
    """The residuals against the gyro's noise: ``(noise (3,), residual RMS (3,), robust scale
    (3,), total noise RMS, ratio)``; the ratio is that of the residuals' total RMS, or of their
    total robust scale (1.4826 MAD) when ``robust``, to the total noise."""
    noise = white_noise_std(ws)
    rms = np.sqrt(np.mean(oe.residuals**2, axis=0))
    spread = _robust_std(oe.residuals)
    noise_rms = _total_noise(noise, ws)
    # outliers are expected with a robust loss: compare the residuals' robust scale
    size = spread if robust else rms
    ratio = float(np.sqrt(np.mean(size**2)) / noise_rms)
    return noise, rms, spread, noise_rms, ratio


def _flags(oe, ratio: float, noise_rms: float, has_rotor: bool, moments, loss: str) -> list[str]:
    """What is wrong with the fit, in words: a model that does not explain the readings, no
    convergence, moments that no body has. Each number says what it is: the residuals' RMS, or
    with a robust ``loss`` their robust scale (the size ``ratio`` measures), and the scale the
    standard errors are calibrated to (``oe.sigma``)."""
    flags = []
    if ratio > MISMATCH_RATIO:
        model = "gyrostat" if has_rotor else "torque-free"
        size = ratio * noise_rms
        if loss == "linear":
            measured = (f"the residuals are {ratio:.3g}× the gyro noise ({size:.3g} against "
                        f"{noise_rms:.3g} rad/s RMS)")  # fmt: skip
            scale = f"{oe.sigma:.3g} rad/s, their standard deviation"
        else:
            rms = float(np.sqrt(np.mean(oe.residuals**2)))
            measured = (f"the residuals' robust scale (1.4826 MAD) is {ratio:.3g}× the gyro "
                        f"noise ({size:.3g} rad/s against {noise_rms:.3g} rad/s RMS; their RMS "
                        f"is {rms:.3g} rad/s)")  # fmt: skip
            scale = f"{oe.sigma:.3g} rad/s, the {loss} loss's M-estimator scale"
        flags.append(
            f"{measured}: the {model} model does not explain the motion"
            + ("" if has_rotor else " (a spinning rotor that was not given?)")
            + "; check the window (was the body free?), the units and the sensor frame. The "
            f"standard errors above are calibrated to the residuals ({scale}; not the gyro's "
            "noise): they count the misfit as noise, and hold if it is random; a systematic "
            "misfit biases the numbers beyond them"
        )
    if not oe.success:
        flags.append(f"the fit did not converge: {oe.message}")
    if (
        core_inertia.check_inertia(np.diag(moments), 1e-3)[0] == 4
    ):  # the triangle, as a fit resolves it
        flags.append(
            f"the moments break the triangle inequality I1 + I2 ≥ I3 (I1 + I2 = "
            f"{moments[0] + moments[1]:.4g}, I3 = {moments[2]:.4g}): no body has them"
        )
    return flags


def _result(oe, ts, ws, flight, has_rotor: bool, J, loss: str) -> IdentifyResult:
    """The :class:`IdentifyResult` of the output-error fit ``oe`` over the window ``ts``."""
    m, E = oe.moments, oe.axes
    absolute = oe.absolute
    scale = 1.0 if absolute else float(np.sum(m))
    moments = m / scale
    inertia = E @ np.diag(moments) @ E.T
    inertia = 0.5 * (inertia + inertia.T)
    ratios = m[:2] / m[2]
    dr = oe.ratios_stderr
    dm, dtrace = _moments_stderr(oe, moments, ratios, absolute)
    rotor_inertia = None
    dJ = None
    if has_rotor:
        if absolute:
            rotor_inertia, dJ = float(J), 0.0
        else:
            rotor_inertia = float(oe.rotor_inertia) * float(m[2]) / scale
            dJ = oe.stderr("kappa") * float(m[2]) / scale
    noise, rms, spread, noise_rms, ratio = _misfit(oe, ws, loss != "linear")
    flags = _flags(oe, ratio, noise_rms, has_rotor, moments, loss)
    bias_k = [oe.names.index(x) for x in ("bias.x", "bias.y", "bias.z")]
    return IdentifyResult(
        inertia=inertia,
        absolute=absolute,
        principal_moments=moments,
        ratios=ratios,
        axes=E,
        ratios_stderr=dr,
        axes_stderr_deg=oe.axes_stderr_deg,
        window=(float(ts[0]), float(ts[-1])),
        t=ts.copy(),
        omega_measured=ws.copy(),
        omega_fit=oe.omega_fit,
        residuals=ws - oe.omega_fit,
        residual_rms=rms,
        noise_std=noise,
        residual_ratio=ratio,
        condition=oe.condition,
        model="gyrostat" if has_rotor else "torque-free",
        rotor_inertia=rotor_inertia,
        rotor_inertia_stderr=dJ,
        principal_moments_stderr=dm,
        trace_stderr=dtrace,
        axes_covariance=oe.axes_covariance,
        omega0=oe.omega0,
        gyro_bias=oe.bias,
        gyro_bias_stderr=np.sqrt(np.clip(np.diag(oe.covariance)[bias_k], 0.0, None)),
        lever_arm=flight.lever_arm,
        accel_bias=flight.accel_bias,
        found_by=flight.found_by,
        flags=tuple(flags),
        nfev=oe.nfev,
        loss=loss,
        residual_scale=spread,
    )


def _refuse_unidentifiable(res: IdentifyResult, where: str, cone: float, rotation: float):
    bad, parts = [], []
    for k, name in enumerate(("I1/I3", "I2/I3")):
        s = res.ratios_stderr[k]
        if not s <= MAX_RATIO_STDERR:
            bad.append(name)
            parts.append(f"{name} (standard error {s:.3g}, above {MAX_RATIO_STDERR:g})")
    for k in range(3):
        s = res.axes_stderr_deg[k]
        if not s <= MAX_AXIS_STDERR_DEG:
            bad.append(f"e{k + 1}")
            parts.append(f"axis e{k + 1} (standard error {s:.3g}°, above "
                         f"{MAX_AXIS_STDERR_DEG:g}°)")  # fmt: skip
    if not bad:
        return
    why = []
    if cone < 10.0:
        why.append(
            f"ω stayed within {cone:.3g}° of one direction: a spin about one principal axis "
            "excites nothing else; throw it tumbling (spinning about a direction between the "
            "axes)"
        )
    else:
        why.append(
            f"the body turned {rotation:.3g} rad; a longer free flight, more spin or a tumble "
            "further from the principal axes would determine them"
        )
    r = res.ratios
    if "e1" in bad and "e2" in bad and abs(r[1] - r[0]) < 3 * (res.ratios_stderr.sum() + 1e-3):
        why.append("I1 and I2 are nearly equal, so e1 and e2 may turn freely in their plane")
    if "e2" in bad and "e3" in bad and abs(1 - r[1]) < 3 * (res.ratios_stderr[1] + 1e-3):
        why.append("I2 and I3 are nearly equal, so e2 and e3 may turn freely in their plane")
    if ("I1/I3" in bad and "e2" in bad and "e3" in bad) or ("I2/I3" in bad and "e1" in bad
                                                            and "e2" in bad):  # fmt: skip
        why.append(
            "a gyro bias along the symmetry axis of a (nearly) symmetric body cannot be told "
            "from the spin about that axis, which leaves the ratio of that axis's moment "
            "undetermined too"
        )
    raise NotIdentifiableError(
        f"`omega`: {where} does not identify {', '.join(parts)}: "
        + "; ".join(why)
        + ". (The fit is in the exception's `result`.)",
        bad,
        res,
    )
