"""The command line as a new user meets it (issue 27): units on every number it prints, the
refusals naming what the user can set, aligned listings, no stray warnings, words that say what
happens, and the files it promises."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from poinsot.app.cli import main

SCENARIOS = Path(__file__).resolve().parents[2] / "src" / "poinsot" / "app" / "scenarios"


def test_polhodes_of_a_sphere_warns_of_nothing(tmp_path, capsys):
    assert main(["polhodes", "--moments", "1", "1", "1", "--omega0", "0", "0", "1", "--out",
                 str(tmp_path / "p")]) == 0  # fmt: skip
    captured = capsys.readouterr()
    assert "warning" not in captured.err and "No artists" not in captured.err
    assert "between flips" not in captured.out and "flip" not in captured.out


def test_polhodes_tells_a_wobble_from_a_flip(tmp_path, capsys):
    assert main(["polhodes", "--moments", "1", "2", "3", "--omega0", "0.01", "0", "1",
                 "--out", str(tmp_path / "a")]) == 0  # fmt: skip
    wobble = capsys.readouterr().out
    assert "nothing flips" in wobble and "time between flips" not in wobble
    assert main(["polhodes", "--moments", "1", "2", "3", "--omega0", "0.001", "1", "0.001",
                 "--out", str(tmp_path / "b")]) == 0  # fmt: skip
    flip = capsys.readouterr().out
    assert "the body flips" in flip
    data = json.loads((tmp_path / "b" / "polhodes.json").read_text())
    assert data["flips"] is True and data["units"]["flip_interval"] == "s"


def test_polhodes_prints_rounded_numbers_with_units(tmp_path, capsys):
    assert main(["polhodes", "--moments", "1", "2", "3", "--omega0", "0.01", "0", "1",
                 "--out", str(tmp_path / "p")]) == 0  # fmt: skip
    out = capsys.readouterr().out
    assert not re.search(r"\d\.\d{8,}", out), out  # 3.0000833321759584 no more
    for line in out.splitlines():
        if re.search(r":\s*-?\d", line) and "fixed points" not in line:
            assert re.search(r"\d (J|s|kg·m²/s|kg·m²)\b", line), line
    data = json.loads((tmp_path / "p" / "polhodes.json").read_text())
    assert data["momentum"] == pytest.approx(np.sqrt(0.01**2 + 9), rel=1e-15)  # raw in JSON


def test_inertia_prints_units(capsys):
    assert main(["inertia", str(SCENARIOS / "notebook.toml")]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^mass\s+10 kg$", out, re.M)
    assert re.search(r"^centre of mass\s+\(0\.5, 1, 1\.5\) m$", out, re.M)
    assert re.search(r"^principal moments\s+\(8\.33333, 16\.6667, 21\.6667\) kg·m²$", out, re.M)
    assert "inertia about the centre of mass [kg·m²]" in out
    assert "e-17" not in out and "-0 " not in out and "-0)" not in out


def test_examples_are_listed_in_aligned_columns(capsys):
    assert main(["examples"]) == 0
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.strip()]
    starts = {re.match(r"\S+\s+", ln).end() for ln in lines}
    assert len(starts) == 1, starts  # every description starts in the same column
    assert any(len(ln.split()[0]) > 20 for ln in lines)  # names longer than the old 20 wide


_UNPHYSICAL = """name = "unphysical"
[body]
type = "mass_properties"
mass = 1.0
inertia = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0]]
{extra}
[initial]
omega = [0.0, 1.0, 0.1]
[time]
span = [0.0, 1.0]
samples = 11
[output]
figures = false
report = false
"""


def test_unphysical_moments_name_the_toml_key(tmp_path, capsys):
    path = tmp_path / "u.toml"
    path.write_text(_UNPHYSICAL.format(extra=""))
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "allow_unphysical = true" in err and "[body]" in err
    assert "allow_unphysical=True" not in err  # a Python keyword means nothing in a TOML file
    path.write_text(_UNPHYSICAL.format(extra="allow_unphysical = true"))
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 0
    assert "warning" in capsys.readouterr().err  # accepted, and said so
    assert main(["polhodes", "--moments", "1", "1", "3", "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err
    assert "--allow-unphysical" in err and "allow_unphysical=True" not in err
    assert main(["polhodes", "--moments", "1", "1", "3", "--allow-unphysical", "--out",
                 str(tmp_path / "p")]) == 0  # fmt: skip


def test_ensemble_writes_its_dataset_without_xarray(tmp_path, monkeypatch, capsys):
    from scipy.io import netcdf_file

    from poinsot.app.job import run_scenario
    from poinsot.app.scenario import load_example

    monkeypatch.setitem(sys.modules, "xarray", None)  # `import xarray` fails: a bare install
    scenario = load_example("tennis-racket-ensemble")
    scenario.ensemble["members"] = 40
    scenario.outputs["figures"] = False
    run_scenario(scenario, tmp_path / "o")
    with netcdf_file(tmp_path / "o" / "ensemble.nc", mmap=False) as f:
        assert f.variables["flip_interval"].shape == (40,)
        assert f.variables["exact_flip_interval"].units == b"s"
        measured = f.variables["flip_interval"][:].copy()
        exact = f.variables["exact_flip_interval"][:].copy()
    np.testing.assert_allclose(measured, exact, rtol=1e-6)
    assert 'href="ensemble.nc"' in (tmp_path / "o" / "report.html").read_text(encoding="utf-8")


def test_netcdf_reads_back_in_xarray(tmp_path):
    xr = pytest.importorskip("xarray")
    from poinsot import simulate
    from poinsot.models import notebook_body

    traj = simulate(notebook_body(), (0, 1), omega0=(0, 1, 1), t_eval=np.linspace(0, 1, 5))
    traj.to_netcdf(tmp_path / "t.nc")
    with xr.open_dataset(tmp_path / "t.nc") as ds:
        np.testing.assert_array_equal(ds["omega"].values, traj.omega)
        assert ds["omega"].attrs["units"] == "rad/s" and list(ds["axis"].values) == list("xyz")
        same = traj.to_xarray()
        np.testing.assert_array_equal(ds["total_energy"].values, same["total_energy"].values)


def test_turntable_says_what_happens(tmp_path, capsys):
    from poinsot.app.scenario import load_example

    scenario = load_example("turntable-spin-up")
    assert "tumbling" not in scenario.description and "keeps its attitude" in scenario.description
    assert main(["run", "--example", "turntable-spin-up", "--out", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    value, unit, _ = summary["table"]["max |ω| absolute"]
    assert value < 1e-12 and unit == "rad/s" and "max |ω| absolute" in out
    assert "does not turn in space" in summary["lead"]
    csv = np.genfromtxt(tmp_path / "o" / "relative.csv", delimiter=",", names=True)
    assert np.abs(csv["omega_abs_z_rads"]).max() < 1e-12  # the brick never moves
    assert np.abs(csv["omega_r_z_rads"]).max() > 1.0  # the table turns under it
    full = np.load(tmp_path / "o" / "relative.npz")  # every field, with frames and units
    np.testing.assert_array_equal(full["omega_r"][:, 2], csv["omega_r_z_rads"])
    np.testing.assert_array_equal(full["omega_absolute"][:, 2], csv["omega_abs_z_rads"])
    assert json.loads(str(full["attributes"]))["omega_r"]["frame"] == "body"
    assert (tmp_path / "o" / "relative.nc").exists()
    # no balancing moment: no conservation (17) nor bound (18) is claimed, anywhere
    assert "hodograph" not in summary and "relative_drift" not in summary["relative_energy"]
    assert "hodograph_bound" not in json.loads(str(full["summary"]))
    header = (tmp_path / "o" / "relative.csv").read_text().splitlines()[0]
    assert header.endswith("transport_moment_magnitude [N m],coriolis_moment_magnitude [N m]")


def test_a_balanced_carrier_run_reports_its_bound(tmp_path, capsys):
    assert main(["run", "--example", "hodograph-bound", "--out", str(tmp_path / "o")]) == 0
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    h = summary["hodograph"]
    assert 1 <= h["ratio"] <= h["bound_sqrt_C_over_A"]
    assert summary["relative_energy"]["relative_drift"] < 1e-8
    assert 'href="relative.npz"' in (tmp_path / "o" / "report.html").read_text(encoding="utf-8")


def _heavy_top(tmp_path, name, omega=None, euler=None, span=None, output=""):
    """The bundled heavy-top example, written to ``tmp_path/name.toml`` with its initial ω,
    its tilt (z-x-z Euler angles), its span or an ``[output]`` table changed."""
    from poinsot.app.scenario import example_text

    text = example_text("heavy-top")
    for old, new in (("omega = [0.0, 1.5, 100.0]", omega), ("euler = [0.0, 0.6, 0.0]", euler),
                     ("span = [0.0, 6.0]", span)):  # fmt: skip
        if new is not None:
            assert old in text
            text = text.replace(old, new)
    path = tmp_path / f"{name}.toml"
    path.write_text(text + (f"\n[output]\n{output}\n" if output else ""), encoding="utf-8")
    return path


# A heavy top in each regime where the library returns a rate that is none or infinite:
# (initial ω, tilt, the summary's key and value there, what the terminal says of it)
_TOP_REGIMES = {
    "too-slow": ("omega = [0, 1.5, 5]", None, "steady_precession_rate_slow", None,
                 "steady at the mean θ: none (the top spins too slowly"),
    "no-spin": ("omega = [0, 0, 0]", None, "gyroscopic_precession_rate", "inf",
                "gyroscopic estimate M g l/(C ω·a) ∞ rad/s"),
    "sleeping": ("omega = [0, 0, 100]", "euler = [0.0, 0.0, 0.0]", "mean_precession_rate", None,
                 "mean precession none (ψ is undefined with the axis on the vertical)"),
}  # fmt: skip


@pytest.mark.parametrize("regime", list(_TOP_REGIMES))
def test_heavy_tops_in_every_regime_print_what_the_library_returned(regime, tmp_path, capsys):
    omega, euler, key, value, said = _TOP_REGIMES[regime]
    path = _heavy_top(tmp_path, regime, omega=omega, euler=euler, span="span = [0.0, 2.0]",
                      output="figures = false\nreport = false")  # fmt: skip
    out = tmp_path / "o"
    assert main(["run", str(path), "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and "error" not in captured.err, captured.err
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert summary["top"][key] == value  # the library's value, as summary.json holds it
    lines = captured.out.splitlines()
    top = [ln for ln in lines if "heavy top:" in ln or "predicted precession:" in ln]
    assert len(top) == 2 and said in captured.out, captured.out
    for line in lines:
        assert not re.search(r"\b(None|nan|inf)\b", line), line
    assert lines[-1] == f"  wrote {out}/ (summary.json, trajectory.npz/.csv/.nc)"
    assert not re.search(r"\bnan\b", summary["lead"]), summary["lead"]
    assert main(["run", str(path), "--out", str(out), "--force", "--quiet"]) == 0
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == ""


@pytest.mark.parametrize(
    ("output", "listed"),
    [
        ("figures = false\nreport = false", "summary.json, trajectory.npz/.csv/.nc"),
        ("data = false\nreport = false", "summary.json, 6 PNG figures"),
        ("data = false\nfigures = false", "summary.json, report.html"),
    ],
)
def test_run_lists_only_the_files_it_wrote(output, listed, tmp_path, capsys):
    path = _heavy_top(tmp_path, "top", span="span = [0.0, 1.0]", output=output)
    out = tmp_path / "o"
    assert main(["run", str(path), "--out", str(out)]) == 0
    wrote = capsys.readouterr().out.splitlines()[-1]
    assert wrote == f"  wrote {out}/ ({listed})", wrote
    files = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    if "figures" in output:  # no figure is written, and none is named
        assert not any(f.endswith(".png") for f in files) and ".png" not in wrote
    if "data" in output:
        assert not any(f.startswith("trajectory") for f in files)
    if "report" in output:
        assert "report.html" not in files


def _every_float(obj, value):
    """``obj`` (a summary) with every float replaced by ``value``."""
    if isinstance(obj, dict):
        return {k: _every_float(v, value) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_every_float(v, value) for v in obj]
    return value if isinstance(obj, float) else obj


@pytest.mark.parametrize("name", ["heavy-top", "notebook", "atwood", "turntable-spin-up",
                                  "tennis-racket-ensemble"])  # fmt: skip
def test_terminal_lines_show_any_value_the_library_returns(name, tmp_path):
    """Every kind of run prints a summary whose numbers are all None, ±inf (as JSON holds
    them, or as floats) or NaN: without failing, and without Python's words for them."""
    from poinsot.app.job import run_scenario
    from poinsot.app.runs import run_for
    from poinsot.app.scenario import load_example

    scenario = load_example(name)
    scenario.outputs.update(figures=False, report=False)
    if getattr(scenario, "ensemble", None):
        scenario.ensemble["members"] = 40
    out = tmp_path / "o"
    summary = run_scenario(scenario, out)
    for value in (None, "inf", "-inf", float("inf"), float("nan")):
        lines = run_for(scenario).terminal_lines(_every_float(summary, value), out)
        assert lines and lines[-1].startswith(f"  wrote {out}/ (summary.json"), lines
        for line in lines:
            assert not re.search(r"\b(None|nan|inf)\b", line), (value, line)
    if name == "heavy-top":
        assert "∞ rad/s" in "\n".join(run_for(scenario).terminal_lines(
            _every_float(summary, "inf"), out))  # fmt: skip


@pytest.mark.parametrize("error", [TypeError, ValueError])
def test_a_failure_after_the_output_is_written_says_it_is_there(error, tmp_path, capsys,
                                                                 monkeypatch):  # fmt: skip
    from poinsot.app.runs.rigid import RigidRun

    def fail(self, summary, out):
        raise error("a bug in printing")

    monkeypatch.setattr(RigidRun, "terminal_lines", fail)
    path = _heavy_top(tmp_path, "top", span="span = [0.0, 1.0]", output="figures = false")
    out = tmp_path / "o"
    assert main(["run", str(path), "--out", str(out)]) == 70  # a bug, not bad input
    err = capsys.readouterr().err
    assert f"internal error: {error.__name__}: a bug in printing" in err
    assert "no partial output" not in err and f"{out}/ had been written in full" in err
    assert (out / "summary.json").exists() and (out / "report.html").exists()
