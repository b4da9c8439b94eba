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
