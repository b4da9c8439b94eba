"""A heavy top's run as its reader gets it: every number of summary.json with its unit, the
top's symmetry axis named a (never e₃, which is another axis for an x-axis top), the axis
traced from the tip towards the centre of mass, a top whose body is a sphere about its centre
of mass run to the end; and ``poinsot grade`` naming its own options when it refuses them."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from poinsot.app.cli import main
from poinsot.viz.numbers import rows_of

EXAMPLES = Path(__file__).resolve().parents[2] / "src" / "poinsot" / "app" / "scenarios"

#: A top whose symmetry axis is body x (e₁ about G: A_G = 0.05 < 0.2), under tilted gravity.
XTOP = """name = "xtop"
[body]
type = "mass_properties"
mass = 2.0
inertia = [[0.05, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.2]]
center_of_mass = [0.3, 0.1, -0.2]
pivot = [0.0, 0.1, -0.2]
[[forces]]
type = "gravity"
g = [1.0, -2.0, -9.0]
[initial]
omega = [20.0, 0.5, -0.3]
orientation = { euler = [0.3, 0.4, 0.2], seq = "ZXZ" }
[integrator]
method = "exact-splitting4"
dt = 0.01
[time]
span = [0.0, 1.0]
samples = 101
[output]
figures = false
report = false
"""


def _run(tmp_path, name, text, capsys=None):
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / name
    assert main(["run", str(path), "--out", str(out)]) == 0
    printed = capsys.readouterr().out if capsys is not None else ""
    return json.loads((out / "summary.json").read_text(encoding="utf-8")), out, printed


@pytest.fixture(scope="module")
def heavy_top(tmp_path_factory):
    out = tmp_path_factory.mktemp("top") / "h"
    assert main(["run", "--example", "heavy-top", "--out", str(out), "--quiet"]) == 0
    return json.loads((out / "summary.json").read_text(encoding="utf-8"))


#: Numbers of a heavy top's summary whose unit is not in the ``units`` map, and why: counts,
#: and the two drifts whose unit the library does not state (relative, or absolute where the
#: reference is zero).
NO_UNIT = {
    "body.particles",
    "integration.samples",
    "integration.nfev",
    "integration.nsteps",
    "top.singular_samples",
    "integration.diagnostics.energy_drift",
    "integration.diagnostics.momentum_drift",
}


def _numbers(node, path=""):
    """The key paths of ``node`` that hold a number or a list of numbers."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _numbers(value, f"{path}.{key}" if path else key)
    elif isinstance(node, bool):
        return
    elif isinstance(node, int | float) or (
        isinstance(node, list) and node and all(isinstance(x, int | float | list) for x in node)
    ):
        yield path


def test_every_number_of_a_heavy_top_has_its_unit(heavy_top):
    units = heavy_top["units"]
    for key, unit in {
        "top.length": "m",
        "top.axis": "1",
        "top.nutation_amplitude": "rad",
        "top.exact.theta_min": "rad",
        "top.exact.theta_max": "rad",
        "top.exact.nutation_period": "s",
        "top.exact.mean_precession_rate": "rad/s",
        "top.exact.max_theta_error": "rad",
        "top.exact.max_psi_error": "rad",
        "top.exact.max_phi_error": "rad",
        "integration.mass": "kg",
        "integration.principal_moments": "kg·m²",
    }.items():
        assert units.get(key) == unit, key
    for name, entry in heavy_top["integration"]["diagnostics"]["invariants"].items():
        path = f"integration.diagnostics.invariants.{name}"  # the unit its entry carries
        assert units[f"{path}.initial"] == units[f"{path}.max_change"] == entry["unit"]
        assert units[f"{path}.max_relative_change"] == "1"
    numbers = list(_numbers({k: v for k, v in heavy_top.items() if k != "units"}))
    assert len(numbers) > 40 and "top.exact.max_phi_error" in numbers  # the walk sees them
    missing = [path for path in numbers if path not in units and path not in NO_UNIT]
    assert not missing, f"numbers without a unit: {missing}"


