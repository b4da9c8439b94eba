"""A self-contained interactive HTML report of a run (needs the ``report`` extra: plotly).

One page, plotly.js inlined (opens with no network): the body tumbling in 3D (animated), ω on
the energy ellipsoid with the polhode family, the time series, and the numbers.
"""

from __future__ import annotations

import html
import json

import numpy as np

from ._io import atomic_write_text

__all__ = [
    "equivalent_box_half_extents",
    "write_ensemble_report",
    "write_lagrangian_report",
    "write_report",
]

MAX_FRAMES = 120


def _plotly():
    try:
        import plotly.graph_objects as go
        import plotly.io as pio
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("the HTML report needs plotly: pip install 'poinsot[report]'") from exc
    return go, pio


def equivalent_box_half_extents(body) -> np.ndarray:
    """Half extents (along e1, e2, e3) of the uniform box with the body's mass and principal
    moments (:func:`poinsot.kernels.shapes.equivalent_box_half_extents`)."""
    from .kernels.shapes import equivalent_box_half_extents as half_extents

    return half_extents(np.asarray(body.principal_moments), float(body.mass))


def _box_lines(half):
    """Vertices (closed polyline through the 12 edges, None-separated) of a box."""
    c = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    edges = [
        (i, j) for i in range(8) for j in range(i + 1, 8) if np.sum(np.abs(c[i] - c[j]) > 0) == 1
    ]
    return c, edges


def _body_figure(traj, go):
    body = traj.body
    E = body.principal_axes
    half = np.maximum(equivalent_box_half_extents(body), 1e-3 * max(1.0, body.mass))
    corners, edges = _box_lines(half)
    step = max(1, len(traj.t) // MAX_FRAMES)
    idx = np.arange(0, len(traj.t), step)
    particles = body.u if body.has_particles else None

    # the body about its centre of mass (or about its fixed pivot): translation has its own plot
    pivot = getattr(traj.system, "pivot", None)
    c = traj.system.c if pivot is not None else np.zeros(3)  # centre of mass from the pivot

    def traces(i):
        Q = traj.Q[i]
        R = Q @ c
        pts = (corners @ E.T) @ Q.T + R  # box in principal axes, then attitude and position
        xs, ys, zs = [], [], []
        for a, b in edges:
            for p in (pts[a], pts[b]):
                xs.append(p[0])
                ys.append(p[1])
                zs.append(p[2])
            xs.append(None)
            ys.append(None)
            zs.append(None)
        out = [
            go.Scatter3d(
                x=xs,
                y=ys,
                z=zs,
                mode="lines",
                line={"color": "#444", "width": 4},
                name="body (equivalent box)",
            )
        ]
        for k, color in enumerate(("#d62728", "#2ca02c", "#1f77b4")):
            tip = R + Q @ E[:, k] * 1.3 * half[k]
            out.append(
                go.Scatter3d(
                    x=[R[0], tip[0]],
                    y=[R[1], tip[1]],
                    z=[R[2], tip[2]],
                    mode="lines",
                    line={"color": color, "width": 7},
                    name=f"e{k + 1}",
                )
            )
        if pivot is not None:
            out.append(
                go.Scatter3d(
                    x=[0, R[0]],
                    y=[0, R[1]],
                    z=[0, R[2]],
                    mode="lines+markers",
                    line={"color": "#8c564b", "width": 5},
                    marker={"size": [5, 2]},
                    name="pivot → centre of mass",
                )
            )
        if particles is not None:
            P = particles @ Q.T + R
            out.append(
                go.Scatter3d(
                    x=P[:, 0],
                    y=P[:, 1],
                    z=P[:, 2],
                    mode="markers",
                    marker={"size": 3, "color": "#ff7f0e"},
                    name="particles",
                )
            )
        return out

    fig = go.Figure(
        data=traces(idx[0]), frames=[go.Frame(data=traces(i), name=f"{traj.t[i]:.3g}") for i in idx]
    )
    reach = 1.4 * float(np.max(half)) + (
        float(np.linalg.norm(traj.system.c)) if pivot is not None else 0.0
    )
    if particles is not None:
        reach = max(reach, float(np.max(np.linalg.norm(particles, axis=1))) * 1.15)
    axes = {f"{c}axis": {"range": [-reach, reach], "title": f"{c} [m]"} for c in "xyz"}
    where = "about the fixed pivot" if pivot is not None else "about the centre of mass"
    fig.update_layout(
        title=f"Body attitude {where} (animated; red e₁, green e₂, blue e₃)",
        scene={**axes, "aspectmode": "cube"},
        height=560,
        updatemenus=[
            {
                "type": "buttons",
                "showactive": False,
                "x": 0.05,
                "y": 0.05,
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
                        "label": "⏸ pause",
                        "method": "animate",
                        "args": [[None], {"mode": "immediate", "frame": {"duration": 0}}],
                    },
                ],
            }
        ],
        sliders=[
            {
                "currentvalue": {"prefix": "t = "},
                "steps": [
                    {
                        "label": f.name,
                        "method": "animate",
                        "args": [
                            [f.name],
                            {"mode": "immediate", "frame": {"duration": 0, "redraw": True}},
                        ],
                    }
                    for f in fig.frames
                ],
            }
        ],
    )
    return fig


