"""Figures of a motion relative to a carrier (``docs/relative.md``): the relative angular
velocity, the carrier's motion, the relative energy and the inertia moments; and the hodograph
of ω_r on the energy ellipsoid (17) with the bound √(C/A) (18).

Plotting only: every plotted quantity is computed by :class:`~poinsot.relative.RelativeTrajectory`
(through the compiled core).
"""

from __future__ import annotations

import numpy as np

from ._style import legend_below, legend_outside

__all__ = ["plot_hodograph", "plot_relative_motion"]


def _plt():
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "module://matplotlib_inline.backend_inline"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_relative_motion(sol, *, title=None):
    """Panels over time: ω_r (body components) with the absolute ω (dashed: the same motion
    seen from space), the carrier's ω_e (carrier components), the
    relative rotational energy ½ ω_r·Jω_r, the magnitudes of the transport and Coriolis inertia
    moments, and the direction of the body's axis of largest moment C in the carrier's axes
    (where a spin axis points relative to the vehicle). Returns the figure.

    Examples
    --------
    >>> from poinsot import RigidBody
    >>> from poinsot.relative import Carrier, simulate_relative
    >>> sol = simulate_relative(RigidBody.box(1.0, (1, 2, 3)), (0, 1), omega_r0=(0, 1, 0),
    ...                         carrier=Carrier(omega_e=(0, 0, 1)), hold_com=True)
    >>> fig = plot_relative_motion(sol)
    >>> [ax.get_ylabel() for ax in fig.axes][:2]
    ['ω_r [rad/s], body axes', 'ω_e [rad/s], carrier axes']
    """
    plt = _plt()
    fig = plt.figure(figsize=(11, 9.5), constrained_layout=True)
    grid = fig.add_gridspec(3, 2)
    axes = np.array([[fig.add_subplot(grid[i, j]) for j in range(2)] for i in range(2)])
    bottom = fig.add_subplot(grid[2, :], sharex=axes[0, 0])
    t = sol.t
    axis_c = np.einsum("nij,j->ni", sol.Q_r, np.asarray(sol.body.principal_axes)[:, 2])
    for k, name in enumerate("xyz"):
        bottom.plot(t, axis_c[:, k], label=f"carrier {name}")
    bottom.set_ylabel("axis of C, carrier axes (dimensionless)")
    bottom.set_xlabel("t [s]")
    bottom.set_title("the body's axis of largest moment C seen from the carrier (unit vector)",
                     fontsize=9)  # fmt: skip
    for k, name in enumerate("xyz"):
        (line,) = axes[0, 0].plot(t, sol.omega_r[:, k], label=f"ω_r,{name}: relative")
        axes[0, 0].plot(t, sol.omega_absolute[:, k], ls="--", color=line.get_color(),
                        label=f"ω_{name}: absolute")  # fmt: skip
        axes[0, 1].plot(t, sol.carrier_motion[:, k], label=f"ω_e,{name}")
    axes[0, 0].set_title("both views: relative to the carrier (solid), in space (dashed)",
                         fontsize=9)  # fmt: skip
    axes[0, 0].set_ylabel("ω_r [rad/s], body axes")
    axes[0, 1].set_ylabel("ω_e [rad/s], carrier axes")
    E = sol.relative_energy
    axes[1, 0].plot(t, E, color="tab:purple", label="½ ω_r·Jω_r")
    axes[1, 0].set_ylabel("relative rotational energy [J]")
    balanced = sol.system.balance_transport
    if balanced:
        axes[1, 0].set_title(
            f"conserved (case (16)): max drift {np.ptp(E) / max(abs(E[0]), 1e-300):.2g} relative",
            fontsize=9,
        )
    else:
        axes[1, 0].set_title("not conserved: the carrier's inertia moments do work", fontsize=9)
    axes[1, 1].plot(t, np.linalg.norm(sol.transport_moment, axis=1),
                    label="|M_e| transport" + (" (balanced)" if balanced else ""))  # fmt: skip
    axes[1, 1].plot(t, np.linalg.norm(sol.coriolis_moment, axis=1), label="|M_c| Coriolis")
    axes[1, 1].set_ylabel("inertia moment [N·m]")
    for ax in [*axes.ravel(), bottom]:
        ax.grid(alpha=0.3)
        legend_outside(ax)
        ax.ticklabel_format(axis="y", style="plain", useOffset=False)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    fig.suptitle(title or "Motion relative to the carrier")
    return fig


def plot_hodograph(sol, *, title=None):
    """The hodograph of ω_r in the principal axes on the energy ellipsoid
    ``A p² + B q² + C r² = 2T_r`` (17) (T_r at t = 0), and |ω_r| over time between the
    ellipsoid's extreme semi-axes ``√(2T_r/C)`` and ``√(2T_r/A)``, whose ratio √(C/A) bounds
    max|ω_r|/min|ω_r| (18) when the transport moment is balanced. Returns the figure."""
    plt = _plt()
    from .torquefree import _ellipsoid_mesh, _equal_3d

    fig = plt.figure(figsize=(12, 5.5), constrained_layout=True)
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ax2 = fig.add_subplot(1, 2, 2)
    moments = np.asarray(sol.body.principal_moments, float)
    E = np.asarray(sol.body.principal_axes, float)
    T0 = float(sol.relative_energy[0])
    w = sol.omega_r @ E  # principal components
    semi = np.sqrt(2 * T0 / moments) if T0 > 0 else np.zeros(3)
    balanced = sol.system.balance_transport
    if T0 > 0:
        x, y, z = _ellipsoid_mesh(semi, np.eye(3))
        ax.plot_wireframe(x, y, z, color="tab:blue", alpha=0.15, linewidth=0.4, rstride=2,
                          cstride=2, label="energy ellipsoid (17), T_r(0)")  # fmt: skip
    ax.plot(w[:, 0], w[:, 1], w[:, 2], color="crimson", lw=1.2, label="ω_r(t)")
    ax.plot(*w[0], "o", color="k", ms=5, label="t = 0")
    radius = max(float(semi.max()), float(np.abs(w).max()), 1e-300)
    _equal_3d(ax, 1.05 * radius)
    ax.set_xlabel("ω_r·e₁ (A) [rad/s]")
    ax.set_ylabel("ω_r·e₂ (B) [rad/s]")
    ax.set_zlabel("ω_r·e₃ (C) [rad/s]")
    legend_below(ax, ncol=3, drop=10)
    ax.set_title("hodograph of ω_r, principal axes (A ≤ B ≤ C)", fontsize=10)
    n = np.linalg.norm(sol.omega_r, axis=1)
    ax2.plot(sol.t, n, color="crimson", label="|ω_r|")
    if T0 > 0:
        ax2.axhline(semi[0], color="tab:blue", ls="--", lw=1, label="√(2T_r/A): largest semi-axis")
        ax2.axhline(semi[2], color="tab:green", ls="--", lw=1,
                    label="√(2T_r/C): smallest semi-axis")  # fmt: skip
    ax2.set_xlabel("t [s]")
    ax2.set_ylabel("|ω_r| [rad/s]")
    ratio, bound = sol.hodograph_ratio(), sol.hodograph_bound()
    state = "balanced transport moment, (16)" if balanced else "transport moment not balanced"
    ax2.set_title(f"max|ω_r| / min|ω_r| = {ratio:.4g}; bound √(C/A) = {bound:.4g} ({state})",
                  fontsize=9)  # fmt: skip
    ax2.grid(alpha=0.3)
    legend_below(ax2, ncol=2)
    fig.suptitle(title or "Relative angular velocity on the energy ellipsoid")
    return fig
