"""A run relative to a carrier: the relative angular velocity, energy and hodograph."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..._io import atomic_path
from .base import Run, jsonable, png_images, pyplot, scenario_header, shown, wrote_line

__all__ = ["RelativeRun", "carrier_only_note", "summarize_relative"]


class RelativeRun(Run):
    """A :class:`~poinsot.app.scenario.RelativeScenario` (``[carrier]``); writes relative.csv
    (the report's quantities), relative.npz and relative.nc (every field of the motion, with
    frames and units: :meth:`~poinsot.relative.RelativeTrajectory.variables`), relative.png,
    hodograph.png (when the transport moment is balanced) and report.html."""

    def simulate(self, progress=None):
        self.result = self.scenario.simulate(progress=progress)

    def summarise(self):
        return summarize_relative(self.scenario, self.result)

    def write_data(self, folder, summary):
        _relative_csv(folder / "relative.csv", self.result)
        self.result.to_npz(folder / "relative.npz")
        self.result.to_netcdf(folder / "relative.nc")

    def figures(self, folder, *, for_report):
        scenario, sol = self.scenario, self.result
        pyplot()
        from ...viz.relative import plot_hodograph, plot_relative_motion

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
        return png_images(figures, folder)

    report_links = ("summary.json", "relative.csv", "relative.npz", "relative.nc")

    def write_report(self, path, summary, images, *, plotlyjs="inline"):
        from ...viz.report import write_relative_report

        write_relative_report(path, summary, images, self.report_links)

    def terminal_lines(self, summary, out):
        lines = [f"  carrier: {summary['carrier']['description']}"]
        for name, (value, unit, _) in summary["table"].items():
            text = shown(value, ".6g", unit=unit or "", none=_NONE.get(name, "none"))
            lines.append(f"  {name}: {text}".rstrip())
        lines.append(wrote_line(out))
        return lines


#: What the terminal says of a table's value that the library returned as none (NaN, None):
#: the drift relative to T_r(0) = 0, the ratio over no samples (:func:`summarize_relative`).
_NONE = {
    "relative energy drift": "none (relative to T_r(0) = 0)",
    "max|ω_r| / min|ω_r|": "none (no samples)",
}


def carrier_only_note(sol) -> str:
    """A sentence when the body does not turn in space (its absolute |ω| stays at round-off
    beside the relative one): its relative motion is then the carrier's, seen backwards."""
    absolute = float(np.linalg.norm(sol.omega_absolute, axis=1).max())
    relative = float(np.linalg.norm(sol.omega_r, axis=1).max())
    if relative > 0 and absolute <= 1e-9 * relative:
        return (
            f" The body does not turn in space (max |ω| absolute = {absolute:.1g} rad/s, "
            f"max |ω_r| = {relative:.3g} rad/s): the carrier turns under it, and its whole "
            "relative motion is the carrier's motion seen backwards, ω_r = −Q_rᵀ ω_e; the "
            "transport and Coriolis moments are what that change of frame looks like."
        )
    return ""


def summarize_relative(scenario, sol) -> dict:
    """The numbers of a motion relative to ``[carrier]``, JSON-ready, with a ``table`` of
    ``name → (value, unit, meaning)`` for the report and the terminal."""
    c = scenario.carrier
    E = sol.relative_energy
    drift = float(np.ptp(E) / abs(E[0])) if E[0] != 0 else None
    ratio, bound = sol.hodograph_ratio(), sol.hodograph_bound()
    table = _relative_table(scenario, sol, drift, ratio, bound)
    energy = {"initial": float(E[0]), "min": float(E.min()), "max": float(E.max())}
    balanced = {}  # conservation (17) and the bound (18) hold only in case (16)
    if c["balance_transport"]:
        energy["relative_drift"] = drift
        balanced["hodograph"] = {"ratio": ratio, "bound_sqrt_C_over_A": bound}
    return jsonable(
        {
            "scenario": scenario_header(scenario),
            "carrier": _carrier_summary(c),
            "lead": (
                "Integrated in the carrier frame with the compact relative Euler equation "
                "(11)–(12)"
                + ("; the transport moment is balanced (16)." if c["balance_transport"] else ".")
                + carrier_only_note(sol)
            ),
            "body": scenario.body.mass_properties(),
            "relative_energy": energy,
            **balanced,
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


def _carrier_summary(c) -> dict:
    """The ``carrier`` entry of the summary: the carrier's motion in words and as given."""
    rotation = ", ".join(str(v) for v in c["rotation"])
    description = f"{c['given']} = ({rotation})" + (
        f", origin acceleration ({', '.join(str(v) for v in c['origin_acceleration'])}) m/s²"
        if c["origin_acceleration"] is not None
        else ""
    )
    return {
        "description": description,
        "given": c["given"],
        "rotation": [str(v) for v in c["rotation"]],
        "origin_acceleration": None
        if c["origin_acceleration"] is None
        else [str(v) for v in c["origin_acceleration"]],
        "balance_transport": c["balance_transport"],
        "hold_com": c["hold_com"],
    }


def _relative_table(scenario, sol, drift, ratio, bound) -> dict:
    """The summary's ``table``, ``name → (value, unit, meaning)``: moments, |ω_r|, the relative
    energy, and (when the transport moment is balanced) its drift and the hodograph's ratio."""
    from ...relative import planar_principal_moments

    E = sol.relative_energy
    moments = np.asarray(scenario.body.principal_moments, float)
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
        "max |ω| absolute": (
            float(np.linalg.norm(sol.omega_absolute, axis=1).max()),
            "rad/s",
            "the body's angular velocity in space (inertial frame)",
        ),
        "relative energy T_r(0)": (float(E[0]), "J", "½ ω_r·Jω_r"),
        "relative energy at the end": (float(E[-1]), "J", ""),
    }
    if scenario.carrier["balance_transport"]:
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
    return table


def _relative_csv(path: Path, sol):
    """t, ω_r, ω_absolute (body), Euler angles of Q_r, T_r, |M_e|, |M_c|, with units."""
    cols = [sol.t[:, None], sol.omega_r, sol.omega_absolute, sol.euler_angles(),
            sol.relative_energy[:, None], np.linalg.norm(sol.transport_moment, axis=1)[:, None],
            np.linalg.norm(sol.coriolis_moment, axis=1)[:, None]]  # fmt: skip
    header = ("t [s],omega_r_x [rad/s],omega_r_y [rad/s],omega_r_z [rad/s],"
              "omega_abs_x [rad/s],omega_abs_y [rad/s],omega_abs_z [rad/s],"
              "psi [rad],theta [rad],phi [rad],relative_energy [J],"
              "transport_moment_magnitude [N m],coriolis_moment_magnitude [N m]")  # fmt: skip
    with atomic_path(path) as tmp:
        np.savetxt(tmp, np.hstack(cols), delimiter=",", header=header, comments="", fmt="%.17g")
