"""A self-contained HTML report of a run.

With the ``report`` extra (plotly), one interactive page, plotly.js inlined by default (opens
with no network; see :data:`PLOTLYJS_MODES` for the smaller choices): the body tumbling in 3D
(animated), ω on the energy ellipsoid with the polhode family, the time series, and the
numbers, grouped, named and with units (:mod:`poinsot.viz.numbers`). Without plotly,
:func:`write_static_report` writes the same numbers with the run's matplotlib figures, and says
how to get the interactive page (:data:`STATIC_NOTE`).
"""

from __future__ import annotations

import html
import json

import numpy as np

from .._io import atomic_write_text
from .interactive import SCENE_CAMERA, legend_per_subplot

__all__ = [
    "PLOTLYJS_MODES",
    "STATIC_NOTE",
    "interactive_available",
    "write_ensemble_report",
    "write_figures_page",
    "write_identify_report",
    "write_lagrangian_report",
    "write_report",
    "write_static_report",
]

MAX_FRAMES = 120


#: What a static report says of itself (and the command line, when it writes one).
STATIC_NOTE = (
    "report.html is a static page (the run's figures and numbers): the interactive figures "
    "need plotly, which is not installed (pip install 'poinsot[report]')"
)


def interactive_available() -> bool:
    """Whether the interactive report can be written: plotly (the ``report`` extra) imports."""
    try:
        import plotly.graph_objects  # noqa: F401
    except ImportError:
        return False
    return True


def _plotly():
    try:
        import plotly.graph_objects as go
        import plotly.io as pio
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("the HTML report needs plotly: pip install 'poinsot[report]'") from exc
    return go, pio


def _box_lines(half):
    """Vertices (closed polyline through the 12 edges, None-separated) of a box."""
    c = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    edges = [
        (i, j) for i in range(8) for j in range(i + 1, 8) if np.sum(np.abs(c[i] - c[j]) > 0) == 1
    ]
    return c, edges


def _body_figure(traj, go):
    """The body's equivalent box and its principal axes e₁, e₂, e₃ about its centre of mass G
    (those of the report's body table), animated. A body on a pivot is drawn in space
    coordinates, as the trajectory and the numbers give them: the box at the centre of mass
    R(t), the pivot P at the fixed position the library gives it, and the segment P → G. A
    free body is drawn about its centre of mass (its path has a figure of its own), on axes
    that say so: x − x_G, y − y_G, z − z_G."""
    body = traj.body
    E = body.principal_axes
    half = np.maximum(body.equivalent_box_half_extents, 1e-3 * max(1.0, body.mass))
    corners, edges = _box_lines(half)
    idx = _frame_indices(len(traj.t))
    particles = body.u if body.has_particles else None
    pivot = traj.pivot_position  # in space (fixed), or None for a free body

    def traces(i):
        Q = traj.Q[i]
        R = traj.R[i] if pivot is not None else np.zeros(3)
        pts = (corners @ E.T) @ Q.T + R  # box in principal axes, then attitude and position
        out = [_box_trace(go, pts, edges), *_axes_traces(go, Q, R, E, half)]
        if pivot is not None:
            out.append(_pivot_trace(go, pivot, R))
        if particles is not None:
            out.append(_particles_trace(go, particles @ Q.T + R))
        return out

    fig = go.Figure(
        data=traces(idx[0]), frames=[go.Frame(data=traces(i), name=str(i)) for i in idx]
    )
    reach = 1.4 * float(np.max(half)) + (
        float(np.linalg.norm(traj.system.c)) if pivot is not None else 0.0
    )
    if particles is not None:
        reach = max(reach, float(np.max(np.linalg.norm(particles, axis=1))) * 1.15)
    if pivot is not None:  # space coordinates, centred on the pivot
        axes = {f"{c}axis": {"range": [pivot[k] - reach, pivot[k] + reach], "title": f"{c} [m]"}
                for k, c in enumerate("xyz")}  # fmt: skip
        where = f"about the fixed pivot P at {_position(pivot)} m, in space coordinates"
    else:  # about the centre of mass
        axes = {f"{c}axis": {"range": [-reach, reach], "title": f"{c} − {c}_G [m]"}
                for c in "xyz"}  # fmt: skip
        where = "about its centre of mass G, on axes relative to G"
    fig.update_layout(
        title=f"Body attitude {where} (animated)<br>red e₁, green e₂, blue e₃: the principal "
        "axes about the centre of mass G (the body table's)",
        scene={**axes, "aspectmode": "cube", "camera": SCENE_CAMERA},
        height=640,
        **_animation_controls(fig.frames, traj.t[idx]),
    )
    return fig


def _position(p) -> str:
    """A position as the numbers table shows one: ``(0, 0, -0.5)``, round-off shown as 0."""
    from .numbers import format_value

    return format_value([float(x) for x in p], digits=4)