def _polhode_figure(traj, go, free, levels):
    """The run's own ω(t), unscaled, on its own energy ellipsoid with the polhodes there."""
    from .kernels.rigid import rotational_energy
    from .plotting.interactive import polhode_family_figure

    w = traj.omega
    k = float(rotational_energy(traj.body.inertia, np.ascontiguousarray(w[0])))
    fig = polhode_family_figure(free, k, levels=levels, omega=w)
    fig.update_layout(
        title=f"This run's ω(t) on its energy ellipsoid (k = {k:.4g} J), with the polhodes "
        "at that energy; ω in rad/s, body frame"
    )
    return fig


def _series_figure(traj, go):
    """ω(t), and the relative change of what this problem conserves (integration error)."""
    from plotly.subplots import make_subplots

    kept = [i for i in traj.invariants if i.conserved]
    lost = [i for i in traj.invariants if not i.conserved]
    right = (
        "Conserved by this problem: relative change (integration error)"
        if kept
        else "Total energy: not conserved here (forces do work)"
    )
    fig = make_subplots(rows=1, cols=2, subplot_titles=("Angular velocity (body frame)", right))
    for i, name in enumerate(("ω₁", "ω₂", "ω₃")):
        fig.add_trace(
            go.Scatter(x=traj.t, y=traj.omega[:, i], name=name, legendgroup="w"), row=1, col=1
        )
    tiny = 1e-17
    for inv in kept:
        fig.add_trace(
            go.Scatter(
                x=traj.t,
                y=inv.change + tiny,
                legendgroup="c",
                name=f"{inv.symbol} [{inv.unit}]: {inv.name}",
            ),
            row=1,
            col=2,
        )
    fig.add_trace(
        go.Scatter(
            x=traj.t,
            y=traj.orthogonality_error + tiny,
            legendgroup="c",
            name="max |QᵀQ − I| (distance from a rotation)",
        ),
        row=1,
        col=2,
    )
    if kept:
        fig.update_yaxes(type="log", title_text="|x(t) − x(0)| / |x(0)|", row=1, col=2)
    else:
        E = traj.total_energy
        fig.add_trace(go.Scatter(x=traj.t, y=E - E[0], name="E(t) − E(0) [J]"), row=1, col=2)
        fig.update_yaxes(title_text="J (energy), 1 (|QᵀQ − I|)", row=1, col=2)
    fig.update_yaxes(title_text="ω [rad/s]", row=1, col=1)
    fig.update_xaxes(title_text="t [s]")
    note = ("Not conserved here: " + "; ".join(f"{i.symbol} ({i.reason})" for i in lost)
            if lost else "")  # fmt: skip
    fig.update_layout(height=460, legend={"orientation": "h", "y": -0.25}, title=note or None)
    return fig


