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
import time

from .. import __version__
from .interrupts import flush_streams, guard  # light: the handlers come before any heavy import

__all__ = ["main"]

EXIT_OK, EXIT_NUMERICAL, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130
EXIT_TERMINATED, EXIT_BROKEN_PIPE, EXIT_INTERNAL = 143, 141, 70
DEFAULT_EXAMPLE = "notebook"


class _Progress:
    """How far the simulation got: recorded for the time limit's message (``guard``), and
    drawn as a one-line bar on stderr, only on a terminal and after one second. Called with
    the time reached, or (:meth:`members`) with the members of an ensemble done.

    Written here rather than taken from tqdm/rich: it is twenty lines, and the core
    dependencies stay numpy, scipy, sympy and matplotlib.
    """

    def __init__(self, t0, t1, enabled, guard=None):
        self.t0, self.t1 = t0, t1
        self.enabled = enabled and sys.stderr.isatty()
        self.guard = guard
        self.start = time.monotonic()
        self.last = 0.0
        self.shown = False

    def __call__(self, t):
        frac = min(max((t - self.t0) / (self.t1 - self.t0), 0.0), 1.0)
        self._show(frac, f"t = {t:.4g} s of [{self.t0:g}, {self.t1:g}] s ({100 * frac:.0f} %)")

    def members(self, done, total):
        frac = done / total if total else 1.0
        self._show(frac, f"{done} of {total} members done ({100 * frac:.0f} %)")

    def _show(self, frac, where):
        if self.guard is not None:
            self.guard.at("simulating", where)
        if not self.enabled:
            return
        now = time.monotonic()
        if now - self.start < 1.0 or now - self.last < 0.1:
            return
        self.last = now
        bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
        sys.stderr.write(f"\r[{bar}] {100 * frac:5.1f}%  {where}")
        sys.stderr.flush()
        self.shown = True

    def close(self):
        if self.shown:
            sys.stderr.write("\n")


def _say(args, *text):
    if not args.quiet and not getattr(args, "json", False):
        print(*text)


def _cmd_run(args):
    from pathlib import Path

    guard = args.guard
    guard.at("loading the scenario")
    from .._io import safe_name
    from .job import run_scenario
    from .runs import run_for
    from .scenario import load_example, load_scenario

    if args.scenario and args.example:
        raise _BadInput("give a SCENARIO file or --example NAME, not both")
    plotlyjs = _plotly_js(args)
    if args.scenario:
        scenario = load_scenario(Path(args.scenario))
    else:
        scenario = load_example(args.example or DEFAULT_EXAMPLE)
    out = _output_folder(args, safe_name(scenario.name))
    _say(args, f"poinsot: {scenario.name} — {scenario.description}")
    progress = _Progress(*scenario.t_span, enabled=not args.quiet, guard=guard)
    try:
        summary = run_scenario(scenario, out, force=args.force, progress=progress,
                               plotlyjs=plotlyjs, on_stage=guard.at)  # fmt: skip
    finally:
        progress.close()
    guard.at("printing the summary")
    if args.json:
        import json

        print(json.dumps(summary, indent=2))
    else:
        for line in run_for(scenario).terminal_lines(summary, out):
            _say(args, line)
    if "report" in summary:  # a static report: say why, and how to get the interactive one
        print(f"poinsot: note: {summary['report']}", file=sys.stderr)
    return EXIT_OK


def _plotly_js(args) -> str:
    """``--plotly-js``, checked before any work: how the interactive report gets plotly.js
    (default ``inline``). Asked for explicitly without plotly installed, it is refused (the
    report would be a static page, where it has no effect)."""
    if args.plotly_js is None:
        return "inline"
    from ..viz.report import interactive_available

    if not interactive_available():
        raise _BadInput(f"--plotly-js {args.plotly_js} needs plotly, which is not installed: "
                        "pip install 'poinsot[report]' (or leave --plotly-js out for a static "
                        "report)")  # fmt: skip
    return args.plotly_js