def _box_trace(go, pts, edges):
    """The equivalent box's edges through its placed corners ``pts``, as one None-separated
    polyline."""
    xs, ys, zs = [], [], []
    for a, b in edges:
        for p in (pts[a], pts[b]):
            xs.append(p[0])
            ys.append(p[1])
            zs.append(p[2])
        xs.append(None)
        ys.append(None)
        zs.append(None)
    return go.Scatter3d(
        x=xs,
        y=ys,
        z=zs,
        mode="lines",
        line={"color": "#444", "width": 4},
        name="body (equivalent box)",
    )


def _axes_traces(go, Q, R, E, half):
    """The principal axes e₁, e₂, e₃ about the centre of mass (red, green, blue) from the
    centre of mass ``R``, turned by ``Q``, each 1.3 times the box's half extent."""
    out = []
    for k, color in enumerate(("#d62728", "#2ca02c", "#1f77b4")):
        tip = R + Q @ E[:, k] * 1.3 * half[k]
        out.append(
            go.Scatter3d(
                x=[R[0], tip[0]],
                y=[R[1], tip[1]],
                z=[R[2], tip[2]],
                mode="lines",
                line={"color": color, "width": 7},
                name=f"e{'₁₂₃'[k]} (principal axis about G)",
            )
        )
    return out


def _pivot_trace(go, P, R):
    """The segment from the fixed pivot ``P`` to the centre of mass ``R`` (space)."""
    return go.Scatter3d(
        x=[P[0], R[0]],
        y=[P[1], R[1]],
        z=[P[2], R[2]],
        mode="lines+markers",
        line={"color": "#8c564b", "width": 5},
        marker={"size": [5, 2]},
        name="pivot P → centre of mass G",
    )


def _particles_trace(go, P):
    """The body's particles at their placed positions ``P`` (n × 3)."""
    return go.Scatter3d(
        x=P[:, 0],
        y=P[:, 1],
        z=P[:, 2],
        mode="markers",
        marker={"size": 3, "color": "#ff7f0e"},
        name="particles",
    )


def _frame_indices(n: int):
    """At most :data:`MAX_FRAMES` sample indices, evenly spread, first and last included."""
    return np.unique(np.linspace(0, n - 1, min(n, MAX_FRAMES)).round().astype(int))


def _animation_controls(frames, times) -> dict:
    """Play/pause buttons and a time slider for a plotly figure's ``frames`` (named by their
    index, so that equal rounded times cannot collide), labelled by ``times`` [s]. Both sit
    under the plot, the buttons left of the slider: neither covers the other, nor the plot;
    the bottom margin makes room for them."""
    return {
        "margin": {"b": 150},
        "updatemenus": [
            {
                "type": "buttons",
                "showactive": False,
                "direction": "down",
                "x": 0.0,
                "y": 0.0,
                "xanchor": "left",
                "yanchor": "top",
                "pad": {"t": 45, "r": 10},
                "buttons": [
                    {
                        "label": "▶ play",
                        "method": "animate",
                        "args": [
                            None,
                            {"frame": {"duration": 60, "redraw": True}, "fromcurrent": True},
                        ],
                    },
                    {
                        "label": "❚❚ pause",
                        "method": "animate",
                        "args": [[None], {"mode": "immediate", "frame": {"duration": 0}}],
                    },
                ],
            }
        ],
        "sliders": [
            {
                "x": 0.12,
                "len": 0.88,
                "y": 0.0,
                "xanchor": "left",
                "yanchor": "top",
                "pad": {"t": 35, "b": 10},
                "currentvalue": {"prefix": "t [s] = "},
                "steps": [
                    {
                        "label": f"{t:.4g}",
                        "method": "animate",
                        "args": [
                            [f.name],
                            {"mode": "immediate", "frame": {"duration": 0, "redraw": True}},
                        ],
                    }
                    for f, t in zip(frames, times, strict=True)
                ],
            }
        ],
    }


def _polhode_figure(traj, go, free, levels):
    """The run's own ω(t), unscaled, on its own energy ellipsoid with the polhodes there."""
    from ..conservation import rotational_energy
    from .interactive import polhode_family_figure

    w = traj.omega
    k = float(rotational_energy(traj.body.inertia, np.ascontiguousarray(w[0])))
    fig = polhode_family_figure(free, k, levels=levels, omega=w)
    fig.update_layout(
        title=f"This run's ω(t) on its energy ellipsoid (k = {k:.4g} J), with the polhodes "
        "at that energy; ω along the principal axes e₁, e₂, e₃"
    )
    return fig


