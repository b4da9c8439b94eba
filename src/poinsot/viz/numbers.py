"""The numbers of a run as a reader sees them: grouped, named in words, with units, rounded.

One table per kind of run maps a key path of ``summary.json`` to a group, a human name and a
unit. The same table gives the ``units`` map written into ``summary.json`` and the report's
"Numbers" section, so the two cannot disagree. Quantities whose number depends on the run
(the conserved quantities, the reactions, the compared integrators) are added from the
summary itself, each with the unit it carries there.

Shown values are rounded to their uncertainty (:func:`format_value`); ``summary.json`` keeps
them unrounded.
"""

from __future__ import annotations

import html
import math

__all__ = ["format_value", "numbers_html", "rows_of", "units_of"]

#: Relative round-off of a computed quantity (a few operations in doubles): entries of a vector
#: or matrix smaller than this times its largest entry are noise (5.6e-17 in a diagonal
#: inertia tensor) and shown as 0.
ROUNDOFF = 1e-12
#: At most this many significant digits are shown (the JSON has them all).
MAX_DIGITS = 6
#: Key paths whose uncertainty another number of the summary states (an absolute error).
UNCERTAINTY = {
    "final.omega": "torque_free.exact_solution_error.omega",
}
#: Groups of error estimates: two significant digits say all they can.
ERROR_GROUPS = ("Accuracy", "Integrators compared at the same step")