def _numbers_table(summary: dict) -> str:
    def fmt(v):
        if isinstance(v, float):
            return f"{v:.6g}"
        if isinstance(v, list):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        return html.escape(str(v))

    rows = []

    def walk(prefix, obj):
        for key, value in obj.items():
            name = f"{prefix}{key}"
            if isinstance(value, dict):
                walk(name + ".", value)
            else:
                rows.append(f"<tr><th>{html.escape(name)}</th><td>{fmt(value)}</td></tr>")

    walk("", summary)
    return "<table class='numbers'>" + "".join(rows) + "</table>"


def _comparison_figure(t, errors, go):
    """The plotly twin of :func:`poinsot.plotting.plot_method_comparison`."""
    from plotly.subplots import make_subplots

    from .plotting.trajectory import COMPARISON_PANELS

    fig = make_subplots(rows=1, cols=3, subplot_titles=[p[1] for p in COMPARISON_PANELS])
    tiny = 1e-17
    for col, (key, _, ylabel) in enumerate(COMPARISON_PANELS, start=1):
        for n, (label, rows) in enumerate(errors.items()):
            if key in rows:
                fig.add_trace(
                    go.Scatter(
                        x=t,
                        y=np.asarray(rows[key]) + tiny,
                        name=label,
                        legendgroup=label,
                        showlegend=col == 1,
                        line={
                            "color": _COLORS[n % len(_COLORS)],
                            "dash": "dash" if label.startswith("exact") else "solid",
                        },
                    ),
                    row=1,
                    col=col,
                )
        fig.update_yaxes(type="log", title_text=ylabel, row=1, col=col)
    fig.update_xaxes(title_text="t [s]")
    fig.update_layout(
        height=430,
        title="Integrators against the exact torque-free solution, same step",
        legend={"orientation": "h", "y": -0.25},
    )
    return fig


_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd")


def write_report(path, traj, summary: dict, *, free=None, levels=7, comparison=None) -> None:
    """Write the interactive report for ``traj`` to ``path`` (atomically); ``comparison``:
    the per-sample errors of :func:`poinsot.job.compare_methods`, drawn second."""
    go, pio = _plotly()
    figures = [_body_figure(traj, go)]
    if comparison is not None:
        figures.append(_comparison_figure(traj.t, comparison, go))
    if free is not None and np.any(traj.omega[0]):
        figures.append(_polhode_figure(traj, go, free, levels))
    figures.append(_series_figure(traj, go))
    _write_page(path, figures, summary, pio)


def write_lagrangian_report(path, sol, summary: dict) -> None:
    """The interactive report of a Lagrangian run: coordinates, multipliers and generalized
    constraint forces, residuals and energy, and the numbers."""
    go, pio = _plotly()
    from plotly.subplots import make_subplots

    names = [str(q).replace("(t)", "") for q in sol.coordinates]
    fig = make_subplots(
        rows=2,
        cols=2,
        subplot_titles=(
            "Generalized coordinates",
            "Multipliers λ (eq. 6.60 sign)",
            "Constraint residuals",
            "Energy h − h(0)",
        ),
    )
    for j, n in enumerate(names):
        fig.add_trace(go.Scatter(x=sol.t, y=sol.q[:, j], name=n), row=1, col=1)
    for k in range(sol.multipliers.shape[1]):
        fig.add_trace(go.Scatter(x=sol.t, y=sol.multipliers[:, k], name=f"λ{k + 1}"), row=1, col=2)
    tiny = 1e-18
    if sol.constraint_residual.size:
        fig.add_trace(
            go.Scatter(
                x=sol.t, y=np.abs(sol.constraint_residual).max(axis=1) + tiny, name="|g(q)|"
            ),
            row=2,
            col=1,
        )
    if sol.constraint_velocity_residual.size:
        fig.add_trace(
            go.Scatter(
                x=sol.t,
                y=np.abs(sol.constraint_velocity_residual).max(axis=1) + tiny,
                name="|G q̇ + b|",
            ),
            row=2,
            col=1,
        )
    fig.update_yaxes(type="log", row=2, col=1)
    fig.add_trace(go.Scatter(x=sol.t, y=sol.energy - sol.energy[0], name="h − h(0)"), row=2, col=2)
    fig.update_xaxes(title_text="t [s]", row=2)
    fig.update_layout(height=720)
    forces = go.Figure(
        [
            go.Scatter(x=sol.t, y=sol.constraint_forces[:, j], name=f"on {n}")
            for j, n in enumerate(names)
        ]
    )
    forces.update_layout(
        title="Generalized constraint forces Σ λ_k ∂g_k/∂q_j", height=400, xaxis_title="t [s]"
    )
    _write_page(path, [fig, forces], summary, pio)