def _series_figure(traj, go):
    """ω(t); the relative change of what this problem conserves (integration error), or the
    energy in joules when it conserves nothing; the distance of the attitude from SO(3)."""
    from plotly.subplots import make_subplots

    kept = [i for i in traj.invariants if i.conserved]
    lost = [i for i in traj.invariants if not i.conserved]
    middle = ("Conserved by this problem: relative change" if kept
              else "Total energy: not conserved here (forces do work)")  # fmt: skip
    from .trajectory import omega_axes, omega_components

    names, point = omega_axes(traj)
    fig = make_subplots(rows=1, cols=3, horizontal_spacing=0.09, subplot_titles=(
        f"ω along the principal axes about {point}", middle,
        "Attitude: distance from a rotation"))  # fmt: skip
    w, labels = omega_components(traj)
    for i, name in enumerate(labels):
        fig.add_trace(go.Scatter(x=traj.t, y=w[:, i], name=name), row=1, col=1)
    tiny = 1e-17
    if kept:
        for inv in kept:
            fig.add_trace(go.Scatter(x=traj.t, y=inv.change + tiny,
                                     name=f"{inv.symbol} [{inv.unit}]"), row=1, col=2)  # fmt: skip
        fig.update_yaxes(type="log", title_text="relative change |x(t) − x(0)| / scale",
                         row=1, col=2)  # fmt: skip
    else:
        E = traj.total_energy
        fig.add_trace(go.Scatter(x=traj.t, y=E - E[0], name="E(t) − E(0)"), row=1, col=2)
        fig.update_yaxes(title_text="E(t) − E(0) [J]", row=1, col=2)
    fig.add_trace(go.Scatter(x=traj.t, y=traj.orthogonality_error + tiny,
                             name="max |QᵀQ − I|"), row=1, col=3)  # fmt: skip
    fig.update_yaxes(type="log", title_text="max |QᵀQ − I| (dimensionless)", row=1, col=3)
    fig.update_yaxes(title_text=f"ω along {', '.join(names)} [rad/s]", row=1, col=1)
    fig.update_xaxes(title_text="t [s]")
    note = ("Not conserved here: " + "; ".join(f"{i.symbol} ({i.reason})" for i in lost)
            if lost else None)  # fmt: skip
    fig.update_layout(title=note)
    legend_per_subplot(fig, cols=3)
    return fig


def _comparison_figure(t, errors, go):
    """The plotly twin of :func:`poinsot.viz.plot_method_comparison`."""
    from plotly.subplots import make_subplots

    from .trajectory import COMPARISON_PANELS

    fig = make_subplots(rows=1, cols=3, subplot_titles=[p[1] for p in COMPARISON_PANELS],
                        horizontal_spacing=0.09)  # fmt: skip
    tiny = 1e-17
    for col, (key, _, ylabel) in enumerate(COMPARISON_PANELS, start=1):
        drawn = []  # (label, values) already on this panel
        for n, (label, rows) in enumerate(errors.items()):
            if key in rows:
                y = np.asarray(rows[key], dtype=float)
                same = next((o for o, v in drawn if np.allclose(v, y, rtol=1e-9, atol=0)), None)
                dash = "dash" if label.startswith("exact") else "solid"
                line = {"color": _COLORS[n % len(_COLORS)], "dash": dash}
                shown = label
                if same is not None:  # on top of another curve: dotted, wider, and said so
                    line |= {"dash": "dot", "width": 4}
                    shown = f"{label} (the same as {same})"
                trace = go.Scatter(x=t, y=y + tiny, name=shown, line=line)
                fig.add_trace(trace, row=1, col=col)
                drawn.append((label, y))
        fig.update_yaxes(type="log", title_text=ylabel, row=1, col=col)
    fig.update_xaxes(title_text="t [s]")
    fig.update_layout(title="Integrators against the exact torque-free solution, same step")
    legend_per_subplot(fig, cols=3)
    return fig


_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd")