#: ``(group, name, key path, unit)`` of a rigid-body run ("1": dimensionless). A row whose
#: group is None gives its number's unit to ``summary.json`` and no row to the report (the
#: number is shown under another key).
RIGID = (
    ("Body", "mass", "body.mass", "kg"),
    ("Body", "centre of mass (reference frame of the body's definition)",
     "body.center_of_mass", "m"),
    ("Body", "principal moments A_G ≤ B_G ≤ C_G about the centre of mass G (along e₁, e₂, e₃)",
     "body.principal_moments", "kg·m²"),
    ("Body", "inertia tensor about the centre of mass", "body.inertia", "kg·m²"),
    ("Body", "principal axes e₁, e₂, e₃ about the centre of mass G (columns, body frame)",
     "body.principal_axes", "1"),
    ("Body", "symmetry", "body.symmetry", ""),
    ("Pivot", "P (reference frame of the body's definition)", "pivot.body_position", "m"),
    ("Pivot", "P in space (fixed)", "pivot.position", "m"),
    ("Pivot", "principal moments about P, ascending (along e₁ᴾ, e₂ᴾ, e₃ᴾ)",
     "pivot.principal_moments", "kg·m²"),
    ("Pivot", "principal axes e₁ᴾ, e₂ᴾ, e₃ᴾ about P (columns, body frame)",
     "pivot.principal_axes", "1"),
    ("Body", "particles", "body.particles", ""),
    ("Initial state", "angular velocity ω₀ (body frame)", "initial.omega", "rad/s"),
    ("Initial state", "rotational energy k = ½ ω·A_G ω about the centre of mass",
     "initial.rotational_energy", "J"),
    ("Initial state", "|L_G| about the centre of mass", "initial.angular_momentum_magnitude",
     "kg·m²/s"),
    ("Initial state", "kinetic energy ½ ω·A_P ω (about the fixed pivot)",
     "initial.rotational_energy_pivot", "J"),
    ("Initial state", "|L_P| about the pivot", "initial.angular_momentum_magnitude_pivot",
     "kg·m²/s"),
    ("Initial state", "a²/2k (sets the polhode family)", "initial.a2_over_2k", "kg·m²"),
    ("Heavy top", "symmetry axis a, from the tip to the centre of mass (body frame)",
     "top.axis", "1"),
    ("Heavy top", "l: distance from the tip to the centre of mass", "top.length", "m"),
    ("Heavy top", "A_P: moment about the tip, across a", "top.A", "kg·m²"),
    ("Heavy top", "C: moment about the symmetry axis a (the same at the tip and at G)", "top.C",
     "kg·m²"),
    ("Heavy top", "M g l", "top.mgl", "N·m"),
    ("Heavy top", "spin ω·a about the symmetry axis a", "top.spin_omega3", "rad/s"),
    ("Heavy top", "θ min (angle of a from the upward vertical)", "top.theta_min", "rad"),
    ("Heavy top", "θ max", "top.theta_max", "rad"),
    ("Heavy top", "mean θ", "top.theta_mean", "rad"),
    ("Heavy top", "nutation amplitude (θ max − θ min)/2", "top.nutation_amplitude", "rad"),
    ("Heavy top", "nutation period", "top.nutation_period", "s"),
    ("Heavy top", "samples with a on the vertical (ψ undefined there)", "top.singular_samples",
     ""),
    ("Heavy top", "mean precession rate (slope of ψ(t))", "top.mean_precession_rate", "rad/s"),
    ("Heavy top", "gyroscopic estimate M g l/(C ω·a)", "top.gyroscopic_precession_rate",
     "rad/s"),
    ("Heavy top", "steady precession at mean θ, slow", "top.steady_precession_rate_slow",
     "rad/s"),
    ("Heavy top", "steady precession at mean θ, fast", "top.steady_precession_rate_fast",
     "rad/s"),
    ("Heavy top: closed form (Lagrange's top from the first sample)", "θ min",
     "top.exact.theta_min", "rad"),
    ("Heavy top: closed form (Lagrange's top from the first sample)", "θ max",
     "top.exact.theta_max", "rad"),
    ("Heavy top: closed form (Lagrange's top from the first sample)", "nutation period",
     "top.exact.nutation_period", "s"),
    ("Heavy top: closed form (Lagrange's top from the first sample)", "mean precession rate",
     "top.exact.mean_precession_rate", "rad/s"),
    ("Torque-free motion", "polhode family", "torque_free.family", ""),
    ("Torque-free motion", "rotational energy k", "torque_free.energy", "J"),
    ("Torque-free motion", "|L|", "torque_free.momentum", "kg·m²/s"),
    ("Torque-free motion", "period of ω(t)", "torque_free.period", "s"),
    ("Torque-free motion", "time between sign changes of ω·e₂ (half the period)",
     "torque_free.flip_interval", "s"),
    ("Torque-free motion", "the body flips (e₂ turns over against L; else it wobbles)",
     "torque_free.flips", ""),
    ("Torque-free motion", "max |e₂·L|/|L| over the motion", "torque_free.e2_swing", "1"),
    ("Torque-free motion", "Floquet: a deviation's growth per period, ‖∂ω(T)/∂ω₀ − 1‖ "
     "(multipliers all 1)", "torque_free.floquet_drift", "1"),
    ("Integration", "method", "integration.method", ""),
    ("Integration", "backend", "integration.backend", ""),
    ("Integration", "start", "integration.t_start", "s"),
    ("Integration", "end", "integration.t_end", "s"),
    ("Integration", "steps", "integration.nsteps", ""),
    ("Integration", "right-hand-side evaluations", "integration.nfev", ""),
    ("Integration", "samples", "integration.samples", ""),
    ("Integration", "wall time of the integration (compiled core: nothing is compiled at run "
     "time)", "integration.wall_time_s", "s"),
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
    ("Accuracy", "max |θ − θ_exact| against the closed-form top", "top.exact.max_theta_error",
     "rad"),
    ("Accuracy", "max |ψ − ψ_exact| against the closed-form top", "top.exact.max_psi_error",
     "rad"),
    ("Accuracy", "max |φ − φ_exact| against the closed-form top", "top.exact.max_phi_error",
     "rad"),
    ("Final state", "t", "final.t", "s"),
    ("Final state", "centre of mass R", "final.R", "m"),
    ("Final state", "angular velocity ω (body frame)", "final.omega", "rad/s"),
    ("Run", "simulation, with its set-up", "timings.simulation_s", "s"),
    ("Run", "total, with figures and files", "timings.total_s", "s"),
    # units only: the report shows these numbers once, in the body's rows
    (None, "mass", "integration.mass", "kg"),
    (None, "principal moments about the centre of mass", "integration.principal_moments",
     "kg·m²"),
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
    ("Accuracy", "max |g(q)|", "integration.max_constraint_residual", "constraint's unit"),
    ("Accuracy", "max |G q̇ + b|", "integration.max_velocity_residual", "constraint's unit/s"),
    ("Final state", "t", "final.t", "s"),
    ("Run", "symbolic derivation of the equations (SymPy; the model's first run in this "
     "process)", "timings.derivation_s", "s"),
    ("Run", "simulation: derivation, code generation (SymPy lambdify) and integration",
     "timings.simulation_s", "s"),
    ("Run", "total, with figures and files", "timings.total_s", "s"),
)  # fmt: skip