def test_the_closed_form_numbers_are_shown_once_with_their_units(heavy_top):
    rows = rows_of(heavy_top)
    shown = {(name, unit): value for _, name, value, unit in rows}
    exact = heavy_top["top"]["exact"]
    assert shown[("nutation period", "s")] == exact["nutation_period"]
    assert (
        shown[("max |ψ − ψ_exact| against the closed-form top", "rad")] == (exact["max_psi_error"])
    )
    # integration.mass and .principal_moments are the body's: in units, not twice in the table
    assert [n for _, n, _, _ in rows].count("mass") == 1


def test_the_symmetry_axis_is_named_a_in_the_summary_the_lead_and_the_terminal(tmp_path, capsys):
    summary, _, printed = _run(tmp_path, "xtop", XTOP, capsys)
    rows = {name: value for _, name, value, _ in rows_of(summary)}
    for text in (summary["lead"], printed, *rows):
        assert "ω₃" not in text, text  # ω₃ would read as ω·e₃, here a transverse component
    assert "ω·a = 20 rad/s about its symmetry axis a" in summary["lead"]
    assert "gyroscopic estimate M g l/(C ω·a)" in printed
    assert rows["spin ω·a about the symmetry axis a"] == pytest.approx(20.0)
    assert any(n.startswith("principal axes e₁, e₂, e₃ about the centre of mass G") for n in rows)
    assert summary["body"]["principal_moments"][0] == pytest.approx(0.05)  # e₁ = x
    assert summary["top"]["axis"] == [1.0, 0.0, 0.0]  # a: body x, e₁ about G, not e₃
    assert rows["symmetry axis a, from the tip to the centre of mass (body frame)"] == [1, 0, 0]


def test_the_axes_about_the_pivot_are_listed_by_their_own_names(tmp_path):
    """e₁ᴾ, e₂ᴾ, e₃ᴾ, which the ω plot of a pivoted body uses, are in the table, with the
    moments about P and the pivot where the trajectory puts it in space."""
    summary, out, _ = _run(tmp_path, "xtop", XTOP)
    rows = {name: value for _, name, value, _ in rows_of(summary)}
    E = np.array(rows["principal axes e₁ᴾ, e₂ᴾ, e₃ᴾ about P (columns, body frame)"])
    moments = rows["principal moments about P, ascending (along e₁ᴾ, e₂ᴾ, e₃ᴾ)"]
    assert abs(E[:, 0] @ summary["top"]["axis"]) == pytest.approx(1.0)  # e₁ᴾ = ±a
    assert moments[0] == pytest.approx(summary["top"]["C"]) and moments[1] == pytest.approx(
        summary["top"]["A"]
    )
    assert rows["P (reference frame of the body's definition)"] == [0.0, 0.1, -0.2]
    attributes = json.loads(str(np.load(out / "trajectory.npz")["attributes"]))
    position = attributes["angular_momentum_pivot"]["pivot_position"]
    assert rows["P in space (fixed)"] == position
    assert summary["units"]["pivot.position"] == "m"


def test_a_top_that_is_a_sphere_about_its_centre_of_mass_runs_to_the_end(tmp_path, capsys):
    """Symmetric about its tip, spherical about G: its axis is a, which the body alone has
    not (the run had stopped with "the body is spherical: it has no single symmetry axis")."""
    text = (XTOP.replace("[[0.05, 0.0, 0.0], [0.0, 0.2, 0.0]", "[[0.2, 0.0, 0.0], [0.0, 0.2, 0.0]")
            .replace("figures = false", "figures = true"))  # fmt: skip
    summary, out, _ = _run(tmp_path, "sphere", text, capsys)
    assert summary["body"]["symmetry"] == "spherical"
    assert summary["top"]["axis"] == [1.0, 0.0, 0.0]
    assert (out / "axis_trace.png").is_file() and (out / "attitude.png").is_file()


