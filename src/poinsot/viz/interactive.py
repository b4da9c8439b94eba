"""Interactive (plotly) figures of the torque-free body; needs the ``report`` extra.

The same constructions as :mod:`poinsot.viz.torquefree`, as ``plotly.graph_objects.Figure``
objects: rotate them in a browser, or ``fig.write_html(path)``. As there, angular velocities
are drawn by their components along the sorted principal axes e1, e2, e3.
"""

from __future__ import annotations

import numpy as np

from ..torquefree import energy_ellipsoid_semi_axes, momentum_ellipsoid_semi_axes

__all__ = [
    "SCENE_CAMERA",
    "energy_ellipsoid_figure",
    "ensemble_histograms_figure",
    "omega_scene",
    "polhode_family_figure",
    "relative_figure",
]

COLORS = {
    "around e1": "#1f77b4",
    "around e3": "#ff7f0e",
    "separatrix": "black",
    "symmetric": "#9467bd",
}


#: A 3D scene's camera far enough out that no tick or axis label is clipped at its edges.
SCENE_CAMERA = {"eye": {"x": 1.55, "y": 1.55, "z": 1.05}}


def omega_scene(moments=None) -> dict:
    """3D axes of angular velocity, components along the principal axes e1, e2, e3."""
    names = [f"ω·e{'₁₂₃'[k]}" + (f" (I{'₁₂₃'[k]} = {moments[k]:.4g})" if moments is not None
                                 else "") + " [rad/s]" for k in range(3)]  # fmt: skip
    return {"aspectmode": "data", "xaxis_title": names[0], "yaxis_title": names[1],
            "zaxis_title": names[2], "camera": SCENE_CAMERA}  # fmt: skip


def _go():
    try:
        import plotly.graph_objects as go
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("interactive figures need plotly: pip install 'poinsot[report]'") from exc
    return go


def _ellipsoid(go, semi, axes, color, name, opacity=0.25):
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 48), np.linspace(0, np.pi, 24))
    unit = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], -1)
    pts = (unit * semi) @ axes.T
    return go.Surface(
        x=pts[..., 0],
        y=pts[..., 1],
        z=pts[..., 2],
        opacity=opacity,
        showscale=False,
        colorscale=[[0, color], [1, color]],
        name=name,
        showlegend=True,
        hoverinfo="skip",
    )


def _line(go, pts, family, show):
    return go.Scatter3d(
        x=pts[:, 0],
        y=pts[:, 1],
        z=pts[:, 2],
        mode="lines",
        name=family,
        legendgroup=family,
        showlegend=show,
        line={
            "color": COLORS.get(family, "gray"),
            "width": 5 if family == "separatrix" else 2,
            "dash": "dash" if family == "separatrix" else "solid",
        },
    )


def polhode_family_figure(body, energy=0.5, *, levels=9, omega=None, n=200):
    """The polhode family on the energy ellipsoid with fixed points (green stable, red
    unstable) and, if given, a path ``omega`` (n, 3, body frame), in components along the
    principal axes. ``body`` is a :class:`~poinsot.torquefree.FreeRigidBody`. Returns a
    plotly figure."""
    go = _go()
    k = float(energy)
    semi = energy_ellipsoid_semi_axes(body.principal_moments, k)
    data = [_ellipsoid(go, semi, np.eye(3), "#9ecae1", "energy ellipsoid")]
    shown = set()
    stable, unstable = [], []
    for p in body.polhode_family(k, levels=levels, n=n):
        if p.family == "fixed point":
            (stable if body.stability(p.points[0]).stable else unstable).append(p.points[0])
        elif p.family != "spherical":
            pts = body.principal_components(p.points)
            data.append(_line(go, pts, p.family, p.family not in shown))
            shown.add(p.family)
    for pts, color, symbol, name in (
        (stable, "green", "circle", "stable fixed points"),
        (unstable, "red", "diamond", "unstable fixed points"),
    ):
        if pts:
            arr = body.principal_components(np.array(pts))
            data.append(
                go.Scatter3d(
                    x=arr[:, 0],
                    y=arr[:, 1],
                    z=arr[:, 2],
                    mode="markers",
                    marker={"size": 6, "color": color, "symbol": symbol},
                    name=name,
                )
            )
    if omega is not None:
        w = body.principal_components(omega)
        data.append(
            go.Scatter3d(
                x=w[:, 0],
                y=w[:, 1],
                z=w[:, 2],
                mode="lines",
                line={"color": "crimson", "width": 6},
                name="ω(t)",
            )
        )
    fig = go.Figure(data=data)
    fig.update_layout(
        title=f"Polhodes on the energy ellipsoid, k = {k:.4g} J",
        height=640,
        scene=omega_scene(body.principal_moments),
    )
    return fig


