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
        """What the command line prints about the finished run written to ``out``: the
        summary's values as :func:`shown` formats them (never failing on a value the library
        returned as None, ±inf or a string), ending with :func:`wrote_line`."""
        raise NotImplementedError


def shown(value, spec: str = "g", *, unit: str = "", none: str = "none") -> str:
    """A summary's value as the terminal prints it, whatever the library returned: a number
    formatted with ``spec`` (followed by `` unit``), ±inf (a float, or the ``"inf"`` /
    ``"-inf"`` that :func:`jsonable` writes) as ``∞`` / ``−∞``, None or NaN (a quantity the
    library found undefined for this run) as ``none`` (a phrase saying why, where the caller
    knows), and any other string as it is (with its unit). It formats; it computes nothing,
    and never fails.

    >>> shown(1.0900000000000005, ".4g", unit="rad/s"), shown("inf", ".4g", unit="rad/s")
    ('1.09 rad/s', '∞ rad/s')
    >>> shown(None, ".4g", none="none (spin too slow)"), shown("rk4", ".2e")
    ('none (spin too slow)', 'rk4')
    """
    tail = f" {unit}" if unit else ""
    if value is None:
        return none
    if isinstance(value, str):
        infinite = {"inf": "∞", "+inf": "∞", "infinity": "∞", "-inf": "−∞", "-infinity": "−∞"}
        word = value.strip().lower()
        if word in infinite:
            return infinite[word] + tail
        return none if word == "nan" else value + tail
    if isinstance(value, bool | np.bool_):
        return str(bool(value))
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        if np.isnan(value):
            return none
        if np.isinf(value):
            return ("∞" if value > 0 else "−∞") + tail
    try:
        return format(value, spec) + tail
    except (TypeError, ValueError):  # not a number after all: shown as it is
        return str(value) + tail


def defined(value) -> bool:
    """Whether the library returned a value at all: not None, NaN or ``"nan"`` (what a summary
    holds where a quantity is undefined for the run); ±inf is a value."""
    if value is None:
        return False
    if isinstance(value, str):
        return value.strip().lower() != "nan"
    try:
        return not np.isnan(value)
    except (TypeError, ValueError):
        return True


def change_shown(described: dict) -> str:
    """The largest change of a conserved quantity, as :func:`poinsot.conservation.change_text`
    words it (``"E 1.20e-09 (relative)"``, or ``"h 6.40e-10 J (absolute; h(0) = 0)"`` where
    there is no relative change), from a summary's entry, whose numbers may be None or
    ``"inf"`` (:func:`jsonable`): formatted by :func:`shown`, never failing."""
    sym = described.get("symbol", "?")
    rel = described.get("max_relative_change")
    if rel is not None:
        return f"{sym} {shown(rel, '.2e')} (relative)"
    change = shown(described.get("max_change"), ".2e", unit=described.get("unit") or "")
    return f"{sym} {change} (absolute; {sym}(0) = 0)"


#: The order in which :func:`wrote_line` joins the suffixes of files of one name.
_SUFFIX_ORDER = (".npz", ".csv", ".nc")


def written_files(out) -> list[str] | None:
    """The files the finished run wrote into ``out``: the list its manifest records
    (:data:`poinsot._io.MANIFEST`), else the folder's visible files; None if neither can be
    read."""
    import json

    from ..._io import MANIFEST

    folder = Path(out)
    try:
        files = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))["files"]
        return [str(f) for f in files if str(f) != MANIFEST]
    except (OSError, ValueError, KeyError, TypeError):
        pass
    try:
        return sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))
    except OSError:
        return None


def wrote_line(out, files: list[str] | None = None) -> str:
    """``"  wrote OUT/ (summary.json, trajectory.npz/.csv/.nc, 6 PNG figures, report.html)"``:
    what the run wrote, as :func:`written_files` finds it in ``out`` (or ``files``), so that
    ``[output] data``, ``figures`` or ``report = false`` leave their files out of the list."""
    files = written_files(out) if files is None else files
    if files is None:
        return f"  wrote {out}/"
    figures = [f for f in files if f.lower().endswith(".png")]
    stems: dict[str, list[str]] = {}
    for f in files:
        if f in ("summary.json", "report.html") or f in figures:
            continue
        stem, dot, suffix = f.rpartition(".")
        stem, suffix = (stem, dot + suffix) if dot and stem else (f, "")
        stems.setdefault(stem, []).append(suffix)
    parts = ["summary.json"] if "summary.json" in files else []
    for stem, suffixes in stems.items():
        suffixes.sort(key=lambda x: (_SUFFIX_ORDER.index(x) if x in _SUFFIX_ORDER else 99, x))
        parts.append(stem + "/".join(suffixes))
    if len(figures) > 3:
        parts.append(f"{len(figures)} PNG figures")
    else:
        parts += figures
    if "report.html" in files:
        parts.append("report.html")
    return f"  wrote {out}/ ({', '.join(parts)})" if parts else f"  wrote {out}/ (nothing)"


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
