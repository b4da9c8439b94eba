"""A rigid body's run: its trajectory, the torque-free analysis where it applies, and the
integrators compared against the exact solution where one exists."""

from __future__ import annotations

import warnings

import numpy as np

from ..._io import PoinsotWarning
from ...torquefree.scope import check_motion_energy, exact_solution_applies, free_rotation
from .base import (
    Run,
    add_units,
    change_shown,
    defined,
    jsonable,
    png_images,
    pyplot,
    scenario_header,
    shown,
    written_files,
    wrote_line,
)

__all__ = [
    "COMPARED_METHODS",
    "RigidRun",
    "compare_methods",
    "comparison_lead",
    "summarize",
    "top_lead",
]

#: The integrators a fixed-step torque-free run is compared with: the notebook's classical
#: RK4 and the Lie-group RKMK4 of the same order, which keeps the attitude on SO(3).
COMPARED_METHODS = ("rk4", "rkmk4")


class RigidRun(Run):
    """A :class:`~poinsot.app.scenario.Scenario`: one body under its forces; writes
    trajectory.npz/.csv/.nc, omega.png, conservation.png, center_of_mass.png, body.png, the
    polhodes (where the torque-free analysis applies), methods.png (where the exact solution
    grades the integrators) and report.html."""

    free = None  # the torque-free analysis, where it applies
    comparison = None  # (errors, table) of compare_methods, where it applies
    top = None  # a heavy top's TopMotion (nutation, precession), where the body is one
    top_axis = None  # that top's symmetry axis a (body frame, tip → centre of mass)

    def simulate(self, progress=None):
        self.result = self.scenario.simulate(progress=progress)

    def summarise(self):
        scenario, traj = self.scenario, self.result
        if scenario.analysis.get("polhodes", True):
            self.free = free_rotation(scenario.body, scenario.pivot)
        if self.free is not None:
            try:
                check_motion_energy(self.free, scenario.body, traj.omega[0])
            except ValueError as exc:  # polhodes outside the double range (moments near 1e300)
                warnings.warn(f"torque-free analysis and polhodes left out: {exc}",
                              PoinsotWarning, stacklevel=3)  # fmt: skip
                self.free = None
        summary = summarize(scenario, traj, self.free)
        self.comparison = compare_methods(scenario, traj, self.free)
        from ...tops import heavy_top, top_motion

        top = heavy_top(scenario.body, scenario.pivot, scenario.forces)
        if top is not None:
            self.top, self.top_axis = top_motion(traj, top), top.axis
            summary["top"] = jsonable({"A": top.A, "C": top.C, "mgl": top.mgl,
                                       "axis": top.axis.tolist(), "length": top.length,
                                       **self.top.summary()})  # fmt: skip
            summary["lead"] = top_lead(self.top)
        add_units(summary)
        if self.comparison is not None:
            summary["method_comparison"] = self.comparison[1]
            summary["lead"] = comparison_lead(self.comparison[1], scenario.dt)
        return summary

    def write_data(self, folder, summary):
        traj = self.result
        traj.to_npz(folder / "trajectory.npz")
        traj.to_csv(folder / "trajectory.csv")
        traj.to_netcdf(folder / "trajectory.nc")

    interactive_report = True
    report_links = ("summary.json", "trajectory.npz", "trajectory.csv", "trajectory.nc")

    def figures(self, folder, *, for_report):
        if folder is None and not for_report:
            return {}
        figures = _figures(self.scenario, self.result, self.free, self.comparison, self.top,
                           self.top_axis)  # fmt: skip
        return png_images(figures, folder, dpi=110)

    def write_report(self, path, summary, images, *, plotlyjs="inline"):
        from ...viz.report import write_report

        comparison = None if self.comparison is None else self.comparison[0]
        write_report(path, self.result, summary, free=self.free, comparison=comparison,
                     top=self.top, top_axis=self.top_axis, plotlyjs=plotlyjs)  # fmt: skip

    def finish(self, summary):
        add_units(summary)

    def terminal_lines(self, summary, out):
        scenario = self.scenario
        i = summary["integration"]
        d = i["diagnostics"]
        body = summary["body"]
        files = written_files(out)  # None: unreadable
        lines = [
            f"  body: mass {shown(body['mass'], '.6g', unit='kg')}, principal moments "
            + ", ".join(shown(x, ".6g") for x in body["principal_moments"])
            + " kg·m²"
        ]
        step = f"dt = {shown(scenario.dt, 'g')} s, " if scenario.dt is not None else ""
        t0, t1 = (shown(t, "g") for t in scenario.t_span)
        lines.append(
            f"  integrated t ∈ [{t0}, {t1}] s with {i['method']} ({step}{i['nsteps']} steps); "
            f"max |QᵀQ − I| {shown(d['orthogonality_error'], '.2e')}"
        )
        kept = [v for v in d["invariants"].values() if v.get("expected_conserved")]
        if kept:
            changes = ", ".join(change_shown(v) for v in kept)
            lines.append(f"  conserved by this problem, largest change: {changes}")
        else:
            lines.append("  nothing is conserved by this problem (its forces do work)")
        if "top" in summary:
            lines += _top_lines(summary["top"], files or ())
        if "torque_free" in summary:
            tf = summary["torque_free"]
            lines.append(f"  torque-free motion: polhode family {tf['family']!r}")
            if "exact_solution_error" in tf:
                e = tf["exact_solution_error"]
                lines.append(
                    f"  against the exact solution: max |ω − ω_exact| "
                    f"{shown(e['omega'], '.2e', unit='rad/s')}, max |Q − Q_exact| "
                    f"{shown(e['attitude'], '.2e')}"
                )
        if "method_comparison" in summary:
            other = {
                m: v
                for m, v in summary["method_comparison"].items()
                if m not in ("exact", i["method"])
            }
            for m, v in other.items():
                lines.append(
                    f"  {m} at the same step: max |QᵀQ − I| {shown(v['orthogonality'], '.2e')}, "
                    f"max |Q − Q_exact| {shown(v['attitude'], '.2e')}"
                    + (" (methods.png)" if "methods.png" in (files or ()) else "")
                )
        lines.append(wrote_line(out, files))
        return lines


