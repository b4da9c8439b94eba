"""An ensemble's run: many initial spins of one body, and the distributions of what they do."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...simulation import SimulationError
from ...torquefree.scope import flip_reference
from .base import Run, jsonable, png_images, pyplot, scenario_header, shown, wrote_line

__all__ = ["EnsembleRun", "summarize_ensemble"]


class EnsembleRun(Run):
    """An :class:`~poinsot.app.scenario.EnsembleScenario` (``[ensemble]``); writes
    ensemble.nc, histograms.png, flip_intervals.png (where the exact flips apply) and
    report.html."""

    free = None  # the free body whose exact flip intervals grade the members, where it applies

    def rows(self):
        return int(self.scenario.ensemble["members"])

    #: ensemble.nc: 188 bytes a member (10⁶ members wrote 188 MB), the samples' states too
    #: when they are kept; the report draws histograms, whatever the members
    report_bytes_per_row = 0

    @property
    def data_bytes_per_row(self):
        kept = self.scenario.ensemble["keep_states"]
        return 2 * (188 + (18 * 8 * int(self.scenario.samples) if kept else 0))

    def simulate(self, progress=None):
        # members done, where the progress object counts them (the command line's does)
        members = getattr(progress, "members", None)
        if members is not None:
            members(0, int(self.scenario.ensemble["members"]))
        self.result = self.scenario.simulate_ensemble(progress=members)
        if len(self.result) and not self.result.success.any():
            raise SimulationError(_all_failed(self.scenario, self.result), None)

    def summarise(self):
        s = self.scenario
        self.free = flip_reference(s.body, s.forces, s.pivot)
        return summarize_ensemble(s, self.result, self.free)

    def write_data(self, folder, summary):
        _write_ensemble_dataset(folder / "ensemble.nc", self.result, self.free)

    def figures(self, folder, *, for_report):
        res, free = self.result, self.free
        from ...viz.ensemble import plot_ensemble_histograms, plot_flip_intervals

        pyplot()

        def figures():  # one at a time: each is drawn, rendered and closed before the next
            yield (plot_ensemble_histograms(res), "histograms.png",
                   "Distributions over the members")  # fmt: skip
            if free is not None and np.isfinite(res.flip_interval).any():
                exact = free.flip_interval(res.initial_omega)
                yield (plot_flip_intervals(res, exact), "flip_intervals.png",
                       "Measured time between flips against the exact 2K(m)/λ")  # fmt: skip

        return png_images(figures(), folder)

    def write_report(self, path, summary, images, *, plotlyjs="inline"):
        from ...viz.report import write_ensemble_report

        write_ensemble_report(path, summary, images)

    def terminal_lines(self, summary, out):
        e = summary["ensemble"]
        lines = [
            f"  {e['members']} members ({summary['distribution']['description']}), "
            f"{e['method']}: {e['succeeded']} finished, integrated in "
            f"{shown(e['wall_time_s'], '.3g', unit='s')} (compiled core; nothing is compiled "
            "at run time)"
        ]
        stats = e["statistics"]
        if stats.get("first_flip", {}).get("count"):
            f = stats["first_flip"]
            spread = f"5–95 %: {shown(f.get('p05'), '.4g')}–{shown(f.get('p95'), '.4g', unit='s')}"
            flipped = f.get("members_with_a_flip")
            lines.append(f"  first flip: median {shown(f.get('median'), '.4g', unit='s')} "
                         f"({spread}), {flipped} flipped")  # fmt: skip
        if "flips_against_exact" in summary:
            r = summary["flips_against_exact"]["relative_error"]
            if r.get("count"):
                rel = (f"median relative error {shown(r.get('median'), '.2e')}, max "
                       f"{shown(r.get('max'), '.2e')}")  # fmt: skip
                lines.append(f"  flip interval against the exact 2K(m)/λ: {rel}")
        lines.append(wrote_line(out))
        return lines


def summarize_ensemble(scenario, res, free=None) -> dict:
    """The numbers of an ensemble run, JSON-ready: the scenario, the distribution of initial
    spins, the body, the run and each statistic's distribution; with ``free`` (a torque-free
    asymmetric body) the measured flip intervals against the exact ones."""
    e = scenario.ensemble
    if e["distribution"] == "sphere":
        dist = {"description": f"ω uniform on the sphere |ω| = {e['speed']:g} rad/s"}
    else:
        from ...viz.numbers import format_value

        mean, std = format_value(e["mean"].tolist()), format_value(e["std"].tolist())
        dist = {
            "description": f"ω ~ N(mean {mean}, standard deviations {std}) rad/s, body frame",
            "mean": e["mean"].tolist(),
            "std": e["std"].tolist(),
        }
    out = {
        "scenario": scenario_header(scenario),
        "distribution": {"kind": e["distribution"], "seed": e["seed"], **dist},
        "body": scenario.body.mass_properties(),
        "ensemble": res.summary(),
        "units": {"time": "s", "omega": "rad/s", "errors": "dimensionless"},
    }
    if free is not None:
        exact = free.flip_interval(res.initial_omega)
        measured = res.flip_interval
        ok = np.isfinite(exact) & np.isfinite(measured)
        rel = measured[ok] / exact[ok] - 1
        out["flips_against_exact"] = {
            "meaning": "measured mean time between flips / exact 2K(m)/λ − 1, per member",
            "members_compared": int(ok.sum()),
            "exact_flip_interval_s": _describe(exact[np.isfinite(exact)]),
            "relative_error": _describe(np.abs(rel)),
        }
    return jsonable(out)


def _describe(values):
    from ...ensemble.result import _describe as describe

    return describe(values)


def _write_ensemble_dataset(path: Path, res, free):
    """ensemble.nc: the members' statistics, their initial ω and the exact flip intervals
    (NetCDF-3 by SciPy's writer: written in every install)."""
    W0 = res.initial_omega
    extra = {"omega0": (("member", "component"), W0, {"units": "rad/s", "frame": "body"})}
    if free is not None:
        extra["exact_flip_interval"] = (("member",), free.flip_interval(W0), {"units": "s"})
    res.to_netcdf(path, extra)


def _all_failed(scenario, result) -> str:
    """Why an ensemble whose members all failed has nothing to summarise or draw, naming the
    keys that set the members and their steps."""
    failed = result.summary()["failed"]
    how = ", ".join(f"{name}: {count}" for name, count in failed.items())
    e = scenario.ensemble
    spread = (f"`ensemble.std` = {[float(v) for v in e['std']]} about `initial.omega`"
              if e["distribution"] != "sphere" else f"`ensemble.speed` = {e['speed']}")  # fmt: skip
    step = (f"`integrator.dt` = {scenario.dt:g}" if scenario.dt is not None
            else f"`integrator.method` = {scenario.method!r}")  # fmt: skip
    return (
        f"every one of the {len(result)} members failed ({how}), so there is nothing to "
        f"summarise or draw; the members come from {spread} and are stepped with {step} "
        "(take a smaller step, or a narrower spread)"
    )
