"""A constrained (Lagrangian) system's run: the solution, its reactions, what it conserves."""

from __future__ import annotations

import json

import numpy as np

from ..._io import atomic_path, atomic_savez
from .base import (
    Run,
    add_units,
    change_shown,
    jsonable,
    png_images,
    pyplot,
    scenario_header,
    shown,
    wrote_line,
)

__all__ = ["LagrangianRun", "summarize_lagrangian"]


class LagrangianRun(Run):
    """A :class:`~poinsot.app.scenario.LagrangianScenario` (``[model]``); writes
    solution.npz/.csv, solution.png, mechanism.png and report.html."""

    derivation_s = 0.0  # the symbolic derivation's share of the simulation's time

    def simulate(self, progress=None):
        import time

        system = self.scenario.model.system
        start = time.perf_counter()
        # the equations of motion, derived once per model and process (cached on the system):
        # timed apart, since the first run of a model pays for it and later ones do not
        system.augmented_matrix, system.augmented_forcing, system.energy_function  # noqa: B018
        self.derivation_s = time.perf_counter() - start
        self.result = self.scenario.simulate(progress=progress)

    def summarise(self):
        summary = summarize_lagrangian(self.scenario, self.result)
        add_units(summary)
        return summary

    def write_data(self, folder, summary):
        sol, model = self.result, self.scenario.model
        fields = solution_fields(sol, model)
        reactions = model.reaction_values(sol)
        atomic_savez(
            folder / "solution.npz",
            **{name: values for name, (values, _, _) in fields.items()},
            coordinates=np.array([_name(q) for q in sol.coordinates]),
            constraints=np.array(_constraint_texts(sol.system), dtype=str),
            reaction_names=np.array(list(reactions), dtype=str),
            units=np.array(json.dumps({name: units for name, (_, _, units) in fields.items()})),
        )
        header, columns = [], []
        for values, labels, units in fields.values():
            per_column = [units] * len(labels) if isinstance(units, str) else units
            header += [f"{c} [{u}]" for c, u in zip(labels, per_column, strict=True)]
            columns.append(values.reshape(len(sol.t), -1))
        with atomic_path(folder / "solution.csv") as tmp:
            np.savetxt(tmp, np.column_stack(columns), delimiter=",", header=",".join(header),
                       comments="", fmt="%.17g")  # fmt: skip

    interactive_report = True
    report_links = ("summary.json", "solution.npz", "solution.csv")

    def figures(self, folder, *, for_report):
        if folder is None and not for_report:
            return {}
        pyplot()
        from ...viz.lagrange import plot_lagrangian_solution, plot_mechanism_frames

        sol, model = self.result, self.scenario.model

        def figures():  # one at a time: each is drawn, rendered and closed before the next
            yield (plot_lagrangian_solution(sol, model=model, title=model.description),
                   "solution.png", "The coordinates, the reactions and the residuals")  # fmt: skip
            if model.points:  # nothing to draw (no named body, no [draw]): no mechanism figure
                yield (plot_mechanism_frames(model, sol), "mechanism.png",
                       "The mechanism at a few times")  # fmt: skip

        return png_images(figures(), folder, dpi=110)

    def write_report(self, path, summary, images, *, plotlyjs="inline"):
        from ...viz.report import write_lagrangian_report

        write_lagrangian_report(path, self.result, summary, model=self.scenario.model,
                                plotlyjs=plotlyjs)  # fmt: skip

    def finish(self, summary):
        summary.setdefault("timings", {})["derivation_s"] = self.derivation_s
        add_units(summary)

    def terminal_lines(self, summary, out):
        scenario = self.scenario
        i = summary["integration"]
        t0, t1 = (shown(t, "g") for t in scenario.t_span)
        lines = [
            f"  coordinates {', '.join(summary['system']['coordinates'])}; "
            f"{len(summary['system']['holonomic_constraints'])} holonomic and "
            f"{len(summary['system']['nonholonomic_constraints'])} non-holonomic "
            "constraints",
            f"  integrated t ∈ [{t0}, {t1}] s with {i['method']} (stabilization "
            f"{i['stabilization']}): max |g| {shown(i['max_constraint_residual'], '.2e')}, "
            f"max |G q̇ + b| {shown(i['max_velocity_residual'], '.2e')}",
        ]
        kept = list(summary["conserved"].values())
        if kept:
            changes = ", ".join(change_shown(v) for v in kept)
            lines.append(f"  conserved by this system, largest change: {changes}")
        for name, v in summary["reactions"].items():
            lines.append(f"  {name}: {shown(v['min'], '.6g')} … "
                         f"{shown(v['max'], '.6g', unit=v.get('unit') or '')}")  # fmt: skip
        for r in summary.get("releases", []):
            lines.append(f"  released at t = {shown(r['t'], '.10g')} s: {r['constraint']} ≥ 0 "
                         "let go")  # fmt: skip
        lines.append(wrote_line(out))
        return lines


def _name(q) -> str:
    return str(q).replace("(t)", "")


def _constraint_texts(system) -> list[str]:
    """The constraints as text, in the multipliers' order (holonomic and one-sided g = 0,
    then the velocity constraints)."""
    from sympy.physics.vector.printing import vsprint  # q̇ printed as q'

    return [vsprint(c) for c in (*system.holonomic, *system.nonholonomic)]


