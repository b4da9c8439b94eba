"""The notebook displays of the library's results and models, registered with
:mod:`poinsot.display` (the library's plug-in point; see there why it is one).

For each class: ``"html"`` — a compact table of what matters, with units (the span, the method
and the steps; the drift of each conserved quantity; the error against the exact solution
where it applies; the reactions; for ensembles, the statistics); ``"plot"`` — the matplotlib
figure the reports use; ``"interactive"`` — the plotly view (``.show()``).
"""

from __future__ import annotations

import html

import numpy as np

from ..display import register
from .numbers import format_value

__all__ = ["table"]


def table(caption: str, rows, note: str = "") -> str:
    """An HTML table: ``caption``; ``rows`` of ``(name, value, unit)`` (a value is formatted by
    :func:`~poinsot.viz.numbers.format_value` unless it is a str, taken as trusted markup);
    ``note`` under it."""
    cells = []
    for name, value, unit in rows:
        shown = value if isinstance(value, str) else format_value(value)
        cells.append(
            f"<tr><th style='text-align:left;font-weight:normal'>{html.escape(name)}</th>"
            f"<td style='text-align:left;font-family:monospace'>{shown}</td>"
            f"<td style='text-align:left;color:#666'>{html.escape(unit)}</td></tr>"
        )
    foot = f"<p style='color:#555;font-size:0.9em'>{html.escape(note)}</p>" if note else ""
    return (
        "<div class='poinsot'><table><caption style='text-align:left;font-weight:bold'>"
        f"{html.escape(caption)}</caption>"
        "<tr><th style='text-align:left'>quantity</th><th style='text-align:left'>value</th>"
        "<th style='text-align:left'>unit</th></tr>" + "".join(cells) + f"</table>{foot}</div>"
    )


def _text(value) -> str:
    return html.escape(str(value))


def _span(t) -> str:
    return _text(f"[{format_value(float(t[0]))}, {format_value(float(t[-1]))}]")


def _invariant_rows(invariants):
    rows = []
    for inv in invariants:
        state = "conserved by the problem" if inv.conserved else f"not conserved: {inv.reason}"
        rows.append((f"max relative change of {inv.symbol} ({inv.name}; {state})",
                     float(np.max(inv.change)), "1"))  # fmt: skip
    return rows


# ----------------------------------------------------------------------------- Trajectory
def _free_analysis(traj):
    """The torque-free analysis of the run and whether its exact solution applies."""
    from ..torquefree.scope import exact_solution_applies, free_rotation

    system = traj.system
    free = free_rotation(traj.body, system.pivot)
    exact = free is not None and exact_solution_applies(system.forces) and np.any(traj.omega[0])
    return free, exact


def _top(traj):
    from ..tops import heavy_top, top_motion

    system = traj.system
    top = heavy_top(traj.body, system.pivot, system.forces)
    return None if top is None else top_motion(traj, top)


@register("poinsot.trajectory.Trajectory", "html")
def _trajectory_html(traj) -> str:
    rows = [
        ("time span", _span(traj.t), "s"),
        ("samples", len(traj.t), ""),
        ("method", _text(f"{traj.method} ({traj.backend} backend)"), ""),
        ("steps", int(traj.nsteps), ""),
        ("right-hand-side evaluations", int(traj.nfev), ""),
        ("wall time of the integration", float(traj.wall_time), "s"),
        ("mass", float(traj.body.mass), "kg"),
        ("principal moments", traj.body.principal_moments.tolist(), "kg·m²"),
        ("max |QᵀQ − I| (distance from a rotation)", float(traj.orthogonality_error.max()), "1"),
    ]
    rows += _invariant_rows(traj.invariants)
    free, exact = _free_analysis(traj)
    if exact:
        err = free.trajectory_error(traj)
        rows.append(("max |ω − ω_exact| against the exact solution", err["omega"], "rad/s"))
        rows.append(("max |Q − Q_exact| against the exact solution", err["attitude"], "1"))
    top = _top(traj)
    if top is not None:
        s = top.summary()
        rows += [
            ("nutation: θ between", [s["theta_min"], s["theta_max"]], "rad"),
            ("mean precession rate", s["mean_precession_rate"], "rad/s"),
            ("gyroscopic estimate M g l/(C ω·a)", s["gyroscopic_precession_rate"], "rad/s"),
            ("steady precession at mean θ (slow, fast)",
             [s["steady_precession_rate_slow"], s["steady_precession_rate_fast"]], "rad/s"),
        ]  # fmt: skip
    return table("Trajectory", rows, "traj.plot() draws ω(t); traj.show() animates the body.")


