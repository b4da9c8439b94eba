"""The ``poinsot`` command line.

    poinsot run [SCENARIO.toml] [--example NAME] [--out DIR] [--force] [--quiet] [--json]
    poinsot examples [--show NAME | --reference]
    poinsot inertia BODY [--mass M | --density RHO] [--json]
    poinsot polhodes --moments I1 I2 I3 [--energy K] [--omega0 W1 W2 W3] [--out DIR] [--json]
    poinsot identify LOG.csv [--map MAP.toml] [--json] [--out DIR] [column, scale, rotor options]

Exit codes: 0 success; 2 bad input (the message on stderr names the file and the key) or an
output folder that cannot or may not be written; 1 numerical failure (with the diagnostic), a
disk that filled while writing, or ``--time-limit`` reached (saying how far the run got); 130
interrupted (Ctrl-C), 143 terminated (SIGTERM), at any moment, within a second and without a
traceback (:mod:`poinsot.app.interrupts`): in all failures nothing half-written is left. 141:
stdout was closed early (``--json | head``). 70: an internal error, a bug in poinsot: one
line names it (``POINSOT_TRACEBACK=1`` prints the traceback for a report).
"""

from __future__ import annotations

import os
import sys

from .. import __version__
from . import commands  # light: what each subcommand does, its heavy imports inside
from .commands import (
    DEFAULT_EXAMPLE,
    EXIT_BAD_INPUT,
    EXIT_BROKEN_PIPE,
    EXIT_INTERNAL,
    EXIT_NUMERICAL,
    BadInput,
)

# light: the handlers come before any heavy import
from .interrupts import flush_streams, guard, left_on_disk

__all__ = ["main"]


def _quantity(unit: str, what: str, positive: bool = False):
    """An argparse ``type``: a number in ``unit`` (SI), or a quantity with a unit (``"100 rpm"``,
    ``"2 min"``) converted to it, as in scenario files (pint, the ``units`` extra)."""

    def convert(text: str) -> float:
        import argparse
        import math

        from .tables import ScenarioError, _quantity

        try:
            value = float(text)
        except ValueError:
            try:
                value = _quantity(text, unit, what)
            except ScenarioError as exc:
                raise argparse.ArgumentTypeError(str(exc)) from None
        if not math.isfinite(value) or (positive and not value > 0):
            kind = "a positive" if positive else "a finite"
            raise argparse.ArgumentTypeError(f"{what}: expected {kind} number ({unit}), "
                                             f"found {text}")  # fmt: skip
        return value

    convert.__name__ = f"quantity in {unit}"  # argparse names the type in its errors
    return convert


_seconds = _quantity("s", "--time-limit", positive=True)