def _top_figure(motion, go):
    """A top's nutation θ(t) with its band and its precession ψ(t) with the mean rate, the
    gyroscopic estimate and the steady precession (the plotly twin of
    :func:`poinsot.viz.trajectory.plot_attitude`)."""
    from plotly.subplots import make_subplots

    m = motion
    t = m.t
    lo, hi = m.theta_band
    fig = make_subplots(rows=1, cols=2, horizontal_spacing=0.1, subplot_titles=(
        _wrapped("Nutation: θ, the angle of the symmetry axis a from the upward vertical"),
        _wrapped(f"Precession ψ (unwrapped): {m.psi_reference()}")))  # fmt: skip
    band = go.Scatter(x=[t[0], t[-1], t[-1], t[0], t[0]], y=[lo, lo, hi, hi, lo], fill="toself",
                      mode="lines", line={"width": 0}, fillcolor="rgba(31,119,180,0.15)",
                      name=f"nutation band {lo:.4g} – {hi:.4g} rad")  # fmt: skip
    fig.add_trace(band, row=1, col=1)
    fig.add_trace(go.Scatter(x=t, y=m.theta, name="θ(t)", line={"color": "#1f77b4"}),
                  row=1, col=1)  # fmt: skip
    fig.add_trace(go.Scatter(x=t, y=m.psi, name="ψ(t)", line={"color": "#2ca02c"}), row=1, col=2)
    e = m.exact
    if e is not None:  # the closed form from the same initial state (tops.exact_motion)
        elo, ehi = e.theta_band
        fig.add_trace(go.Scatter(x=[t[0], t[-1], None, t[0], t[-1]], y=[elo, elo, None, ehi, ehi],
                                 mode="lines", line={"color": "black", "dash": "dot", "width": 1},
                                 name=f"exact band {elo:.6g} – {ehi:.6g} rad"),
                      row=1, col=1)  # fmt: skip
        fig.add_trace(go.Scatter(x=t, y=e.theta, name="θ exact", line={"color": "black",
                                 "dash": "dot", "width": 1}), row=1, col=1)  # fmt: skip
    for rate, dash, color, name in (
        (m.mean_precession_rate, "dash", "black", "mean rate (fit of ψ)"),
        (
            np.nan if e is None else e.mean_precession_rate,
            "longdash",
            "#8c564b",
            "exact mean rate (closed form)",
        ),
        (m.gyroscopic_rate, "dot", "#d62728", "gyroscopic M g l/(C ω·a)"),
        (m.steady_rates[0], "dashdot", "#9467bd", "steady precession at mean θ"),
    ):
        if np.isfinite(rate):
            style = {"dash": dash, "color": color, "width": 1.5}
            line = go.Scatter(x=t, y=m.psi[0] + rate * (t - t[0]),
                              name=f"{name}: {rate:.5g} rad/s", line=style)  # fmt: skip
            fig.add_trace(line, row=1, col=2)
    fig.update_yaxes(title_text="θ [rad]", row=1, col=1)
    fig.update_yaxes(title_text="ψ [rad]", row=1, col=2)
    fig.update_xaxes(title_text="t [s]")
    legend_per_subplot(fig, cols=2, top=60 + 20 * _extra_lines(fig))
    return fig


#: The most characters on one line of a title over half a report's width (two panels side by
#: side, 1200 px): longer titles are wrapped (:func:`_wrapped`), never run into the next one.
HALF_WIDTH_CHARS = 60


def _wrapped(text: str, width: int = HALF_WIDTH_CHARS) -> str:
    """``text`` on lines of at most ``width`` characters (plotly's ``<br>``), words unbroken."""
    import textwrap

    return "<br>".join(textwrap.wrap(text, width, break_long_words=False))


def _extra_lines(fig) -> int:
    """How many lines the longest subplot title of ``fig`` has beyond its first."""
    return max((a.text.count("<br>") for a in fig.layout.annotations), default=0)


