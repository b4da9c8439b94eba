"""Figures of an identification (:func:`poinsot.identify.identify`): measured against fitted
ω(t) with the residuals, the fitted motion on the energy ellipsoid of the fitted moments, and
the principal axes drawn on the body's box.

Every function takes an :class:`~poinsot.identify.IdentifyResult`, returns the figure it drew
on, and imports matplotlib only when called.
"""

from __future__ import annotations

import numpy as np

from ._style import label_3d, png_images
from .torquefree import _box_edges, _plt

__all__ = [
    "plot_identified_axes",
    "plot_identified_fit",
    "plot_identified_polhode",
    "write_identify_report_folder",
]

_COLORS = ("tab:red", "tab:green", "tab:blue")


def plot_identified_fit(result, *, fig=None):
    """Measured and fitted gyro readings ω(t) [rad/s], sensor frame (top), and the residuals,
    measured − fitted [rad/s], with ±2 noise standard deviations shaded (bottom).

    Examples
    --------
    >>> from poinsot.identify import identify, synthetic_throw
    >>> th = synthetic_throw(rotor=False, seed=1)
    >>> fig = plot_identified_fit(identify(th.t, th.omega))
    >>> [ax.get_ylabel() for ax in fig.axes]
    ['ω, sensor frame [rad/s]', 'measured − fitted [rad/s]']
    """
    plt = _plt()
    if fig is None:
        fig = plt.figure(figsize=(9, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(3, 2))
    t = result.t
    for k, name in enumerate("xyz"):
        top.plot(t, result.omega_measured[:, k], ".", ms=1.5, color=_COLORS[k], alpha=0.35,
                 label=f"ω_{name} measured")  # fmt: skip
        top.plot(t, result.omega_fit[:, k], "-", lw=1.2, color=_COLORS[k],
                 label=f"ω_{name} fitted")  # fmt: skip
    top.set_ylabel("ω, sensor frame [rad/s]")
    top.legend(ncol=3, fontsize=8, loc="best", framealpha=0.8)
    top.grid(alpha=0.3)
    model = "gyrostat (rotor given)" if result.model == "gyrostat" else "torque-free"
    top.set_title(f"Measured and fitted gyro readings: {model} model, "
                  f"{len(t)} samples")  # fmt: skip
    for k, name in enumerate("xyz"):
        bottom.plot(t, result.residuals[:, k], lw=0.6, color=_COLORS[k], label=name)
    sigma = float(np.sqrt(np.mean(np.asarray(result.noise_std) ** 2)))
    if np.isfinite(sigma):
        bottom.axhspan(-2 * sigma, 2 * sigma, color="0.85", zorder=0,
                       label="±2σ gyro noise")  # fmt: skip
    bottom.set_xlabel("t [s]")
    bottom.set_ylabel("measured − fitted [rad/s]")
    bottom.grid(alpha=0.3)
    bottom.legend(ncol=4, fontsize=8, loc="upper right")
    # the ratio is of the residuals' RMS, or of their robust scale with a robust loss
    size = "RMS" if result.loss == "linear" else "robust scale, 1.4826 MAD"
    bottom.set_title(f"Residuals: {result.residual_ratio:.3g}× the gyro noise ({size})"
                     + ("" if result.ok else " — flagged"), fontsize=10)  # fmt: skip
    return fig


def plot_identified_polhode(result, *, ax=None):
    """The fitted motion ω(t) (bias removed) in the principal frame of the fitted moments, on
    their energy ellipsoid ``Σ I_i ω_i² = 2k`` (k at the start of the window) with the
    momentum ellipsoid and the polhode. Torque-free, the fitted ω stays on the polhode; with a
    rotor the energy changes as it spins up and the path leaves the ellipsoid. The ellipsoids'
    sizes do not depend on the scale of the inertia.

    Examples
    --------
    >>> from poinsot.identify import identify, synthetic_throw
    >>> th = synthetic_throw(rotor=False, seed=1)
    >>> fig = plot_identified_polhode(identify(th.t, th.omega))
    >>> fig.axes[0].get_xlabel().split(" (")[0]  # ω along the fitted e1, in rad/s
    'ω·e₁'
    """
    from ..torquefree import FreeRigidBody
    from .torquefree import plot_energy_ellipsoid

    moments = np.asarray(result.principal_moments, dtype=float)
    free = FreeRigidBody(moments)  # the table's own normalisation: trace 1, or kg·m²
    w = (np.asarray(result.omega_fit) - np.asarray(result.gyro_bias)) @ result.axes
    k, a = free.invariants(w[0])
    fig = plot_energy_ellipsoid(free, float(k), float(a), ax=ax, cone=False)
    ax = fig.axes[0] if ax is None else ax
    ax.plot(*w.T, color="black", lw=1.5, label="fitted ω(t)")
    ax.scatter(*w[0], color="black", s=20)
    ax.legend(loc="upper left", fontsize=8)
    note = "" if result.model == "torque-free" else " (the rotor changes k: ω leaves it)"
    scale = "moments in kg·m²" if result.absolute else "moments up to scale, trace 1"
    ax.set_title(f"Fitted motion on the energy ellipsoid, principal frame{note}\n({scale}, "
                 "as in the table)", fontsize=10)  # fmt: skip
    return fig


def plot_identified_axes(result, *, box=None, ax=None):
    """The principal axes e1, e2, e3 in the sensor frame, drawn through the body's box.

    ``box`` (a, b, c) [m] is the body's size along the sensor's x, y, z (a box aligned with the
    sensor); without it, the uniform box with the fitted principal moments (its shape only:
    ``a_i ∝ √(I_j + I_k − I_i)``, aligned with the principal axes) is drawn. Each axis carries
    a cone of its standard error (``axes_stderr_deg``); the sensor axes are thin and dashed.

    Examples
    --------
    >>> from poinsot.identify import identify, synthetic_throw
    >>> th = synthetic_throw(rotor=False, seed=1)
    >>> fig = plot_identified_axes(identify(th.t, th.omega), box=(0.07, 0.06, 0.03))
    >>> fig.axes[0].get_xlabel()
    'sensor x [m]'
    """
    plt = _plt()
    if ax is None:
        fig = plt.figure(figsize=(6.5, 6))
        ax = fig.add_subplot(projection="3d")
    fig = ax.figure
    E = np.asarray(result.axes)
    if box is not None:
        half = 0.5 * np.asarray(box, dtype=float)
        frame = np.eye(3)
        unit = "m"
        what = f"the body's box {' × '.join(f'{1000 * x:.0f}' for x in 2 * half)} mm"
    else:
        half = result.box_shape
        frame = E
        unit = "arbitrary units"
        what = "the uniform box of the fitted moments (shape only)"
    corners, edges = _box_edges(half)
    pts = corners @ frame.T
    for i, j in edges:
        ax.plot(*np.array([pts[i], pts[j]]).T, color="0.35", lw=1)
    r = float(np.linalg.norm(half))
    length = 1.25 * r
    for k in range(3):  # the sensor frame
        d = np.eye(3)[k] * length
        ax.plot([0, d[0]], [0, d[1]], [0, d[2]], color="0.6", lw=0.8, ls="--")
        ax.text(*(1.05 * d), "xyz"[k], color="0.4", fontsize=9)
    theta = np.linspace(0, 2 * np.pi, 40)
    for k in range(3):  # the principal axes and their uncertainty cones
        e = E[:, k]
        ax.quiver(0, 0, 0, *(e * length), color=_COLORS[k], lw=2.2, arrow_length_ratio=0.08)
        sd = float(result.axes_stderr_deg[k])
        label = f"e{k + 1} ± {sd:.2g}°" if np.isfinite(sd) else f"e{k + 1} (not identifiable)"
        ax.text(*(e * length * 1.08), label, color=_COLORS[k], fontsize=9)
        if np.isfinite(sd) and sd > 0:
            u = np.cross(e, [1.0, 0.0, 0.0] if abs(e[0]) < 0.9 else [0.0, 1.0, 0.0])
            u /= np.linalg.norm(u)
            v = np.cross(e, u)
            rad = length * np.tan(np.radians(min(sd, 45.0)))
            ring = e * length + rad * (np.outer(np.cos(theta), u) + np.outer(np.sin(theta), v))
            ax.plot(*ring.T, color=_COLORS[k], lw=1)
    lim = 1.3 * length
    for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setter(-lim, lim)
    ax.set_box_aspect((1, 1, 1))
    label_3d(ax, f"sensor x [{unit}]", f"sensor y [{unit}]", f"sensor z [{unit}]")
    r1, r2 = result.ratios
    ax.set_title(f"Principal axes (I1/I3 = {r1:.4f}, I2/I3 = {r2:.4f}) on\n{what}", fontsize=10)
    return fig


#: The figures of an identification's report: (file, caption).
REPORT_FIGURES = (
    ("fit.png", "Measured and fitted ω(t) in the sensor frame, and the residuals"),
    ("polhode.png", "The fitted motion on the energy ellipsoid of the fitted moments"),
    ("axes.png", "The principal axes with their standard errors, on the body's box"),
)


def write_identify_report_folder(folder, result, *, name: str = "identify", box=None,
                                 extra: dict | None = None) -> list[str]:  # fmt: skip
    """Write the figures (``fit.png``, ``polhode.png``, ``axes.png``) and ``report.html`` of
    an identification into the existing ``folder`` (each file atomically); ``extra`` entries
    join the report's JSON summary. Returns the file names written."""
    from pathlib import Path

    from .report import write_identify_report

    folder = Path(folder)
    drawn = (plot_identified_fit(result), plot_identified_polhode(result),
             plot_identified_axes(result, box=box))  # fmt: skip
    figures = [(fig, file, caption) for fig, (file, caption)
               in zip(drawn, REPORT_FIGURES, strict=True)]  # fmt: skip
    images = png_images(figures, folder)
    page = {**result.to_dict(), **(extra or {}),
            "scenario": {"name": name, "description": "Inertia from a gyroscope log"}}  # fmt: skip
    write_identify_report(folder / "report.html", page, images)
    return [file for file, _ in REPORT_FIGURES] + ["report.html"]