def _output_folder(args, name: str):
    """``--out`` as given; without it ``./poinsot-out/NAME``, or when that exists (and no
    ``--force``) its first free sibling ``NAME-2``, ``NAME-3``, … so that a command can be
    run twice. The folder used is printed by the command."""
    from pathlib import Path

    if args.out:
        return Path(args.out)
    base = Path("poinsot-out") / name
    if args.force or not os.path.lexists(base):
        return base
    n = 2
    while os.path.lexists(base.with_name(f"{name}-{n}")):
        n += 1
    return base.with_name(f"{name}-{n}")


def _cmd_examples(args):
    from .scenario import example_text, list_examples

    if args.show:
        sys.stdout.write(example_text(args.show))
        return EXIT_OK
    if args.data:
        from importlib.resources import files

        from ..identify.synthetic import SAMPLE_LOG

        if args.data != SAMPLE_LOG:
            raise _BadInput(f"--data: no sample named {args.data!r}; available: {SAMPLE_LOG}")
        sys.stdout.write(files("poinsot.identify").joinpath("samples", SAMPLE_LOG)
                         .read_text(encoding="utf-8"))  # fmt: skip
        return EXIT_OK
    if args.reference:
        from .scenario_reference import render_reference

        print(render_reference())
        return EXIT_OK
    examples = list_examples()
    examples["gyro.csv"] = (
        "sample data, not a scenario: a synthetic gyro log of a thrown phone for "
        "`poinsot identify` (`--data gyro.csv` prints it)"
    )
    width = max(map(len, examples), default=0)
    for name, description in examples.items():
        print(f"{name:{width}s}  {description}")
    return EXIT_OK


def _cmd_inertia(args):
    import json
    from pathlib import Path

    from .scenario import ScenarioError, _Table, build_body, load_scenario

    path = Path(args.body)
    if not path.exists():
        raise _BadInput(f"{path}: no such file")
    if path.suffix.lower() == ".toml":
        if args.mass is not None or args.density is not None:
            raise _BadInput("--mass/--density apply to mesh files only")
        try:
            body = load_scenario(path).body
        except ScenarioError:
            from .._io import TOMLError, read_toml

            try:  # a file with only a [body] table is fine too
                data = read_toml(path.read_text(encoding="utf-8"), str(path))
            except TOMLError as exc:
                raise ScenarioError(str(exc)) from None
            if set(data) != {"body"}:
                raise
            try:
                body = build_body(_Table(data["body"], "body"), path.parent)
            except ScenarioError as exc:
                raise ScenarioError(f"{path}: {exc}") from None
    else:
        from ..bodies import RigidBody

        try:
            body = RigidBody.from_mesh(path, mass=args.mass, density=args.density)
        except (ValueError, TypeError, ImportError) as exc:
            raise _BadInput(f"{path}: {exc}") from None
    info = body.mass_properties()
    if args.json:
        info["units"] = {"mass": "kg", "center_of_mass": "m", "inertia": "kg·m²",
                         "principal_moments": "kg·m²", "principal_axes": "1"}  # fmt: skip
        print(json.dumps(info, indent=2))
        return EXIT_OK
    import numpy as np

    from ..viz.numbers import format_value

    def vec(v):
        return format_value(np.asarray(v).tolist())

    def rows(m):
        return "\n".join("  " + vec(r) for r in np.asarray(m))

    print(f"mass               {format_value(float(body.mass))} kg")
    print(f"centre of mass     {vec(body.center_of_mass)} m")
    print(f"inertia about the centre of mass [kg·m²]\n{rows(body.inertia)}")
    print(f"principal moments  {vec(body.principal_moments)} kg·m²")
    print(f"principal axes (columns e1, e2, e3; dimensionless)\n{rows(body.principal_axes)}")
    print(
        f"symmetry           {body.symmetry}"
        + ("  (degenerate: all mass on a line)" if body.is_degenerate else "")
    )
    return EXIT_OK