@register("poinsot.trajectory.Trajectory", "plot")
def _trajectory_plot(traj, kind="omega"):
    """``kind``: ``"omega"`` (default), ``"conservation"``, ``"attitude"`` (a heavy top's
    nutation and precession), ``"axis_trace"``, ``"polhodes"``, ``"center_of_mass"``."""
    from . import trajectory as T

    if kind == "omega":
        return T.plot_omega_series(traj)
    if kind == "conservation":
        return T.plot_conservation(traj)
    if kind == "center_of_mass":
        return T.plot_center_of_mass_path(traj)
    if kind == "attitude":
        top = _top(traj)
        if top is None:
            raise ValueError("`kind` 'attitude' draws a heavy top's nutation and precession: "
                             "this run is not a heavy symmetric top")  # fmt: skip
        return T.plot_attitude(top)
    if kind == "axis_trace":
        from ..tops import heavy_top

        system = traj.system
        top = heavy_top(traj.body, system.pivot, system.forces)
        if top is None:  # the body's own symmetry axis, either way along it
            return T.plot_axis_trace(traj.axis_trace())
        return T.plot_axis_trace(traj.axis_trace(top.axis), label="direction of a",
                                 title="Trace of the symmetry axis a (tip → centre of mass) on "
                                 "the unit sphere")  # fmt: skip
    if kind == "polhodes":
        from .torquefree import plot_polhode_family

        free, _ = _free_analysis(traj)
        if free is None or not np.any(traj.omega[0]):
            raise ValueError("`kind` 'polhodes' needs a torque-free analysis of the body")
        k = float(free.invariants(traj.omega[0])[0])
        return plot_polhode_family(free, k, omega=traj.omega, omega_label="ω(t) of this run")
    raise ValueError(
        "`kind` must be 'omega', 'conservation', 'attitude', 'axis_trace', 'polhodes' or "
        f"'center_of_mass', found {kind!r}"
    )


@register("poinsot.trajectory.Trajectory", "interactive")
def _trajectory_interactive(traj, kind="body"):
    """``kind``: ``"body"`` (the body animated, default) or ``"series"``."""
    from .report import _body_figure, _plotly, _series_figure

    go, _ = _plotly()
    if kind == "body":
        return _body_figure(traj, go)
    if kind == "series":
        return _series_figure(traj, go)
    raise ValueError(f"`kind` must be 'body' or 'series', found {kind!r}")


# ----------------------------------------------------------------------------- FreeRigidBody
@register("poinsot.torquefree.body.FreeRigidBody", "html")
def _free_html(body) -> str:
    rows = [
        ("principal moments I₁ ≤ I₂ ≤ I₃", body.principal_moments.tolist(), "kg·m²"),
        ("symmetry", _text(body.symmetry), ""),
        ("principal axes e₁, e₂, e₃ (columns, body frame)", body.principal_axes.tolist(), "1"),
    ]
    for fp in body.fixed_points():
        rows.append((f"fixed points {fp.label}", "stable" if fp.stable else "unstable", ""))
    return table("FreeRigidBody (torque-free)", rows,
                 "body.plot() draws the polhodes on the energy ellipsoid.")  # fmt: skip


@register("poinsot.torquefree.body.FreeRigidBody", "plot")
def _free_plot(body, energy=0.5, *, omega0=None, levels=9):
    """The polhode family at ``energy`` [J] (that of ``omega0`` when given, with its ω(t))."""
    from .torquefree import plot_polhode_family

    path = None
    if omega0 is not None:
        energy = float(body.invariants(omega0)[0])
        family = body.classify(omega0)
        span = body.period(omega0) if family in ("around e1", "around e3") else 50.0
        path = body.exact_omega(omega0, np.linspace(0.0, min(span, 200.0), 400))
    return plot_polhode_family(body, energy, levels=levels, omega=path, omega_label="ω(t)")


@register("poinsot.torquefree.body.FreeRigidBody", "interactive")
def _free_interactive(body, energy=0.5, *, levels=9):
    from .interactive import polhode_family_figure

    return polhode_family_figure(body, energy, levels=levels)


