"""What an identification returns: :class:`IdentifyResult` (one throw) and the refusal
:class:`NotIdentifiableError`."""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

__all__ = ["IdentifyResult", "ModelMismatchWarning", "NotIdentifiableError"]


class ModelMismatchWarning(UserWarning):
    """The fitted model does not explain the readings (its residuals exceed the gyro noise)."""


class NotIdentifiableError(ValueError):
    """The motion does not determine some ratio or axis.

    Attributes
    ----------
    unidentifiable : tuple of str
        The quantities that are not identifiable: ``"I1/I3"``, ``"I2/I3"``, ``"e1"``, ``"e2"``,
        ``"e3"``.
    result : IdentifyResult or None
        The fit as it came out, for inspection (its numbers for the quantities named are not
        to be trusted).
    """

    def __init__(self, message: str, unidentifiable=(), result=None):
        super().__init__(message)
        self.unidentifiable = tuple(unidentifiable)
        self.result = result


def _floats(a):
    return np.asarray(a, dtype=float).tolist()


#: The standard deviation of Gaussian noise over its median absolute deviation, 1/Φ⁻¹(3/4).
_MAD_TO_STD = 1.482602218505602


def _robust_std(residuals) -> np.ndarray:
    """The residuals' robust scale per column, ``1.4826 · MAD`` (the median absolute deviation
    from the median) [their unit]: their standard deviation for Gaussian noise, a few outliers
    aside."""
    r = np.asarray(residuals, dtype=float)
    return _MAD_TO_STD * np.median(np.abs(r - np.median(r, axis=0)), axis=0)


def _total_noise(noise_std, omega) -> float:
    """The gyro's total noise ``√(mean σ_k²)`` [rad/s] from its per-axis ``noise_std``, at least
    1e-9 of the readings' RMS (noiseless readings would otherwise divide by zero)."""
    floor = 1e-9 * float(np.sqrt(np.mean(np.asarray(omega, dtype=float) ** 2)))
    return max(float(np.sqrt(np.mean(np.asarray(noise_std, dtype=float) ** 2))), floor)