#: What a heavy top's rate is where the library returns none (NaN, None in the summary):
#: the mean precession where ψ is undefined at (almost) every sample (an axis on the vertical,
#: a sleeping top), the steady precessions where the top spins too slowly to precess steadily
#: at its mean θ (:func:`poinsot.tops.steady_precession_rates`).
_NO_MEAN_PRECESSION = "none (ψ is undefined with the axis on the vertical)"
_NO_STEADY_PRECESSION = "none (the top spins too slowly to precess steadily at its mean θ)"


def _top_lines(tp: dict, files=()) -> list[str]:
    """The terminal's lines about a heavy top (the summary's ``top``): the values as the
    library returned them, formatted by :func:`shown` (None, ±inf and strings included);
    ``files``: what the run wrote (its figure is named where it was written)."""
    rads = "rad/s"
    slow, fast = tp.get("steady_precession_rate_slow"), tp.get("steady_precession_rate_fast")
    if not defined(slow) and not defined(fast):
        steady = _NO_STEADY_PRECESSION
    else:
        steady = (f"{shown(slow, '.4g', unit=rads, none='none')} (slow), "
                  f"{shown(fast, '.4g', unit=rads, none='none')} (fast)")  # fmt: skip
    lines = [
        f"  heavy top: θ between {shown(tp.get('theta_min'), '.4g')} and "
        f"{shown(tp.get('theta_max'), '.4g', unit='rad')}, mean precession "
        f"{shown(tp.get('mean_precession_rate'), '.4g', unit=rads, none=_NO_MEAN_PRECESSION)}"
        + (" (attitude.png)" if "attitude.png" in files else ""),
        f"  predicted precession: gyroscopic estimate M g l/(C ω·a) "
        f"{shown(tp.get('gyroscopic_precession_rate'), '.4g', unit=rads)}; steady at the mean θ: "
        f"{steady}",
    ]
    if "exact" in tp:
        ex = tp["exact"]
        lines.append(
            f"  closed form (Lagrange's top): θ between {shown(ex.get('theta_min'), '.6g')} and "
            f"{shown(ex.get('theta_max'), '.6g', unit='rad')}, nutation period "
            f"{shown(ex.get('nutation_period'), '.6g', unit='s')}, mean precession "
            f"{shown(ex.get('mean_precession_rate'), '.6g', unit=rads)}; the run's largest "
            f"differences θ {shown(ex.get('max_theta_error'), '.2e')}, ψ "
            f"{shown(ex.get('max_psi_error'), '.2e', unit='rad')}"
        )
    return lines


