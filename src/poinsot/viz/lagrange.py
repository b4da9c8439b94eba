"""Figures of a :class:`~poinsot.lagrange.LagrangianSolution` (matplotlib).

Every panel shows something: coordinates grouped by unit (metres and radians never share an
axis), the constraint reactions as the named forces they are (or the multipliers when the
model names none), the constraint residuals, and the relative change of what the system
conserves. Panels with nothing to show (no constraints) are left out.
"""

from __future__ import annotations

import numpy as np

from ._style import legend_below, legend_outside
from .torquefree import _plt

__all__ = ["lagrangian_panels", "plot_lagrangian_solution", "plot_mechanism_frames"]

_RATE = {"m": "m/s", "rad": "rad/s"}


def _name(q):
    return str(q).replace("(t)", "")


def coordinate_groups(sol) -> dict:
    """``unit → [(index, name)]`` of the coordinates, in order of first appearance."""
    groups = {}
    for j, q in enumerate(sol.coordinates):
        groups.setdefault(sol.system.unit_of(q), []).append((j, _name(q)))
    return groups


def lagrangian_panels(sol, model=None) -> list:
    """The panels of a Lagrangian run as data, shared by the PNG and the HTML report:
    ``[(title, ylabel, log, [(label, x, y)])]``. Only panels with something to show."""
    t = sol.t
    panels = []
    for unit, members in coordinate_groups(sol).items():
        what = {"m": "lengths", "rad": "angles"}.get(unit, "coordinates")
        label = {"m": "length [m]", "rad": "angle [rad]"}.get(unit, f"[{unit}]" if unit else "q")
        curves = [(name, t, sol.q[:, j]) for j, name in members]
        panels.append((f"Generalized coordinates: {what}", label, False, curves))
    m = sol.multipliers.shape[1]
    reactions = model.reaction_values(sol) if model is not None else {}
    if reactions:
        units = {u for _, u, _ in reactions.values()}
        panels.append(
            (
                "Constraint reactions (from the multipliers)",
                ("force [N]" if units == {"N"} else " / ".join(f"[{u}]" for u in sorted(units))),
                False,
                [(n, t, v) for n, (v, _, _) in reactions.items()],
            )
        )
    elif m:
        panels.append(
            (
                "Lagrange multipliers λ (sign of eq. (6.60))",
                "λ [the constraint's units]",
                False,
                [(f"λ{k + 1}", t, sol.multipliers[:, k]) for k in range(m)],
            )
        )
    tiny = 1e-18
    residuals = []
    if sol.constraint_residual.shape[1]:
        residuals.append(("max |g(q)| (holonomic)", t,
                          np.nanmax(np.abs(sol.constraint_residual), axis=1) + tiny))  # fmt: skip
    if sol.constraint_velocity_residual.shape[1]:
        vel = np.nanmax(np.abs(sol.constraint_velocity_residual), axis=1) + tiny
        residuals.append(("max |G q̇ + b| (velocity level)", t, vel))
    if residuals:
        panels.append((f"Constraint residuals (stabilization: {sol.stabilization})",
                       "residual [the constraints' units]", True, residuals))  # fmt: skip
    kept = sol.invariants
    if kept:
        panels.append(("Conserved by this system: relative change (integration error)",
                       "relative change |x(t) − x(0)| / scale (dimensionless)", True,
                       [(f"{i.symbol} [{i.unit}]" if i.unit else i.symbol, t, i.change + tiny)
                        for i in kept]))  # fmt: skip
    else:
        h = sol.energy
        panels.append(("Energy h: not conserved here (forces, motors or moving constraints)",
                       "h(t) − h(0) [J]", False, [("h − h(0)", t, h - h[0])]))  # fmt: skip
    return panels


def plot_lagrangian_solution(sol, *, model=None, title=None):
    """The panels of :func:`lagrangian_panels`, two per row; ``model`` (a
    :class:`~poinsot.models.Model`) names the reactions."""
    plt = _plt()
    panels = lagrangian_panels(sol, model)
    rows = (len(panels) + 1) // 2
    fig, axes = plt.subplots(rows, 2, figsize=(12, 4.4 * rows + 0.6), squeeze=False)
    for ax, (panel, ylabel, log, curves) in zip(axes.ravel(), panels, strict=False):
        for label, x, y in curves:
            (ax.semilogy if log else ax.plot)(x, y, label=label)
        ax.set_title(panel, fontsize=10)
        ax.set_ylabel(ylabel)
        ax.set_xlabel("t [s]")
        ax.grid(alpha=0.3, which="both")
        legend_below(ax, fontsize=7, ncol=2)
    for ax in axes.ravel()[len(panels) :]:
        ax.remove()
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_mechanism_frames(model, sol, *, frames=6, ax=None):
    """The mechanism drawn at a few instants, later ones darker (a stroboscope), from the
    model's geometry: points, links and fixed outlines, in metres, equal axes."""
    if not model.points:
        raise ValueError("the model has no points to draw (name a body, or give [draw] points)")
    plt = _plt()
    names, P = model.positions(sol)
    index = {n: k for k, n in enumerate(names)}
    idx = np.linspace(0, len(sol.t) - 1, frames).astype(int)
    three = model.view == "3d"
    if ax is None:
        fig = plt.figure(figsize=(8.5, 6))
        ax = fig.add_subplot(projection="3d" if three else None)
    cols = slice(0, 3) if three else slice(0, 2)
    for name, pts in model.outlines(sol.params).items():
        ax.plot(*pts[:, cols].T, color="0.6", lw=1, ls="--", label=name)
    if model.trail is not None:
        path = P[:, index[model.trail], cols]
        ax.plot(*path.T, color="#e0a040", lw=1, label=f"path of the {model.trail}")
    for n, i in enumerate(idx):
        shade = 0.25 + 0.75 * n / max(len(idx) - 1, 1)
        for a, b in model.links:
            seg = P[i, [index[a], index[b]]][:, cols]
            ax.plot(*seg.T, color=(0.1, 0.2, 0.6, shade), lw=1.5)
        ends = [k for k, nm in enumerate(names) if "#" not in nm]  # '#' points: no marker
        ax.scatter(*P[i, ends][:, cols].T, color=(0.8, 0.2, 0.1, shade), s=18)
        if three:
            ax.text(*P[i, ends[-1]], f"{sol.t[i]:.2g} s", fontsize=7)
        else:
            ax.annotate(f"{sol.t[i]:.2g} s", P[i, ends[-1], :2], fontsize=7,
                        xytext=(3, 3), textcoords="offset points")  # fmt: skip
    allp = P.reshape(-1, 3)
    lo, hi = allp.min(0), allp.max(0)
    mid, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-3) * 1.1
    if three:
        for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), mid, strict=True):
            setter(c - half, c + half)
        ax.set_box_aspect((1, 1, 1))
        ax.set_zlabel("z [m]")
    else:
        ax.set_xlim(mid[0] - half, mid[0] + half)
        ax.set_ylim(mid[1] - half, mid[1] + half)
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    title = f"{model.description}\nthe mechanism at {frames} instants (darker = later)"
    ax.set_title(title, fontsize=9)
    if model.outline or model.trail:
        legend_outside(ax, fontsize=7)
        ax.figure.tight_layout() if not three else ax.figure.subplots_adjust(right=0.72)
    return ax.figure