@dataclass(frozen=True, eq=False)
class IdentifyResult:
    """The inertia of a body identified from a gyro log.

    Attributes
    ----------
    inertia : ndarray (3, 3)
        The inertia tensor about the centre of mass, sensor frame: kg m² when ``absolute``,
        otherwise up to scale, normalised to trace 1.
    absolute : bool
        Whether ``inertia`` is in physical units: only when the rotor's inertia ``J`` was
        given.
    principal_moments : ndarray (3,)
        Ascending, on the scale of ``inertia``.
    ratios : ndarray (2,)
        ``(I1/I3, I2/I3)``.
    axes : ndarray (3, 3)
        Principal axes, columns ``e1, e2, e3`` (of ``principal_moments``), sensor frame,
        right-handed; each column's sign is arbitrary (the core's sign rule).
    ratios_stderr : ndarray (2,)
        Standard errors of ``ratios``.
    axes_stderr_deg : ndarray (3,)
        Standard error [deg] of the direction of each axis: the root-mean-square angle by which
        the true axis may differ.
    window : (float, float)
        First and last sample times [s] of the free flight used.
    t, omega_measured, omega_fit, residuals : ndarray (n,), (n, 3), (n, 3), (n, 3)
        The window's times and readings, the fitted readings (model plus bias) and
        measured − fitted [rad/s].
    residual_rms : ndarray (3,)
        RMS residual per sensor axis [rad/s].
    noise_std : ndarray (3,)
        The gyro's white noise, estimated from the readings alone [rad/s].
    residual_ratio : float
        Total RMS residual over total noise; with a robust ``loss``, the residuals' total robust
        scale (``residual_scale``) over total noise instead, so that the outliers the loss is
        there to ignore do not count. About 1 when the model explains the readings.
    condition : float
        Condition number of the (column-scaled) fit's Jacobian: the identifiability of the
        whole set of unknowns (large: some combination is barely determined).
    model : str
        ``"torque-free"`` or ``"gyrostat"``.
    rotor_inertia, rotor_inertia_stderr : float or None
        ``J``: as given (``absolute``), or fitted on the scale of ``inertia``.
    principal_moments_stderr : ndarray (3,)
        Standard errors of ``principal_moments`` (those of the ratios times the scale, and
        the scale's own with a known ``J``).
    trace_stderr : float
        Standard error of ``trace(inertia)`` (0 when the trace is fixed to 1).
    axes_covariance : ndarray (3, 3)
        Covariance [rad²] of the small rotation of the principal frame about its own axes
        ``e1, e2, e3``.
    omega0 : ndarray (K, 3)
        Fitted ω at the start of each segment [rad/s], without the bias.
    gyro_bias, gyro_bias_stderr : ndarray (3,)
        [rad/s].
    lever_arm, accel_bias : ndarray (3,) or None
        The accelerometer's position from the centre of mass [m] and its bias [m/s²], when an
        accelerometer found the free flight.
    found_by : str
        How the window was chosen: ``"accelerometer"``, ``"window"`` or ``"gyroscope"``.
    flags : tuple of str
        What is wrong with the fit, in words; empty when nothing is (see :attr:`ok`).
    nfev : int
        Model evaluations (each one integration of the window).
    loss : str
        The fit's loss: ``"linear"`` (least squares) or a robust one. With a robust loss the
        standard errors are those of an M-estimator (``poinsot.identify.output_error``).
    residual_scale : ndarray (3,)
        The residuals' robust scale per sensor axis, ``1.4826 · MAD`` [rad/s]: their standard
        deviation for Gaussian noise, outliers aside.
    """

    inertia: np.ndarray
    absolute: bool
    principal_moments: np.ndarray
    ratios: np.ndarray
    axes: np.ndarray
    ratios_stderr: np.ndarray
    axes_stderr_deg: np.ndarray
    window: tuple
    t: np.ndarray
    omega_measured: np.ndarray
    omega_fit: np.ndarray
    residuals: np.ndarray
    residual_rms: np.ndarray
    noise_std: np.ndarray
    residual_ratio: float
    condition: float
    model: str
    rotor_inertia: float | None = None
    rotor_inertia_stderr: float | None = None
    principal_moments_stderr: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))
    trace_stderr: float = 0.0
    axes_covariance: np.ndarray = field(default_factory=lambda: np.full((3, 3), np.nan))
    omega0: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    gyro_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gyro_bias_stderr: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))
    lever_arm: np.ndarray | None = None
    accel_bias: np.ndarray | None = None
    found_by: str = "window"
    flags: tuple = ()
    nfev: int = 0
    loss: str = "linear"
    residual_scale: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))

    # ------------------------------------------------------------------ reading it
    @property
    def ok(self) -> bool:
        """True when nothing was flagged."""
        return not self.flags

    @property
    def trace(self) -> float:
        return float(np.trace(self.inertia))

    @property
    def box_shape(self) -> np.ndarray:
        """The shape of the uniform box with the fitted principal moments: its half extents
        (3,) along ``e1, e2, e3``, the largest 1 (dimensionless: a fit gives the moments'
        ratios; ``equivalent_box_half_extents`` of ``crates/core/src/shapes.rs``)."""
        from .._bindings import inertia as core_inertia

        moments = np.asarray(self.principal_moments, dtype=float)
        half = np.asarray(core_inertia.equivalent_box_half_extents(moments, 1.0))
        return half / half.max()

    def check(self) -> None:
        """Check the result against itself; raise ``ValueError`` naming the first broken rule.

        The tensor is ``axes · diag(principal_moments) · axesᵀ``, the moments ascend and are
        positive, the ratios are theirs, the axes are orthonormal and right-handed, the trace
        is 1 when not ``absolute``, the standard errors are non-negative (or infinite), the
        window lies within the samples and the residuals are measured − fitted.
        """
        I, m, E = self.inertia, self.principal_moments, self.axes
        scale = float(np.max(np.abs(m)))
        rules = [
            (np.shape(I) == (3, 3) and np.shape(E) == (3, 3) and np.shape(m) == (3,),
             "shapes: inertia (3, 3), axes (3, 3), principal_moments (3,)"),
            (np.all(np.isfinite(I)) and np.all(np.isfinite(E)) and np.all(np.isfinite(m)),
             "inertia, axes and principal_moments are finite"),
            (np.all(m > 0) and np.all(np.diff(m) >= 0), "principal_moments ascend and are > 0"),
            (np.allclose(E.T @ E, np.eye(3), atol=1e-9) and np.linalg.det(E) > 0,
             "axes are orthonormal and right-handed"),
            (np.allclose(E @ np.diag(m) @ E.T, I, atol=1e-9 * scale, rtol=0),
             "inertia = axes · diag(principal_moments) · axesᵀ"),
            (np.allclose(self.ratios, m[:2] / m[2], rtol=1e-12, atol=0),
             "ratios = (I1/I3, I2/I3)"),
            (self.absolute or abs(np.trace(I) - 1.0) < 1e-9, "trace 1 when not absolute"),
            (np.all(~(np.asarray(self.ratios_stderr) < 0))
             and np.all(~(np.asarray(self.axes_stderr_deg) < 0))
             and np.shape(self.ratios_stderr) == (2,) and np.shape(self.axes_stderr_deg) == (3,),
             "standard errors are (2,), (3,) and not negative"),
            (len(self.t) >= 2 and self.window[0] == self.t[0] and self.window[1] == self.t[-1],
             "window = (first, last) sample time"),
            (np.allclose(self.omega_measured - self.omega_fit, self.residuals, atol=1e-12,
                         rtol=1e-12), "residuals = measured − fitted"),
        ]  # fmt: skip
        for ok, rule in rules:
            if not bool(ok):
                raise ValueError(f"IdentifyResult breaks its rule: {rule}")

    # ------------------------------------------------------------------ exporting it
    def to_dict(self, *, series: bool = False) -> dict:
        """A JSON-ready dict: the quantities above (arrays as nested lists; ``axes`` row by
        row, its columns the axes), their units, and with ``series`` the time series too."""
        d = {
            "ratios": _floats(self.ratios),
            "ratios_stderr": _floats(self.ratios_stderr),
            "axes": _floats(self.axes),
            "axes_stderr_deg": _floats(self.axes_stderr_deg),
            "inertia": _floats(self.inertia),
            "absolute": bool(self.absolute),
            "principal_moments": _floats(self.principal_moments),
            "principal_moments_stderr": _floats(self.principal_moments_stderr),
            "trace_stderr": float(self.trace_stderr),
            "window": [float(self.window[0]), float(self.window[1])],
            "model": self.model,
            "rotor_inertia": None if self.rotor_inertia is None else float(self.rotor_inertia),
            "rotor_inertia_stderr": None
            if self.rotor_inertia_stderr is None
            else float(self.rotor_inertia_stderr),
            "gyro_bias": _floats(self.gyro_bias),
            "gyro_bias_stderr": _floats(self.gyro_bias_stderr),
            "lever_arm": None if self.lever_arm is None else _floats(self.lever_arm),
            "accel_bias": None if self.accel_bias is None else _floats(self.accel_bias),
            "found_by": self.found_by,
            "residual_rms": _floats(self.residual_rms),
            "residual_scale": _floats(self.residual_scale),
            "noise_std": _floats(self.noise_std),
            "residual_ratio": float(self.residual_ratio),
            "loss": self.loss,
            "condition": float(self.condition),
            "samples": len(self.t),
            "flags": list(self.flags),
            "ok": self.ok,
            "units": {
                "inertia": "kg m²" if self.absolute else "1 (up to scale: trace 1)",
                "principal_moments": "kg m²" if self.absolute else "1 (up to scale: trace 1)",
                "rotor_inertia": "kg m²" if self.absolute else "1 (on the scale of inertia)",
                "ratios": "1",
                "axes": "unit vectors (columns e1, e2, e3), sensor frame",
                "axes_stderr_deg": "deg",
                "window": "s",
                "gyro_bias": "rad/s",
                "lever_arm": "m",
                "accel_bias": "m/s²",
                "residual_rms": "rad/s",
                "residual_scale": "rad/s",
                "noise_std": "rad/s",
            },
        }
        if series:
            d["series"] = {
                "t": _floats(self.t),
                "omega_measured": _floats(self.omega_measured),
                "omega_fit": _floats(self.omega_fit),
            }
        return d

    def to_json(self, **kwargs) -> str:
        """:meth:`to_dict` as JSON text (keyword arguments go to :func:`json.dumps`)."""
        series = kwargs.pop("series", False)
        kwargs.setdefault("indent", 2)
        return json.dumps(self.to_dict(series=series), **kwargs)

    def summary(self) -> list[str]:
        """The result in words, one line each (what ``poinsot identify`` prints)."""
        unit = "kg m²" if self.absolute else "(up to scale, trace 1)"
        r, dr = self.ratios, self.ratios_stderr
        lines = [
            f"free flight   t = {self.window[0]:.4f} … {self.window[1]:.4f} s "
            f"({len(self.t)} samples, found by the {self.found_by})",
            f"model         {self.model}",
            f"ratios        I1/I3 = {r[0]:.5f} ± {dr[0]:.2g}   I2/I3 = {r[1]:.5f} ± {dr[1]:.2g}",
            "moments       " + ", ".join(f"{x:.6g}" for x in self.principal_moments) + f" {unit}",
        ]
        for k in range(3):
            e = self.axes[:, k]
            lines.append(
                f"axis e{k + 1}       ({e[0]:+.4f}, {e[1]:+.4f}, {e[2]:+.4f})"
                f" ± {self.axes_stderr_deg[k]:.2g}°"
            )
        with np.printoptions(precision=6, suppress=False):
            rows = [" ".join(f"{v:+.6e}" for v in row) for row in self.inertia]
        lines.append(f"inertia       [{rows[0]}]  {unit}")
        lines += [f"              [{row}]" for row in rows[1:]]
        if self.rotor_inertia is not None:
            su = "kg m²" if self.absolute else "(on the scale of the inertia)"
            fitted = "" if self.absolute else " fitted"
            lines.append(f"rotor J       {self.rotor_inertia:.6g} {su}{fitted}")
        b = self.gyro_bias
        lines.append(f"gyro bias     ({b[0]:+.4f}, {b[1]:+.4f}, {b[2]:+.4f}) rad/s")
        if self.lever_arm is not None:
            p = 1000 * self.lever_arm
            lines.append(f"lever arm     ({p[0]:+.1f}, {p[1]:+.1f}, {p[2]:+.1f}) mm "
                         "(accelerometer from the centre of mass)")  # fmt: skip
        noise = _total_noise(self.noise_std, self.omega_measured)
        rms = float(np.sqrt(np.mean(np.asarray(self.residual_rms) ** 2)))
        lines.append(
            f"residuals     {rms:.4g} rad/s RMS, {rms / noise:.3g}× the gyro noise; "
            f"condition {self.condition:.3g}"
        )
        if self.loss != "linear":  # the scale the robust fit judges itself by
            scale = float(np.sqrt(np.mean(np.asarray(self.residual_scale) ** 2)))
            lines.append(
                f"robust scale  {scale:.4g} rad/s (1.4826 MAD of the residuals), "
                f"{scale / noise:.3g}× the gyro noise; loss {self.loss}"
            )
        for f in self.flags:
            lines.append(f"warning       {f}")
        return lines
