"""Figures of a simulated :class:`~poinsot.trajectory.Trajectory` (matplotlib)."""

from __future__ import annotations

import numpy as np

from ._style import fit_titles, label_3d, legend_below, legend_outside
from .torquefree import _plt

__all__ = [
    "omega_axes",
    "omega_components",
    "plot_attitude",
    "plot_axis_trace",
    "plot_center_of_mass_path",
    "plot_conservation",
    "plot_method_comparison",
    "plot_omega_series",
]


def omega_axes(traj) -> tuple[list[str], str]:
    """``(names, point)``: the names of the three axes :func:`omega_components` projects ω on
    and the point they are principal about. A free body's are the principal axes e₁, e₂, e₃
    about its centre of mass G, those of the body's own table; a body on a pivot's are the
    principal axes about the pivot P, named e₁ᴾ, e₂ᴾ, e₃ᴾ: they are other axes (the symmetry
    axis of the heavy-top example is e₃ about G and e₁ᴾ about its tip), and no label calls
    them e₁, e₂, e₃."""
    if traj.system.pivot is None:
        return ["e₁", "e₂", "e₃"], "the centre of mass G"
    return ["e₁ᴾ", "e₂ᴾ", "e₃ᴾ"], "the pivot P"


def omega_components(traj):
    """``(components (n, 3), labels)``: ω along the sorted principal axes of the inertia about
    the run's reference point (``ω·e_k``): e₁, e₂, e₃ about the centre of mass G for a free
    body; e₁ᴾ, e₂ᴾ, e₃ᴾ about the pivot for a body on one (:func:`omega_axes`; a run's report
    lists both sets). Each label names its axis, its moment and that point."""
    system = traj.system
    E, I = system.principal_axes, system.principal_moments
    names, _ = omega_axes(traj)
    point = "G" if system.pivot is None else "the pivot"
    labels = [f"ω·{n} (I{n[1:]} = {I[k]:.4g} kg·m² about {point})" for k, n in enumerate(names)]
    return traj.omega @ E, labels


def plot_omega_series(traj, *, ax=None):
    """ω against time, by its components along the principal axes about the run's reference
    point (ascending moments: e₁, e₂, e₃ about G, or e₁ᴾ, e₂ᴾ, e₃ᴾ about a pivot), and
    ``|ω|``.

    Examples
    --------
    >>> from poinsot import simulate
    >>> from poinsot.models import notebook_body
    >>> ax = plot_omega_series(simulate(notebook_body(), (0, 1), omega0=(0, 0, 1))).axes[0]
    >>> ax.get_lines()[0].get_ydata()[0], ax.get_legend().get_texts()[0].get_text()
    (np.float64(1.0), 'ω·e₁ (I₁ = 8.333 kg·m² about G)')
    """
    plt = _plt()
    if ax is None:
        _, ax = plt.subplots(figsize=(9.5, 3.8))
    w, labels = omega_components(traj)
    for i, name in enumerate(labels):
        ax.plot(traj.t, w[:, i], label=name)
    ax.plot(traj.t, np.linalg.norm(traj.omega, axis=1), "k--", lw=1, label="|ω|")
    names, point = omega_axes(traj)
    ax.set_xlabel("t [s]")
    ax.set_ylabel(f"ω along {', '.join(names)} [rad/s]")
    ax.set_title(f"Angular velocity along the principal axes about {point} ({traj.method})")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    ax.figure.tight_layout()
    return ax.figure


