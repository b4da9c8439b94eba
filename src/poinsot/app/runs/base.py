"""What every kind of run does, and the helpers they share."""

from __future__ import annotations

from pathlib import Path

import numpy as np


class Run:
    """One run of one scenario: simulate, summarise, write data, figures and the report.

    :func:`poinsot.app.job.run_scenario` calls them in this order, the same for every kind:
    :meth:`simulate`; :meth:`summarise`; then, inside the output folder being written,
    :meth:`write_data` (unless ``[output] data = false``), :meth:`figures` and
    :meth:`write_report` (unless switched off); and :meth:`finish` once the timings are in,
    before ``summary.json`` is written. :meth:`terminal_lines` says what the command line
    prints about the finished run.
    """

    #: The report draws its own, interactive figures (plotly); without plotly the job writes a
    #: static page of :meth:`figures` instead (:func:`poinsot.viz.report.write_static_report`).
    interactive_report = False
    #: The files the report links to (the first holds the numbers unrounded).
    report_links: tuple[str, ...] = ("summary.json",)

    def __init__(self, scenario):
        self.scenario = scenario
        self.result = None  # what simulate() returned

    def rows(self) -> int:
        """The rows of the data the run writes: its samples (an ensemble: its members)."""
        return int(self.scenario.samples)

    #: Bytes of data and of report per row, about twice what was measured (the notebook's
    #: 101 samples: 1.25 kB of data per sample in three formats).
    data_bytes_per_row = 2_500
    report_bytes_per_row = 1_000

    def estimated_bytes(self, *, report: bool = True, plotlyjs: str = "inline") -> int:
        """A generous estimate of what this run writes, checked against the free disk space:
        only the outputs asked for (``[output]``, ``report``), each about twice its measured
        size (the notebook's 101 samples wrote 1.25 kB of data per sample in three formats,
        0.73 MB of figures and a 5.5 MB report with plotly.js inline)."""
        wanted, rows = self.scenario.outputs, self.rows()
        need = 100_000  # summary.json, the manifest
        if wanted.get("data", True):
            need += self.data_bytes_per_row * rows
        if wanted.get("figures", True):
            need += 2_000_000
        if report and wanted.get("report", True):
            need += ((10_000_000 if plotlyjs == "inline" else 1_000_000)
                     + self.report_bytes_per_row * rows)  # fmt: skip
        return need

    def simulate(self, progress=None) -> None:
        """Run the simulation into :attr:`result`; ``progress``: a callback of the time
        reached (see :func:`poinsot.simulate`), where the kind of run reports it."""
        raise NotImplementedError

    def summarise(self) -> dict:
        """The numbers of the run, JSON-ready."""
        raise NotImplementedError

    def write_data(self, folder: Path, summary: dict) -> None:
        """The sampled data, into ``folder``."""
        raise NotImplementedError

    def figures(self, folder: Path | None, *, for_report: bool) -> dict[str, bytes]:
        """Draw the figures: saved as PNG into ``folder`` (None: not saved) and returned as
        ``{caption: PNG bytes}`` where the report shows them (``for_report``)."""
        raise NotImplementedError

    def write_report(self, path: Path, summary: dict, images: dict, *, plotlyjs="inline"):
        """The HTML report, at ``path``."""
        raise NotImplementedError

    def write_static_report(self, path: Path, summary: dict, images: dict) -> None:
        """The report of a run whose interactive report cannot be written (no plotly): its
        numbers and its figures (``images``) on a static page."""
        from ...viz.report import write_static_report

        write_static_report(path, summary, images, self.report_links)

    def finish(self, summary: dict) -> None:
        """Complete ``summary`` once its timings are in (default: nothing to add)."""

    def terminal_lines(self, summary: dict, out) -> list[str]:
        """What the command line prints about the finished run written to ``out``."""
        raise NotImplementedError


def jsonable(obj):
    """``obj`` with NumPy scalars as Python numbers and non-finite floats as JSON can hold
    them (NaN as null, ±inf as "inf"/"-inf")."""
    if isinstance(obj, dict):
        return {k: jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        return None if np.isnan(obj) else ("inf" if obj > 0 else "-inf")
    return obj


def add_units(summary: dict) -> None:
    """``summary["units"]``: the unit of every number, by key path (:mod:`poinsot.viz.numbers`),
    plus the per-quantity units the summary already carries."""
    from ...viz.numbers import units_of

    summary["units"] = {**summary.get("units", {}), **units_of(summary)}


def scenario_header(scenario, **extra) -> dict:
    """The ``scenario`` entry of a summary: name, description, source (and ``extra``)."""
    quantities = getattr(scenario, "quantities", None)
    return {
        "name": scenario.name,
        "description": scenario.description,
        "source": scenario.source,
        **({"quantities": quantities} if quantities else {}),
        **extra,
    }


def pyplot():
    """matplotlib's pyplot on the Agg backend (no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def png_images(figures, folder: Path | None, dpi: int = 100) -> dict[str, bytes]:
    """``figures`` (``(figure, file name, caption)``) rendered as PNG once: written into
    ``folder`` unless it is None, and returned as ``{caption: PNG bytes}`` for the report
    (:func:`poinsot.viz._style.png_images`, on the Agg backend)."""
    pyplot()
    from ...viz._style import png_images as render

    return render(figures, folder, dpi)