def _coordinate_units(sol):
    """``{name: unit}`` of the coordinates and ``{name_dot: unit/s}`` of their speeds."""
    units = {}
    for q in sol.coordinates:
        name, unit = _name(q), sol.system.unit_of(q)
        units[name] = unit
        units[f"{name}_dot"] = f"{unit}/s" if unit else "1/s"
    return units


def solution_fields(sol, model) -> dict:
    """Every field of solution.npz, as solution.csv carries it too: ``name → (values
    (n_samples,) or (n_samples, k), column labels, unit or one unit per column)``. A unit the
    run cannot know (a constraint's, a reaction declared without one) is said in words."""
    names = [_name(q) for q in sol.coordinates]
    units = _coordinate_units(sol)
    more = sol.export_units()
    m, nh = sol.multipliers.shape[1], sol.constraint_residual.shape[1]
    reactions = model.reaction_values(sol)
    values = [v for v, _, _ in reactions.values()]
    return {
        "t": (sol.t, ["t"], "s"),
        "q": (sol.q, names, [units[n] or "unit not given" for n in names]),
        "qd": (sol.qd, [f"{n}_dot" for n in names], [units[f"{n}_dot"] for n in names]),
        "multipliers": (sol.multipliers, [f"lambda{k + 1}" for k in range(m)],
                        more["multipliers"]),
        "constraint_forces": (sol.constraint_forces, [f"constraint_force_{n}" for n in names],
                              more["constraint_forces"]),
        "reactions": (np.column_stack(values) if values else np.zeros((len(sol.t), 0)),
                      list(reactions), [u or "unit not given" for _, u, _ in reactions.values()]),
        "constraint_residual": (sol.constraint_residual, [f"g{k + 1}" for k in range(nh)],
                                more["constraint_residual"]),
        "constraint_velocity_residual": (
            sol.constraint_velocity_residual,
            [f"G{k + 1}_qd_plus_b{k + 1}" for k in range(m)],
            more["constraint_velocity_residual"]),
        "energy": (sol.energy, ["energy_h"], "J"),
    }  # fmt: skip


def summarize_lagrangian(scenario, sol) -> dict:
    """The numbers of a Lagrangian run, JSON-ready, with a ``units`` map, the reactions as
    named forces and what the system conserves."""
    from sympy.physics.vector.printing import vsprint  # q̇ printed as q'

    system = sol.system
    model = scenario.model
    names = [str(q).replace("(t)", "") for q in sol.coordinates]
    e0 = sol.energy[0]
    reactions = model.reaction_values(sol)
    invariants = sol.invariants
    out = {
        "scenario": scenario_header(scenario, model=model.name),
        "system": {
            "coordinates": names,
            "holonomic_constraints": [vsprint(g) for g in system.holonomic],
            "nonholonomic_constraints": [vsprint(a) for a in system.nonholonomic],
            "parameters": {str(k): float(v) for k, v in scenario.params.items()},
            "parameter_units": {str(k): model.unit_of_parameter(k) for k in scenario.params},
        },
        "initial": {
            "q": dict(zip(names, sol.q[0].tolist(), strict=True)),
            "qd": dict(zip(names, sol.qd[0].tolist(), strict=True)),
            "energy_h_J": float(e0),
        },
        "final": {
            "t": float(sol.t[-1]),
            "q": dict(zip(names, sol.q[-1].tolist(), strict=True)),
            "qd": dict(zip(names, sol.qd[-1].tolist(), strict=True)),
            "multipliers": sol.multipliers[-1].tolist(),
        },
        "integration": {
            "method": sol.method,
            "stabilization": sol.stabilization,
            "nfev": int(sol.nfev),
            "samples": len(sol.t),
            "max_constraint_residual": float(np.nanmax(np.abs(sol.constraint_residual)))
            if sol.constraint_residual.size
            else 0.0,
            "max_velocity_residual": float(np.nanmax(np.abs(sol.constraint_velocity_residual)))
            if sol.constraint_velocity_residual.size
            else 0.0,
        },
        "conserved": {i.name: i.describe() for i in invariants},
        "releases": [
            {"t": t, "constraint": constraint, "meaning": "a one-sided constraint let go"}
            for t, constraint, _ in getattr(sol, "releases", ())
        ],
        "reactions": {
            name: {
                "unit": unit,
                "meaning": meaning,
                "initial": float(v[0]),
                "min": float(v.min()),
                "max": float(v.max()),
            }
            for name, (v, unit, meaning) in reactions.items()
        },
        "multipliers": {
            "min": sol.multipliers.min(axis=0).tolist(),
            "max": sol.multipliers.max(axis=0).tolist(),
        }
        if sol.multipliers.size
        else {},
        "units": {
            "t": "s",
            **_coordinate_units(sol),
            "energy_h": "J",
            "max_constraint_residual": "the constraints' own units",
            **{name: unit for name, (_, unit, _) in reactions.items()},
            **{f"system.parameters.{k}": model.unit_of_parameter(k) for k in scenario.params},
        },
    }
    return jsonable(out)