def _write_page(path, figures, summary, pio):
    parts = [
        pio.to_html(
            f,
            full_html=False,
            include_plotlyjs=(i == 0),
            auto_play=False,
            div_id=f"poinsot-plot-{i}",
        )
        for i, f in enumerate(figures)
    ]
    title = html.escape(f"poinsot — {summary.get('scenario', {}).get('name', 'run')}")
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1200px;
       color: #222; }}
h1 {{ font-size: 1.5em; }} .plot {{ margin: 1em 0; }}
table.numbers {{ border-collapse: collapse; font-size: 0.85em; }}
table.numbers th {{ text-align: left; padding: 2px 12px 2px 0; font-weight: normal;
                    color: #555; }}
table.numbers td {{ font-family: ui-monospace, monospace; }}
</style></head><body>
<h1>{title}</h1>
<p>{html.escape(summary.get("scenario", {}).get("description", ""))}</p>
{f'<p class="lead">{html.escape(summary["lead"])}</p>' if summary.get("lead") else ""}
{"".join(f'<div class="plot">{p}</div>' for p in parts)}
<h2>Numbers</h2>
{_numbers_table(summary)}
<script type="application/json" id="poinsot-summary">{html.escape(json.dumps(summary))}</script>
</body></html>
"""
    atomic_write_text(path, page)


def write_ensemble_report(path, summary: dict, images: dict) -> None:
    """A self-contained HTML page of an ensemble run: what was run, the distributions of the
    per-member statistics as a table, and the figures (``images``: caption → PNG bytes,
    embedded), with the raw summary JSON. Needs nothing beyond the standard library."""
    stats = summary.get("ensemble", {}).get("statistics", {})
    rows = []
    for name, entry in stats.items():
        if not entry.get("count"):
            continue
        cells = "".join(f"<td>{entry[k]:.4g}</td>" for k in ("min", "p05", "median", "p95", "max"))
        rows.append(
            f"<tr><th>{html.escape(name)}</th><td>{entry['count']}</td>{cells}"
            f"<td class='meaning'>{html.escape(entry.get('meaning', ''))}</td></tr>"
        )
    table = (
        "<table class='numbers'><tr><th>statistic</th><th>members</th><th>min</th><th>5 %</th>"
        "<th>median</th><th>95 %</th><th>max</th><th>meaning</th></tr>" + "".join(rows) + "</table>"
    )
    e = summary.get("ensemble", {})
    lead = (
        f"{e.get('members')} members ({summary.get('distribution', {}).get('description', '')}), "
        f"{e.get('method')}; {e.get('succeeded')} finished in {e.get('wall_time_s', 0):.3g} s."
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
    scenario = summary.get("scenario", {})
    title = html.escape(f"poinsot — {scenario.get('name', 'run')}")
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
table.numbers td.meaning {{ font-family: system-ui, sans-serif; color: #555; }}
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


def write_relative_report(path, summary: dict, images: dict) -> None:
    """A self-contained HTML page of a motion relative to a carrier: the carrier, the numbers
    (with units and meanings) and the figures (``images``: caption → PNG bytes)."""
    rows = []
    for name, (value, unit, meaning) in summary.get("table", {}).items():
        shown = f"{value:.6g}" if isinstance(value, float) else html.escape(str(value))
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
    _image_page(path, summary, lead, table, images, ("summary.json", "relative.csv"))
