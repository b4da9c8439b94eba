"""The output-error fit: the gyrostat integrated with the measured rotor speed and fitted to
the raw gyro readings by nonlinear least squares (``docs/theory.md`` §4).

The model of the readings is ``ω_meas(t) = ω(t; ω0, I, J) + b + noise``: ``ω(t)`` the motion of
the gyrostat ``I ω̇ + ω × (I ω + h) + ḣ = 0``, ``h = J ω_R(t) a``, from ``ω0`` at the start of
each segment of the window, computed by the compiled core (``poinsot._core.gyrostat_omegas``:
RK4 on the momentum form over the sampled rotor speed; its Jacobian the exact derivatives of
that motion, ``poinsot._core.gyrostat_sensitivities``: the variational equations integrated
with it), and ``b`` the gyro's bias. SciPy's
:func:`scipy.optimize.least_squares` (MINPACK's Levenberg–Marquardt, on the logarithms of the
ratios so that they stay positive) minimises the residuals ``ω_meas − ω − b``, from the
equation-error estimate. A robust loss (SciPy's ``soft_l1``, ``huber``, ``cauchy``,
``arctan``) is minimised by iteratively reweighted least squares: each pass a weighted fit
with the weights ``ρ'(r²/f²)`` of the last pass's residuals, whose fixed point is the robust
minimum.

Parameters. The inertia is ``I = E diag(m) Eᵀ`` with ``m = I3 (ρ1, ρ2, 1)`` and
``E = E0 exp(hat δ)``: the moment ratios ``ρ`` and a small rotation ``δ`` of the principal
frame about its own axes. Without a rotor the motion does not depend on the scale of ``I``
(``I3 = 1``); with a rotor of known ``J`` the scale is fitted (``I3 = I3⁰ e^η``); with a rotor
of unknown ``J`` only ``κ = J/I3`` can be (``I3 = 1``, ``J = κ``).

Uncertainty. At the optimum the fit is re-expanded about itself (``E0`` the fitted axes sorted
by ascending moment, ``δ = 0``) and the covariance of the parameters is ``σ² (JᵀJ)⁻¹``, ``J`` the
Jacobian. With least squares ``σ² = s² = Σ r²/(N − p)``, the residual variance (``N`` readings,
``p`` parameters: the Gauss–Newton approximation). A robust loss makes the fit an M-estimator,
whose covariance is the sandwich ``H⁻¹ B H⁻¹`` with ``H = Jᵀ diag(ψ') J`` and
``B = Jᵀ diag(ψ²) J``: ``ψ(r) = ρ'(r²/f²) r`` the loss's influence function (the fit solves
``Σ ψ(r) ∇r = 0``), ``ψ' = ρ' + 2 (r²/f²) ρ''`` its slope, and ``f`` the residual scale the fit
was made with (``f_scale``, by default the readings' noise). For independent, identically
distributed noise, which least squares assumes too, ``H`` and ``B`` are ``mean ψ' · JᵀJ`` and
``mean ψ² · JᵀJ``, and the sandwich is ``σ² (JᵀJ)⁻¹`` with

    σ² = K² [Σ ψ²/(N − p)] / [Σ ψ'/N]²,   K = 1 + (p/N) var ψ' / (mean ψ')²,

Huber's estimate (*Robust Statistics*, 1981, §7.6), ``K`` his correction for a finite ``N``.
With least squares (``ψ = r``, ``ψ' = 1``, ``K = 1``) it is ``s²`` exactly. It is preferred
to the matrix forms (``H⁻¹ B H⁻¹`` as it stands, or with ``B`` replaced by
``mean ψ² · JᵀJ``) because ``Jᵀ diag(ψ') J`` need not be positive definite for a redescending
loss (``cauchy``, ``arctan``: ``ψ' < 0`` beyond the scale), and it keeps the least-squares
machinery (the free turn of a symmetric body held fixed, infinite variances along
unidentified directions); over synthetic throws the three are calibrated alike. (The
reweighting's ``s² (Jᵀ W J)⁻¹``, ``W = diag(ρ')``, is not an M-estimator's covariance: over
throws with Gaussian noise its standard errors were 1.3–2.4 times too small.) The ratios'
standard errors are those of ``ρ``; axis ``e_k`` turns by the components of ``δ`` about the two
other axes, so its angular standard error is ``√(var δ_i + var δ_j)``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from .._bindings import identify as core_identify
from .._bindings import inertia as core_inertia
from .._validation import as_scalar
from ..rotation import matrix_from_rotvec

__all__ = ["LOSSES", "OutputErrorFit", "output_error"]

#: Loss functions offered for the fit (those of :func:`scipy.optimize.least_squares`).
LOSSES = ("linear", "soft_l1", "huber", "cauchy", "arctan")
#: Passes of the reweighting for a robust loss, and the change of weights that ends them.
IRLS_PASSES = 12
IRLS_TOLERANCE = 1e-3
#: The fitted ratios are kept within exp(±LOG_RATIO_LIMIT).
LOG_RATIO_LIMIT = 7.0
#: The most the body turns in one RK4 step of the model [rad]: the local error is about
#: (ω h)⁵/120 of |ω|, 3e-11 here.
MAX_TURN_PER_STEP = 0.02
#: At most this many RK4 steps per sample interval (a log sampled too slowly for its spin,
#: or read in the wrong units, would otherwise cost without bound).
MAX_SUBSTEPS = 16


@dataclass(frozen=True)
class OutputErrorFit:
    """The output-error fit (see the module's docstring for the parameters).

    Attributes
    ----------
    moments : ndarray (3,)
        Principal moments, ascending; kg m² when ``absolute``, else with ``I3 = 1``.
    axes : ndarray (3, 3)
        Principal axes (columns e1, e2, e3), sensor frame, right-handed.
    absolute : bool
    rotor_inertia : float or None
        ``J`` on the scale of ``moments`` (None without a rotor).
    omega0 : ndarray (K, 3)
        ω at the start of each segment [rad/s].
    bias : ndarray (3,)
        Gyro bias [rad/s].
    omega_fit : ndarray (n, 3)
        The fitted readings ``ω(t) + b``.
    residuals : ndarray (n, 3)
        Measured minus fitted [rad/s].
    names : tuple of str
        The parameters, in the order of ``covariance``.
    covariance : ndarray (p, p)
        At the optimum, expanded about itself (``δ = 0``, ``η = 0``).
    sigma : float
        The residual scale ``σ`` [rad/s] the covariance is calibrated to
        (``covariance = σ² (JᵀJ)⁻¹``): the residual standard deviation ``s`` for least squares,
        Huber's M-estimator scale ``K √(Σ ψ²/(N − p)) / mean ψ'`` for a robust loss (the
        module's docstring); infinite when the loss leaves the fit no information.
    condition : float
        Condition number of the column-scaled Jacobian at the optimum (unweighted: the matrix
        whose inverse the covariance is).
    cost : float
        ``½ Σ r²`` of the residuals at the optimum [rad²/s²].
    nfev : int
        Evaluations of the model (members integrated).
    success : bool
    message : str
    """

    moments: np.ndarray
    axes: np.ndarray
    absolute: bool
    rotor_inertia: float | None
    omega0: np.ndarray
    bias: np.ndarray
    omega_fit: np.ndarray
    residuals: np.ndarray
    names: tuple
    covariance: np.ndarray
    sigma: float
    condition: float
    cost: float
    nfev: int
    success: bool
    message: str
    segments: tuple = field(default=())

    def stderr(self, name: str) -> float:
        """The standard error of one parameter."""
        k = self.names.index(name)
        return float(np.sqrt(max(self.covariance[k, k], 0.0)))

    @property
    def ratios_stderr(self) -> np.ndarray:
        return np.array([self.stderr("rho1"), self.stderr("rho2")])

    @property
    def axes_covariance(self) -> np.ndarray:
        """Covariance (3, 3) [rad²] of the small rotation δ of the principal frame about its
        own axes e1, e2, e3."""
        k = self.names.index("delta1")
        return self.covariance[k : k + 3, k : k + 3].copy()

    @property
    def axes_stderr_deg(self) -> np.ndarray:
        c = np.diag(self.axes_covariance).clip(min=0.0)
        return np.degrees(np.sqrt(np.array([c[1] + c[2], c[0] + c[2], c[0] + c[1]])))


class _Model:
    """The residuals and their Jacobian for one window split into segments."""

    def __init__(self, t, omega, segments, rotor, rotor_inertia, E0, I3_0, max_step):
        self.t = t
        self.omega = omega
        self.segments = segments
        self.K = len(segments)
        self.rotor = rotor  # None or (rotor_t, rotor_speed, axis)
        self.J = rotor_inertia  # given J, or None
        self.E0 = E0
        self.I3_0 = I3_0
        # each segment's run, built once: every member and every call of the fit shares it
        self.runs = [gyrostat_run(t[seg], max_step) for seg in segments]
        self.extra = "eta" if (rotor is not None and rotor_inertia is not None) else (
            "kappa" if rotor is not None else None)  # fmt: skip
        names = [f"omega0[{k}].{c}" for k in range(self.K) for c in "xyz"]
        names += ["rho1", "rho2", "delta1", "delta2", "delta3"]
        if self.extra:
            names.append(self.extra)
        names += ["bias.x", "bias.y", "bias.z"]
        self.names = tuple(names)
        self.p = len(names)
        self.shared = list(range(3 * self.K, self.p - 3))  # ρ, δ, η/κ
        self.nfev = 0

    # ------------------------------------------------------------------ parameters
    def unpack(self, x):
        K = self.K
        w0 = x[: 3 * K].reshape(K, 3)
        rho = x[3 * K : 3 * K + 2]
        delta = x[3 * K + 2 : 3 * K + 5]
        extra = x[3 * K + 5] if self.extra else None
        bias = x[-3:]
        return w0, rho, delta, extra, bias

    def physical(self, rho, delta, extra):
        """(moments (3,), axes (3, 3), J) of the parameters."""
        I3 = self.I3_0 * np.exp(extra) if self.extra == "eta" else 1.0
        moments = I3 * np.array([rho[0], rho[1], 1.0])
        axes = self.E0 @ matrix_from_rotvec(delta)
        if self.rotor is None:
            J = 0.0
        elif self.extra == "eta":
            J = float(self.J)
        else:
            J = float(extra)
        return moments, axes, J

    # ------------------------------------------------------------------ the model
    def _simulate(self, k, members):
        """ω (m, n_seg, 3) of the members ``[(moments, axes, J, ω0)]`` over segment ``k``."""
        m = len(members)
        moments = np.array([a for a, _, _, _ in members])
        axes = np.array([b for _, b, _, _ in members])
        J = np.array([c for _, _, c, _ in members])
        w0 = np.array([d for _, _, _, d in members])
        if self.rotor is None:
            rt, rs, ax = np.zeros(0), np.zeros(0), np.array([1.0, 0.0, 0.0])
        else:
            rt, rs, ax = self.rotor
        out = core_identify.gyrostat_omegas(moments, axes, J, w0, self.runs[k], rt, rs, ax)
        self.nfev += m
        return out

    def prediction(self, x):
        """The fitted readings ``ω(t) + b`` (n, 3)."""
        w0, rho, delta, extra, bias = self.unpack(x)
        moments, axes, J = self.physical(rho, delta, extra)
        out = np.empty_like(self.omega)
        for k, seg in enumerate(self.segments):
            out[seg] = self._simulate(k, [(moments, axes, J, w0[k])])[0] + bias
        return out

    def residuals(self, x):
        r = (self.omega - self.prediction(x)).ravel()
        return np.where(np.isfinite(r), r, 1e6)

    def _seeds(self, x, k):
        """The directions of segment ``k``'s derivatives (the shared parameters, then its ω0):
        the seeds of the moments ``m = I3 (ρ1, ρ2, 1)``, of ``δ``, of ``J`` and of ``ω0``
        along each column of ``x`` it depends on (the chain rule of the parametrisation)."""
        _, rho, delta, extra, _ = self.unpack(x)
        moments = self.physical(rho, delta, extra)[0]
        cols = [*self.shared, 3 * k, 3 * k + 1, 3 * k + 2]
        I3 = moments[2]
        p = len(cols)
        dm, dd, dj, dw = np.zeros((p, 3)), np.zeros((p, 3)), np.zeros(p), np.zeros((p, 3))
        for i, j in enumerate(cols):
            name = self.names[j]
            if name in ("rho1", "rho2"):
                dm[i, int(name[-1]) - 1] = I3
            elif name.startswith("delta"):
                dd[i, int(name[-1]) - 1] = 1.0
            elif name == "eta":  # m = I3⁰ e^η (ρ1, ρ2, 1)
                dm[i] = moments
            elif name == "kappa":  # J = κ
                dj[i] = 1.0
            else:  # omega0[k].c
                dw[i, "xyz".index(name[-1])] = 1.0
        return cols, dm, dd, dj, dw

    def jacobian(self, x):
        """∂r/∂x (3n, p): the exact derivatives of the model's RK4 motion (forward
        sensitivities integrated with it in the compiled core, the segments as one ensemble on
        the core's threads: ``poinsot._core.gyrostat_sensitivities``), −1 entries for the
        bias."""
        n = len(self.t)
        Jm = np.zeros((n, 3, self.p))
        w0, rho, delta, extra, _ = self.unpack(x)
        moments, _, J = self.physical(rho, delta, extra)
        if self.rotor is None:
            rt, rs, ax = np.zeros(0), np.zeros(0), np.array([1.0, 0.0, 0.0])
        else:
            rt, rs, ax = self.rotor
        c = np.ascontiguousarray
        _, dm, dd, dj, dw = self._seeds(x, 0)  # the same seeds for every segment
        outs = core_identify.gyrostat_sensitivities(
            c(moments, dtype=float), dm, c(self.E0, dtype=float), c(delta, dtype=float), dd,
            float(J), dj, c(w0, dtype=float), dw, self.runs, rt, rs, ax,
        )  # fmt: skip
        for k, (seg, (_, d)) in enumerate(zip(self.segments, outs, strict=True)):
            Jm[seg][:, :, self._seeds(x, k)[0]] = d
        self.nfev += len(outs)
        for c_ in range(3):
            Jm[:, c_, self.p - 3 + c_] = 1.0
        Jr = -Jm.reshape(3 * n, self.p)
        return np.where(np.isfinite(Jr), Jr, 0.0)


def _segments(n: int, t, segment: float) -> list[slice]:
    span = t[-1] - t[0]
    K = max(1, int(np.ceil(span / segment - 1e-9)))
    edges = np.searchsorted(t, t[0] + span * np.arange(1, K) / K)
    bounds = [0, *edges.tolist(), n]
    return [slice(a, b) for a, b in itertools.pairwise(bounds) if b - a >= 2]


def _sorted_frame(moments, axes):
    """Moments ascending and the matching right-handed axes (the core's sign rule)."""
    I = axes @ np.diag(moments) @ axes.T
    m, E = core_inertia.principal_decomposition(0.5 * (I + I.T))
    return np.asarray(m), np.asarray(E)


def _start_frame(initial_inertia):
    """The starting principal moments (each at least 1e-3 of the largest), axes and ``I3`` of
    ``initial_inertia``; refused when they give no finite start."""
    I0 = 0.5 * (np.asarray(initial_inertia, float) + np.asarray(initial_inertia, float).T)
    m0, E0 = core_inertia.principal_decomposition(I0)
    m0 = np.abs(np.asarray(m0, float))
    m0 = np.maximum(m0, 1e-3 * m0.max())
    E0 = np.asarray(E0, float)
    I3_0 = float(m0[2])
    if not (I3_0 > 0 and np.isfinite(m0).all()):
        _no_start(I3_0)
    return m0, E0, I3_0


def gyrostat_run(t, max_step: float):
    """The run of a gyrostat's motion onto the sample times ``t`` (increasing), as the core
    takes it (:func:`~poinsot.integrate.driver.run_spec`): RK4 with steps of at most
    ``max_step`` (≤ 0: one step per sample interval, the longest), within a step budget that
    covers the samples' own step ends. Built once per stretch of a log and shared by every
    member and every call of a fit (:func:`output_error`,
    :func:`~poinsot.identify.synthetic_throw`)."""
    from ..integrate.driver import run_spec

    t = np.ascontiguousarray(t, dtype=float)
    longest = float(np.max(np.diff(t))) if len(t) > 1 else 0.0
    dt = max_step if max_step > 0 else max(longest, np.finfo(float).tiny)
    budget = math.ceil((t[-1] - t[0]) / dt) + 2 * len(t) + 16
    return run_spec("rk4", t_end=t[-1], dt=dt, t_eval=t, max_steps=budget)


def _default_max_step(t, omega) -> float:
    """The longest RK4 step when none is given (see :func:`output_error`'s ``max_step``)."""
    n = len(t)
    top = float(np.max(np.linalg.norm(omega, axis=1))) if n else 0.0
    interval = float(np.max(np.diff(t))) if n > 1 else 0.0
    max_step = MAX_TURN_PER_STEP / top if top > 0 else 0.0
    max_step = max(max_step, interval / MAX_SUBSTEPS)  # a bounded cost
    if max_step >= interval:
        max_step = 0.0  # one step per sample
    return max_step


def _start_omegas(t, omega, omega0, segments):
    """ω at the start of each segment: ``omega0`` broadcast, or the (smoothed) readings."""
    if omega0 is None:
        from .signals import smooth

        ws = smooth(t, omega) if len(t) >= 7 else omega
        return np.array([ws[s.start] for s in segments])
    return np.broadcast_to(np.asarray(omega0, float), (len(segments), 3)).copy()


def _parameter_vector(extra, w0, moments, J, bias):
    """The model's parameters ``x`` about the principal frame of ``moments`` (``δ = 0``,
    ``η = 0``): ω0, the ratios to ``I3``, ``κ = J/I3`` when fitted, and the bias."""
    I3 = float(moments[2])
    x = [*np.ravel(w0), moments[0] / I3, moments[1] / I3, 0.0, 0.0, 0.0]
    if extra == "eta":
        x.append(0.0)
    elif extra == "kappa":
        x.append(float(J) / I3)
    return np.array([*x, *bias], dtype=float)


def _residual_scale(omega, f_scale) -> float:
    """The residual size [rad/s] where a robust loss begins to down-weight: ``f_scale``, by
    default the readings' noise, 1 when that is not a positive number."""
    from .signals import white_noise_std

    noise = white_noise_std(omega)
    scale = float(np.nanmedian(noise)) if f_scale is None else float(f_scale)
    if not np.isfinite(scale) or scale <= 0:
        scale = 1.0
    return scale


def _from_log(y, lr):
    """The parameters of the optimiser's variables ``y``: the ratios (slice ``lr``) back from
    their logarithms, clipped to :data:`LOG_RATIO_LIMIT`."""
    x = y.copy()
    x[lr] = np.exp(np.clip(y[lr], -LOG_RATIO_LIMIT, LOG_RATIO_LIMIT))
    return x


def _minimise(model, x0, lr, loss, scale, max_nfev):
    """SciPy's result of the fit from ``x0`` (the ratios ``lr`` as logarithms), its ``x``
    turned back into the model's parameters; a robust loss by reweighting."""
    from scipy.optimize import least_squares

    def jac(y):
        x = _from_log(y, lr)
        Jy = model.jacobian(x)
        inside = np.abs(y[lr]) < LOG_RATIO_LIMIT  # flat where clipped
        Jy[:, lr] *= np.where(inside, x[lr], 0.0)
        return Jy

    # a robust loss by iteratively reweighted least squares: each pass is a weighted
    # least-squares fit (Levenberg–Marquardt) with the weights ρ'(r²/f²) of the last pass's
    # residuals; its fixed point is the minimum of Σ ρ(r²/f²) (the same stationarity
    # condition Σ ρ' r ∇r = 0 as least_squares with that loss)
    weight = np.ones(3 * len(model.t))
    for _ in range(IRLS_PASSES if loss != "linear" else 1):
        root = np.sqrt(weight)
        sol = least_squares(
            lambda y, root=root: root * model.residuals(_from_log(y, lr)),
            x0,
            jac=lambda y, root=root: root[:, None] * jac(y),
            x_scale="jac",
            max_nfev=max_nfev,
            method="lm",
        )
        if loss == "linear":
            break
        new = _loss_weight(loss, (model.residuals(_from_log(sol.x, lr)) / scale) ** 2)
        x0 = sol.x
        if np.max(np.abs(new - weight)) < IRLS_TOLERANCE:
            break
        weight = new
    sol.x = _from_log(sol.x, lr)
    return sol


def _uncertainty(model, x, loss, scale, moments):
    """``(covariance, condition, σ²)`` of the fit at ``x``: ``σ² (JᵀJ)⁻¹`` with the
    M-estimator's variance ``σ²`` of the loss (:func:`_m_estimator_variance`; ``s²`` for least
    squares), with a symmetric body's free turn held fixed."""
    r = model.residuals(x)
    Jac = model.jacobian(x)
    psi, dpsi = _influence(loss, r, scale)
    s2 = _m_estimator_variance(psi, dpsi, model.p)
    cov, cond = _gauss_newton_covariance(Jac, s2)
    cov = _profile_symmetric_pairs(Jac, s2, cov, moments, model.names)
    return cov, cond, s2


def _m_estimator_variance(psi, dpsi, p: int) -> float:
    """Huber's variance ``σ² = K² [Σ ψ²/(N − p)] / [Σ ψ'/N]²`` of an M-estimator with ``p``
    parameters, from the influence ``psi`` [rad/s] and its slope ``dpsi`` at the ``N``
    residuals, ``K = 1 + (p/N) var ψ' / (mean ψ')²``: the covariance is ``σ² (JᵀJ)⁻¹`` (the
    module's docstring). Least squares (``ψ = r``, ``ψ' = 1``) gives ``s² = Σ r²/(N − p)``
    exactly. Infinite when ``mean ψ' ≤ 0`` (a redescending loss with most residuals beyond its
    scale: the fit has no information left)."""
    n = len(psi)
    dof = max(n - p, 1)
    mean = float(np.mean(dpsi)) if n else 0.0
    if not mean > 0:
        return np.inf
    K = 1.0 + (p / n) * float(np.var(dpsi)) / mean**2
    return K**2 * (float(psi @ psi) / dof) / mean**2


def output_error(
    t,
    omega,
    initial_inertia,
    *,
    omega0=None,
    rotor_speed=None,
    rotor_axis=None,
    rotor_inertia=None,
    initial_rotor_inertia=None,
    segment: float = 1.0,
    loss: str = "linear",
    f_scale: float | None = None,
    max_nfev: int = 100,
    max_step: float | None = None,
) -> OutputErrorFit:
    """Fit the gyrostat's motion to gyro readings by nonlinear least squares.

    Parameters
    ----------
    t : ndarray (n,)
        Increasing times of one free flight [s].
    omega : ndarray (n, 3)
        Gyro readings [rad/s], sensor frame.
    initial_inertia : ndarray (3, 3)
        Starting inertia (any scale; e.g. the equation-error estimate). With a known
        ``rotor_inertia`` it should be in kg m².
    omega0 : ndarray (K, 3) or (3,), optional
        Starting ω at the start of each segment (default: the readings there).
    rotor_speed : ndarray (n,), optional
        The rotor's speed [rad/s] at the times ``t`` (linear between them).
    rotor_axis : ndarray (3,), optional
        Its unit axis, sensor frame.
    rotor_inertia : float, optional
        ``J`` [kg m²]: the inertia comes out in kg m². Without it, ``J/I3`` is fitted.
    initial_rotor_inertia : float, optional
        Starting ``J`` on the scale of ``initial_inertia`` when ``J`` is fitted.
    segment : float
        Longest stretch [s] integrated from one ``ω0``: a longer window is split, each piece
        with its own ``ω0`` (sensitivity to ω0 grows along a tumble).
    loss : str
        One of :data:`LOSSES` (robust losses down-weight outliers; ``f_scale`` sets the
        residual size [rad/s] where they begin to, by default the readings' noise). With a
        robust loss the covariance is the M-estimator's, with the same scale (the module's
        docstring).
    f_scale : float, optional
        That residual size [rad/s] (default: the readings' noise, 1 when it is not a positive
        number).
    max_nfev : int
        Bound on the optimiser's iterations.
    max_step : float, optional
        Longest RK4 step [s]; default: the sample interval, shortened so that the body turns
        at most :data:`MAX_TURN_PER_STEP` per step (RK4's error then stays far below any
        gyro's noise), into at most :data:`MAX_SUBSTEPS` steps; ≤ 0: one step per sample
        interval.

    Returns
    -------
    OutputErrorFit
    """
    if loss not in LOSSES:
        raise ValueError(f"`loss` must be one of {LOSSES}, found {loss!r}")
    t = np.asarray(t, dtype=float)
    omega = np.asarray(omega, dtype=float)
    n = len(t)
    segments = _segments(n, t, segment)
    rotor = None
    if rotor_speed is not None:
        rotor = (t.copy(), np.asarray(rotor_speed, float), np.asarray(rotor_axis, float))
    m0, E0, I3_0 = _start_frame(initial_inertia)
    max_step = _default_max_step(t, omega) if max_step is None else as_scalar(max_step, "max_step")
    model = _Model(t, omega, segments, rotor, rotor_inertia, E0, I3_0, max_step)
    K = len(segments)
    w0 = _start_omegas(t, omega, omega0, segments)
    J0 = initial_rotor_inertia if initial_rotor_inertia is not None else 0.0
    x0 = _parameter_vector(model.extra, w0, m0, J0, (0.0, 0.0, 0.0))
    if not np.isfinite(x0).all():
        _no_start(I3_0)
    # the ratios are fitted as their logarithms (positive without bounds, which lets MINPACK's
    # Levenberg–Marquardt run: it needs no LAPACK call, whose threads cost more than the
    # solve on a busy machine)
    lr = slice(3 * K, 3 * K + 2)
    x0[lr] = np.log(np.clip(x0[lr], 1e-3, 1e3))
    scale = _residual_scale(omega, f_scale)
    sol = _minimise(model, x0, lr, loss, scale, max_nfev)
    # re-expand about the optimum: axes sorted by ascending moment, δ = 0, η = 0
    w0, rho, delta, extra, bias = model.unpack(sol.x)
    moments, axes, J = model.physical(rho, delta, extra)
    moments, axes = _sorted_frame(moments, axes)
    final = _Model(t, omega, segments, rotor, rotor_inertia, axes, float(moments[2]), max_step)
    x = _parameter_vector(final.extra, w0, moments, J, bias)
    cov, cond, s2 = _uncertainty(final, x, loss, scale, moments)
    pred = final.prediction(x)
    if final.extra == "eta":
        moments_out = moments
        J_out = float(rotor_inertia)
    else:
        moments_out = moments / moments[2]
        J_out = float(J) / float(moments[2]) if rotor is not None else None
    return OutputErrorFit(
        moments=moments_out,
        axes=axes,
        absolute=final.extra == "eta",
        rotor_inertia=J_out,
        omega0=w0.copy(),
        bias=bias.copy(),
        omega_fit=pred,
        residuals=omega - pred,
        names=final.names,
        covariance=cov,
        sigma=float(np.sqrt(s2)),
        condition=cond,
        cost=0.5 * float(np.sum((omega - pred) ** 2)),
        nfev=int(model.nfev + final.nfev),
        success=bool(sol.success),
        message=str(sol.message),
        segments=tuple((s.start, s.stop) for s in segments),
    )


def _gauss_newton_covariance(J, s2: float):
    """``s² (JᵀJ)⁻¹`` and the condition number of the column-scaled ``J``, from the small
    normal matrix (p × p) rather than an SVD of the tall ``J``: the columns are scaled to unit
    norm first, so that squaring the condition number costs no accuracy at the sizes met
    here. An unidentifiable direction (a zero eigenvalue) gives infinite variances, and so does
    an infinite ``s2`` (every one)."""
    if not np.isfinite(s2):
        return np.full((J.shape[1], J.shape[1]), np.inf), np.inf
    col = np.linalg.norm(J, axis=0)
    col[col == 0] = 1.0
    Js = J / col
    lam, V = np.linalg.eigh(Js.T @ Js)
    lam = np.clip(lam, 0.0, None)
    top = lam[-1] if lam[-1] > 0 else 1.0
    ok = lam > top * 1e-15
    cond = float(np.sqrt(top / lam[0])) if lam[0] > 0 else np.inf
    cov_s = (V[:, ok] / lam[ok]) @ V[:, ok].T
    if not ok.all():  # no information along a direction: its parameters are unbounded
        touched = np.any(np.abs(V[:, ~ok]) > 1e-8, axis=1)
        cov_s[np.ix_(touched, touched)] = np.inf
    return s2 * cov_s / np.outer(col, col), cond


#: A rotation of the principal frame less determined than this [rad] about an axis whose two
#: companions have moments closer than :data:`SYMMETRIC_GAP` (relative to I3) is the free
#: turn of a (nearly) symmetric body.
FREE_TURN = 0.1
SYMMETRIC_GAP = 0.05


def _profile_symmetric_pairs(J, s2, cov, moments, names):
    """The covariance with the free turn of a (nearly) symmetric body held fixed.

    When two moments are (nearly) equal the body's motion does not change when its principal
    frame turns about the third axis (δ_k turns e_i and e_j in their plane): that direction
    is not identifiable, and inverting the normal matrix lets its huge variance leak into
    every parameter it is numerically mixed with (the ratios among them). Here such a δ_k
    gets an infinite variance and the other parameters the covariance of the fit with δ_k
    fixed, which is exact for an exactly symmetric body.
    """
    k0 = names.index("delta1")
    free = []
    for k in range(3):
        i, j = [x for x in range(3) if x != k]
        gap = abs(moments[j] - moments[i]) / moments[2]
        if not cov[k0 + k, k0 + k] <= FREE_TURN**2 and gap < SYMMETRIC_GAP:
            free.append(k0 + k)
    if not free:
        return cov
    keep = [c for c in range(len(names)) if c not in free]
    sub, _ = _gauss_newton_covariance(J[:, keep], s2)
    out = np.full_like(cov, np.inf)
    out[np.ix_(keep, keep)] = sub
    for c in free:
        out[c, keep] = out[keep, c] = 0.0
    return out


def _loss_weight(loss: str, z):
    """``ρ'(z)`` of SciPy's losses: the reweighting of squared residuals ``z``."""
    if loss == "soft_l1":
        return 1.0 / np.sqrt(1.0 + z)
    if loss == "huber":
        return np.where(z <= 1.0, 1.0, 1.0 / np.sqrt(np.maximum(z, 1.0)))
    if loss == "cauchy":
        return 1.0 / (1.0 + z)
    if loss == "arctan":
        return 1.0 / (1.0 + z**2)
    return np.ones_like(z)


def _loss_slope(loss: str, z):
    """``ρ'(z) + 2 z ρ''(z)`` of SciPy's losses, the slope ``dψ/dr`` of the influence
    ``ψ(r) = ρ'(r²/f²) r`` at ``z = r²/f²``: 1 for least squares and within a Huber loss's
    scale, 0 beyond it, ``(1 + z)^(−3/2)`` (soft_l1), ``(1 − z)/(1 + z)²`` (cauchy),
    ``(1 − 3 z²)/(1 + z²)²`` (arctan)."""
    if loss == "soft_l1":
        return (1.0 + z) ** -1.5
    if loss == "huber":
        return np.where(z <= 1.0, 1.0, 0.0)
    if loss == "cauchy":
        return (1.0 - z) / (1.0 + z) ** 2
    if loss == "arctan":
        return (1.0 - 3.0 * z**2) / (1.0 + z**2) ** 2
    return np.ones_like(z)


def _influence(loss: str, r, scale: float):
    """``(ψ, ψ')`` of the residuals ``r`` [rad/s] under ``loss`` with the residual scale
    ``scale`` [rad/s]: the influence ``ψ(r) = ρ'(r²/f²) r`` [rad/s] (the gradient of the fit's
    objective ``½ f² Σ ρ(r²/f²)`` is ``Σ ψ ∇r``) and its slope ``dψ/dr``. ``(r, 1)`` for least
    squares."""
    z = (r / scale) ** 2
    return _loss_weight(loss, z) * r, _loss_slope(loss, z)


def _no_start(I3_0):
    """The readings leave the output-error fit no starting point: refused, named."""
    from .result import NotIdentifiableError

    raise NotIdentifiableError(
        "`omega`: the readings give the output-error fit no finite starting point (a starting "
        f"inertia with I3 = {I3_0:.3g}): the inertia is not identifiable from them",
        ("I1/I3", "I2/I3", "e1", "e2", "e3"),
    )
