"""Running a scenario end to end: simulate, analyse, and write data, figures and the report.

Everything is written through :class:`~poinsot._io.OutputFolder`: into a hidden folder beside
the target, moved into place only when complete, so an interrupted run (Ctrl-C, SIGTERM, a
crash) never leaves a half-written output folder. The target is checked before the simulation
starts; an existing folder is replaced only with ``force=True`` and only if poinsot wrote it.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from .._io import OutputError, OutputExistsError, OutputFolder, atomic_path, atomic_write_text

__all__ = ["OutputError", "OutputExistsError", "run_scenario", "summarize"]


def estimated_output_bytes(scenario) -> int:
    """A generous estimate of what a run writes, checked against the free disk space: figures
    and a self-contained report (~10 MB) plus the sampled data."""
    ensemble = getattr(scenario, "ensemble", None)
    rows = ensemble["members"] if ensemble is not None else scenario.samples
    return 10_000_000 + 2_000 * int(rows)


def _torque_free(scenario):
    """The torque-free analysis of the body, or ``None`` when it does not apply."""
    from ..torquefree import FreeRigidBody

    if not scenario.analysis.get("polhodes", True) or scenario.body.is_degenerate:
        return None
    if scenario.pivot is not None and np.any(scenario.pivot != scenario.body.center_of_mass):
        return None
    return FreeRigidBody.from_body(scenario.body)


def _within_range(free, scenario, traj):
    """``free``, or None (with a warning) when the run's energy puts its polhodes outside the
    double range (moments near 1e300): the torque-free figures are then left out."""
    from ..kernels.rigid import rotational_energy

    k = float(rotational_energy(scenario.body.inertia, np.ascontiguousarray(traj.omega[0])))
    try:
        if k > 0:
            free.check_energy_range(k)
    except ValueError as exc:
        import warnings

        from .._io import PoinsotWarning

        warnings.warn(f"torque-free analysis and polhodes left out: {exc}", PoinsotWarning,
                      stacklevel=3)  # fmt: skip
        return None
    return free


def summarize(scenario, traj, free=None) -> dict:
    """The numbers of a run, JSON-ready: body, invariants, torque-free analysis, diagnostics."""
    from ..kernels.rigid import angular_momentum_body, rotational_energy

    body = scenario.body
    w0 = np.ascontiguousarray(traj.omega[0])
    k0 = float(rotational_energy(body.inertia, w0))
    a0 = float(np.hypot.reduce(angular_momentum_body(body.inertia, w0)))  # no overflow
    out = {
        "scenario": {
            "name": scenario.name,
            "description": scenario.description,
            "source": scenario.source,
        },
        "body": body.mass_properties(),
        "initial": {
            "omega": w0.tolist(),
            "rotational_energy": k0,
            "angular_momentum_magnitude": a0,
            "a2_over_2k": a0 * a0 / (2 * k0) if k0 > 0 else None,
        },
        "final": {
            "t": float(traj.t[-1]),
            "R": traj.R[-1].tolist(),
            "omega": traj.omega[-1].tolist(),
        },
        "integration": traj.summary(),
    }
    if free is not None and k0 > 0:
        analysis = free.describe(w0)
        from ..forces import Gravity

        if all(isinstance(f, Gravity) for f in scenario.forces):  # no torque about the c.o.m.
            analysis["exact_solution_error"] = free.trajectory_error(traj)
        out["torque_free"] = analysis
    return _jsonable(out)


def _jsonable(obj):
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        return None if np.isnan(obj) else ("inf" if obj > 0 else "-inf")
    return obj


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
        "scenario": {
            "name": scenario.name,
            "description": scenario.description,
            "source": scenario.source,
            "model": model.name,
        },
        "system": {
            "coordinates": names,
            "holonomic_constraints": [vsprint(g) for g in system.holonomic],
            "nonholonomic_constraints": [vsprint(a) for a in system.nonholonomic],
            "parameters": {str(k): float(v) for k, v in scenario.params.items()},
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
            "energy_drift": float(np.abs(sol.energy - e0).max() / (abs(e0) or 1.0)),
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
            "energy_drift": "1 (relative)",
            "max_constraint_residual": "the constraints' own units",
            **{name: unit for name, (_, unit, _) in reactions.items()},
        },
    }
    return _jsonable(out)


def _write_lagrangian(work: Path, scenario, sol, summary, report, plotlyjs="inline"):
    names = [str(q).replace("(t)", "") for q in sol.coordinates]
    model = scenario.model
    reactions = model.reaction_values(sol)
    if scenario.outputs.get("data", True):
        with atomic_path(work / "solution.npz", suffix=".npz") as tmp, open(tmp, "wb") as fh:
            np.savez_compressed(
                fh,
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
        with atomic_path(work / "solution.csv") as tmp:
            np.savetxt(tmp, table, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    if scenario.outputs.get("figures", True):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from ..viz.lagrange import plot_lagrangian_solution, plot_mechanism_frames

        for fig, name in (
            (plot_lagrangian_solution(sol, model=model, title=model.description), "solution.png"),
            (plot_mechanism_frames(model, sol), "mechanism.png"),
        ):
            with atomic_path(work / name) as tmp:
                fig.savefig(tmp, dpi=110, format="png")
            plt.close(fig)
    if report and scenario.outputs.get("report", True):
        from ..viz.report import write_lagrangian_report

        write_lagrangian_report(work / "report.html", sol, summary, model=model,
                                plotlyjs=plotlyjs)  # fmt: skip


def _figures(folder: Path, scenario, traj, free, comparison=None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .._core import equivalent_box_half_extents
    from ..viz import (
        plot_attitude_frames,
        plot_center_of_mass_path,
        plot_conservation,
        plot_omega_series,
        plot_polhode_family,
    )

    def save(fig, name):
        with atomic_path(folder / name) as tmp:
            fig.savefig(tmp, dpi=110, format="png")
        plt.close(fig)

    save(plot_omega_series(traj), "omega.png")
    if comparison is not None:
        from ..viz import plot_method_comparison

        save(
            plot_method_comparison(
                traj.t,
                comparison[0],
                title="Integrators against the exact torque-free solution, same step",
            ),
            "methods.png",
        )
    save(plot_conservation(traj), "conservation.png")
    if np.ptp(traj.R, axis=0).max() > 0:  # a centre of mass at rest has no path to draw
        save(plot_center_of_mass_path(traj), "center_of_mass.png")
    half = equivalent_box_half_extents(scenario.body.principal_moments, scenario.body.mass)
    QE = traj.Q @ scenario.body.principal_axes  # draw the box in principal axes
    half = np.maximum(half, 1e-3 * half.max())  # a flat body is drawn as a thin box
    save(plot_attitude_frames(QE, traj.t, half_extents=half), "body.png")
    if free is not None:
        from ..kernels.rigid import rotational_energy

        energy = scenario.analysis.get("energy")
        k_traj = float(
            rotational_energy(scenario.body.inertia, np.ascontiguousarray(traj.omega[0]))
        )
        levels = scenario.analysis.get("levels", 9)
        if k_traj > 0:  # the run's ω(t) on its own energy ellipsoid, with the family there
            fig = plot_polhode_family(free, k_traj, levels=levels)
            ax = fig.axes[0]
            ax.plot(*traj.omega.T, color="crimson", lw=2.5, label="ω(t) of this run")
            ax.set_title(f"This run's ω(t) (rad/s, body frame) on its energy ellipsoid, "
                         f"k = {k_traj:.4g} J\nwith the polhodes at that energy")  # fmt: skip
            ax.legend(loc="upper left", fontsize=8)
            save(fig, "polhodes.png")
        if energy is not None and not np.isclose(energy, k_traj, rtol=1e-12):
            fig = plot_polhode_family(free, energy, levels=levels)  # [analysis] energy's sweep
            fig.axes[0].set_title(f"The polhode family at k = {energy:g} J ([analysis] energy), "
                                  "not this run's energy")  # fmt: skip
            save(fig, "polhodes_sweep.png")


#: The integrators a fixed-step torque-free run is compared with: the notebook's classical
#: RK4 and the Lie-group RKMK4 of the same order, which keeps the attitude on SO(3).
COMPARED_METHODS = ("rk4", "rkmk4")


def compare_methods(scenario, traj, free):
    """Run the scenario again with each of :data:`COMPARED_METHODS` (same step) and measure
    each run against the exact torque-free solution.

    Returns ``(errors, table)`` or None when the comparison does not apply (no exact solution:
    a torque about the centre of mass; or an adaptive step, which has no step to share).
    ``errors``: ``label → per-sample arrays`` for :func:`~poinsot.viz.plot_method_comparison`
    (the exact solution's own distance from SO(3) included); ``table``: the maxima, JSON-ready.
    """
    from ..forces import Gravity
    from ..kernels.rigid import orthogonality_error

    if free is None or scenario.dt is None or not np.any(traj.omega[0]):
        return None
    if not all(isinstance(f, Gravity) for f in scenario.forces):
        return None
    runs = {traj.method: traj}
    for method in COMPARED_METHODS:
        if method not in runs:
            runs[method] = scenario.simulate(method=method)
    errors, table = {}, {}
    for method, tr in runs.items():
        label = f"{method}, dt = {scenario.dt:g} s"
        errors[label] = {"orthogonality": tr.orthogonality_error, **free.error_series(tr)}
        table[method] = {
            k: float(np.max(errors[label][k])) for k in ("orthogonality", "attitude", "omega")
        }
    t = traj.t - traj.t[0]
    Q = free.exact_attitude(traj.omega[0], t, traj.Q[0])
    errors["exact solution (round-off)"] = {"orthogonality": orthogonality_error(Q)}
    table["exact"] = {
        "orthogonality": float(errors["exact solution (round-off)"]["orthogonality"].max())
    }
    return errors, table


def comparison_lead(table: dict, dt: float) -> str:
    """One sentence stating what the method comparison shows."""
    parts = [
        f"{m.upper()} leaves SO(3) by {v['orthogonality']:.2g} and is off the exact "
        f"attitude by {v['attitude']:.2g}"
        for m, v in table.items()
        if m != "exact"
    ]
    omega = [v["omega"] for m, v in table.items() if m != "exact"]
    same = len(omega) > 1 and np.ptp(omega) <= 1e-6 * max(omega)
    return (
        f"Integrators at the same step dt = {dt:g} s against the exact solution: "
        + "; ".join(parts)
        + f"; the exact solution stays within {table['exact']['orthogonality']:.1g} of SO(3)."
        + (
            " Their ω errors coincide: Euler's equation for ω does not involve the attitude, "
            "and both are 4th-order Runge–Kutta for it."
            if same
            else ""
        )
    )


def run_scenario(
    scenario, out, *, force=False, progress=None, report=True, plotlyjs="inline"
) -> dict:
    """Simulate ``scenario`` and write its outputs to the folder ``out``; return the summary.

    Raises :class:`OutputExistsError` if ``out`` exists and ``force`` is false,
    :class:`OutputError` if ``out`` cannot or may not be written (both checked before any
    work; see :class:`~poinsot._io.OutputFolder`), and
    :class:`~poinsot.simulation.SimulationError` on a numerical failure. ``plotlyjs``: how the
    report gets plotly.js (:data:`poinsot.viz.report.PLOTLYJS_MODES`).
    """
    folder = OutputFolder(
        out, force=force, command="run", needs_bytes=estimated_output_bytes(scenario)
    )
    if getattr(scenario, "ensemble", None) is not None:
        return _run_ensemble(scenario, folder, report=report)
    if getattr(scenario, "carrier", None) is not None:
        return _run_relative(scenario, folder, progress=progress, report=report)
    start = time.perf_counter()
    traj = scenario.simulate(progress=progress)
    sim_time = time.perf_counter() - start
    from .scenario import LagrangianScenario

    lagrangian = isinstance(scenario, LagrangianScenario)
    free = None if lagrangian else _torque_free(scenario)
    if free is not None:
        free = _within_range(free, scenario, traj)
    summary = (
        summarize_lagrangian(scenario, traj) if lagrangian else summarize(scenario, traj, free)
    )
    comparison = None if lagrangian else compare_methods(scenario, traj, free)
    _add_units(summary)
    if comparison is not None:
        summary["method_comparison"] = comparison[1]
        summary["lead"] = comparison_lead(comparison[1], scenario.dt)
    with folder.writing() as work:
        if lagrangian:
            _write_lagrangian(work, scenario, traj, summary, report, plotlyjs)
        elif scenario.outputs.get("data", True):
            traj.to_npz(work / "trajectory.npz")
            traj.to_csv(work / "trajectory.csv")
            try:
                ds = traj.to_xarray()
            except ImportError:
                pass
            else:
                with atomic_path(work / "trajectory.nc") as tmp:
                    ds.to_netcdf(tmp, engine="scipy")
        if not lagrangian and scenario.outputs.get("figures", True):
            _figures(work, scenario, traj, free, comparison)
        if not lagrangian and report and scenario.outputs.get("report", True):
            from ..viz.report import write_report

            write_report(
                work / "report.html",
                traj,
                summary,
                free=free,
                comparison=None if comparison is None else comparison[0],
                plotlyjs=plotlyjs,
            )
        summary["timings"] = {"simulation_s": sim_time, "total_s": time.perf_counter() - start}
        _add_units(summary)
        atomic_write_text(work / "summary.json", json.dumps(_jsonable(summary), indent=2))
    return summary


def _add_units(summary: dict) -> None:
    """``summary["units"]``: the unit of every number, by key path (:mod:`poinsot.viz.numbers`),
    plus the per-quantity units the summary already carries."""
    from ..viz.numbers import units_of

    summary["units"] = {**summary.get("units", {}), **units_of(summary)}


# --------------------------------------------------------------------------- ensembles
def summarize_ensemble(scenario, res, free=None) -> dict:
    """The numbers of an ensemble run, JSON-ready: the scenario, the distribution of initial
    spins, the body, the run and each statistic's distribution; with ``free`` (a torque-free
    asymmetric body) the measured flip intervals against the exact ones."""
    e = scenario.ensemble
    if e["distribution"] == "sphere":
        dist = {"description": f"ω uniform on the sphere |ω| = {e['speed']:g} rad/s"}
    else:
        dist = {
            "description": f"ω ~ N({e['mean'].tolist()}, diag({e['std'].tolist()})²) rad/s",
            "mean": e["mean"].tolist(),
            "std": e["std"].tolist(),
        }
    out = {
        "scenario": {
            "name": scenario.name,
            "description": scenario.description,
            "source": scenario.source,
        },
        "distribution": {"kind": e["distribution"], "seed": e["seed"], **dist},
        "body": scenario.body.mass_properties(),
        "ensemble": res.summary(),
        "units": {"time": "s", "omega": "rad/s", "errors": "dimensionless"},
    }
    if free is not None:
        exact = free.flip_interval(res.initial_state[:, 15:18])
        measured = res.flip_interval
        ok = np.isfinite(exact) & np.isfinite(measured)
        rel = measured[ok] / exact[ok] - 1
        out["flips_against_exact"] = {
            "meaning": "measured mean time between flips / exact 2K(m)/λ − 1, per member",
            "members_compared": int(ok.sum()),
            "exact_flip_interval_s": _describe(exact[np.isfinite(exact)]),
            "relative_error": _describe(np.abs(rel)),
        }
    return _jsonable(out)


def _describe(values):
    from ..ensemble.result import _describe as describe

    return describe(values)


def _ensemble_free_body(scenario):
    """The torque-free body whose exact flip intervals grade the ensemble, or None."""
    if scenario.forces or scenario.pivot is not None or scenario.body.is_degenerate:
        return None
    from ..torquefree import FreeRigidBody

    free = FreeRigidBody.from_body(scenario.body)
    return free if free.symmetry == "asymmetric" else None


def _run_ensemble(scenario, folder: OutputFolder, *, report=True) -> dict:
    """Run ``[ensemble]`` and write summary.json, ensemble.nc, histograms and report.html."""
    start = time.perf_counter()
    res = scenario.simulate_ensemble(progress=None)
    sim_time = time.perf_counter() - start
    free = _ensemble_free_body(scenario)
    summary = summarize_ensemble(scenario, res, free)
    with folder.writing() as work:
        images = {}
        if scenario.outputs.get("data", True):
            _write_ensemble_dataset(work / "ensemble.nc", res, free)
        if scenario.outputs.get("figures", True) or (report and scenario.outputs.get("report")):
            images = _ensemble_figures(work, scenario, res, free)
        if report and scenario.outputs.get("report", True):
            from ..viz.report import write_ensemble_report

            write_ensemble_report(work / "report.html", summary, images)
        summary["timings"] = {"simulation_s": sim_time, "total_s": time.perf_counter() - start}
        atomic_write_text(work / "summary.json", json.dumps(_jsonable(summary), indent=2))
    return summary


def _write_ensemble_dataset(path: Path, res, free):
    try:
        ds = res.to_xarray()
    except ImportError:
        return
    W0 = res.initial_state[:, 15:18]
    ds["omega0"] = (("member", "component"), W0, {"units": "rad/s", "frame": "body"})
    if free is not None:
        ds["exact_flip_interval"] = (("member",), free.flip_interval(W0), {"units": "s"})
    for name in list(ds.variables):  # NetCDF-3 (SciPy's writer) has no 64-bit integers
        if ds[name].dtype == np.int64:
            ds[name] = ds[name].astype(np.int32)
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine="scipy")


def _ensemble_figures(folder: Path, scenario, res, free) -> dict:
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..viz.ensemble import plot_ensemble_histograms, plot_flip_intervals

    images = {}

    def save(fig, name, caption):
        buf = io.BytesIO()
        fig.savefig(buf, dpi=100, format="png")
        plt.close(fig)
        if scenario.outputs.get("figures", True):
            with atomic_path(folder / name) as tmp:
                Path(tmp).write_bytes(buf.getvalue())
        images[caption] = buf.getvalue()

    save(plot_ensemble_histograms(res), "histograms.png", "Distributions over the members")
    if free is not None and np.isfinite(res.flip_interval).any():
        exact = free.flip_interval(res.initial_state[:, 15:18])
        save(plot_flip_intervals(res, exact), "flip_intervals.png",
             "Measured time between flips against the exact 2K(m)/λ")  # fmt: skip
    return images


# --------------------------------------------------------------------------- relative motion
def summarize_relative(scenario, sol) -> dict:
    """The numbers of a motion relative to ``[carrier]``, JSON-ready, with a ``table`` of
    ``name → (value, unit, meaning)`` for the report and the terminal."""
    from ..relative import planar_principal_moments

    c = scenario.carrier
    body = scenario.body
    E = sol.relative_energy
    drift = float(np.ptp(E) / abs(E[0])) if E[0] != 0 else None
    ratio, bound = sol.hodograph_ratio(), sol.hodograph_bound()
    rotation = ", ".join(str(v) for v in c["rotation"])
    description = f"{c['given']} = ({rotation})" + (
        f", origin acceleration ({', '.join(str(v) for v in c['origin_acceleration'])}) m/s²"
        if c["origin_acceleration"] is not None
        else ""
    )
    moments = np.asarray(body.principal_moments, float)
    table = {
        "principal moments A, B, C": (
            ", ".join(f"{m:.6g}" for m in moments),
            "kg·m²",
            "about the centre of mass, ascending",
        ),
        "planar moments A', B', C'": (
            ", ".join(f"{m:.6g}" for m in planar_principal_moments(moments)),
            "kg·m²",
            "A' = (B + C − A)/2, … (planar inertia tensor)",
        ),
        "initial |ω_r|": (
            float(np.linalg.norm(sol.omega_r[0])),
            "rad/s",
            "relative angular velocity",
        ),
        "final |ω_r|": (float(np.linalg.norm(sol.omega_r[-1])), "rad/s", ""),
        "relative energy T_r(0)": (float(E[0]), "J", "½ ω_r·Jω_r"),
        "relative energy at the end": (float(E[-1]), "J", ""),
    }
    if c["balance_transport"]:
        table.update(
            {
                "relative energy drift": (
                    drift,
                    "",
                    "(max − min)/T_r(0): conserved under the "
                    "balancing moment (16), up to the integrator's tolerance",
                ),
                "max|ω_r| / min|ω_r|": (ratio, "", "over the samples"),
                "bound √(C/A)": (bound, "", "eq. (18): the ratio can approach it, never exceed it"),
            }
        )
    table.update({
        "steps": (int(sol.nsteps), "", f"{sol.method}, {sol.backend} backend"),
    })  # fmt: skip
    return _jsonable(
        {
            "scenario": {
                "name": scenario.name,
                "description": scenario.description,
                "source": scenario.source,
            },
            "carrier": {
                "description": description,
                "given": c["given"],
                "rotation": [str(v) for v in c["rotation"]],
                "origin_acceleration": None
                if c["origin_acceleration"] is None
                else [str(v) for v in c["origin_acceleration"]],
                "balance_transport": c["balance_transport"],
                "hold_com": c["hold_com"],
            },
            "lead": (
                "Integrated in the carrier frame with the compact relative Euler equation "
                "(11)–(12)"
                + ("; the transport moment is balanced (16)." if c["balance_transport"] else ".")
            ),
            "body": body.mass_properties(),
            "relative_energy": {
                "initial": float(E[0]),
                "min": float(E.min()),
                "max": float(E.max()),
                "relative_drift": drift,
            },
            "hodograph": {"ratio": ratio, "bound_sqrt_C_over_A": bound},
            "final": {
                "t": float(sol.t[-1]),
                "omega_r": sol.omega_r[-1].tolist(),
                "omega_absolute": sol.omega_absolute[-1].tolist(),
            },
            "integration": {
                "method": sol.method,
                "backend": sol.backend,
                "nsteps": int(sol.nsteps),
                "nfev": int(sol.nfev),
                "success": bool(sol.success),
                "message": sol.message,
            },
            "units": {
                "omega_r": "rad/s",
                "omega_absolute": "rad/s",
                "relative_energy": "J",
                "t": "s",
                "ratio": "1",
            },
            "table": table,
        }
    )


def _relative_csv(path: Path, sol):
    """t, ω_r, ω_absolute (body), Euler angles of Q_r, T_r, |M_e|, |M_c|, with units."""
    cols = [sol.t[:, None], sol.omega_r, sol.omega_absolute, sol.euler_angles(),
            sol.relative_energy[:, None], np.linalg.norm(sol.transport_moment, axis=1)[:, None],
            np.linalg.norm(sol.coriolis_moment, axis=1)[:, None]]  # fmt: skip
    header = ("t [s],omega_r_x [rad/s],omega_r_y [rad/s],omega_r_z [rad/s],"
              "omega_abs_x [rad/s],omega_abs_y [rad/s],omega_abs_z [rad/s],"
              "psi [rad],theta [rad],phi [rad],relative_energy [J],"
              "transport_moment [N m],coriolis_moment [N m]")  # fmt: skip
    with atomic_path(path) as tmp:
        np.savetxt(tmp, np.hstack(cols), delimiter=",", header=header, comments="", fmt="%.17g")


def _run_relative(scenario, folder: OutputFolder, *, progress=None, report=True) -> dict:
    """Run a scenario with ``[carrier]``; write summary.json, relative.csv, relative.png,
    hodograph.png and report.html (atomically, as :func:`run_scenario`)."""
    import io

    start = time.perf_counter()
    sol = scenario.simulate(progress=progress)
    sim_time = time.perf_counter() - start
    summary = summarize_relative(scenario, sol)
    with folder.writing() as work:
        if scenario.outputs.get("data", True):
            _relative_csv(work / "relative.csv", sol)
        images = {}
        if scenario.outputs.get("figures", True) or (report and scenario.outputs.get("report")):
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt

            from ..viz.relative import plot_hodograph, plot_relative_motion

            figures = [
                (
                    plot_relative_motion(sol, title=scenario.name),
                    "relative.png",
                    "Relative angular velocity, the carrier's rotation, the relative energy "
                    "and the inertia moments",
                )
            ]
            if scenario.carrier["balance_transport"]:  # ω_r then stays on the ellipsoid (17)
                figures.append(
                    (
                        plot_hodograph(sol, title=scenario.name),
                        "hodograph.png",
                        "Hodograph of ω_r on the energy ellipsoid (17), and |ω_r| "
                        "against the bound √(C/A) (18)",
                    )
                )
            for fig, name, caption in figures:  # fmt: skip
                buf = io.BytesIO()
                fig.savefig(buf, dpi=100, format="png")
                plt.close(fig)
                if scenario.outputs.get("figures", True):
                    with atomic_path(work / name) as tmp:
                        Path(tmp).write_bytes(buf.getvalue())
                images[caption] = buf.getvalue()
        if report and scenario.outputs.get("report", True):
            from ..viz.report import write_relative_report

            write_relative_report(work / "report.html", summary, images)
        summary["timings"] = {"simulation_s": sim_time, "total_s": time.perf_counter() - start}
        atomic_write_text(work / "summary.json", json.dumps(_jsonable(summary), indent=2))
    return summary