def _axis_trace_figure(trace, go):
    """The symmetry axis's direction on the unit sphere: the nutation loops."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 48), np.linspace(0, np.pi, 24))
    sphere = go.Surface(x=np.cos(u) * np.sin(v), y=np.sin(u) * np.sin(v), z=np.cos(v),
                        opacity=0.12, showscale=False, colorscale=[[0, "#999"], [1, "#999"]],
                        hoverinfo="skip", name="unit sphere", showlegend=True)  # fmt: skip
    path = go.Scatter3d(x=trace[:, 0], y=trace[:, 1], z=trace[:, 2], mode="lines",
                        line={"color": "#1f77b4", "width": 5},
                        name="symmetry axis a (tip → centre of mass)")  # fmt: skip
    ends = go.Scatter3d(x=trace[[0, -1], 0], y=trace[[0, -1], 1], z=trace[[0, -1], 2],
                        mode="markers", marker={"size": 5, "color": ["green", "red"]},
                        name="start (green), end (red)")  # fmt: skip
    fig = go.Figure(data=[sphere, path, ends])
    scene = {f"{c}axis": {"range": [-1.05, 1.05], "title": f"{c} (dimensionless)"} for c in "xyz"}
    fig.update_layout(title="The direction of the symmetry axis a on the unit sphere: "
                      "precession and nutation loops", height=640,
                      scene={**scene, "aspectmode": "cube", "camera": SCENE_CAMERA})  # fmt: skip
    return fig


def write_report(
    path,
    traj,
    summary: dict,
    *,
    free=None,
    levels=7,
    comparison=None,
    top=None,
    top_axis=None,
    plotlyjs="inline",
) -> None:
    """Write the interactive report for ``traj`` to ``path`` (atomically); ``comparison``:
    the per-sample errors of :func:`poinsot.app.runs.rigid.compare_methods`, drawn second;
    ``top``: a heavy top's :class:`~poinsot.tops.TopMotion` (its nutation and precession);
    ``top_axis``: that top's symmetry axis a (body frame, from the tip towards the centre of
    mass: :attr:`poinsot.tops.HeavyTop.axis`), whose direction is traced on the unit sphere
    (no trace without it); ``plotlyjs``: one of :data:`PLOTLYJS_MODES`."""
    go, pio = _plotly()
    figures = [_body_figure(traj, go)]
    if top is not None:
        figures.append(_top_figure(top, go))
    if top_axis is not None:
        figures.append(_axis_trace_figure(traj.axis_trace(top_axis), go))
    if comparison is not None:
        figures.append(_comparison_figure(traj.t, comparison, go))
    if free is not None and np.any(traj.omega[0]):
        figures.append(_polhode_figure(traj, go, free, levels))
    figures.append(_series_figure(traj, go))
    _write_page(path, figures, summary, pio, plotlyjs=plotlyjs)


def _mechanism_figure(model, sol, go):
    """The mechanism animated from the model's geometry (points, links, outlines), with a
    slider and a play button; metres on equal axes."""
    names, P = model.positions(sol)
    index = {n: k for k, n in enumerate(names)}
    idx = _frame_indices(len(sol.t))
    three = model.view == "3d"
    Scatter = go.Scatter3d if three else go.Scatter
    ends = [k for k, n in enumerate(names) if "#" not in n]  # '#' points get no marker

    def coords(pts):
        keys = ("x", "y", "z") if three else ("x", "y")
        return {k: pts[:, j] for j, k in enumerate(keys)}

    def segments(i):
        xs = []
        for a, b in model.links:
            xs += [P[i, index[a]], P[i, index[b]], np.full(3, np.nan)]
        return np.array(xs) if xs else np.zeros((0, 3))

    # labels left of the points left of centre, right of the others: neighbours do not overlap
    centre = P[0, ends, 0].mean()
    sides = ["middle left" if P[0, k, 0] < centre - 1e-12 else "middle right" for k in ends]

    def traces(i):
        return [
            Scatter(**coords(segments(i)), mode="lines", line={"color": "#1f3f99", "width": 4},
                    name="links", connectgaps=False),
            Scatter(**coords(P[i, ends]), mode="markers+text", text=[names[k] for k in ends],
                    textposition=sides, marker={"size": 8, "color": "#d62728"}, name="points"),
        ]  # fmt: skip

    static = [
        Scatter(**coords(pts), mode="lines", line={"color": "#999", "dash": "dash"}, name=name)
        for name, pts in model.outlines(sol.params).items()
    ]
    if model.trail is not None:
        static.append(Scatter(**coords(P[:, index[model.trail]]), mode="lines",
                              line={"color": "#e0a040", "width": 2},
                              name=f"path of the {model.trail}"))  # fmt: skip
    fig = go.Figure(
        data=traces(idx[0]) + static,
        frames=[go.Frame(data=traces(i), name=str(i), traces=[0, 1]) for i in idx],
    )
    everything = np.concatenate([P.reshape(-1, 3), *model.outlines(sol.params).values()])
    lo, hi = np.nanmin(everything, 0), np.nanmax(everything, 0)
    mid, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-3) * 1.1
    ranges = {c: [mid[j] - half, mid[j] + half] for j, c in enumerate("xyz")}
    title = f"{model.description} (animated)"
    if three:
        fig.update_layout(scene={**{f"{c}axis": {"range": ranges[c], "title": f"{c} [m]"}
                                    for c in "xyz"}, "aspectmode": "cube",
                                 "camera": SCENE_CAMERA})  # fmt: skip
    else:
        fig.update_xaxes(range=ranges["x"], title_text="x [m]")
        fig.update_yaxes(range=ranges["y"], title_text="y [m]", scaleanchor="x", scaleratio=1)
    fig.update_layout(title=title, height=640, **_animation_controls(fig.frames, sol.t[idx]))
    return fig


def _panels_figure(panels, go, title=None):
    """Plotly subplots of :func:`poinsot.viz.lagrange.lagrangian_panels`, two per row,
    each with its own legend."""
    from plotly.subplots import make_subplots

    rows = (len(panels) + 1) // 2
    fig = make_subplots(rows=rows, cols=2, subplot_titles=[p[0] for p in panels],
                        horizontal_spacing=0.12)  # fmt: skip
    for n, (_, ylabel, log, curves) in enumerate(panels):
        row, col = n // 2 + 1, n % 2 + 1
        for label, x, y in curves:
            fig.add_trace(go.Scatter(x=x, y=y, name=label), row=row, col=col)
        fig.update_yaxes(title_text=ylabel, type="log" if log else "linear", row=row, col=col)
        fig.update_xaxes(title_text="t [s]", row=row, col=col)
    fig.update_layout(title=title)
    legend_per_subplot(fig, cols=2, top=80 if title else 50)
    return fig


def write_lagrangian_report(path, sol, summary: dict, *, model=None, plotlyjs="inline") -> None:
    """The interactive report of a Lagrangian run: the mechanism animated (with ``model``, a
    :class:`~poinsot.models.Model`), the coordinates by unit, the reactions as named forces,
    the residuals, what the system conserves, and the numbers."""
    go, pio = _plotly()
    from .lagrange import lagrangian_panels

    figures = []
    if model is not None and model.points:
        figures.append(_mechanism_figure(model, sol, go))
    figures.append(_panels_figure(lagrangian_panels(sol, model), go))
    _write_page(path, figures, summary, pio, plotlyjs=plotlyjs)


#: How a plotly report gets plotly.js: ``"inline"`` (self-contained, ~4.8 MB, the default),
#: ``"cdn"`` (a ``<script>`` from cdn.plot.ly: small, needs the network) or ``"shared"`` (one
#: ``plotly-VERSION.min.js`` written once beside the output folders, e.g. in ``poinsot-out/``,
#: and referenced by every report there).
PLOTLYJS_MODES = ("inline", "cdn", "shared")


def _shared_plotlyjs(folder) -> str:
    """Write ``plotly-VERSION.min.js`` into ``folder`` unless it is already there with the
    same content (a different file of that name is refused, never replaced); its name."""
    from pathlib import Path

    import plotly
    from plotly.offline import get_plotlyjs

    name = f"plotly-{plotly.__version__}.min.js"
    target = Path(folder) / name
    text = get_plotlyjs()
    if target.exists():
        if target.read_text(encoding="utf-8", errors="replace") != text:
            raise OSError(f"{target} exists and is not plotly.js {plotly.__version__}: "
                          "move it away or use --plotly-js inline")  # fmt: skip
        return name
    atomic_write_text(target, text)
    return name


def _write_page(path, figures, summary, pio, *, plotlyjs="inline", raw_link="summary.json"):
    from pathlib import Path

    from .numbers import numbers_html

    if plotlyjs not in PLOTLYJS_MODES:
        raise ValueError(f"`plotlyjs` must be one of {PLOTLYJS_MODES}, found {plotlyjs!r}")
    head = ""
    include = plotlyjs == "inline" or ("cdn" if plotlyjs == "cdn" else False)
    if plotlyjs == "shared":  # the page sits in OUT/; the script one level up, beside OUT
        name = _shared_plotlyjs(Path(path).parent.parent)
        head = f'<script src="../{html.escape(name)}"></script>'
    parts = []
    for i, f in enumerate(figures):
        f.update_xaxes(exponentformat="power")  # 10⁻⁶, never SI prefixes (1µ) on numbers
        f.update_yaxes(exponentformat="power")
        f.update_scenes(xaxis_exponentformat="power", yaxis_exponentformat="power",
                        zaxis_exponentformat="power")  # fmt: skip
        parts.append(pio.to_html(f, full_html=False, include_plotlyjs=include if i == 0 else False,
                                 auto_play=False, div_id=f"poinsot-plot-{i}"))  # fmt: skip
    title = html.escape(f"poinsot — {summary.get('scenario', {}).get('name', 'run')}")
    lead = summary.get("lead")
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">{head}
<style>
body {{ font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1200px;
       color: #222; padding: 0 1em; }}
h1 {{ font-size: 1.5em; }} .plot {{ margin: 1em 0; }} p.lead {{ font-size: 1.05em; }}
h3 {{ font-size: 1em; margin: 1.2em 0 0.3em; }}
table.numbers {{ border-collapse: collapse; font-size: 0.88em; }}
table.numbers th {{ text-align: left; padding: 2px 16px 2px 0; font-weight: normal;
                    color: #444; }}
table.numbers td {{ font-family: ui-monospace, monospace; padding: 2px 12px 2px 0; }}
table.numbers td.unit {{ font-family: system-ui, sans-serif; color: #666; }}
</style></head><body>
<h1>{title}</h1>
<p>{html.escape(summary.get("scenario", {}).get("description", ""))}</p>
{f'<p class="lead">{html.escape(lead)}</p>' if lead else ""}
{"".join(f'<div class="plot">{p}</div>' for p in parts)}
<h2>Numbers</h2>
{numbers_html(summary, raw_link)}
<script type="application/json" id="poinsot-summary">{html.escape(json.dumps(summary))}</script>
</body></html>
"""
    atomic_write_text(path, page)