def summarize(scenario, traj, free=None) -> dict:
    """The numbers of a run, JSON-ready: body, invariants, torque-free analysis, diagnostics."""
    from ...conservation import angular_momentum_body, rotational_energy

    body = scenario.body
    w0 = np.ascontiguousarray(traj.omega[0])
    k0 = float(rotational_energy(body.inertia, w0))
    a0 = float(np.hypot.reduce(angular_momentum_body(body.inertia, w0)))  # no overflow
    initial = {"omega": w0.tolist()}
    if scenario.pivot is None or free is not None:  # about the centre of mass
        initial |= {"rotational_energy": k0, "angular_momentum_magnitude": a0}
    else:  # about the fixed pivot: the whole kinetic energy and the moment there
        J = traj.system.inertia
        initial |= {
            "rotational_energy_pivot": float(rotational_energy(J, w0)),
            "angular_momentum_magnitude_pivot": float(
                np.hypot.reduce(angular_momentum_body(J, w0))),
        }  # fmt: skip
    if free is not None:  # a torque-free analysis (about G) exists: its polhode family
        initial["a2_over_2k"] = a0 * (a0 / (2 * k0)) if k0 > 0 else None  # a² may overflow
    out = {
        "scenario": scenario_header(scenario),
        "body": body.mass_properties(),
        "initial": initial,
        "final": {
            "t": float(traj.t[-1]),
            "R": traj.R[-1].tolist(),
            "omega": traj.omega[-1].tolist(),
        },
        "integration": traj.summary(),
    }
    if scenario.pivot is not None:  # the pivot, and the principal axes about it (e₁ᴾ, e₂ᴾ, e₃ᴾ)
        system = traj.system
        out["pivot"] = {
            "body_position": np.asarray(scenario.pivot, float).tolist(),
            "position": traj.pivot_position.tolist(),
            "principal_moments": system.principal_moments.tolist(),
            "principal_axes": system.principal_axes.tolist(),
        }
    if free is not None and k0 > 0:
        analysis = free.describe(w0)
        if exact_solution_applies(scenario.forces):
            analysis["exact_solution_error"] = free.trajectory_error(traj)
        out["torque_free"] = analysis
    return jsonable(out)


def top_lead(motion) -> str:
    """One sentence stating what a heavy top's run shows: its nutation band and its mean
    precession against the gyroscopic estimate and the steady precession (the values as the
    library returned them: a rate it found undefined is said to be, an infinite one is ∞)."""
    m = motion
    slow, fast = m.steady_rates
    rate = shown(m.mean_precession_rate, ".4g", unit="rad/s")
    precesses = (f"precesses at a mean {rate} (slope of ψ(t))" if defined(m.mean_precession_rate)
                 else "has no mean precession rate (ψ is undefined with the axis on the "
                 "vertical)")  # fmt: skip
    theta = shown(m.theta_mean, ".4g", unit="rad")
    if not defined(slow) and not defined(fast):
        steady = (f"no steady precession exists at the mean θ = {theta} (the top spins too "
                  "slowly to precess steadily there)")  # fmt: skip
    else:
        steady = (f"the exact steady precessions at the mean θ = {theta} are "
                  f"{shown(slow, '.4g', unit='rad/s')} (slow) and "
                  f"{shown(fast, '.4g', unit='rad/s')} (fast)")  # fmt: skip
    return (
        f"A heavy top spinning at ω·a = {shown(m.spin, '.4g', unit='rad/s')} about its "
        "symmetry axis a: a nutates "
        f"between θ = {shown(m.theta_band[0], '.4g')} and "
        f"{shown(m.theta_band[1], '.4g', unit='rad')} from the upward vertical and {precesses}; "
        f"the gyroscopic estimate M g l/(C ω·a) gives "
        f"{shown(m.gyroscopic_rate, '.4g', unit='rad/s')}, and {steady}."
    )


