"""Figures of a simulated :class:`~poinsot.trajectory.Trajectory` (matplotlib)."""

from __future__ import annotations

import numpy as np

from .torquefree import _plt

__all__ = [
    "plot_center_of_mass_path",
    "plot_conservation",
    "plot_method_comparison",
    "plot_omega_series",
]


def plot_omega_series(traj, *, ax=None):
    """ω (body frame) and ``|ω|`` against time."""
    plt = _plt()
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 3.8))
    for i, name in enumerate(("ω₁", "ω₂", "ω₃")):
        ax.plot(traj.t, traj.omega[:, i], label=name)
    ax.plot(traj.t, np.linalg.norm(traj.omega, axis=1), "k--", lw=1, label="|ω|")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("ω, body frame [rad/s]")
    ax.set_title(f"Angular velocity ({traj.method})")
    ax.grid(alpha=0.3)
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=8)
    ax.figure.tight_layout()
    return ax.figure


def plot_conservation(traj, *, axes=None):
    """What this problem conserves, and how well the run kept it.

    Left: the relative change ``|x(t) − x(0)| / |x(0)|`` of each quantity the problem conserves
    (:attr:`~poinsot.trajectory.Trajectory.invariants`: total energy, the momenta its forces
    and constraint leave alone), log scale, so what is plotted is the integrator's error. The
    quantities that are *not* conserved are named in the title instead of plotted as if they
    drifted. With nothing conserved (drag, a driving torque) the panel shows ``E(t) − E(0)``
    in joules. Right: the distance of the attitude from SO(3), ``max |QᵀQ − I|``.
    """
    plt = _plt()
    if axes is None:
        _, axes = plt.subplots(1, 2, figsize=(11, 3.9), gridspec_kw={"width_ratios": [1.5, 1]})
    tiny = 1e-17
    ax = axes[0]
    kept = [i for i in traj.invariants if i.conserved]
    lost = [i for i in traj.invariants if not i.conserved]
    if kept:
        for inv in kept:
            ax.semilogy(traj.t, inv.change + tiny, label=f"{inv.symbol} [{inv.unit}]: {inv.name}")
        ax.set_ylabel("relative change |x(t) − x(0)| / scale")
        title = "Conserved by this problem: the plotted change is integration error"
        ax.legend(fontsize=7, loc="lower right")
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
    ax.legend(fontsize=8)
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
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.0), sharex=True)
    tiny = 1e-17  # log axes: an exact zero is drawn at the floor
    for ax, (key, panel, ylabel) in zip(axes, COMPARISON_PANELS, strict=True):
        for n, (label, rows) in enumerate(errors.items()):
            if key in rows:
                ax.semilogy(
                    t,
                    np.asarray(rows[key]) + tiny,
                    label=label,
                    color=f"C{n}",
                    ls="--" if label.startswith("exact") else "-",
                )
        ax.set_title(panel, fontsize=10)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig
