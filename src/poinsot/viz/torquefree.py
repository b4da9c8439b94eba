"""Figures of the torque-free body: Poinsot's construction in 3D, polhodes, ω(t), tumbling.

These are the notebook's figures that never rendered ("3D rendering not yet implemented").
Angular velocities are drawn by their components along the sorted principal axes e1, e2, e3
(``ω·e_k``, :meth:`~poinsot.torquefree.FreeRigidBody.principal_components`), and the axes are
labelled so: a curve "around e1" circles the axis labelled e₁ whatever the body's own axes are.
"""

from __future__ import annotations

import numpy as np

from .._io import atomic_path
from ..torquefree import energy_ellipsoid_semi_axes, momentum_ellipsoid_semi_axes
from ._style import legend_outside, omega_axis_labels

__all__ = [
    "animate_tumbling",
    "plot_attitude_frames",
    "plot_energy_ellipsoid",
    "plot_omega",
    "plot_polhode_family",
]

FAMILY_STYLE = {
    "around e1": {"color": "tab:blue", "lw": 1.2, "ls": "-"},
    "around e3": {"color": "tab:orange", "lw": 1.2, "ls": "-"},
    "symmetric": {"color": "tab:purple", "lw": 1.2, "ls": "-"},
    "separatrix": {"color": "black", "lw": 2.4, "ls": "--"},
}


def _plt():
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "module://matplotlib_inline.backend_inline"):
        try:
            import matplotlib.pyplot as plt
        except Exception:  # pragma: no cover - headless without a GUI backend
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
    else:
        import matplotlib.pyplot as plt
    return plt


def _axes3d(ax, figsize=(9.5, 6.5)):
    plt = _plt()
    if ax is None:
        fig = plt.figure(figsize=figsize)
        ax = fig.add_subplot(projection="3d")
    return ax.figure, ax


def _equal_3d(ax, radius, moments=None):
    from matplotlib.ticker import MaxNLocator

    for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setter(-radius, radius)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):  # few ticks: their labels never collide
        axis.set_major_locator(MaxNLocator(5))
    ax.set_box_aspect((1, 1, 1), zoom=0.85)  # room for the tick and axis labels
    omega_axis_labels(ax, moments)


def _legend_3d(fig, ax):
    """The legend to the right of a 3D axes, which is narrowed to make room for it."""
    legend = legend_outside(ax, loc="upper left", bbox_to_anchor=(1.0, 0.95))
    if legend is not None:
        fig.subplots_adjust(left=0.0, right=0.68)
    return legend