# ----------------------------------------------------------------------------- Lagrangian
def _name(q) -> str:
    return str(q).replace("(t)", "")


@register("poinsot.lagrange.system.LagrangianSystem", "html")
def _system_html(system) -> str:
    from sympy.physics.vector.printing import vsprint

    coords = ", ".join(f"{_name(q)} [{system.unit_of(q) or '—'}]" for q in system.coordinates)
    rows = [("coordinates [unit]", _text(coords), "")]
    for k, g in enumerate(system.holonomic):
        kind = "one-sided, ≥ 0" if k in system.unilateral else "= 0"
        rows.append((f"holonomic constraint {k + 1} ({kind})", _text(vsprint(g)), ""))
    for k, a in enumerate(system.nonholonomic):
        rows.append((f"non-holonomic constraint {k + 1} (= 0)", _text(vsprint(a)), ""))
    rows.append(("parameters", _text(", ".join(map(str, system.parameters)) or "none"), ""))
    if system.inputs:
        rows.append(("inputs", _text(", ".join(_name(u) for u in system.inputs)), ""))
    for name, symbol, unit, _, reason in system.constants_of_motion():
        rows.append((f"conserved: {symbol}, {name}", _text(reason), unit))
    for r in getattr(system, "hidden", ()):
        rows.append((f"reaction {r.name}", _text(r.meaning or f"along {_name(r.coordinate)}"),
                     r.unit))  # fmt: skip
    return table("LagrangianSystem", rows, "Its equations: system.equations() (LaTeX in a "
                 "notebook: display(Math(system._repr_latex_())))")  # fmt: skip


def _reactions(sol) -> dict:
    """``name → (values, unit, meaning)``: the model's named reactions (when the solution
    knows its model) and the system's hidden ones (:meth:`~poinsot.lagrange.LagrangianSystem.
    reaction_forces`)."""
    model = getattr(sol, "model", None)
    if model is not None:
        return model.reaction_values(sol)
    out = {}
    if getattr(sol.system, "hidden", ()):
        forces = sol.system.reaction_forces(sol)
        for r in sol.system.hidden:
            out[r.name] = (forces[r.name], r.unit, r.meaning)
    return out


@register("poinsot.lagrange.solution.LagrangianSolution", "html")
def _solution_html(sol) -> str:
    rows = [
        ("time span", _span(sol.t), "s"),
        ("samples", len(sol.t), ""),
        ("method", _text(f"{sol.method}, stabilization {sol.stabilization}"), ""),
        ("right-hand-side evaluations", int(sol.nfev), ""),
    ]
    if sol.constraint_residual.size:
        rows.append(("max |g(q)|", float(np.nanmax(np.abs(sol.constraint_residual))),
                     "the constraints' units"))  # fmt: skip
    if sol.constraint_velocity_residual.size:
        rows.append(("max |G q̇ + b|", float(np.nanmax(np.abs(sol.constraint_velocity_residual))),
                     "the constraints' units/s"))  # fmt: skip
    for inv in sol.invariants:
        rows.append((f"max relative change of {inv.symbol} ({inv.name}; conserved)",
                     float(np.max(inv.change)), "1"))  # fmt: skip
    for name, (values, unit, _) in _reactions(sol).items():
        rows.append((f"{name}: range", [float(np.min(values)), float(np.max(values))], unit))
    for t, constraint, _ in sol.releases:
        rows.append((f"released: {constraint} ≥ 0", float(t), "s"))
    return table("LagrangianSolution", rows, "sol.plot() draws the coordinates, reactions, "
                 "residuals and conserved quantities.")  # fmt: skip


@register("poinsot.lagrange.solution.LagrangianSolution", "plot")
def _solution_plot(sol, *, title=None):
    from .lagrange import plot_lagrangian_solution

    model = getattr(sol, "model", None)
    return plot_lagrangian_solution(sol, model=model, title=title or getattr(model, "description",
                                                                            None))  # fmt: skip