def _figures(scenario, traj, free, comparison=None, top=None, top_axis=None):
    """The run's matplotlib figures, one at a time, as ``(figure, file name, caption)``;
    ``top``, ``top_axis``: a heavy top's motion and its symmetry axis a (body frame, tip →
    centre of mass), whose direction in space is traced on the unit sphere."""
    from ...viz import (
        plot_attitude_frames,
        plot_center_of_mass_path,
        plot_conservation,
        plot_omega_series,
        plot_polhode_family,
    )

    pyplot()
    yield plot_omega_series(traj), "omega.png", "Angular velocity ω(t) in the body frame"
    if comparison is not None:
        from ...viz import plot_method_comparison

        title = "Integrators against the exact torque-free solution, same step"
        yield (plot_method_comparison(traj.t, comparison[0], title=title), "methods.png", title)
    yield plot_conservation(traj), "conservation.png", "Conserved quantities: relative change"
    if top is not None:
        from ...viz.trajectory import plot_attitude, plot_axis_trace

        yield plot_attitude(top, title=scenario.name), "attitude.png", "Euler angles of the top"
        trace = plot_axis_trace(traj.axis_trace(top_axis), label="direction of a",
                                title="Trace of the symmetry axis a (tip → centre of mass) on "
                                "the unit sphere")  # fmt: skip
        yield trace, "axis_trace.png", "Trace of the symmetry axis a on the unit sphere"
    if np.ptp(traj.R, axis=0).max() > 0:  # a centre of mass at rest has no path to draw
        yield (plot_center_of_mass_path(traj), "center_of_mass.png",
               "Path of the centre of mass")  # fmt: skip
    half = scenario.body.equivalent_box_half_extents
    QE = traj.Q @ scenario.body.principal_axes  # draw the box in principal axes
    half = np.maximum(half, 1e-3 * half.max())  # a flat body is drawn as a thin box
    yield (plot_attitude_frames(QE, traj.t, half_extents=half, about="the centre of mass G"),
           "body.png", "The body's attitude (its equivalent box) at a few times")  # fmt: skip
    if free is not None:
        from ...conservation import rotational_energy

        energy = scenario.analysis.get("energy")
        k_traj = float(
            rotational_energy(scenario.body.inertia, np.ascontiguousarray(traj.omega[0]))
        )
        levels = scenario.analysis.get("levels", 9)
        if k_traj > 0:  # the run's ω(t) on its own energy ellipsoid, with the family there
            fig = plot_polhode_family(free, k_traj, levels=levels, omega=traj.omega,
                                      omega_label="ω(t) of this run")  # fmt: skip
            fig.axes[0].set_title(f"This run's ω(t) on its energy ellipsoid, k = {k_traj:.4g} J,"
                                  "\nwith the polhodes at that energy (ω along e₁, e₂, e₃)",
                                  fontsize=10)  # fmt: skip
            yield fig, "polhodes.png", "ω(t) on its energy ellipsoid, with the polhodes"
        if energy is not None and not np.isclose(energy, k_traj, rtol=1e-12):
            fig = plot_polhode_family(free, energy, levels=levels)  # [analysis] energy's sweep
            fig.axes[0].set_title(f"The polhode family at k = {energy:g} J ([analysis] energy), "
                                  "not this run's energy")  # fmt: skip
            yield fig, "polhodes_sweep.png", "The polhode family at the [analysis] energy"


def compare_methods(scenario, traj, free):
    """Run the scenario again with each of :data:`COMPARED_METHODS` (same step) and measure
    each run against the exact torque-free solution.

    Returns ``(errors, table)`` or None when the comparison does not apply (no exact solution:
    a torque about the centre of mass; or an adaptive step, which has no step to share).
    ``errors``: ``label → per-sample arrays`` for :func:`~poinsot.viz.plot_method_comparison`
    (the exact solution's own distance from SO(3) included); ``table``: the maxima, JSON-ready.
    """
    from ...conservation import orthogonality_error

    if free is None or scenario.dt is None or not np.any(traj.omega[0]):
        return None
    if not exact_solution_applies(scenario.forces):
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
