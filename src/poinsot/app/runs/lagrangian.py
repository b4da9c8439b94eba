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
        names = [str(q).replace("(t)", "") for q in sol.coordinates]
        reactions = model.reaction_values(sol)
        atomic_savez(
            folder / "solution.npz",
            t=sol.t,
            q=sol.q,
            qd=sol.qd,
            multipliers=sol.multipliers,
            constraint_forces=sol.constraint_forces,
            constraint_residual=sol.constraint_residual,
            constraint_velocity_residual=sol.constraint_velocity_residual,
            energy=sol.energy,
            coordinates=np.array(names),
            units=np.array(json.dumps(summary["units"])),
        )
        units = _coordinate_units(sol)
        header = (
            ["t [s]"]
            + [f"{n} [{units[n]}]" if units[n] else n for n in names]
            + [f"{n}_dot [{units[n + '_dot']}]" for n in names]
            + [f"lambda{k + 1}" for k in range(sol.multipliers.shape[1])]
            + [f"{n} [{u}]" for n, (_, u, _) in reactions.items()]
            + ["energy_h [J]"]
        )
        table = np.column_stack(
            [
                sol.t,
                sol.q,
                sol.qd,
                sol.multipliers,
                *[v for v, _, _ in reactions.values()],
                sol.energy,
            ]
        )
        with atomic_path(folder / "solution.csv") as tmp:
            np.savetxt(tmp, table, delimiter=",", header=",".join(header), comments="", fmt="%.17g")

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
            yield plot_mechanism_frames(model, sol), "mechanism.png", "The mechanism at a few times"

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


def _coordinate_units(sol):
    """``{name: unit}`` of the coordinates and ``{name_dot: unit/s}`` of their speeds."""
    units = {}
    for q in sol.coordinates:
        name, unit = str(q).replace("(t)", ""), sol.system.unit_of(q)
        units[name] = unit
        units[f"{name}_dot"] = f"{unit}/s" if unit else "1/s"
    return units


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
