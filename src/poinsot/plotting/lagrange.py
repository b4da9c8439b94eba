"""Figures of a :class:`~poinsot.lagrange.LagrangianSolution` (matplotlib)."""

from __future__ import annotations

import numpy as np

from .torquefree import _plt

__all__ = ["plot_lagrangian_solution"]


def plot_lagrangian_solution(sol, *, title=None):
    """Four panels: coordinates, multipliers, constraint residuals, energy drift."""
    plt = _plt()
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    names = [str(q).replace("(t)", "") for q in sol.coordinates]
    ax = axes[0, 0]
    for j, name in enumerate(names):
        ax.plot(sol.t, sol.q[:, j], label=name)
    ax.set_title("Generalized coordinates")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    if sol.multipliers.shape[1]:
        for k in range(sol.multipliers.shape[1]):
            ax.plot(sol.t, sol.multipliers[:, k], label=f"λ{k + 1}")
        ax.legend(fontsize=8)
        ax.set_title("Lagrange multipliers (sign of eq. 6.60)")
    else:
        ax.text(0.5, 0.5, "no constraints", ha="center", va="center", transform=ax.transAxes)
        ax.set_title("Lagrange multipliers")
    ax = axes[1, 0]
    tiny = 1e-18
    if sol.constraint_residual.shape[1]:
        ax.semilogy(sol.t, np.abs(sol.constraint_residual).max(axis=1) + tiny, label="|g(q)|")
    if sol.constraint_velocity_residual.shape[1]:
        ax.semilogy(
            sol.t, np.abs(sol.constraint_velocity_residual).max(axis=1) + tiny, label="|G q̇ + b|"
        )
    ax.set_title(f"Constraint residuals (stabilization: {sol.stabilization})")
    if ax.get_lines():
        ax.legend(fontsize=8)
    ax = axes[1, 1]
    e0 = sol.energy[0]
    ax.semilogy(sol.t, np.abs(sol.energy - e0) / (abs(e0) or 1.0) + tiny)
    ax.set_title("Relative change of the energy h = Σ q̇ ∂L/∂q̇ − L")
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    for ax in axes.ravel():
        ax.grid(alpha=0.3, which="both")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig
