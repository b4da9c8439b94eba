"""The ``poinsot`` commands: what each subcommand of :mod:`poinsot.app.cli` does with its
parsed arguments (``args``), returning the exit code. The command line itself (the parser,
the exit codes, interrupts and failures) is :mod:`poinsot.app.cli`; a command raises and the
command line turns the error into its one-line message.
"""

from __future__ import annotations

import os
import sys
import time

#: The exit codes of the command line (:mod:`poinsot.app.cli`'s docstring says when).
EXIT_OK, EXIT_NUMERICAL, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130
EXIT_TERMINATED, EXIT_BROKEN_PIPE, EXIT_INTERNAL = 143, 141, 70
DEFAULT_EXAMPLE = "notebook"


class BadInput(ValueError):
    """An argument of the command line that a command refuses (exit code 2)."""


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


def say(args, *text):
    if not args.quiet and not getattr(args, "json", False):
        print(*text)


def cmd_run(args):
    from pathlib import Path

    guard = args.guard
    guard.at("loading the scenario")
    from .._io import safe_name
    from .job import run_scenario
    from .runs import run_for
    from .scenario import load_example, load_scenario

    if args.scenario and args.example:
        raise BadInput("give a SCENARIO file or --example NAME, not both")
    plotlyjs = _plotly_js(args)
    if args.scenario:
        scenario = load_scenario(Path(args.scenario))
    else:
        scenario = load_example(args.example or DEFAULT_EXAMPLE)
    out = _output_folder(args, safe_name(scenario.name))
    say(args, f"poinsot: {scenario.name} — {scenario.description}")
    progress = _Progress(*scenario.t_span, enabled=not args.quiet, guard=guard)
    try:
        summary = run_scenario(scenario, out, force=args.force, progress=progress,
                               plotlyjs=plotlyjs, on_stage=guard.at)  # fmt: skip
    finally:
        progress.close()
    args.written = out  # complete from here on: a later failure must not say otherwise
    guard.at("printing the summary")
    if args.json:
        import json

        print(json.dumps(summary, indent=2))
    else:
        for line in run_for(scenario).terminal_lines(summary, out):
            say(args, line)
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
        raise BadInput(f"--plotly-js {args.plotly_js} needs plotly, which is not installed: "
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


def cmd_examples(args):
    from .scenario import example_text, list_examples

    if args.show:
        sys.stdout.write(example_text(args.show))
        return EXIT_OK
    if args.data:
        from importlib.resources import files

        from ..identify.synthetic import SAMPLE_LOG

        if args.data != SAMPLE_LOG:
            raise BadInput(f"--data: no sample named {args.data!r}; available: {SAMPLE_LOG}")
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


def cmd_inertia(args):
    import json
    from pathlib import Path

    from .scenario import ScenarioError, _Table, build_body, load_scenario

    path = Path(args.body)
    if not path.exists():
        raise BadInput(f"{path}: no such file")
    if path.suffix.lower() == ".toml":
        if args.mass is not None or args.density is not None:
            raise BadInput("--mass/--density apply to mesh files only")
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
            raise BadInput(f"{path}: {exc}") from None
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


def cmd_polhodes(args):
    import json
    import math

    import numpy as np

    from ..bodies import UnphysicalInertiaError
    from ..torquefree import FreeRigidBody

    try:
        free = FreeRigidBody(args.moments, allow_unphysical=args.allow_unphysical)
    except UnphysicalInertiaError as exc:
        raise BadInput(f"--moments: {exc.reason} (add --allow-unphysical to study the "
                        "equations anyway)") from None  # fmt: skip
    except ValueError as exc:
        raise BadInput(f"--moments: {exc}") from None
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
            raise BadInput("--omega0: expected three finite numbers, not all zero")
        # ω0 along the sorted principal axes, as principal_moments are listed (the label
        # says so), and as given, along the axes of --moments
        result["omega0"] = free.principal_components(w0).tolist()
        result["omega0_given"] = w0.tolist()
        result.update(free.describe(w0))
        k = result["energy"]
        if energy is not None and not math.isclose(energy, k, rel_tol=1e-9):
            raise BadInput(
                f"--energy {energy:g} conflicts with --omega0, whose energy is {k:.10g}: give "
                "one of them (the ellipsoid is drawn at the energy of ω0)"
            )
        energy = k
    energy = 0.5 if energy is None else energy
    if not energy > 0:
        raise BadInput(f"--energy: expected a positive number, found {energy}")
    result.setdefault("energy", energy)  # the drawn ellipsoid's, given or by default
    try:
        free.check_energy_range(energy)
    except ValueError as exc:
        raise BadInput(f"--energy: {exc}") from None
    from .._io import OutputFolder

    plotlyjs = _plotly_js(args)
    out = _output_folder(args, "polhodes")
    folder = OutputFolder(out, force=args.force, command="polhodes", needs_bytes=12_000_000)
    with folder.writing() as work:
        written = _write_polhodes(work, args, free, energy, result, plotlyjs)
    args.written = out
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        from ..viz.numbers import POLHODES, format_value

        names = {path: name for _, name, path, _ in POLHODES}
        moments = ", ".join(format_value(float(x)) for x in I)
        say(args, f"principal moments {moments} kg·m² ({free.symmetry})")
        for fp in result["fixed_points"]:
            say(args, f"  fixed points {fp['set']}: {'stable' if fp['stable'] else 'unstable'}")
        for key in ("family", "energy", "momentum", "period", "flip_interval"):
            if key in result:
                value = result[key]
                shown = format_value(value) if isinstance(value, float) else str(value)
                say(args, f"  {names[key]}: {shown} {result['units'].get(key, '')}".rstrip())
        if "flip_interval" in result:
            say(args, f"  {flip_note(result)}")
        say(args, f"  wrote {out}/ ({', '.join(written)})")
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


def cmd_identify(args):
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
        raise BadInput(str(exc)) from None
    if args.rotor_inertia is not None and not args.rotor_inertia > 0:
        raise BadInput(f"--rotor-inertia must be a positive number (kg m²), found "
                        f"{args.rotor_inertia}")  # fmt: skip
    try:
        with warnings.catch_warnings(record=True):  # the flags are printed with the result
            warnings.simplefilter("always", ModelMismatchWarning)
            res = identify(log.t, log.omega, loss=args.loss, **log.identify_kwargs())
    except NotIdentifiableError as exc:
        raise BadInput(f"{path}: {exc}") from None
    except (ValueError, TypeError) as exc:
        raise BadInput(f"{path}: {exc}{_columns_of(str(exc), log.columns)}") from None
    data = res.to_dict()
    data["log"] = {"path": str(path), "columns": log.columns, "notes": list(log.notes)}
    if args.out:
        _write_identify(Path(args.out), args, res, data)
        args.written = Path(args.out)
    if args.json:
        print(json.dumps(data, indent=2))
        return EXIT_OK
    for note in log.notes:
        say(args, f"note          {note}")
    for line in res.summary():
        if line.startswith("warning"):
            print(f"poinsot: {line.replace('warning       ', 'warning: ')}", file=sys.stderr)
        else:
            say(args, line)
    if args.out:
        say(args, f"wrote {args.out}/ (report.html, result.json, fit.png, polhode.png, axes.png)")
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


def cmd_grade(args):
    from .grade import run_grade

    return run_grade(args)