def _cmd_polhodes(args):
    import json
    import math

    import numpy as np

    from ..bodies import UnphysicalInertiaError
    from ..torquefree import FreeRigidBody

    try:
        free = FreeRigidBody(args.moments, allow_unphysical=args.allow_unphysical)
    except UnphysicalInertiaError as exc:
        raise _BadInput(f"--moments: {exc.reason} (add --allow-unphysical to study the "
                        "equations anyway)") from None  # fmt: skip
    except ValueError as exc:
        raise _BadInput(f"--moments: {exc}") from None
    I = free.principal_moments
    result = {
        "principal_moments": I.tolist(),
        "symmetry": free.symmetry,
        "fixed_points": [{"set": fp.label, "stable": fp.stable} for fp in free.fixed_points()],
    }
    energy = args.energy
    if args.omega0 is not None:
        w0 = np.array(args.omega0, dtype=float)
        if not np.all(np.isfinite(w0)) or not np.any(w0):
            raise _BadInput("--omega0: expected three finite numbers, not all zero")
        result["omega0"] = w0.tolist()
        result.update(free.describe(w0))
        k = result["energy"]
        if energy is not None and not math.isclose(energy, k, rel_tol=1e-9):
            raise _BadInput(
                f"--energy {energy:g} conflicts with --omega0, whose energy is {k:.10g}: give "
                "one of them (the ellipsoid is drawn at the energy of ω0)"
            )
        energy = k
    energy = 0.5 if energy is None else energy
    if not energy > 0:
        raise _BadInput(f"--energy: expected a positive number, found {energy}")
    try:
        free.check_energy_range(energy)
    except ValueError as exc:
        raise _BadInput(f"--energy: {exc}") from None
    from .._io import OutputFolder

    plotlyjs = _plotly_js(args)
    out = _output_folder(args, "polhodes")
    folder = OutputFolder(out, force=args.force, command="polhodes", needs_bytes=12_000_000)
    with folder.writing() as work:
        written = _write_polhodes(work, args, free, energy, result, plotlyjs)
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        from ..viz.numbers import POLHODES, format_value

        names = {path: name for _, name, path, _ in POLHODES}
        moments = ", ".join(format_value(float(x)) for x in I)
        _say(args, f"principal moments {moments} kg·m² ({free.symmetry})")
        for fp in result["fixed_points"]:
            _say(args, f"  fixed points {fp['set']}: {'stable' if fp['stable'] else 'unstable'}")
        for key in ("family", "energy", "momentum", "period", "flip_interval"):
            if key in result:
                value = result[key]
                shown = format_value(value) if isinstance(value, float) else str(value)
                _say(args, f"  {names[key]}: {shown} {result['units'].get(key, '')}".rstrip())
        if "flip_interval" in result:
            _say(args, f"  {flip_note(result)}")
        _say(args, f"  wrote {out}/ ({', '.join(written)})")
    if "report" in result:
        print(f"poinsot: note: {result['report']}", file=sys.stderr)
    return EXIT_OK


def flip_note(result) -> str:
    """What the time between sign changes of ω·e₂ means for this motion: a flip of the body
    (e₂ turns over against L) or a wobble about a stable axis (nothing flips)."""
    import math

    swing = result.get("e2_swing")
    if result.get("flips"):
        return (f"the body flips: e₂ turns over against L every half period (e₂ comes within "
                f"{math.degrees(math.acos(min(swing, 1.0))):.3g}° of ±L)")  # fmt: skip
    return (f"nothing flips: ω·e₂ changes sign as the body wobbles about {result['family'][-2:]}"
            f" (e₂ stays within {math.degrees(math.asin(min(swing, 1.0))):.3g}° of the plane "
            "perpendicular to L)")  # fmt: skip