def write_static_report(path, summary: dict, images: dict, links=("summary.json",)) -> None:
    """The report without plotly: the summary's numbers, grouped with units as in the
    interactive page, and the run's figures (``images``: caption → PNG bytes, embedded), with
    :data:`STATIC_NOTE` at the top. Needs nothing beyond the standard library."""
    from .numbers import numbers_html

    lead = summary.get("lead") or ""
    note = f"<p class='note'><em>{html.escape(STATIC_NOTE)}.</em></p>"
    numbers = f"<h2>Numbers</h2>{numbers_html(summary, links[0])}"
    _image_page(path, summary, lead, note + numbers, images, links)


def write_figures_page(path, figures, summary: dict, *, plotlyjs="inline",
                       raw_link="summary.json") -> None:  # fmt: skip
    """A page of plotly ``figures`` with the summary's numbers (e.g. ``poinsot polhodes``);
    ``raw_link``: the file beside it that holds the numbers unrounded."""
    _, pio = _plotly()
    _write_page(path, figures, summary, pio, plotlyjs=plotlyjs, raw_link=raw_link)


def write_ensemble_report(path, summary: dict, images: dict) -> None:
    """A self-contained HTML page of an ensemble run: what was run, the distributions of the
    per-member statistics as a table, and the figures (``images``: caption → PNG bytes,
    embedded), with the raw summary JSON. Needs nothing beyond the standard library."""
    stats = summary.get("ensemble", {}).get("statistics", {})
    units = {"first_flip": "s", "flip_interval": "s", "flip_count": "",
             "energy_error": "1", "momentum_error": "1", "orthogonality_error": "1"}  # fmt: skip
    rows = []
    for name, entry in stats.items():
        if not entry.get("count"):
            continue
        cells = "".join(f"<td>{entry[k]:.4g}</td>" for k in ("min", "p05", "median", "p95", "max"))
        rows.append(
            f"<tr><th>{html.escape(name)}</th><td>{entry['count']}</td>{cells}"
            f"<td class='unit'>{html.escape(units.get(name, ''))}</td>"
            f"<td class='meaning'>{html.escape(entry.get('meaning', ''))}</td></tr>"
        )
    table = (
        "<table class='numbers'><tr><th>statistic</th><th>members</th><th>min</th><th>5 %</th>"
        "<th>median</th><th>95 %</th><th>max</th><th>unit</th><th>meaning</th></tr>"
        + "".join(rows)
        + "</table>"
    )
    e = summary.get("ensemble", {})
    lead = (
        f"{e.get('members')} members ({summary.get('distribution', {}).get('description', '')}), "
        f"{e.get('method')}; {e.get('succeeded')} finished, integrated in "
        f"{e.get('wall_time_s', 0):.3g} s (wall time in the compiled core; nothing is compiled "
        "at run time)."
    )
    _image_page(path, summary, lead, "<h2>Per-member statistics</h2>" + table, images,
                ("summary.json", "ensemble.nc"))  # fmt: skip