def plot_attitude(motion, *, axes=None, title=None):
    """A top's nutation and precession (:class:`~poinsot.tops.TopMotion`): θ(t), the tilt of
    its symmetry axis a from the upward vertical, with its nutation band, and the unwrapped
    ψ(t) with its mean precession rate against the gyroscopic estimate ``M g l/(C ω·a)``
    (``ω·a`` the spin, the library's ω₃) and the slow steady precession at the mean θ. Each
    panel's title is wrapped to the panel's width (:func:`~poinsot.viz._style.fit_titles`)."""
    plt = _plt()
    if axes is None:
        fig, axes = plt.subplots(1, 2, figsize=(13, 4.4))
    m = motion
    t = m.t
    ax = axes[0]
    lo, hi = m.theta_band
    band = f"nutation band {lo:.4g} – {hi:.4g} rad"
    ax.fill_between(t, lo, hi, color="tab:blue", alpha=0.12, label=band)
    ax.plot(t, m.theta, color="tab:blue", lw=1, label="θ(t): tilt of a")
    ax.axhline(m.theta_mean, color="0.3", ls=":", lw=1, label=f"mean θ = {m.theta_mean:.4g} rad")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("θ [rad]")
    ax.set_title("Nutation: θ, the angle of the symmetry axis a from the upward vertical",
                 fontsize=10)  # fmt: skip
    ax.grid(alpha=0.3)
    legend_below(ax, ncol=1, bbox_to_anchor=(0.0, -0.16))
    ax = axes[1]
    ax.plot(t, m.psi, color="tab:green", lw=1.2, label="ψ(t): z-x-z Euler precession angle")
    psi0 = m.psi[0]
    for rate, style, name in (
        (m.mean_precession_rate, {"color": "black", "ls": "--"}, "mean rate (fit of ψ)"),
        (m.gyroscopic_rate, {"color": "tab:red", "ls": ":"}, "gyroscopic M g l/(C ω·a)"),
        (m.steady_rates[0], {"color": "tab:purple", "ls": "-."}, "steady precession at mean θ"),
    ):
        if np.isfinite(rate):
            ax.plot(t, psi0 + rate * (t - t[0]), lw=1, **style, label=f"{name}: {rate:.5g} rad/s")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("ψ [rad] (unwrapped)")
    ax.set_title(f"Precession ψ: {m.psi_reference()}", fontsize=10)
    ax.grid(alpha=0.3)
    legend_below(ax, ncol=1, bbox_to_anchor=(0.0, -0.16))
    fig = axes[0].figure
    if title:
        fig.suptitle(title, fontsize=11)
    fit_titles(fig)
    return fig


def plot_axis_trace(trace, *, ax=None, title="Trace of the symmetry axis on the unit sphere",
                    label="axis direction"):  # fmt: skip
    """The path of a body axis's direction (n, 3 unit vectors, :meth:`~poinsot.trajectory.
    Trajectory.axis_trace`) on the unit sphere (3D, equal axes, dimensionless); ``title`` and
    ``label`` (the path's legend entry) say which axis it is."""
    plt = _plt()
    if ax is None:
        fig = plt.figure(figsize=(8.5, 6.5))
        ax = fig.add_subplot(projection="3d")
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 36), np.linspace(0, np.pi, 19))
    ax.plot_wireframe(np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v), color="0.8",
                      lw=0.4)  # fmt: skip
    ax.plot(*trace.T, color="tab:blue", lw=1.2, label=label)
    ax.scatter(*trace[0], color="green", depthshade=False, label="start")
    ax.scatter(*trace[-1], color="red", depthshade=False, label="end")
    for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setter(-1, 1)
    ax.set_box_aspect((1, 1, 1), zoom=0.85)
    label_3d(ax, "x (dimensionless)", "y (dimensionless)", "z (dimensionless)")
    ax.set_title(title, fontsize=10)
    legend_outside(ax, bbox_to_anchor=(1.0, 0.95))
    ax.figure.subplots_adjust(left=0.0, right=0.72)
    return ax.figure


