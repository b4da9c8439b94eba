"""``poinsot grade``: another engine's trajectories against the exact motion.

One file prints its grade line by line; several print one table row each (the comparison of
engines or steps the recipe in ``docs/grade.md`` makes). ``--out`` writes ``grade.json``,
the figures and ``report.html`` of the first file.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

__all__ = ["run_grade"]


def _reference(args):
    """``(kind, inertia or HeavyTop)`` from ``--inertia`` or ``--top``."""
    import numpy as np

    from .commands import BadInput

    if (args.inertia is None) == (args.top is None):
        raise BadInput("give the body as exactly one of --inertia (a free body) or --top A C "
                        "MGL (a heavy symmetric top)")  # fmt: skip
    if args.inertia is not None:
        if len(args.inertia) not in (3, 6):
            raise BadInput(
                "--inertia takes three principal moments along the body axes, or "
                f"six: Ixx Iyy Izz Ixy Ixz Iyz; found {len(args.inertia)} numbers"
            )
        v = np.asarray(args.inertia, dtype=float)
        J = np.diag(v) if len(v) == 3 else np.array([[v[0], v[3], v[4]], [v[3], v[1], v[5]],
                                                      [v[4], v[5], v[2]]])  # fmt: skip
        from ..bodies import check_inertia

        try:
            check_inertia(J, "--inertia")
        except ValueError as exc:
            raise BadInput(str(exc)) from None
        return "free body", J
    from ..tops import HeavyTop

    A, C, mgl = args.top
    if not all(math.isfinite(x) and x > 0 for x in (A, C, mgl)):
        raise BadInput(f"--top: A, C and M g l must be positive and finite, found {A}, {C}, "
                       f"{mgl}")  # fmt: skip
    axis, up = _direction(args.axis, "--axis"), _direction(args.up, "--up")
    return "heavy top", HeavyTop(A, C, mgl, axis, up, math.nan)


def _direction(values, option: str):
    """The unit vector along the three numbers of ``option``, refused naming the option when
    they are not finite or all zero. Scaled by the largest first, so that no square
    overflows (``1e308 1e308 0``) or underflows (``1e-320 0 0``) on the way."""
    import numpy as np

    from .commands import BadInput

    v = np.asarray(values, dtype=float)
    if not np.isfinite(v).all():
        raise BadInput(f"{option}: expected three finite numbers, found {v.tolist()}")
    largest = float(np.abs(v).max())
    if not largest > 0:
        raise BadInput(f"{option}: expected a non-zero direction, found {v.tolist()}")
    v = v / largest
    return v / np.linalg.norm(v)


def _options(args) -> dict:
    return {
        "time": args.time,
        "gyro": tuple(args.gyro) if args.gyro else None,
        "attitude": tuple(args.attitude) if args.attitude else None,
        "delimiter": args.delimiter,
        "decimal": args.decimal,
    }


def _grade_one(path, args, kind, ref):
    from ..grade import grade_free, grade_top, read_motion
    from ..identify.log import LogMap, LogMapError, load_map
    from .commands import BadInput

    try:
        log_map = load_map(args.map) if args.map else None
        options = _options(args)
        if Path(path).suffix.lower() == ".npz":
            options = {k: v for k, v in options.items() if v is not None}
        else:
            log_map = log_map or LogMap()
        motion = read_motion(path, log_map, **options)
    except LogMapError as exc:
        raise BadInput(str(exc)) from None
    try:
        if kind == "free body":
            return motion, grade_free(motion.t, motion.omega, ref, motion.Q)
        return motion, grade_top(motion.t, motion.omega, motion.Q, ref)
    except ValueError as exc:
        raise BadInput(f"{path}: {exc}") from None


#: What the attitude's steps match when they do not follow the gyro's body-frame ω.
_VERDICTS = {
    "space": "they follow ω taken in the space frame: is the gyro's ω in the body frame?",
    "transposed": "they follow Qᵀ: is the matrix space → body, or the quaternion conjugate?",
    "degrees": "they follow ω·π/180: is the gyro in deg/s?",
    "": "check the attitude's column order (w, x, y, z; a matrix row by row) and frames",
}


def gyro_note(s) -> str:
    """A line when the attitude's steps do not follow the gyro (``summary()``'s
    ``gyro_attitude_mismatch`` above :data:`poinsot.grade.FOLLOW_RTOL`), else ""."""
    from ..grade import FOLLOW_RTOL

    m = s.get("gyro_attitude_mismatch")
    if m is None or m <= FOLLOW_RTOL:
        return ""
    return (f"the attitude does not follow the gyro: its steps Q_kᵀQ_k+1 differ from ω Δt by "
            f"{100 * m:.3g} % (median); {_VERDICTS[s['gyro_attitude_verdict']]}")  # fmt: skip


def lines_of(grade, path) -> list[str]:
    """The grade of one file, as ``poinsot grade`` prints it."""
    s = grade.summary()
    out = [
        f"grade         {path}: {s['kind']} against the exact motion from its first sample",
        f"samples       {s['samples']}, t = {s['t_start']:.6g} … {s['t_end']:.6g} s",
    ]
    if s["kind"] == "free body":
        if s["family_kept"]:
            fam = f"{s['family']} (every sample)"
        else:
            fam = (
                f"{s['family']} at the start; left at t = {s['family_left_at']:.6g} s "
                f"({100 * s['wrong_family_fraction']:.3g} % of the samples in another)"
            )
        out.append(f"family        {fam}")
    out.append(f"omega         max |ω − ω_exact| = {s['max_omega_error']:.3e} rad/s")
    if s["max_attitude_error"] is not None:
        out.append(f"attitude      max |Q − Q_exact| = {s['max_attitude_error']:.3e}; "
                   f"max |QᵀQ − I| = {s['max_orthogonality_error']:.3e}")  # fmt: skip
        note = gyro_note(s)
        if note:
            out.append(f"check         {note}")
    if s["kind"] == "free body":
        out += [f"energy        max |k/k₀ − 1| = {s['max_energy_error']:.3e}",
                f"momentum      max ||L|/|L₀| − 1| = {s['max_momentum_error']:.3e}"]  # fmt: skip
        if s["max_polhode_distance"] is not None:
            out.append(f"polhode       max distance of ω from its exact polhode = "
                       f"{s['max_polhode_distance']:.3e} rad/s")  # fmt: skip
        if s["exact_flips"] or s["flips"]:
            err = s["max_flip_time_error"]
            out.append(f"flips         {s['flips']} measured, {s['exact_flips']} exact "
                       f"(every {s['flip_interval']:.6g} s)"
                       + ("" if err is None else f"; max |Δt| = {err:.3e} s"))  # fmt: skip
    else:
        out.append("angles        max error θ {:.3e}, ψ {:.3e}, φ {:.3e} rad".format(
            s["max_theta_error"], s["max_psi_error"], s["max_phi_error"]))  # fmt: skip
    return out


def lead_of(grade) -> str:
    """One sentence of what the grade says, for the report."""
    s = grade.summary()
    if s["kind"] != "free body":
        return (f"Against Lagrange's top in closed form from the first sample, ω is at most "
                f"{s['max_omega_error']:.3g} rad/s off, and the axis's nutation θ, precession "
                f"ψ and spin φ at most {s['max_theta_error']:.3g}, {s['max_psi_error']:.3g} "
                f"and {s['max_phi_error']:.3g} rad.")  # fmt: skip
    family = (
        f"ω stays in its family ({s['family']})"
        if s["family_kept"]
        else f"ω leaves its family ({s['family']}) at t = {s['family_left_at']:.4g} s"
    )
    flips = (f"; {s['flips']} flips against {s['exact_flips']} exact"
             + ("" if s["max_flip_time_error"] is None
                else f", at most {s['max_flip_time_error']:.3g} s off")
             if s["exact_flips"] or s["flips"] else "")  # fmt: skip
    polhode = (
        ""
        if s["max_polhode_distance"] is None
        else f" and {s['max_polhode_distance']:.3g} rad/s from its exact polhode"
    )
    return (f"Against the exact motion from the first sample, ω is at most "
            f"{s['max_omega_error']:.3g} rad/s off{polhode}; the energy changes by up to "
            f"{s['max_energy_error']:.3g} (relative); {family}{flips}.")  # fmt: skip


def table_of(rows) -> list[str]:
    """One row per file: the largest errors side by side (the columns of its kind)."""
    free = rows[0][1].kind == "free body"
    head = ("file", "max|Δω| rad/s", "max|ΔQ|", "max|QᵀQ−I|")
    head += (("energy", "|L|", "polhode rad/s", "family", "flips") if free
             else ("θ rad", "ψ rad", "φ rad"))  # fmt: skip
    body = []
    for path, g in rows:
        s = g.summary()

        def e(key, s=s):
            v = s.get(key)
            return "—" if v is None else f"{v:.2e}"

        row = (Path(path).name, e("max_omega_error"), e("max_attitude_error"),
               e("max_orthogonality_error"))  # fmt: skip
        if free:
            fam = "kept" if s["family_kept"] else f"left at {s['family_left_at']:.3g} s"
            row += (e("max_energy_error"), e("max_momentum_error"), e("max_polhode_distance"),
                    fam, f"{s['flips']}/{s['exact_flips']}")  # fmt: skip
        else:
            row += (e("max_theta_error"), e("max_psi_error"), e("max_phi_error"))
        body.append(row)
    widths = [max(len(r[k]) for r in (head, *body)) for k in range(len(head))]
    fmt = "  ".join(f"{{:{w}s}}" for w in widths)
    return [fmt.format(*r).rstrip() for r in (head, tuple("-" * w for w in widths), *body)]


def run_grade(args) -> int:
    from .commands import EXIT_OK, say

    kind, ref = _reference(args)
    rows = [(path, _grade_one(path, args, kind, ref)[1]) for path in args.logs]
    if args.out:
        _write(Path(args.out), args, rows[0][0], rows[0][1], kind)
        args.written = Path(args.out)
    if args.json:
        print(json.dumps({str(p): g.summary() for p, g in rows}, indent=2))
        return EXIT_OK
    if len(rows) == 1:
        for line in lines_of(rows[0][1], rows[0][0]):
            say(args, line)
    else:
        say(args, f"{len(rows)} {kind} trajectories graded against the exact motion from "
                   "each file's first sample")  # fmt: skip
        for line in table_of(rows):
            say(args, line)
    if args.out:
        say(args, f"wrote {args.out}/ (report.html, grade.json, errors.png"
                   + (", polhode.png)" if kind == "free body" else ")"))  # fmt: skip
    sys.stdout.flush()
    return EXIT_OK


def _write(out, args, path, grade, kind):
    import matplotlib

    matplotlib.use("Agg")
    from .._io import OutputFolder, atomic_write_text
    from ..viz.grade import write_grade_report_folder

    folder = OutputFolder(out, force=args.force, command="grade", needs_bytes=5_000_000)
    with folder.writing() as work:
        name = Path(path).name
        summary = {
            "scenario": {"name": name, "description": f"{name} against the exact {kind}'s motion"},
            "grade": grade.summary(),
            "lead": lead_of(grade),
        }
        write_grade_report_folder(work, grade, summary)
        atomic_write_text(work / "grade.json", json.dumps(summary, indent=2))