def _image_page(path, summary: dict, lead: str, body_html: str, images: dict, links) -> None:
    """A self-contained HTML page: title, description, ``lead``, ``body_html`` (trusted markup
    built here), the figures (``images``: caption → PNG bytes, embedded), links to the raw files
    and the summary JSON. Needs nothing beyond the standard library."""
    import base64

    figures = "".join(
        f"<figure><img alt='{html.escape(caption)}' src='data:image/png;base64,"
        f"{base64.b64encode(png).decode()}'><figcaption>{html.escape(caption)}</figcaption>"
        "</figure>"
        for caption, png in images.items()
    )
    from pathlib import Path

    scenario = summary.get("scenario", {})
    title = html.escape(f"poinsot — {scenario.get('name', 'run')}")
    # a data file is linked only when it is there (``[output] data = false`` writes none);
    # summary.json is always written, after the report, once the timings are in
    here = Path(path).parent
    links = [x for x in links if x == "summary.json" or (here / x).exists()]
    link_html = " · ".join(f'<a href="{html.escape(x)}">{html.escape(x)}</a>' for x in links)
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1200px;
       color: #222; padding: 0 1em; }}
h1 {{ font-size: 1.5em; }} img {{ max-width: 100%; }}
table.numbers {{ border-collapse: collapse; font-size: 0.85em; }}
table.numbers th {{ text-align: left; padding: 2px 12px 2px 0; font-weight: normal;
                    color: #555; }}
table.numbers td {{ font-family: ui-monospace, monospace; padding: 2px 10px 2px 0; }}
table.numbers td.meaning, table.numbers td.unit {{ font-family: system-ui, sans-serif;
                                                   color: #555; }}
h3 {{ font-size: 1em; margin: 1.2em 0 0.3em; }} p.note {{ color: #8a4b00; }}
figcaption {{ color: #555; font-size: 0.9em; }}
</style></head><body>
<h1>{title}</h1>
<p>{html.escape(scenario.get("description", ""))}</p>
<p>{html.escape(lead)}</p>
{body_html}
{figures}
<p>{link_html}</p>
<script type="application/json" id="poinsot-summary">{html.escape(json.dumps(summary))}</script>
</body></html>
"""
    atomic_write_text(path, page)


def write_relative_report(path, summary: dict, images: dict,
                          links=("summary.json", "relative.csv")) -> None:  # fmt: skip
    """A self-contained HTML page of a motion relative to a carrier: the carrier, the numbers
    (with units and meanings), the figures (``images``: caption → PNG bytes) and ``links`` to
    the run's data files."""
    from .numbers import format_value

    rows = []
    for name, (value, unit, meaning) in summary.get("table", {}).items():
        shown = format_value(value) if isinstance(value, float) else html.escape(str(value))
        rows.append(
            f"<tr><th>{html.escape(name)}</th><td>{shown}</td><td>{html.escape(unit)}</td>"
            f"<td class='meaning'>{html.escape(meaning)}</td></tr>"
        )
    table = (
        "<h2>Numbers</h2><table class='numbers'><tr><th>quantity</th><th>value</th>"
        "<th>unit</th><th>meaning</th></tr>" + "".join(rows) + "</table>"
    )
    c = summary.get("carrier", {})
    lead = f"Carrier: {c.get('description', '')}. " + summary.get("lead", "")
    _image_page(path, summary, lead, table, images, links)


def write_identify_report(path, summary: dict, images: dict) -> None:
    """A self-contained HTML page of an identification (``poinsot identify``): the estimate
    with its standard errors and units, the fit's quality and flags, and the figures
    (``images``: caption → PNG bytes). ``summary`` is
    :meth:`poinsot.identify.IdentifyResult.to_dict` with a ``scenario`` entry (name,
    description)."""
    units = summary.get("units", {})
    r, dr = summary["ratios"], summary["ratios_stderr"]
    scale = units.get("inertia", "")
    rows = [
        ("I1/I3", f"{r[0]:.6g} ± {dr[0]:.2g}", "1", "ratio of the smallest to the largest "
         "principal moment"),
        ("I2/I3", f"{r[1]:.6g} ± {dr[1]:.2g}", "1", "ratio of the middle to the largest"),
        ("principal moments", ", ".join(f"{x:.6g}" for x in summary["principal_moments"]),
         scale, "ascending"),
    ]  # fmt: skip
    axes = np.asarray(summary["axes"])
    for k in range(3):
        e = axes[:, k]
        rows.append((f"axis e{k + 1}", f"({e[0]:+.4f}, {e[1]:+.4f}, {e[2]:+.4f}) ± "
                     f"{summary['axes_stderr_deg'][k]:.2g}°", "sensor frame",
                     f"principal axis of I{k + 1}"))  # fmt: skip
    inertia = "<br>".join(" ".join(f"{v:+.5e}" for v in row) for row in summary["inertia"])
    rows.append(("inertia tensor", inertia, scale, "about the centre of mass, sensor frame"))
    if summary.get("rotor_inertia") is not None:
        rows.append(("rotor J", f"{summary['rotor_inertia']:.6g}", units.get("rotor_inertia",
                     ""), "given" if summary["absolute"] else "fitted"))  # fmt: skip
    w = summary["window"]
    rows += [
        ("free flight", f"{w[0]:.4f} … {w[1]:.4f}", "s", f"found by the {summary['found_by']}"
         f", {summary['samples']} samples"),
        ("gyro bias", ", ".join(f"{x:+.4g}" for x in summary["gyro_bias"]), "rad/s", "fitted"),
        ("residuals / noise" if summary.get("loss", "linear") == "linear"
         else "residuals' robust scale / noise", f"{summary['residual_ratio']:.3g}", "1",
         "about 1 when the model explains the readings"),
        ("condition", f"{summary['condition']:.3g}", "1", "of the fit's scaled Jacobian"),
    ]  # fmt: skip
    if summary.get("lever_arm") is not None:
        rows.append(("lever arm", ", ".join(f"{1000 * x:+.1f}" for x in summary["lever_arm"]),
                     "mm", "accelerometer from the centre of mass"))  # fmt: skip
    cells = "".join(
        f"<tr><th>{html.escape(a)}</th><td>{b if a == 'inertia tensor' else html.escape(b)}"
        f"</td><td>{html.escape(c)}</td><td class='meaning'>{html.escape(d)}</td></tr>"
        for a, b, c, d in rows
    )
    table = ("<h2>Estimate</h2><table class='numbers'><tr><th>quantity</th><th>value</th>"
             "<th>unit</th><th>meaning</th></tr>" + cells + "</table>")  # fmt: skip
    flags = summary.get("flags") or []
    if flags:
        table = ("<h2>Warnings</h2><ul>" + "".join(f"<li>{html.escape(f)}</li>" for f in flags)
                 + "</ul>" + table)  # fmt: skip
    scale_note = ("absolute (the rotor's inertia was given)" if summary["absolute"]
                  else "up to scale (trace 1): give the rotor's inertia for kg m²")  # fmt: skip
    lead = f"Inertia identified from a gyro log: {summary['model']} model, {scale_note}."
    _image_page(path, summary, lead, table, images, ("result.json",))