def _write_polhodes(out, args, free, energy, result, plotlyjs) -> list[str]:
    """polhodes.png (+ energy_ellipsoid.png with --omega0), one report.html of both
    (interactive with plotly, else a static page of the two images), and polhodes.json (with
    units), into the folder ``out``; the names of the files written."""

    import json

    import numpy as np

    from .._io import atomic_write_text
    from ..viz import plot_energy_ellipsoid, plot_polhode_family
    from ..viz.numbers import units_of
    from ..viz.report import STATIC_NOTE, interactive_available
    from .runs.base import png_images

    def figures():
        path = None
        if args.omega0 is not None:  # ω0 fixes the energy: its ω(t) lies on this ellipsoid
            w0 = np.array(args.omega0, dtype=float)
            periodic = result["family"] not in ("fixed point", "spherical", "separatrix")
            t = np.linspace(0, min(free.period(w0), 200.0) if periodic else 50.0, 400)
            path = free.exact_omega(w0, t)
        yield (plot_polhode_family(free, energy, omega=path, omega_label="ω(t) from ω0"),
               "polhodes.png", "The polhode family on the energy ellipsoid")  # fmt: skip
        if args.omega0 is not None:
            fig = plot_energy_ellipsoid(free, result["energy"], result["momentum"])
            yield fig, "energy_ellipsoid.png", "The energy ellipsoid and the momentum sphere"

    images = png_images(figures(), out, dpi=110)
    about = "Torque-free analysis: fixed points, invariants and the energy ellipsoid"
    page = {**result, "scenario": {"name": "polhodes", "description": about}}
    if interactive_available():  # one interactive page with both figures and the numbers
        from ..viz.interactive import energy_ellipsoid_figure, polhode_family_figure
        from ..viz.report import write_figures_page

        plots = [polhode_family_figure(free, energy)]
        if args.omega0 is not None:
            plots.append(energy_ellipsoid_figure(free, result["energy"], result["momentum"]))
        write_figures_page(out / "report.html", plots, page, plotlyjs=plotlyjs,
                           raw_link="polhodes.json")  # fmt: skip
    else:
        from ..viz.report import write_static_report

        result["report"] = STATIC_NOTE
        write_static_report(out / "report.html", page, images, ("polhodes.json",))
    result["units"] = units_of(result)
    atomic_write_text(out / "polhodes.json", json.dumps(result, indent=2))
    files = ["polhodes.json", *(name for name in ("polhodes.png", "energy_ellipsoid.png")
                                if (out / name).exists()), "report.html"]  # fmt: skip
    return files


def _cmd_identify(args):
    import json
    import warnings
    from pathlib import Path

    from ..identify import (
        LogMap,
        LogMapError,
        ModelMismatchWarning,
        NotIdentifiableError,
        identify,
        load_map,
        read_log,
    )
    from ..identify.log import parse_scale

    path = Path(args.log)
    try:
        log_map = load_map(args.map) if args.map else LogMap()
        options = {
            "time": args.time,
            "gyro": tuple(args.gyro) if args.gyro else None,
            "accel": tuple(args.accel) if args.accel else None,
            "rotor_speed": args.rotor_speed,
            "rotor_axis": tuple(args.rotor_axis) if args.rotor_axis else None,
            "rotor_inertia": args.rotor_inertia,
            "window": tuple(args.window) if args.window else None,
            "delimiter": args.delimiter,
            "decimal": args.decimal,
        }
        for key, kind in (("time", "time"), ("gyro", "rate"), ("accel", "accel"),
                          ("rotor_speed", "rate")):  # fmt: skip
            value = getattr(args, f"{key}_scale")
            if value is not None:
                flag = f"--{key.replace('_', '-')}-scale"
                options[f"{key}_scale"] = parse_scale(_number_or_text(value), kind, flag)
        if args.saturation is not None:
            options["saturation"] = parse_scale(_number_or_text(args.saturation), "rate",
                                                "--saturation")  # fmt: skip
        log = read_log(path, log_map, **options)
    except LogMapError as exc:
        raise _BadInput(str(exc)) from None
    if args.rotor_inertia is not None and not args.rotor_inertia > 0:
        raise _BadInput(f"--rotor-inertia must be a positive number (kg m²), found "
                        f"{args.rotor_inertia}")  # fmt: skip
    try:
        with warnings.catch_warnings(record=True):  # the flags are printed with the result
            warnings.simplefilter("always", ModelMismatchWarning)
            res = identify(log.t, log.omega, loss=args.loss, **log.identify_kwargs())
    except NotIdentifiableError as exc:
        raise _BadInput(f"{path}: {exc}") from None
    except (ValueError, TypeError) as exc:
        raise _BadInput(f"{path}: {exc}{_columns_of(str(exc), log.columns)}") from None
    data = res.to_dict()
    data["log"] = {"path": str(path), "columns": log.columns, "notes": list(log.notes)}
    if args.out:
        _write_identify(Path(args.out), args, res, data)
    if args.json:
        print(json.dumps(data, indent=2))
        return EXIT_OK
    for note in log.notes:
        _say(args, f"note          {note}")
    for line in res.summary():
        if line.startswith("warning"):
            print(f"poinsot: {line.replace('warning       ', 'warning: ')}", file=sys.stderr)
        else:
            _say(args, line)
    if args.out:
        _say(args, f"wrote {args.out}/ (report.html, result.json, fit.png, polhode.png, axes.png)")
    return EXIT_OK