def _parser():
    import argparse
    import re

    class Parser(argparse.ArgumentParser):
        """argparse's parser, reading ``-2e-3`` and ``-1E+5`` as numbers where Python 3.11
        reads only ``-2`` and ``-.5`` (``--up -2e-3 0 1`` was "expected 3 arguments").
        ``add_subparsers`` makes every subcommand's parser of this class."""

        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")

    p = Parser(
        prog="poinsot",
        description="Dynamics of rigid bodies and constrained mechanical systems.",
        epilog="Exit codes: 0 success, 2 bad input, 1 numerical failure or --time-limit "
        "reached, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM), 70 internal error.",
    )
    p.add_argument("--version", action="version", version=f"poinsot {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    _add_run_command(sub)
    _add_examples_command(sub)
    _add_inertia_command(sub)
    _add_polhodes_command(sub)
    _add_identify_command(sub)
    _grade_parser(sub)
    return p


def _add_run_command(sub):
    """Add the `run` subcommand: simulate a scenario into an output folder."""
    run = sub.add_parser(
        "run",
        help="simulate a scenario and write data, figures and a report",
        description="Simulate a scenario (TOML) and write trajectory.npz/.csv, "
        "summary.json, PNG figures and report.html. With no SCENARIO it runs "
        f"the built-in default, the example {DEFAULT_EXAMPLE!r}: the source "
        "notebook's 27-particle body under gravity with its polhode sweep.",
    )
    run.add_argument(
        "scenario",
        nargs="?",
        metavar="SCENARIO.toml",
        help="scenario file (see docs/scenarios.md); default: the built-in example",
    )
    run.add_argument(
        "--example",
        metavar="NAME",
        help="run a bundled example instead (list them with `poinsot examples`)",
    )
    run.add_argument(
        "--out", metavar="DIR", help="output folder (default ./poinsot-out/<scenario-name>/)"
    )
    run.add_argument("--force", action="store_true", help="replace the output folder if it exists")
    run.add_argument(
        "--plotly-js",
        choices=("inline", "cdn", "shared"),
        default=None,
        help="how report.html gets plotly.js: inline (default; self-contained, ~5 MB), cdn "
        "(small, loads it from cdn.plot.ly) or shared (writes plotly-VERSION.min.js once "
        "beside the output folder, e.g. in poinsot-out/, for all the reports there); needs "
        "the report extra (without plotly the report is a static page)",
    )
    run.add_argument("--quiet", action="store_true", help="print nothing but errors")
    run.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    run.add_argument(
        "--time-limit",
        type=_seconds,
        metavar="SECONDS",
        help="stop when the command has run this long (wall clock): exit 1, saying how far "
        "the run got, with nothing written",
    )
    run.set_defaults(func=commands.cmd_run)


def _add_examples_command(sub):
    """Add the `examples` subcommand: list or print the bundled scenarios and data."""
    ex = sub.add_parser(
        "examples",
        help="list the bundled example scenarios",
        description="List the bundled example scenarios; with --show NAME print one as a "
        "starting template (`poinsot examples --show heavy-top > mine.toml`).",
    )
    ex.add_argument("--show", metavar="NAME", help="print the scenario file of example NAME")
    ex.add_argument("--data", metavar="NAME",
                    help="print the sample data file NAME (gyro.csv: a synthetic gyro log of a "
                    "thrown phone, for `poinsot identify`)")  # fmt: skip
    ex.add_argument("--reference", action="store_true",
                    help="print the reference of every scenario key (Markdown)")  # fmt: skip
    ex.set_defaults(func=commands.cmd_examples, quiet=False)


def _add_inertia_command(sub):
    """Add the `inertia` subcommand: mass properties of a scenario's body or a mesh."""
    inertia = sub.add_parser(
        "inertia",
        help="mass properties of a body (scenario or mesh file)",
        description="Mass, centre of mass, inertia, principal moments and "
        "axes, and symmetry class of the [body] of a scenario file, or of a "
        "closed triangle mesh (STL/OBJ/PLY; needs poinsot[mesh]).",
    )
    inertia.add_argument("body", metavar="BODY", help="scenario .toml or mesh file")
    group = inertia.add_mutually_exclusive_group()
    group.add_argument("--mass", type=_quantity("kg", "--mass", True), help="mesh: total mass (kg)")
    group.add_argument(
        "--density",
        type=_quantity("kg/m^3", "--density", True),
        help="mesh: density (kg/m³; default 1)",
    )
    inertia.add_argument("--json", action="store_true", help="print JSON for machines")
    inertia.set_defaults(func=commands.cmd_inertia, quiet=False)


def _add_polhodes_command(sub):
    """Add the `polhodes` subcommand: torque-free analysis and polhode figures."""
    pol = sub.add_parser(
        "polhodes",
        help="torque-free analysis and polhode figures",
        description="Fixed points, stability, invariants, period and flip "
        "interval of the torque-free body, and its polhodes drawn on the energy "
        "ellipsoid (polhodes.png; with --omega0 also energy_ellipsoid.png), one "
        "interactive report.html of both, and polhodes.json.",
    )
    pol.add_argument(
        "--moments",
        type=_quantity("kg*m^2", "--moments"),
        nargs=3,
        required=True,
        metavar=("I1", "I2", "I3"),
        help="principal moments (kg m²)",
    )
    pol.add_argument("--allow-unphysical", action="store_true",
                     help="accept moments that break I1 + I2 ≥ I3 (no mass distribution has "
                     "them; Euler's equation is still well posed)")  # fmt: skip
    pol.add_argument(
        "--energy",
        type=_quantity("J", "--energy"),
        metavar="K",
        help="rotational kinetic energy k of the ellipsoid (default 0.5; with --omega0 it is "
        "that of ω0, and a different --energy is refused)",
    )
    pol.add_argument(
        "--omega0",
        type=_quantity("rad/s", "--omega0"),
        nargs=3,
        metavar=("W1", "W2", "W3"),
        help="an initial angular velocity (body = principal frame)",
    )
    pol.add_argument("--out", metavar="DIR", help="output folder (default ./poinsot-out/polhodes/)")
    pol.add_argument("--force", action="store_true", help="replace the output folder's files")
    pol.add_argument("--plotly-js", choices=("inline", "cdn", "shared"), default=None,
                     help="how report.html gets plotly.js (as for `poinsot run`)")  # fmt: skip
    pol.add_argument("--quiet", action="store_true", help="print nothing but errors")
    pol.add_argument("--json", action="store_true", help="print the analysis as JSON")
    pol.set_defaults(func=commands.cmd_polhodes)


def _add_identify_command(sub):
    """Add the `identify` subcommand: a body's inertia from a gyro log."""
    ide = sub.add_parser(
        "identify",
        help="identify a body's inertia from a gyro log (CSV)",
        description="Principal moments (their ratios I1/I3, I2/I3), principal axes and the "
        "inertia tensor of a body thrown tumbling, from its gyroscope log: time and gyro x, y, "
        "z (a phone app's export is recognised by its header), optionally a spinning rotor "
        "(speed column, axis, inertia: the inertia then comes out in kg m²) and the "
        "accelerometer (finds the free flight). Columns and scales come from --map MAP.toml "
        "or the options below (see docs/identify.md).",
    )
    ide.add_argument("log", metavar="LOG.csv", help="the log: a CSV file with a header line")
    ide.add_argument("--map", metavar="MAP.toml", help="column map and scales (docs/identify.md)")
    ide.add_argument("--time", metavar="COL", help="time column (header name or 0-based number)")
    ide.add_argument("--gyro", nargs=3, metavar=("X", "Y", "Z"), help="gyro columns")
    ide.add_argument("--accel", nargs=3, metavar=("X", "Y", "Z"), help="accelerometer columns")
    ide.add_argument("--rotor-speed", metavar="COL", help="rotor speed column")
    for key, example in (("time", '"1 us"'), ("gyro", '"1/16.384 deg/s"'),
                         ("accel", '"1/2048 g"'), ("rotor-speed", '"1 rpm"')):  # fmt: skip
        ide.add_argument(f"--{key}-scale", metavar="SCALE",
                         help=f"one unit of the {key.replace('-', ' ')} column in SI, a number or "
                         f"e.g. {example}")  # fmt: skip
    ide.add_argument("--rotor-axis", type=float, nargs=3, metavar=("X", "Y", "Z"),
                     help="rotor axis in the sensor frame")  # fmt: skip
    ide.add_argument("--rotor-inertia", type=_quantity("kg*m^2", "--rotor-inertia"), metavar="J",
                     help="rotor's axial moment of inertia (kg m²)")  # fmt: skip
    ide.add_argument("--window", type=_quantity("s", "--window"), nargs=2, metavar=("T0", "T1"),
                     help="the stretch of the log to use or search, in seconds")  # fmt: skip
    ide.add_argument(
        "--saturation",
        metavar="RATE",
        help='the gyro range, rad/s or e.g. "2000 deg/s" (default: recognised)',
    )
    ide.add_argument("--loss", default="linear",
                     choices=("linear", "soft_l1", "huber", "cauchy", "arctan"),
                     help="the fit's loss (robust ones resist outliers)")  # fmt: skip
    ide.add_argument("--delimiter", metavar="CHAR", help="CSV delimiter (default: guessed)")
    ide.add_argument("--decimal", choices=(".", ","), help="decimal mark (default .)")
    ide.add_argument(
        "--box",
        type=_quantity("m", "--box"),
        nargs=3,
        metavar=("A", "B", "C"),
        help="the body's size along the sensor's x, y, z in m (for axes.png)",
    )
    ide.add_argument(
        "--out", metavar="DIR", help="also write report.html, result.json and figures into DIR"
    )
    ide.add_argument("--force", action="store_true", help="replace the output folder's files")
    ide.add_argument("--quiet", action="store_true", help="print nothing but errors")
    ide.add_argument("--json", action="store_true", help="print the result as JSON")
    ide.set_defaults(func=commands.cmd_identify)


def _grade_parser(sub):
    gr = sub.add_parser(
        "grade",
        help="grade another engine's free body or heavy top against the exact motion",
        description="Read trajectories of a free body (or a heavy symmetric top) from any "
        "engine — CSV (column maps as for `poinsot identify`, plus `attitude`: four quaternion "
        "w, x, y, z or nine matrix columns) or .npz (t, omega, quaternion or Q) — and grade "
        "each against the exact motion from its first sample: errors of ω and Q, drift of the "
        "energy and |L|, distance from the exact polhode, flip instants, polhode family (see "
        "docs/grade.md). One file prints its grade; several, one table row each.",
    )
    gr.add_argument("logs", nargs="+", metavar="FILE", help="CSV or .npz trajectories")
    gr.add_argument("--inertia", type=_quantity("kg*m^2", "--inertia"), nargs="+",
                    metavar="I", help="a free body: its principal moments along the body axes "
                    "(3 numbers) or its inertia tensor Ixx Iyy Izz Ixy Ixz Iyz (6)")  # fmt: skip
    gr.add_argument("--top", type=float, nargs=3, metavar=("A", "C", "MGL"),
                    help="a heavy symmetric top: A about the tip across the axis, C about the "
                    "axis (kg m²), M g l (N m)")  # fmt: skip
    for flag, what in (("--axis", "the top's axis, tip → centre of mass, body frame"),
                       ("--up", "the top's upward vertical, space frame")):  # fmt: skip
        gr.add_argument(flag, type=float, nargs=3, default=(0.0, 0.0, 1.0),
                        metavar=("X", "Y", "Z"), help=f"{what} (default z)")  # fmt: skip
    gr.add_argument("--map", metavar="MAP.toml", help="column map (as for identify)")
    gr.add_argument("--time", metavar="COL", help="time column (header name or 0-based number)")
    gr.add_argument("--gyro", nargs=3, metavar=("X", "Y", "Z"), help="ω columns (body frame)")
    gr.add_argument(
        "--attitude",
        nargs="+",
        metavar="COL",
        help="attitude columns: quaternion w x y z, or a matrix row by row",
    )
    gr.add_argument("--delimiter", metavar="CHAR", help="CSV delimiter (default: guessed)")
    gr.add_argument("--decimal", choices=(".", ","), help="decimal mark (default .)")
    gr.add_argument(
        "--out",
        metavar="DIR",
        help="also write report.html, grade.json and figures (first file) into DIR",
    )
    gr.add_argument("--force", action="store_true", help="replace the output folder's files")
    gr.add_argument("--quiet", action="store_true", help="print nothing but errors")
    gr.add_argument("--json", action="store_true", help="print the grades as JSON")
    gr.set_defaults(func=commands.cmd_grade)


def _show_warning(message, category, filename, lineno, file=None, line=None):
    print(f"poinsot: warning: {message}", file=sys.stderr)


def main(argv=None) -> int:
    """Entry point of the ``poinsot`` console script; returns the exit code.

    Called without ``argv`` (the console script, ``python -m poinsot``) it runs as the
    process's own command: a signal ends it within a second with its exit code
    (:mod:`poinsot.app.interrupts`), and after an interrupt the process ends as soon as the
    message is written. Called with ``argv`` (from Python), the previous signal handlers come
    back when it returns.
    """
    process = argv is None
    g = guard(process=process)  # first: before argparse, NumPy and the rest are imported
    try:
        try:
            code = _run(argv, g)
        finally:
            g.finish()  # from here on a signal in the command's process ends it at once
    except KeyboardInterrupt:  # a signal in the last moments, after _run's own handling
        print(g.message(), file=sys.stderr)
        code = g.exit_code
    if process and g.signum is not None:  # interrupted: skip the interpreter's slow teardown
        flush_streams()
        os._exit(code)
    return code


def _run(argv, g) -> int:
    import warnings

    try:
        parser = _parser()
        args = parser.parse_args(argv)
        if args.command is None:
            parser.print_help()
            return EXIT_BAD_INPUT
        if getattr(args, "time_limit", None) is not None:
            g.limit(args.time_limit)
        args.guard = g
        g.args = args
        with warnings.catch_warnings():
            if getattr(args, "quiet", False):
                warnings.simplefilter("ignore")
            else:
                warnings.showwarning = _show_warning
            return _dispatch(args)
    except KeyboardInterrupt:  # Ctrl-C, SIGTERM or the time limit, wherever it landed
        print(g.message(), file=sys.stderr)
        return g.exit_code


def _dispatch(args) -> int:
    g = args.guard
    try:
        code = args.func(args)
        sys.stdout.flush()  # here, so that a closed pipe is met inside this try
        return code
    except KeyboardInterrupt:
        raise
    except BaseException as exc:
        if g.signum is not None:  # a library turned the interrupt into an error of its own
            raise KeyboardInterrupt from exc
        return _failure(exc, getattr(args, "written", None))


def _failure(exc, written=None) -> int:
    """The exit code and message of a command that failed with ``exc``; ``written``: the
    output folder it had completed before (then said to be there), or None."""
    from .._io import OutputError, is_disk_full
    from ..simulation import SimulationError
    from .scenario import ScenarioError

    try:
        raise exc
    except (ScenarioError, BadInput, OutputError) as exc:
        print(f"poinsot: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except SimulationError as exc:
        print(f"poinsot: numerical failure: {exc}", file=sys.stderr)
        return EXIT_NUMERICAL
    except ValueError as exc:  # the library refusing a run before it starts (e.g. max_steps)
        if written is not None:  # not a refusal: the run was over, its output written
            return _internal(exc, written)
        print(f"poinsot: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except BrokenPipeError:  # `poinsot ... --json | head`: the reader left; say nothing more
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except MemoryError:
        print("poinsot: error: out of memory; ask for fewer samples or members", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:
        where = f"{exc.filename}: " if exc.filename else ""
        if is_disk_full(exc):
            print(f"poinsot: error: {where}the disk is full; {left_on_disk(written)}",
                  file=sys.stderr)  # fmt: skip
            return EXIT_NUMERICAL
        print(f"poinsot: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Exception as exc:  # a bug: one line, never a traceback unless asked for
        return _internal(exc, written)


def _internal(exc, written=None) -> int:
    """An internal error (a bug): one line naming it and what was left on disk, never a
    traceback unless ``POINSOT_TRACEBACK`` asks for one."""
    if os.environ.get("POINSOT_TRACEBACK"):
        import traceback

        traceback.print_exception(exc, file=sys.stderr)
    print(f"poinsot: internal error: {type(exc).__name__}: {exc} (a bug in poinsot, please "
          f"report it; POINSOT_TRACEBACK=1 prints where it happened); {left_on_disk(written)}",
          file=sys.stderr)  # fmt: skip
    return EXIT_INTERNAL


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
