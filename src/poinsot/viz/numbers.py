"""The numbers of a run as a reader sees them: grouped, named in words, with units.

One table per kind of run maps a key path of ``summary.json`` to a group, a human name and a
unit. The same table gives the ``units`` map written into ``summary.json`` and the report's
"Numbers" section, so the two cannot disagree. Quantities whose number depends on the run
(the conserved quantities, the reactions, the compared integrators) are added from the
summary itself, each with the unit it carries there.
"""

from __future__ import annotations

import html

__all__ = ["numbers_html", "rows_of", "units_of"]

#: ``(group, name, key path, unit)`` of a rigid-body run ("1": dimensionless).
RIGID = (
    ("Body", "mass", "body.mass", "kg"),
    ("Body", "centre of mass (reference frame of the body's definition)",
     "body.center_of_mass", "m"),
    ("Body", "principal moments A ≤ B ≤ C", "body.principal_moments", "kg·m²"),
    ("Body", "inertia tensor about the centre of mass", "body.inertia", "kg·m²"),
    ("Body", "principal axes (columns e₁, e₂, e₃)", "body.principal_axes", "1"),
    ("Body", "symmetry", "body.symmetry", ""),
    ("Body", "particles", "body.particles", ""),
    ("Initial state", "angular velocity ω₀ (body frame)", "initial.omega", "rad/s"),
    ("Initial state", "rotational energy k = ½ ω·Aω", "initial.rotational_energy", "J"),
    ("Initial state", "|L| about the centre of mass", "initial.angular_momentum_magnitude",
     "kg·m²/s"),
    ("Initial state", "a²/2k (sets the polhode family)", "initial.a2_over_2k", "kg·m²"),
    ("Torque-free motion", "polhode family", "torque_free.family", ""),
    ("Torque-free motion", "period of ω(t)", "torque_free.period", "s"),
    ("Torque-free motion", "time between flips", "torque_free.flip_interval", "s"),
    ("Integration", "method", "integration.method", ""),
    ("Integration", "backend", "integration.backend", ""),
    ("Integration", "start", "integration.t_start", "s"),
    ("Integration", "end", "integration.t_end", "s"),
    ("Integration", "steps", "integration.nsteps", ""),
    ("Integration", "right-hand-side evaluations", "integration.nfev", ""),
    ("Integration", "samples", "integration.samples", ""),
    ("Integration", "wall time of the integration", "integration.wall_time_s", "s"),
    ("Accuracy", "max |QᵀQ − I| (distance from a rotation)",
     "integration.diagnostics.orthogonality_error", "1"),
    ("Accuracy", "max change of a distance between body points",
     "integration.diagnostics.rigidity_error", "m"),
    ("Accuracy", "max |ω − ω_exact| against the exact solution",
     "torque_free.exact_solution_error.omega", "rad/s"),
    ("Accuracy", "max |Q − Q_exact| against the exact solution",
     "torque_free.exact_solution_error.attitude", "1"),
    ("Accuracy", "max relative error of k", "torque_free.exact_solution_error.energy", "1"),
    ("Accuracy", "max relative error of |L|", "torque_free.exact_solution_error.momentum", "1"),
    ("Final state", "t", "final.t", "s"),
    ("Final state", "centre of mass R", "final.R", "m"),
    ("Final state", "angular velocity ω (body frame)", "final.omega", "rad/s"),
    ("Run", "simulation", "timings.simulation_s", "s"),
    ("Run", "total, with figures and files", "timings.total_s", "s"),
)  # fmt: skip

#: The same for a run of a constrained (Lagrangian) model; coordinates add their own rows.
LAGRANGIAN = (
    ("System", "model", "scenario.model", ""),
    ("System", "coordinates", "system.coordinates", ""),
    ("System", "holonomic constraints g(q) = 0", "system.holonomic_constraints", ""),
    ("System", "non-holonomic constraints", "system.nonholonomic_constraints", ""),
    ("Initial state", "energy h", "initial.energy_h_J", "J"),
    ("Integration", "method", "integration.method", ""),
    ("Integration", "constraint stabilization", "integration.stabilization", ""),
    ("Integration", "right-hand-side evaluations", "integration.nfev", ""),
    ("Integration", "samples", "integration.samples", ""),
    ("Accuracy", "max relative change of h", "integration.energy_drift", "1"),
    ("Accuracy", "max |g(q)|", "integration.max_constraint_residual", "constraint's unit"),
    ("Accuracy", "max |G q̇ + b|", "integration.max_velocity_residual", "constraint's unit/s"),
    ("Final state", "t", "final.t", "s"),
    ("Run", "simulation", "timings.simulation_s", "s"),
    ("Run", "total, with figures and files", "timings.total_s", "s"),
)  # fmt: skip