def _ellipsoid_mesh(semi_axes, axes, n=40):
    """x, y, z (n, n) of the ellipsoid with ``semi_axes`` along the columns of ``axes``."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n), np.linspace(0, np.pi, n // 2))
    unit = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], axis=-1)
    pts = (unit * semi_axes) @ axes.T
    return pts[..., 0], pts[..., 1], pts[..., 2]


def plot_energy_ellipsoid(
    body, energy=0.5, momentum=None, *, ax=None, cone=True, momentum_ellipsoid=True
):
    """The energy (Poinsot) ellipsoid ``Σ I_i ω_i² = 2k`` with, for ``|L| = momentum``, the cone
    (32) and the momentum ellipsoid ``Σ I_i² ω_i² = a²``; their intersection, the polhode, drawn
    thick. ``body`` is a :class:`~poinsot.torquefree.FreeRigidBody`. Returns the figure.

    Examples
    --------
    >>> from poinsot.torquefree import FreeRigidBody
    >>> fig = plot_energy_ellipsoid(FreeRigidBody((1, 2, 3)), 0.5, 1.6 ** 0.5)
    >>> fig.axes[0].get_title()
    'Energy ellipsoid, k = 0.5 J, a²/2k = 1.6 kg·m²'
    """
    fig, ax = _axes3d(ax)
    I = body.principal_moments
    S = np.eye(3)  # drawn in principal components: the ellipsoids' axes are the plot's axes
    k = float(energy)
    semi = energy_ellipsoid_semi_axes(np.asarray(I, float), k)
    x, y, z = _ellipsoid_mesh(semi, S)
    ax.plot_surface(x, y, z, color="tab:blue", alpha=0.12, linewidth=0, label="energy ellipsoid")
    ax.plot_wireframe(x, y, z, color="tab:blue", alpha=0.15, linewidth=0.3, rstride=2, cstride=2)
    title = f"Energy ellipsoid, k = {k:g} J"
    if momentum is not None:
        a = float(momentum)
        D = body.check_feasible(k, a)
        title += f", a²/2k = {D:.4g} kg·m²"
        if momentum_ellipsoid:
            xm, ym, zm = _ellipsoid_mesh(momentum_ellipsoid_semi_axes(np.asarray(I, float), a), S)
            ax.plot_wireframe(
                xm,
                ym,
                zm,
                color="tab:green",
                alpha=0.25,
                linewidth=0.4,
                rstride=2,
                cstride=2,
                label="momentum ellipsoid",
            )
        curves = [body.principal_components(c) for c in _intersection(body, k, a)]
        if cone and body.symmetry != "spherical":
            s = np.linspace(-1.35, 1.35, 25)
            for pts in curves:
                if len(pts) > 1:
                    X = s[:, None] * pts[None, :, 0]
                    Y = s[:, None] * pts[None, :, 1]
                    Z = s[:, None] * pts[None, :, 2]
                    ax.plot_surface(X, Y, Z, color="tab:red", alpha=0.18, linewidth=0)
            ax.plot([], [], color="tab:red", alpha=0.5, lw=6, label="cone (32)")
        for i, pts in enumerate(curves):
            style = {"marker": "o", "ms": 7} if len(pts) == 1 else {}
            ax.plot(
                pts[:, 0],
                pts[:, 1],
                pts[:, 2],
                color="crimson",
                lw=3,
                **style,
                label="intersection (polhode)" if i == 0 else None,
            )
    ax.set_title(title, fontsize=10)
    _equal_3d(ax, 1.05 * semi.max(), I)
    _legend_3d(fig, ax)
    return fig


def _intersection(body, k, a):
    """Polhode curves with invariants (k, a): both branches, or the four separatrix arcs."""
    moments = np.asarray(body.principal_moments, dtype=float)
    _, I2, I3 = moments
    if body.symmetry == "spherical":  # every ω on the sphere is a fixed point
        theta = np.linspace(0, 2 * np.pi, 200)
        r = float(energy_ellipsoid_semi_axes(moments, k)[0])
        return [np.column_stack([r * np.cos(theta), r * np.sin(theta), 0 * theta])]
    D = a * a / (2 * k)
    if body.symmetry == "asymmetric" and abs(D - I2) <= 1e-9 * I3:
        return [arc.points for arc in body.separatrix_arcs(k)]
    for fp in body.fixed_points():  # a symmetric body's plane of fixed points: a whole circle
        if fp.kind == "plane" and abs(D - fp.moment) <= 1e-9 * I3:
            th = np.linspace(0, 2 * np.pi, 200)
            r = float(energy_ellipsoid_semi_axes(np.full(3, fp.moment), k)[0])
            return [
                r * (np.outer(np.cos(th), fp.basis[:, 0]) + np.outer(np.sin(th), fp.basis[:, 1]))
            ]
    return [body.polhode(body.point_on_polhode(k, a, sgn)).points for sgn in (1.0, -1.0)]


def plot_polhode_family(body, energy=0.5, *, levels=9, ax=None, n=300, omega=None,
                        omega_label="ω(t)"):  # fmt: skip
    """The polhode family on the energy ellipsoid (the notebook's sweep, k = ½, done exactly):
    closed curves around e1 and e3, the separatrices (black, dashed), stable fixed points
    (green dots) and unstable ones (red crosses), in components along the principal axes e1,
    e2, e3; ``omega`` (n, 3), a body-frame path (a run's ω(t)) drawn on it. Returns the
    figure.

    Examples
    --------
    >>> from poinsot.torquefree import FreeRigidBody
    >>> ax = plot_polhode_family(FreeRigidBody((1, 2, 3)), 0.5, levels=3).axes[0]
    >>> ax.get_xlabel(), ax.get_zlabel()
    ('ω·e₁ (I₁ = 1) [rad/s]', 'ω·e₃ (I₃ = 3) [rad/s]')
    """
    fig, ax = _axes3d(ax)
    I = body.principal_moments
    semi = energy_ellipsoid_semi_axes(np.asarray(I, float), float(energy))
    x, y, z = _ellipsoid_mesh(semi, np.eye(3))
    ax.plot_surface(x, y, z, color="0.7", alpha=0.12, linewidth=0)
    seen = set()
    stable_pts, unstable_pts = [], []
    for p in body.polhode_family(energy, levels=levels, n=n):
        if p.family == "fixed point":
            w = p.points[0]
            ok = body.stability(w).stable
            (stable_pts if ok else unstable_pts).append(w)
            continue
        if p.family == "spherical":
            continue
        style = FAMILY_STYLE.get(p.family, {"color": "gray"})
        label = None if p.family in seen else p.family
        seen.add(p.family)
        ax.plot(*body.principal_components(p.points).T, **style, label=label)
    for pts, kw in (
        (stable_pts, {"c": "green", "marker": "o", "s": 50, "label": "stable"}),
        (unstable_pts, {"c": "red", "marker": "X", "s": 80, "label": "unstable"}),
    ):
        if pts:
            arr = body.principal_components(np.array(pts))
            ax.scatter(*arr.T, depthshade=False, **kw)
    for fp in body.fixed_points():
        if fp.kind == "plane":
            e1, e2 = fp.basis[:, 0], fp.basis[:, 1]
            th = np.linspace(0, 2 * np.pi, 200)
            r = float(energy_ellipsoid_semi_axes(np.full(3, fp.moment), float(energy))[0])
            circ = r * (np.outer(np.cos(th), e1) + np.outer(np.sin(th), e2))
            ax.plot(*body.principal_components(circ).T, color="red", lw=2.5,
                    label="unstable plane of fixed points")  # fmt: skip
    if omega is not None:
        path = body.principal_components(omega)
        ax.plot(*path.T, color="crimson", lw=2.5, label=omega_label)
    ax.set_title(
        f"Polhodes on the energy ellipsoid, k = {energy:g} J, I = "
        + ", ".join(f"{v:.4g}" for v in I)
        + " kg·m²",
        fontsize=10,
    )
    _equal_3d(ax, 1.05 * semi.max(), I)
    _legend_3d(fig, ax)
    return fig


def plot_omega(t, omega, *, ax=None, exact=None, labels=("ω·e₁", "ω·e₂", "ω·e₃")):
    """ω(t) components (n, 3) against t [s]; ``exact`` (n, 3) overlaid dashed if given. The
    ``labels`` name the components (default: along the principal axes; give the body's
    ``("ω_x", "ω_y", "ω_z")`` for body-frame components)."""
    plt = _plt()
    if ax is None:
        fig, ax = plt.subplots(figsize=(8, 4))
    fig = ax.figure
    for i in range(3):
        (line,) = ax.plot(t, omega[:, i], label=labels[i])
        if exact is not None:
            ax.plot(
                t, exact[:, i], ls="--", color=line.get_color(), lw=1, label=f"{labels[i]} exact"
            )
    ax.set_xlabel("t [s]")
    ax.set_ylabel("ω [rad/s]")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    fig.tight_layout()
    return fig


def _box_edges(half):
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    corners = corners * half
    edges = [
        (i, j)
        for i in range(8)
        for j in range(i + 1, 8)
        if np.sum(np.abs(corners[i] - corners[j]) > 0) == 1
    ]
    return corners, edges


def plot_attitude_frames(Q, t=None, *, indices=None, axes=None, half_extents=(0.3, 0.5, 0.8),
                         about=None):  # fmt: skip
    """The body (a box with the given half extents, along its e1, e2, e3) and its axes at a few
    instants, one 3D panel each: attitudes ``Q`` (n, 3, 3). ``indices`` picks the samples
    (default: five evenly spaced); ``axes`` a sequence of 3D axes to draw into; ``about``: the
    point the axes e1, e2, e3 are principal about, for the title (e.g. ``"the centre of mass
    G"``), when they are principal axes. The axes are scaled to the body: the limits are the
    box's circumscribed radius (its arrows, 1.3 half extents long, included), the same in
    every panel, so the body fills them at any size."""
    plt = _plt()
    Q = np.asarray(Q)
    idx = np.linspace(0, len(Q) - 1, 5).astype(int) if indices is None else np.asarray(indices)
    if axes is None:
        fig = plt.figure(figsize=(2.6 * len(idx), 3.0))
        axes = [fig.add_subplot(1, len(idx), j + 1, projection="3d") for j in range(len(idx))]
    fig = axes[0].figure
    corners, edges = _box_edges(np.asarray(half_extents))
    colors = ("tab:red", "tab:green", "tab:blue")
    half = np.asarray(half_extents, dtype=float)
    arrows = 1.3 * np.maximum(half, 0.3 * half.max())  # a thin axis still gets a visible arrow
    r = 1.02 * max(float(np.linalg.norm(half)), float(arrows.max()))
    for ax, i in zip(axes, idx, strict=True):
        pts = corners @ Q[i].T
        for a, b in edges:
            ax.plot(*np.array([pts[a], pts[b]]).T, color="0.3", lw=1)
        for k in range(3):
            ax.quiver(0, 0, 0, *(Q[i][:, k] * arrows[k]), color=colors[k], lw=2)
        for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
            setter(-r, r)
        ax.set_box_aspect((1, 1, 1))
        ax.set_axis_off()
        if t is not None:
            ax.set_title(f"t = {t[i]:.3g} s", fontsize=10)
    which = f": the principal axes about {about}" if about else ""
    fig.suptitle(f"Body attitude (red e₁, green e₂, blue e₃{which}); panels ±{r:.3g} m")
    return fig


def animate_tumbling(Q, t, path, *, half_extents=(0.3, 0.5, 0.8), fps=20, angular_momentum=None):
    """Animate the tumbling body (attitudes ``Q`` (n, 3, 3) at times ``t``) to ``path``:
    ``.gif`` (Pillow), ``.mp4`` (needs ffmpeg) or ``.html`` (self-contained JavaScript player).
    The file is written atomically. Returns the path."""
    suffix = str(path).rsplit(".", 1)[-1].lower()
    if suffix not in ("gif", "mp4", "html"):
        raise ValueError(f"`path` must end in .gif, .mp4 or .html, found {str(path)!r}")
    plt = _plt()
    from matplotlib import animation

    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")
    corners, edges = _box_edges(np.asarray(half_extents))
    lines = [ax.plot([], [], [], color="0.25", lw=1.5)[0] for _ in edges]
    axes_lines = [
        ax.plot([], [], [], color=c, lw=3)[0] for c in ("tab:red", "tab:green", "tab:blue")
    ]
    if angular_momentum is not None:
        L = np.asarray(angular_momentum, float)
        L = L / np.linalg.norm(L)
        ax.plot([0, 1.2 * L[0]], [0, 1.2 * L[1]], [0, 1.2 * L[2]], color="k", ls=":", label="L")
        legend_outside(ax, bbox_to_anchor=(0.98, 0.98))
    r = 1.1 * float(np.linalg.norm(half_extents))
    for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setter(-r, r)
    ax.set_box_aspect((1, 1, 1))
    title = ax.set_title("")

    def frame(i):
        pts = corners @ Q[i].T
        for line, (a, b) in zip(lines, edges, strict=True):
            seg = np.array([pts[a], pts[b]])
            line.set_data(seg[:, 0], seg[:, 1])
            line.set_3d_properties(seg[:, 2])
        for k, line in enumerate(axes_lines):
            tip = Q[i][:, k] * r * 0.9
            line.set_data([0, tip[0]], [0, tip[1]])
            line.set_3d_properties([0, tip[2]])
        title.set_text(f"t = {t[i]:.2f} s")
        return [*lines, *axes_lines, title]

    anim = animation.FuncAnimation(fig, frame, frames=len(Q), interval=1000 / fps, blit=False)
    try:
        with atomic_path(path) as tmp:
            if suffix == "html":
                tmp.write_text(anim.to_jshtml(fps=fps), encoding="utf-8")
            elif suffix == "gif":
                anim.save(tmp, writer=animation.PillowWriter(fps=fps))
            else:
                anim.save(tmp, writer=animation.FFMpegWriter(fps=fps))
    finally:
        plt.close(fig)
    return path
