"""Running a scenario end to end: simulate, analyse, and write data, figures and the report.

The same sequence for every kind of scenario; what each kind simulates, summarises and writes
is its run object's (:mod:`poinsot.app.runs`, chosen once by the scenario's type).

Everything is written through :class:`~poinsot._io.OutputFolder`: into a hidden folder beside
the target, moved into place only when complete, so an interrupted run (Ctrl-C, SIGTERM, a
crash) never leaves a half-written output folder. The target is checked before the simulation
starts; an existing folder is replaced only with ``force=True`` and only if poinsot wrote it.
"""

from __future__ import annotations

import json
import time

from .._io import OutputError, OutputExistsError, OutputFolder, atomic_write_text
from ..viz.report import STATIC_NOTE, interactive_available
from .runs import run_for
from .runs.base import jsonable

__all__ = ["OutputError", "OutputExistsError", "run_scenario"]


def run_scenario(
    scenario, out, *, force=False, progress=None, report=True, plotlyjs="inline", on_stage=None
) -> dict:
    """Simulate ``scenario`` and write its outputs to the folder ``out``; return the summary.

    Raises :class:`OutputExistsError` if ``out`` exists and ``force`` is false,
    :class:`OutputError` if ``out`` cannot or may not be written (both checked before any
    work; see :class:`~poinsot._io.OutputFolder`), and
    :class:`~poinsot.simulation.SimulationError` on a numerical failure. ``plotlyjs``: how the
    report gets plotly.js (:data:`poinsot.viz.report.PLOTLYJS_MODES`). ``on_stage``: called
    with the name of each stage as it begins ("simulating", "drawing the figures", …), to say
    how far a run got when it is stopped.

    Without plotly (the ``report`` extra) the report of a rigid-body or Lagrangian run is a
    static page of its numbers and matplotlib figures, and ``summary["report"]`` says so
    (:data:`~poinsot.viz.report.STATIC_NOTE`).
    """
    stage = on_stage or (lambda name: None)
    run = run_for(scenario)
    needs = run.estimated_bytes(report=report, plotlyjs=plotlyjs)
    folder = OutputFolder(out, force=force, command="run", needs_bytes=needs)
    start = time.perf_counter()
    stage("simulating")
    run.simulate(progress=progress)
    sim_time = time.perf_counter() - start
    stage("summarising the run")
    summary = run.summarise()
    wanted = scenario.outputs
    figures = wanted.get("figures", True)
    with_report = report and wanted.get("report", True)
    static = with_report and run.interactive_report and not interactive_available()
    if static:  # the numbers and the matplotlib figures, on a page that says so
        summary["report"] = STATIC_NOTE
    with folder.writing() as work:
        if wanted.get("data", True):
            stage("writing the data")
            run.write_data(work, summary)
        images = {}
        if figures or with_report:
            stage("drawing the figures")
            for_report = with_report and (static or not run.interactive_report)
            images = run.figures(work if figures else None, for_report=for_report)
        if static:
            stage("writing the report")
            run.write_static_report(work / "report.html", summary, images)
        elif with_report:
            stage("writing the report")
            run.write_report(work / "report.html", summary, images, plotlyjs=plotlyjs)
        stage("writing the summary")
        summary["timings"] = {"simulation_s": sim_time, "total_s": time.perf_counter() - start}
        run.finish(summary)
        atomic_write_text(work / "summary.json", json.dumps(jsonable(summary), indent=2))
    return summary
