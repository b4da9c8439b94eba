"""Figures of a simulated :class:`~poinsot.trajectory.Trajectory` (matplotlib)."""

from __future__ import annotations

import numpy as np

from .torquefree import _plt

__all__ = ["plot_center_of_mass_path", "plot_conservation", "plot_omega_series"]


def plot_omega_series(traj, *, ax=None):
    """ω (body frame) and |ω| against time."""
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
    """Relative energy drift and angular-momentum drift against time (log scale of |drift|),
    with |QᵀQ − I| — what the integrator conserved and what it did not."""
    plt = _plt()
    if axes is None:
        _, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    tiny = 1e-17
    ax = axes[0]
    label = "total energy" if traj.is_conservative else "energy (forces do work)"
    ax.semilogy(traj.t, np.abs(traj.energy_drift) + tiny, label=label)
    ax.semilogy(traj.t, traj.orthogonality_error + tiny, label="|QᵀQ − I|")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("relative drift")
    ax.set_title("Energy and orthogonality")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    ax = axes[1]
    ax.semilogy(traj.t, traj.momentum_drift + tiny, color="tab:green")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("|L(t) − L(0)| / |L(0)|")
    ax.set_title("Angular momentum about the centre of mass")
    ax.grid(alpha=0.3, which="both")
    axes[0].figure.tight_layout()
    return axes[0].figure


def plot_center_of_mass_path(traj, *, ax=None):
    """The path of the centre of mass in space (3D, equal axes)."""
    plt = _plt()
    if ax is None:
        fig = plt.figure(figsize=(6, 5.5))
        ax = fig.add_subplot(projection="3d")
    R = traj.R
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