def energy_ellipsoid_figure(body, energy, momentum):
    """The energy ellipsoid, the momentum ellipsoid, the cone (32) and their intersection for
    invariants ``(k, a)`` (refused with the numbers when infeasible, (33))."""
    from .torquefree import _intersection

    go = _go()
    k, a = float(energy), float(momentum)
    D = body.check_feasible(k, a)
    I = body.principal_moments
    E = np.eye(3)  # principal components: the ellipsoids' axes are the plot's axes
    data = [
        _ellipsoid(go, energy_ellipsoid_semi_axes(I, k), E, "#9ecae1", "energy ellipsoid"),
        _ellipsoid(
            go, momentum_ellipsoid_semi_axes(I, a), E, "#a1d99b", "momentum ellipsoid", 0.15
        ),
    ]
    curves = [body.principal_components(c) for c in _intersection(body, k, a)]
    s = np.linspace(-1.35, 1.35, 25)
    if body.symmetry != "spherical":
        for i, pts in enumerate(curves):
            if len(pts) > 1:
                X, Y, Z = (s[:, None] * pts[None, :, c] for c in range(3))
                data.append(
                    go.Surface(
                        x=X,
                        y=Y,
                        z=Z,
                        opacity=0.3,
                        showscale=False,
                        colorscale=[[0, "#fc9272"], [1, "#fc9272"]],
                        name="cone (32)",
                        showlegend=i == 0,
                        hoverinfo="skip",
                    )
                )
    for i, pts in enumerate(curves):
        data.append(
            go.Scatter3d(
                x=pts[:, 0],
                y=pts[:, 1],
                z=pts[:, 2],
                mode="lines+markers" if len(pts) == 1 else "lines",
                line={"color": "crimson", "width": 7},
                name="polhode (intersection)",
                showlegend=i == 0,
            )
        )
    fig = go.Figure(data=data)
    fig.update_layout(
        title=f"Energy ellipsoid ∩ cone, k = {k:.4g} J, a²/2k = {D:.4g} kg·m²",
        height=640,
        scene=omega_scene(I),
    )
    return fig