#: ``poinsot polhodes``: the torque-free analysis of principal moments (and an ω0).
POLHODES = (
    ("Body", "principal moments A ≤ B ≤ C", "principal_moments", "kg·m²"),
    ("Body", "symmetry", "symmetry", ""),
    ("Initial state", "angular velocity ω₀ (principal frame)", "omega0", "rad/s"),
    ("Torque-free motion", "polhode family", "family", ""),
    ("Torque-free motion", "rotational energy k of the drawn ellipsoid", "energy", "J"),
    ("Torque-free motion", "|L|", "momentum", "kg·m²/s"),
    ("Torque-free motion", "period of ω(t)", "period", "s"),
    ("Torque-free motion", "time between flips", "flip_interval", "s"),
)


def _spec(summary):
    if "system" in summary:
        return LAGRANGIAN
    if "fixed_points" in summary:
        return POLHODES
    return RIGID


def _get(summary, path):
    node = summary
    for key in path.split("."):
        if not isinstance(node, dict) or key not in node:
            return None
        node = node[key]
    return node


def _dynamic_rows(summary):
    """Rows whose names come from the run: conserved quantities, reactions, coordinates,
    compared integrators."""
    rows = []
    conserved = _get(summary, "integration.diagnostics.invariants") or summary.get("conserved")
    for name, v in (conserved or {}).items():
        state = "conserved by the problem" if v["expected_conserved"] else "not conserved"
        rows.append(("Invariants", f"{v['symbol']}: {name}, initial", v["initial"], v["unit"]))
        rows.append(("Accuracy", f"{v['symbol']}: max relative change ({state})",
                     v["max_relative_change"], "1"))  # fmt: skip
    units = summary.get("units", {})
    for when in ("initial", "final"):
        group = "Initial state" if when == "initial" else "Final state"
        for kind, suffix in (("q", ""), ("qd", "_dot")):
            for name, value in (_get(summary, f"{when}.{kind}") or {}).items():
                label = f"d{name}/dt" if suffix else name
                rows.append((group, label, value, units.get(name + suffix, "")))
    for name, v in (summary.get("reactions") or {}).items():
        rows.append(("Reactions", f"{name}: {v['meaning']}, initial", v["initial"], v["unit"]))
        rows.append(("Reactions", f"{name}: range", [v["min"], v["max"]], v["unit"]))
    for method, v in (summary.get("method_comparison") or {}).items():
        for key, label, unit in (("orthogonality", "max |QᵀQ − I|", "1"),
                                 ("attitude", "max |Q − Q_exact|", "1"),
                                 ("omega", "max |ω − ω_exact|", "rad/s")):  # fmt: skip
            if key in v:
                rows.append(("Integrators compared at the same step", f"{method}: {label}",
                             v[key], unit))  # fmt: skip
    for fp in summary.get("fixed_points") or []:
        rows.append(("Torque-free motion", f"fixed points {fp['set']}",
                     "stable" if fp["stable"] else "unstable", ""))  # fmt: skip
    for name, value in (_get(summary, "system.parameters") or {}).items():
        rows.append(("System", f"parameter {name}", value, ""))
    return rows


def rows_of(summary: dict) -> list[tuple[str, str, object, str]]:
    """``[(group, name, value, unit)]`` of a run's summary, in reading order; keys the
    summary does not have are skipped."""
    spec = _spec(summary)
    rows = [(g, name, _get(summary, path), unit) for g, name, path, unit in spec]
    rows = [r for r in rows if r[2] is not None]
    order = ["System", "Body", "Initial state", "Invariants", "Reactions", "Torque-free motion",
             "Integration", "Accuracy", "Integrators compared at the same step", "Final state",
             "Run"]  # fmt: skip
    rows += _dynamic_rows(summary)
    return sorted(rows, key=lambda r: order.index(r[0]) if r[0] in order else len(order))


def units_of(summary: dict) -> dict:
    """``{key path: unit}`` of the fixed rows present in ``summary`` (for ``summary.json``)."""
    spec = _spec(summary)
    return {path: unit for _, _, path, unit in spec if unit and _get(summary, path) is not None}


def _format(value) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list):
        if value and all(isinstance(v, list) for v in value):
            return "<br>".join(_format(v) for v in value)
        return "(" + ", ".join(_format(v) for v in value) + ")"
    return html.escape(str(value))


def numbers_html(summary: dict, raw_link: str = "summary.json") -> str:
    """The report's "Numbers" section: one table per group (quantity, value, unit), and a
    link to the raw JSON."""
    parts = []
    group = None
    for g, name, value, unit in rows_of(summary):
        if g != group:
            if group is not None:
                parts.append("</table>")
            parts.append(f"<h3>{html.escape(g)}</h3><table class='numbers'>")
            group = g
        parts.append(f"<tr><th>{html.escape(name)}</th><td>{_format(value)}</td>"
                     f"<td class='unit'>{html.escape(unit)}</td></tr>")  # fmt: skip
    if group is not None:
        parts.append("</table>")
    parts.append(f"<p>All numbers, unrounded: <a href='{html.escape(raw_link)}'>"
                 f"{html.escape(raw_link)}</a> (also embedded in this page).</p>")  # fmt: skip
    return "\n".join(parts)