def test_the_traced_axis_points_from_the_tip_to_the_centre_of_mass(tmp_path, monkeypatch):
    """A top hanging below its tip (a = −z): the trace points down, as its θ > π/2 says; the
    body's symmetry axis about G (+z) points up, and had been drawn as a."""
    import poinsot.viz.trajectory as T

    traced = []
    original = T.plot_axis_trace

    def spy(trace, **kwargs):
        traced.append(np.array(trace))
        return original(trace, **kwargs)

    monkeypatch.setattr(T, "plot_axis_trace", spy)
    text = (EXAMPLES / "heavy-top.toml").read_text(encoding="utf-8")
    for old, new in (("pivot = [0.0, 0.0, -0.5]", "pivot = [0.0, 0.0, 0.5]"),
                     ("span = [0.0, 6.0]", "span = [0.0, 0.5]")):  # fmt: skip
        assert old in text
        text = text.replace(old, new)
    summary, _, _ = _run(tmp_path, "hanging", text + "\n[output]\nreport = false\n")
    top = summary["top"]
    assert top["theta_min"] > np.pi / 2  # a below the horizontal all along
    (trace,) = traced
    up = trace[:, 2]  # a·up, up = +z: cos θ
    assert up.max() < 0
    assert np.cos(top["theta_max"]) - 1e-9 <= up.min() and up.max() <= np.cos(top["theta_min"])
    assert top["axis"] == [0.0, 0.0, -1.0]


# --------------------------------------------------------------------------- poinsot grade
@pytest.fixture(scope="module")
def top_log(tmp_path_factory):
    from poinsot import Gravity, RigidBody, simulate
    from poinsot.tops import heavy_top

    body = RigidBody(2.0, np.diag([0.05, 0.2, 0.2]), (0.3, 0.1, -0.2))
    # up = −g/|g| with no negative component: argparse takes "-2e-301" for an option
    pivot, gravity = (0.0, 0.1, -0.2), Gravity((-1.0, -2.0, -9.0))
    traj = simulate(body, (0, 0.5), omega0=(20.0, 0.5, -0.3), pivot=pivot, forces=[gravity],
                    Q0=[[0.0, -1.0, 0.0], [0.6, 0.0, -0.8], [0.8, 0.0, 0.6]],
                    t_eval=np.linspace(0, 0.5, 51), rtol=1e-11, atol=1e-12)  # fmt: skip
    path = tmp_path_factory.mktemp("grade") / "xtop.npz"
    np.savez(path, t=traj.t, omega=traj.omega, Q=traj.Q)
    top = heavy_top(body, pivot, [gravity])
    return str(path), [repr(top.A), repr(top.C), repr(top.mgl)], top


@pytest.mark.parametrize(("option", "values", "said"), [
    ("--up", ["inf", "0", "1"], "--up: expected three finite numbers, found [inf, 0.0, 1.0]"),
    ("--axis", ["nan", "0", "1"], "--axis: expected three finite numbers"),
    ("--up", ["0", "0", "0"], "--up: expected a non-zero direction"),
])  # fmt: skip
def test_grade_refuses_a_direction_naming_its_option(top_log, capsys, option, values, said):
    path, top, _ = top_log
    assert main(["grade", path, "--top", *top, option, *values]) == 2
    err = capsys.readouterr().err
    assert said in err and "HeavyTop" not in err and "warning" not in err, err


def test_grade_refuses_an_infinite_moment_naming_top(top_log, capsys):
    path, top, _ = top_log
    assert main(["grade", path, "--top", "inf", *top[1:]]) == 2
    err = capsys.readouterr().err
    assert "--top: A, C and M g l must be positive and finite, found inf" in err, err
    assert "HeavyTop" not in err


def test_grade_takes_a_direction_at_any_scale(top_log, capsys):
    """``1e308 …`` and ``1e-300 …`` are directions like any other: no square overflows to
    inf (the up vector had come out of length 0) nor underflows to 0 (refused as zero)."""
    path, top, exact = top_log
    graded = []
    for scale in (1.0, 1e308 / np.abs(exact.up).max(), 1e-300 / np.abs(exact.up).max()):
        up = [repr(float(x * scale)) for x in exact.up]
        axis = [repr(float(x * min(scale, 1e300))) for x in exact.axis]
        assert main(["grade", path, "--top", *top, "--axis", *axis, "--up", *up, "--json"]) == 0
        graded.append(json.loads(capsys.readouterr().out)[path])
    assert graded[0]["max_omega_error"] < 1e-6  # the right top: graded at its tolerance
    for other in graded[1:]:
        assert other["max_omega_error"] == pytest.approx(graded[0]["max_omega_error"], rel=1e-6,
                                                         abs=1e-12)  # fmt: skip
    assert not re.search(r"warning", capsys.readouterr().err)