#: ``poinsot polhodes``: the torque-free analysis of principal moments (and an ω0).
POLHODES = (
    ("Body", "principal moments A ≤ B ≤ C", "principal_moments", "kg·m²"),
    ("Body", "symmetry", "symmetry", ""),
    ("Initial state", "angular velocity ω₀ (principal frame)", "omega0", "rad/s"),
    ("Initial state", "ω₀ as given (the axes of --moments)", "omega0_given", "rad/s"),
    ("Torque-free motion", "polhode family", "family", ""),
    ("Torque-free motion", "rotational energy k of the drawn ellipsoid", "energy", "J"),
    ("Torque-free motion", "|L|", "momentum", "kg·m²/s"),
    ("Torque-free motion", "period of ω(t)", "period", "s"),
    (
        "Torque-free motion",
        "time between sign changes of ω·e₂ (half the period)",
        "flip_interval",
        "s",
    ),
    (
        "Torque-free motion",
        "the body flips (e₂ turns over against L; else it wobbles)",
        "flips",
        "",
    ),
    ("Torque-free motion", "max |e₂·L|/|L| over the motion", "e2_swing", "1"),
    (
        "Torque-free motion",
        "Floquet: a deviation's growth per period, ‖∂ω(T)/∂ω₀ − 1‖ (multipliers all 1)",
        "floquet_drift",
        "1",
    ),
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
        if v.get("max_relative_change") is not None:
            rows.append(("Accuracy", f"{v['symbol']}: max relative change ({state})",
                         v["max_relative_change"], "1"))  # fmt: skip
        else:  # a zero initial value: the change itself, with its unit
            rows.append(("Accuracy", f"{v['symbol']}: max |{v['symbol']}(t) − "
                         f"{v['symbol']}(0)|, from {v['symbol']}(0) = 0 ({state})",
                         v["max_change"], v["unit"]))  # fmt: skip
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
    units = _get(summary, "system.parameter_units") or {}
    for name, value in (_get(summary, "system.parameters") or {}).items():
        rows.append(("System", f"parameter {name}", value, units.get(name, "")))
    return rows


def rows_of(summary: dict) -> list[tuple[str, str, object, str]]:
    """``[(group, name, value, unit)]`` of a run's summary, in reading order; keys the
    summary does not have are skipped. Values are as in the summary (unrounded)."""
    return [row[:4] for row in _rows(summary)]


def _rows(summary):
    """``[(group, name, value, unit, uncertainty)]``: the uncertainty an absolute number
    where the summary states one (:data:`UNCERTAINTY`), else None (round-off)."""
    spec = _spec(summary)
    rows = []
    for g, name, path, unit in spec:
        value = _get(summary, path)
        if value is None or g is None:
            continue
        unc = _get(summary, UNCERTAINTY[path]) if path in UNCERTAINTY else None
        rows.append((g, name, value, unit, unc if isinstance(unc, int | float) else None))
    order = ["System", "Body", "Pivot", "Initial state", "Invariants", "Reactions", "Heavy top",
             "Heavy top: closed form (Lagrange's top from the first sample)",
             "Torque-free motion",
             "Integration", "Accuracy", "Integrators compared at the same step", "Final state",
             "Run"]  # fmt: skip
    rows += [(*r, None) for r in _dynamic_rows(summary)]
    return sorted(rows, key=lambda r: order.index(r[0]) if r[0] in order else len(order))


def units_of(summary: dict) -> dict:
    """``{key path: unit}`` of the fixed rows present in ``summary`` (for ``summary.json``),
    and of the numbers of each conserved quantity, by the unit its entry carries (its relative
    change: "1")."""
    spec = _spec(summary)
    out = {path: unit for _, _, path, unit in spec if unit and _get(summary, path) is not None}
    for base in ("integration.diagnostics.invariants", "conserved"):
        for name, v in (_get(summary, base) or {}).items():
            for key, unit in (("initial", v.get("unit")), ("max_change", v.get("unit")),
                              ("max_relative_change", "1")):  # fmt: skip
                if unit and v.get(key) is not None:
                    out[f"{base}.{name}.{key}"] = unit
    return out


def _scale(value) -> float:
    """The largest magnitude among the numbers of ``value`` (a number or nested lists)."""
    if isinstance(value, bool):
        return 0.0
    if isinstance(value, int | float):
        return abs(value) if math.isfinite(value) else 0.0
    if isinstance(value, list):
        return max((_scale(v) for v in value), default=0.0)
    return 0.0


def _round(x: float, unc: float, digits: int) -> str:
    """``x`` to the digit of ``unc`` (at most ``digits`` significant digits); zero when
    ``|x| < unc``; never ``-0``."""
    if not math.isfinite(x):
        return str(x)
    if unc > 0 and abs(x) < unc:
        return "0"
    if x == 0:
        return "0"
    lead = math.floor(math.log10(abs(x)))
    n = digits if not unc > 0 else min(digits, max(1, lead - math.floor(math.log10(unc)) + 1))
    text = f"{x:.{n}g}"
    return "0" if float(text) == 0 else text


def format_value(value, uncertainty=None, *, digits=MAX_DIGITS) -> str:
    """A summary's value as shown (HTML-escaped): numbers rounded to ``uncertainty`` (an
    absolute number), by default the round-off of the quantity (:data:`ROUNDOFF` times its
    largest entry, so that the noise of a vector or matrix shows as 0), at most ``digits``
    significant digits; never ``-0``. Vectors in parentheses, matrices one row a line.

    Examples
    --------
    >>> format_value([[21.666666666666668, -5.551115123125783e-17], [-0.0, 16.666666666666668]])
    '(21.6667, 0)<br>(0, 16.6667)'
    >>> format_value(0.9873084531, uncertainty=2.3e-4)
    '0.9873'
    """
    if uncertainty is None or not uncertainty > 0:
        uncertainty = ROUNDOFF * _scale(value)
    unc = float(uncertainty)

    def fmt(v):
        if isinstance(v, bool):
            return "yes" if v else "no"
        if isinstance(v, int):
            return str(v)
        if isinstance(v, float):
            return _round(v, unc, digits)
        if isinstance(v, list):
            if v and all(isinstance(x, list) for x in v):
                return "<br>".join(fmt(x) for x in v)
            return "(" + ", ".join(fmt(x) for x in v) + ")"
        return html.escape(str(v))

    return fmt(value)


def numbers_html(summary: dict, raw_link: str = "summary.json") -> str:
    """The report's "Numbers" section: one table per group (quantity, value, unit), and a
    link to the raw JSON."""
    parts = []
    group = None
    for g, name, value, unit, unc in _rows(summary):
        if g != group:
            if group is not None:
                parts.append("</table>")
            parts.append(f"<h3>{html.escape(g)}</h3><table class='numbers'>")
            group = g
        shown = format_value(value, unc, digits=2 if g in ERROR_GROUPS else MAX_DIGITS)
        parts.append(f"<tr><th>{html.escape(name)}</th><td>{shown}</td>"
                     f"<td class='unit'>{html.escape(unit)}</td></tr>")  # fmt: skip
    if group is not None:
        parts.append("</table>")
    parts.append("<p>Values are rounded to their uncertainty (round-off, or the error against "
                 "the exact solution where one is known). All numbers, unrounded: "
                 f"<a href='{html.escape(raw_link)}'>{html.escape(raw_link)}</a> (also embedded "
                 "in this page).</p>")  # fmt: skip
    return "\n".join(parts)