def _columns_of(message: str, columns: dict) -> str:
    """The log's columns behind the argument a library message names, e.g. " (columns
    'gyroADC[0]', 'gyroADC[1]', 'gyroADC[2]')" for "`omega` ..."."""
    keys = {
        "t": ("time",),
        "omega": ("gyro.x", "gyro.y", "gyro.z"),
        "accel": ("accel.x", "accel.y", "accel.z"),
        "rotor_speed": ("rotor_speed",),
    }
    for name, wanted in keys.items():
        if message.startswith(f"`{name}`") or message.startswith(f"`{name}["):
            found = [repr(columns[k]) for k in wanted if k in columns]
            if found:
                return f" (the column{'s' if len(found) > 1 else ''} {', '.join(found)})"
    return ""


def _number_or_text(value: str):
    try:
        return float(value)
    except ValueError:
        return value


def _write_identify(out, args, res, data):
    import json
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    from .._io import OutputFolder, atomic_write_text
    from ..viz.identify import write_identify_report_folder

    folder = OutputFolder(out, force=args.force, command="identify", needs_bytes=5_000_000)
    with folder.writing() as work:
        write_identify_report_folder(work, res, name=Path(args.log).name, box=args.box,
                                     extra={"log": data["log"]})  # fmt: skip
        full = res.to_dict(series=True)
        full["log"] = data["log"]
        atomic_write_text(work / "result.json", json.dumps(full, indent=2))


class _BadInput(ValueError):
    pass


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

    p = argparse.ArgumentParser(
        prog="poinsot",
        description="Dynamics of rigid bodies and constrained mechanical systems.",
        epilog="Exit codes: 0 success, 2 bad input, 1 numerical failure or --time-limit "
        "reached, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM), 70 internal error.",
    )
    p.add_argument("--version", action="version", version=f"poinsot {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")

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
    run.set_defaults(func=_cmd_run)

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
    ex.set_defaults(func=_cmd_examples, quiet=False)

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
    inertia.set_defaults(func=_cmd_inertia, quiet=False)

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
    pol.set_defaults(func=_cmd_polhodes)

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
    ide.set_defaults(func=_cmd_identify)
    _grade_parser(sub)
    return p


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
    gr.set_defaults(func=_cmd_grade)


def _cmd_grade(args):
    from .grade import run_grade

    return run_grade(args)


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
        return _failure(exc)


def _failure(exc) -> int:
    """The exit code and message of a command that failed with ``exc``."""
    from .._io import OutputError, is_disk_full
    from ..simulation import SimulationError
    from .scenario import ScenarioError

    try:
        raise exc
    except (ScenarioError, _BadInput, OutputError) as exc:
        print(f"poinsot: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except SimulationError as exc:
        print(f"poinsot: numerical failure: {exc}", file=sys.stderr)
        return EXIT_NUMERICAL
    except ValueError as exc:  # the library refusing a run before it starts (e.g. max_steps)
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
            print(f"poinsot: error: {where}the disk is full; no partial output was left",
                  file=sys.stderr)  # fmt: skip
            return EXIT_NUMERICAL
        print(f"poinsot: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Exception as exc:  # a bug: one line, never a traceback unless asked for
        import os

        if os.environ.get("POINSOT_TRACEBACK"):
            import traceback

            traceback.print_exception(exc, file=sys.stderr)
        print(f"poinsot: internal error: {type(exc).__name__}: {exc} (a bug in poinsot, "
              "please report it; POINSOT_TRACEBACK=1 prints where it happened); no partial "
              "output was left", file=sys.stderr)  # fmt: skip
        return EXIT_INTERNAL


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