def ensemble_histograms_figure(result):
    """Histograms of an ensemble's per-member statistics (those of
    :func:`poinsot.viz.ensemble.plot_ensemble_histograms`), one subplot each, errors on
    logarithmic axes."""
    from plotly.subplots import make_subplots

    from .ensemble import LABELS, _values

    go = _go()
    names = [n for n in LABELS if _values(result, n)[0].size]
    if not names:
        raise ValueError("the ensemble has no statistic with a finite value to draw")
    cols = min(3, len(names))
    rows = -(-len(names) // cols)
    fig = make_subplots(rows=rows, cols=cols, subplot_titles=[LABELS[n][0] for n in names],
                        horizontal_spacing=0.08)  # fmt: skip
    for k, name in enumerate(names):
        values, _ = _values(result, name)
        log = LABELS[name][1]
        if log:
            values = np.log10(values[values > 0])
        fig.add_trace(go.Histogram(x=values, nbinsx=40, name=name, showlegend=False),
                      row=k // cols + 1, col=k % cols + 1)  # fmt: skip
        fig.update_xaxes(title_text="log₁₀ of the value" if log else LABELS[name][0],
                         row=k // cols + 1, col=k % cols + 1)  # fmt: skip
        fig.update_yaxes(title_text="members", row=k // cols + 1, col=k % cols + 1)
    fig.update_layout(title=f"{len(result)} members, {result.method}")
    legend_per_subplot(fig, cols=cols)
    return fig


def relative_figure(sol):
    """A motion relative to a carrier, both views: ω_r (relative, body axes) and the absolute
    ω (dashed), and the relative energy, against time."""
    from plotly.subplots import make_subplots

    go = _go()
    fig = make_subplots(rows=1, cols=2, horizontal_spacing=0.1, subplot_titles=(
        "ω relative to the carrier (solid) and in space (dashed), body axes",
        "relative energy ½ ω_r·Jω_r"))  # fmt: skip
    colors = ("#1f77b4", "#ff7f0e", "#2ca02c")
    for k, c in enumerate("xyz"):
        fig.add_trace(go.Scatter(x=sol.t, y=sol.omega_r[:, k], name=f"ω_r,{c}",
                                 line={"color": colors[k]}), row=1, col=1)  # fmt: skip
        dashed = {"color": colors[k], "dash": "dash"}
        fig.add_trace(go.Scatter(x=sol.t, y=sol.omega_absolute[:, k], name=f"ω_{c} absolute",
                                 line=dashed), row=1, col=1)  # fmt: skip
    fig.add_trace(go.Scatter(x=sol.t, y=sol.relative_energy, name="T_r"), row=1, col=2)
    fig.update_yaxes(title_text="ω [rad/s]", row=1, col=1)
    fig.update_yaxes(title_text="T_r [J]", row=1, col=2)
    fig.update_xaxes(title_text="t [s]")
    legend_per_subplot(fig, cols=2, top=60)
    return fig


#: Pixel sizes of a row of subplots (:func:`legend_per_subplot`): subplot title, plot,
#: tick labels with the x-axis title, one legend entry, gap between rows.
_ROW_PX = {"title": 40, "plot": 270, "axis": 62, "entry": 20, "gap": 18}


def legend_per_subplot(fig, cols=2, top=80) -> None:
    """Give each subplot its own legend (plotly's ``legend2``…), below its plotting area and
    its x-axis title, and size the figure so that every row of subplots has room for its
    title, plot, axis labels and legend: a legend never covers a curve. ``cols``: the
    columns of the ``make_subplots`` grid; ``top``: the margin above, for the title."""
    by_axes = {}
    for trace in fig.data:
        by_axes.setdefault((trace.xaxis or "x", trace.yaxis or "y"), []).append(trace)
    index = {key: int(key[0][1:] or 1) - 1 for key in by_axes}  # x, x2, …: row-major
    rows = max(index.values()) // cols + 1 if index else 1
    entries = [0] * rows
    for key, traces in by_axes.items():
        shown = sum(1 for t in traces if t.showlegend is not False)
        entries[index[key] // cols] = max(entries[index[key] // cols], shown)
    px = _ROW_PX
    heights = [px["title"] + px["plot"] + px["axis"] + px["entry"] * n + px["gap"]
               for n in entries]  # fmt: skip
    area = sum(heights)
    y = 1.0
    tops = []
    for r in range(rows):
        upper = y - px["title"] / area
        tops.append(upper)
        for c in range(cols):
            k = r * cols + c
            axis = fig.layout[f"yaxis{k + 1 if k else ''}"]
            if axis is not None:
                axis.domain = [upper - px["plot"] / area, upper]
        y -= heights[r] / area
    titles = [a for a in fig.layout.annotations if a.yref == "paper" and a.yanchor == "bottom"]
    for k, a in enumerate(titles):  # make_subplots' subplot titles, in subplot order
        a.y = tops[k // cols]
    for n, (key, traces) in enumerate(by_axes.items()):
        name = "legend" if n == 0 else f"legend{n + 1}"
        xa, ya = key
        xdom = fig.layout[f"xaxis{xa[1:]}"].domain or (0, 1)
        ydom = fig.layout[f"yaxis{ya[1:]}"].domain or (0, 1)
        for trace in traces:
            trace.legend = name
        fig.layout[name] = {"x": xdom[0], "y": ydom[0] - px["axis"] / area, "xanchor": "left",
                            "yanchor": "top", "orientation": "v", "font": {"size": 10},
                            "bgcolor": "rgba(255,255,255,0)"}  # fmt: skip
    fig.update_layout(height=int(area + top + 10), margin={"t": top, "b": 10})