@register("poinsot.lagrange.solution.LagrangianSolution", "interactive")
def _solution_interactive(sol, kind=None):
    """``kind``: ``"mechanism"`` (the mechanism animated, the default when the solution's
    model has its geometry) or ``"panels"``."""
    from .lagrange import lagrangian_panels
    from .report import _mechanism_figure, _panels_figure, _plotly

    go, _ = _plotly()
    model = getattr(sol, "model", None)
    kind = kind or ("mechanism" if model is not None and model.points else "panels")
    if kind == "mechanism":
        if model is None or not model.points:
            raise ValueError("`kind` 'mechanism' needs the model's geometry: run it with "
                             "model.simulate(...)")  # fmt: skip
        return _mechanism_figure(model, sol, go)
    if kind == "panels":
        return _panels_figure(lagrangian_panels(sol, model), go)
    raise ValueError(f"`kind` must be 'mechanism' or 'panels', found {kind!r}")


@register("poinsot.models.Model", "html")
def _model_html(model) -> str:
    rows = [(f"parameter {p}", float(v), model.unit_of_parameter(p))
            for p, v in model.params.items()]  # fmt: skip
    rows += [(f"initial {_name(q)}", float(v), model.system.unit_of(q))
             for q, v in model.q0.items()]  # fmt: skip
    for name, (_, unit, meaning) in model.reactions.items():
        rows.append((f"reaction {name}", _text(meaning), unit))
    return table(f"Model {model.name}: {model.description}", rows) + _system_html(model.system)


# ----------------------------------------------------------------------------- ensembles
@register("poinsot.ensemble.result.EnsembleResult", "html")
def _ensemble_html(res) -> str:
    from ..ensemble.result import STATISTICS

    s = res.summary()
    rows = [
        ("members", s["members"], ""),
        ("finished", s["succeeded"], ""),
        ("method", _text(s["method"]), ""),
        ("time span", list(map(float, s["t_span"])), "s"),
        ("wall time (compiled core)", float(res.wall_time), "s"),
    ]
    units = {"first_flip": "s", "flip_interval": "s"}
    for name, entry in s["statistics"].items():
        if not entry.get("count"):
            continue
        unit = units.get(name, "1" if name in STATISTICS and name != "flip_count" else "")
        rows.append((f"{name}: min, median, max", [entry["min"], entry["median"], entry["max"]],
                     unit))  # fmt: skip
    return table("EnsembleResult", rows, "res.plot() draws the distributions.")


@register("poinsot.ensemble.result.EnsembleResult", "plot")
def _ensemble_plot(res, names=None):
    from .ensemble import plot_ensemble_histograms

    return plot_ensemble_histograms(res, names)


@register("poinsot.ensemble.result.EnsembleResult", "interactive")
def _ensemble_interactive(res):
    from .interactive import ensemble_histograms_figure

    return ensemble_histograms_figure(res)


# ----------------------------------------------------------------------------- relative motion
@register("poinsot.relative.simulate.RelativeTrajectory", "html")
def _relative_html(sol) -> str:
    E = sol.relative_energy
    rows = [
        ("carrier", _text(repr(sol.carrier)), ""),
        ("time span", [float(sol.t[0]), float(sol.t[-1])], "s"),
        ("method", _text(f"{sol.method} ({sol.backend} backend)"), ""),
        ("steps", int(sol.nsteps), ""),
        ("principal moments", np.asarray(sol.body.principal_moments).tolist(), "kg·m²"),
        ("|ω_r| initial, final",
         [float(np.linalg.norm(sol.omega_r[0])), float(np.linalg.norm(sol.omega_r[-1]))],
         "rad/s"),
        ("max |ω| absolute (in space)", float(np.linalg.norm(sol.omega_absolute, axis=1).max()),
         "rad/s"),
        ("relative energy ½ ω_r·Jω_r, initial and final", [float(E[0]), float(E[-1])], "J"),
    ]  # fmt: skip
    return table("RelativeTrajectory", rows, "sol.plot() draws ω_r, the carrier, the energy "
                 "and the inertia moments.")  # fmt: skip


@register("poinsot.relative.simulate.RelativeTrajectory", "plot")
def _relative_plot(sol, kind="motion"):
    """``kind``: ``"motion"`` (default) or ``"hodograph"``."""
    from .relative import plot_hodograph, plot_relative_motion

    if kind == "motion":
        return plot_relative_motion(sol)
    if kind == "hodograph":
        return plot_hodograph(sol)
    raise ValueError(f"`kind` must be 'motion' or 'hodograph', found {kind!r}")


@register("poinsot.relative.simulate.RelativeTrajectory", "interactive")
def _relative_interactive(sol):
    from .interactive import relative_figure

    return relative_figure(sol)