def plot_conservation(traj, *, axes=None):
    """What this problem conserves, and how well the run kept it (legend under the panel).

    Left: the relative change ``|x(t) − x(0)| / |x(0)|`` of each quantity the problem conserves
    (:attr:`~poinsot.trajectory.Trajectory.invariants`: total energy, the momenta its forces
    and constraint leave alone), log scale, so what is plotted is the integrator's error. The
    quantities that are *not* conserved are named in the title instead of plotted as if they
    drifted. With nothing conserved (drag, a driving torque) the panel shows ``E(t) − E(0)``
    in joules. Right: the distance of the attitude from SO(3), ``max |QᵀQ − I|``.
    """
    plt = _plt()
    if axes is None:
        _, axes = plt.subplots(1, 2, figsize=(11, 4.8), gridspec_kw={"width_ratios": [1.5, 1]})
    tiny = 1e-17
    ax = axes[0]
    kept = [i for i in traj.invariants if i.conserved]
    lost = [i for i in traj.invariants if not i.conserved]
    if kept:
        for inv in kept:
            ax.semilogy(traj.t, inv.change + tiny, label=f"{inv.symbol} [{inv.unit}]: {inv.name}")
        ax.set_ylabel("relative change |x(t) − x(0)| / scale (dimensionless)")
        title = "Conserved by this problem: the plotted change is integration error"
        legend_below(ax, ncol=1, fontsize=7, bbox_to_anchor=(0.0, -0.18))
    else:
        E = traj.total_energy
        ax.plot(traj.t, E - E[0], color="tab:red")
        ax.set_ylabel("E(t) − E(0) [J]")
        title = "Total energy: not conserved here (forces do work)"
    if lost:
        title += "\nnot conserved here: " + "; ".join(f"{i.symbol} ({i.reason})" for i in lost)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("t [s]")
    ax.grid(alpha=0.3, which="both")
    ax = axes[1]
    ax.semilogy(traj.t, traj.orthogonality_error + tiny, color="tab:purple")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("max |QᵀQ − I| (dimensionless)")
    ax.set_title("Attitude: distance from a rotation", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    axes[0].figure.tight_layout()
    return axes[0].figure


def plot_center_of_mass_path(traj, *, ax=None):
    """The path of the centre of mass in space (3D, equal axes). A centre of mass at rest
    has no path: the panel then says so and where it stays."""
    plt = _plt()
    if ax is None:
        fig = plt.figure(figsize=(6, 5.5))
        ax = fig.add_subplot(projection="3d")
    R = traj.R
    if not np.ptp(R, axis=0).max() > 0:
        ax.text2D(
            0.5,
            0.5,
            "the centre of mass is at rest at\n("
            + ", ".join(f"{x:.4g}" for x in R[0])
            + ") m: no path to draw",
            transform=ax.transAxes,
            ha="center",
        )
        ax.set_title("Centre of mass path")
        return ax.figure
    ax.plot(*R.T, color="tab:blue")
    ax.scatter(*R[0], color="green", label="start", depthshade=False)
    ax.scatter(*R[-1], color="red", label="end", depthshade=False)
    center = 0.5 * (R.max(0) + R.min(0))
    half = max(0.5 * float(np.ptp(R, axis=0).max()), 1e-9)
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), center, strict=True):
        setter(c - half, c + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title("Centre of mass path")
    legend_outside(ax, bbox_to_anchor=(1.0, 0.95))
    return ax.figure


#: The three errors of :func:`plot_method_comparison`: key, panel title, y label.
COMPARISON_PANELS = (
    ("orthogonality", "Distance from SO(3)", "max |QᵀQ − I| (dimensionless)"),
    ("attitude", "Attitude against the exact solution", "max |Q − Q_exact| (dimensionless)"),
    ("omega", "Angular velocity against the exact solution", "max |ω − ω_exact| [rad/s]"),
)


def plot_method_comparison(t, errors, *, title=None):
    """Integrators side by side on one torque-free problem: three errors over time.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times [s].
    errors : dict
        ``label → {"orthogonality": (n,), "attitude": (n,), "omega": (n,)}`` (a key may be
        missing: the exact solution has no error against itself, only its round-off distance
        from SO(3)); see :meth:`poinsot.torquefree.FreeRigidBody.error_series`.
    title : str, optional
    """
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.8), sharex=True)
    tiny = 1e-17  # log axes: an exact zero is drawn at the floor
    for ax, (key, panel, ylabel) in zip(axes, COMPARISON_PANELS, strict=True):
        drawn = []  # (label, values) already on this panel
        for n, (label, rows) in enumerate(errors.items()):
            if key not in rows:
                continue
            y = np.asarray(rows[key], dtype=float)
            same = next((other for other, v in drawn if np.allclose(v, y, rtol=1e-9, atol=0)),
                        None)  # fmt: skip
            style = {"color": f"C{n}", "lw": 1.5, "ls": "--" if label.startswith("exact") else "-"}
            if same is not None:  # a curve on top of another: dotted, thicker, and said so
                style |= {"ls": ":", "lw": 2.6}
                label = f"{label} (the same as {same})"
            ax.semilogy(t, y + tiny, label=label, **style)
            drawn.append((label.split(" (the same")[0], y))
        ax.set_title(panel, fontsize=10)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3, which="both")
        legend_below(ax, ncol=1, bbox_to_anchor=(0.0, -0.18))
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig
