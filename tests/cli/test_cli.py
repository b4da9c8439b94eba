"""The `poinsot` command line: runs, examples, inertia, polhodes, bad input, interrupts."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bounded import deadline
from poinsot.app.cli import main
from poinsot.app.scenario import list_examples
from scenario_texts import BOX_SCENARIO

ROOT = Path(__file__).resolve().parents[2]


def _poinsot(*args, cwd, timeout=300):
    return subprocess.run(
        [sys.executable, "-m", "poinsot.app.cli", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def test_run_without_arguments_in_an_empty_folder(tmp_path):
    res = _poinsot("run", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    out = tmp_path / "poinsot-out" / "notebook"
    expected = {
        "summary.json",
        "trajectory.npz",
        "trajectory.csv",
        "omega.png",
        "conservation.png",
        "center_of_mass.png",
        "body.png",
        "polhodes.png",
        "report.html",
    }
    assert expected <= {p.name for p in out.iterdir()}
    assert not [p for p in tmp_path.rglob(".*partial*")]
    summary = json.loads((out / "summary.json").read_text())
    # the same problem through the library API
    from poinsot import Gravity, simulate
    from poinsot.models import notebook_body
    from poinsot.torquefree import FreeRigidBody

    body = notebook_body()
    traj = simulate(
        body,
        (0, 20),
        omega0=(0, 1, 1),
        forces=[Gravity((0, 0, -9.8))],
        method="rk4",
        dt=0.2,
        t_eval=np.linspace(0, 20, 101),
    )
    np.testing.assert_allclose(
        summary["body"]["principal_moments"], body.principal_moments, rtol=1e-14
    )
    np.testing.assert_allclose(summary["final"]["R"], traj.R[-1], rtol=1e-14)
    np.testing.assert_allclose(summary["final"]["omega"], traj.omega[-1], rtol=1e-14)
    d = summary["integration"]["diagnostics"]
    assert d["energy_drift"] == pytest.approx(traj.diagnostics()["energy_drift"], rel=1e-12)
    free = FreeRigidBody.from_body(body)
    assert summary["torque_free"]["period"] == pytest.approx(free.period((0, 1, 1)), rel=1e-14)
    data = np.load(out / "trajectory.npz")
    # the scenario's grid lists the particles in another order: sums round differently
    np.testing.assert_allclose(data["omega"], traj.omega, rtol=1e-12, atol=1e-14)
    # the README's command runs twice: the second run writes to a fresh sibling and says so
    before = out.stat().st_mtime_ns
    again = _poinsot("run", cwd=tmp_path)
    assert again.returncode == 0 and "wrote poinsot-out/notebook-2/" in again.stdout
    assert (tmp_path / "poinsot-out" / "notebook-2" / "summary.json").is_file()
    assert out.stat().st_mtime_ns == before  # the first run's folder is untouched
    assert _poinsot("run", "--quiet", cwd=tmp_path).returncode == 0
    assert (tmp_path / "poinsot-out" / "notebook-3").is_dir()
    # an explicit --out keeps the rule: an existing folder is not overwritten without --force
    again = _poinsot("run", "--out", str(out), cwd=tmp_path)
    assert again.returncode == 2 and "output folder exists" in again.stderr
    assert _poinsot("run", "--force", "--quiet", cwd=tmp_path).returncode == 0
    assert not (tmp_path / "poinsot-out" / "notebook-4").exists()


def test_version_and_module_entry_point(tmp_path):
    from poinsot import __version__

    done = subprocess.run([sys.executable, "-m", "poinsot", "--version"], capture_output=True,
                          text=True, cwd=tmp_path)  # fmt: skip
    assert done.returncode == 0 and done.stdout.strip() == f"poinsot {__version__}"


def test_examples_show_prints_a_loadable_template(tmp_path, capsys):
    from poinsot.app.scenario import load_scenario

    assert main(["examples", "--show", "heavy-top"]) == 0
    text = capsys.readouterr().out
    assert load_scenario(text).name == "heavy-top"
    assert main(["examples", "--show", "heavy-topp"]) == 2
    assert "did you mean 'heavy-top'" in capsys.readouterr().err


@pytest.mark.parametrize("name", sorted(list_examples()))
def test_every_bundled_example_runs(name, tmp_path):
    assert main(["run", "--example", name, "--out", str(tmp_path / name), "--quiet"]) == 0
    summary = json.loads((tmp_path / name / "summary.json").read_text())
    assert summary["scenario"]["name"] == name
    assert (tmp_path / name / "report.html").stat().st_size > 100_000


def test_examples_listing(capsys):
    assert main(["examples"]) == 0
    out = capsys.readouterr().out
    for name in ("notebook", "tennis-racket", "heavy-top"):
        assert name in out


def test_json_output(tmp_path, capsys):
    assert main(["run", "--example", "tennis-racket", "--out", str(tmp_path / "o"), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["torque_free"]["flip_interval"] == pytest.approx(3.3357687, abs=1e-6)


GOOD = "\n" + BOX_SCENARIO


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("name = 't'\n[body\n", "TOML syntax error"),
        (
            GOOD.replace("[time]", "[time]\nspam = 1"),
            r"time\.spam: unknown key; did you mean 'span'",
        ),
        (GOOD.replace("mass = 1.0", "mas = 1.0"), r"body\.mas: unknown key; did you mean 'mass'"),
        (
            GOOD.replace("size = [1.0, 2.0, 3.0]", 'size = "big"'),
            r"body\.size: expected an array of 3 numbers, found 'big'",
        ),
        (
            GOOD.replace("mass = 1.0", "mass = -1"),
            r"body\.mass: expected a positive number, "
            r"found -1",
        ),
        (
            GOOD.replace(
                'type = "box"',
                'type = "particles"\n[[body.particles]]\nmass = 1\n'
                "position = [0, 0, 0]\n[[body.particles]]\nmass = -1\nposition = [1, 0, 0]",
            ).replace("mass = 1.0\nsize = [1.0, 2.0, 3.0]\n", ""),
            r"body\.particles\[1\]\.mass: expected a positive number, found -1",
        ),
        (
            GOOD.replace(
                "[initial]", "[initial]\norientation = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]"
            ),
            r"initial\.orientation: is not a rotation",
        ),
        (
            GOOD + "[analysis]\nenergy = 0.5\nmomentum = 100.0\n",
            r"analysis\.momentum: infeasible invariants .*: every motion has I1 ≤ a²/\(2k\) ≤ I3",
        ),
        (  # a² alone overflows (OverflowError in the parser before issue 26)
            GOOD + "[analysis]\nenergy = 0.5\nmomentum = 1e300\n",
            r"analysis\.momentum: infeasible invariants .* a²/\(2k\) = inf",
        ),
        (GOOD.replace('type = "box"', 'type = "boks"'), r"body\.type: .*did you mean 'box'"),
        (
            GOOD + '[integrator]\nmethod = "rk4"\n',
            r"integrator\.dt: required for the "
            r"fixed-step method 'rk4'",
        ),
        (
            GOOD + '[[forces]]\ntype = "gravity"\ng = [0, 0]\n',
            r"forces\[0\]\.g: expected an array of 3 numbers",
        ),
        (
            GOOD + '[ensemble]\nmembers = 0\ndistribution = "sphere"\nspeed = 1.0\n',
            r"ensemble\.members: expected a positive integer, found 0",
        ),
        (
            GOOD + '[ensemble]\nmembers = 10\ndistribution = "uniform"\n',
            r"ensemble\.distribution: expected one of 'sphere', 'gaussian'",
        ),
        (
            GOOD + '[ensemble]\nmembers = 10\ndistribution = "sphere"\n',
            r"ensemble\.speed: required key is missing",
        ),
        (
            GOOD + '[ensemble]\nmembers = 10\ndistribution = "gaussian"\nstd = [0.1, -1, 0]\n',
            r"ensemble\.std: expected numbers ≥ 0",
        ),
        (
            GOOD + '[ensemble]\nmembers = 10\ndistribution = "sphere"\nspeed = 1\nsed = 3\n',
            r"ensemble\.sed: unknown key.*seed",
        ),
        (
            GOOD
            + '[ensemble]\nmembers = 10\ndistribution = "sphere"\nspeed = 1\nstd = [1, 0, 0]\n',
            r"ensemble\.std: not used with distribution = 'sphere'; it belongs to 'gaussian'",
        ),
        (
            GOOD + '[ensemble]\nmembers = 10\ndistribution = "gaussian"\nstd = [1, 0, 0]\n'
            "speed = 3\n",
            r"ensemble\.speed: not used with distribution = 'gaussian'; it belongs to 'sphere'",
        ),
    ],
)
def test_malformed_scenarios_exit_2_naming_the_key(text, match, tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    code = main(["run", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2, err
    assert str(path) in err
    import re

    assert re.search(match, err), err
    assert not (tmp_path / "out").exists()


def test_numerical_failure_exit_1(tmp_path, capsys):
    path = tmp_path / "blowup.toml"
    path.write_text(
        GOOD.replace(
            "[initial]", '[[forces]]\ntype = "torque"\ntorque = [1e308, 1e308, 0]\n[initial]'
        )
    )
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 1
    assert "poinsot: numerical failure:" in capsys.readouterr().err
    path.write_text(path.read_text() + '[integrator]\nmethod = "rk4"\ndt = 0.1\n')
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 1
    assert "numerical failure: non-finite Q, omega at t = 0.1" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_inertia_command(tmp_path, capsys):
    path = tmp_path / "b.toml"
    path.write_text(GOOD)
    assert main(["inertia", str(path), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(info["principal_moments"], [5 / 12, 10 / 12, 13 / 12])
    assert info["units"]["principal_moments"] == "kg·m²" and info["units"]["mass"] == "kg"
    only_body = tmp_path / "only.toml"
    only_body.write_text('[body]\ntype = "sphere"\nmass = 2.0\nradius = 0.5\n')
    assert main(["inertia", str(only_body)]) == 0
    assert "spherical" in capsys.readouterr().out
    trimesh = pytest.importorskip("trimesh")
    stl = tmp_path / "box.stl"
    trimesh.creation.box(extents=(1, 2, 3)).export(stl)
    assert main(["inertia", str(stl), "--mass", "12", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(info["principal_moments"], [5, 10, 13], rtol=1e-12)
    assert main(["inertia", str(tmp_path / "none.stl")]) == 2


def test_polhodes_command(tmp_path, capsys):
    out = tmp_path / "p"
    assert (
        main(
            [
                "polhodes",
                "--moments",
                "1",
                "2",
                "3",
                "--omega0",
                "1e-3",
                "1",
                "1e-3",
                "--out",
                str(out),
                "--json",
            ]
        )
        == 0
    )
    result = json.loads(capsys.readouterr().out)
    assert result["flip_interval"] == pytest.approx(27.530840553733, rel=1e-12)
    assert (out / "polhodes.png").exists() and (out / "energy_ellipsoid.png").exists()
    assert main(["polhodes", "--moments", "1", "1", "3", "--out", str(tmp_path / "q")]) == 2
    assert "I1 + I2 ≥ I3" in capsys.readouterr().err


def test_polhodes_json_pairs_omega0_with_the_moments_it_lists(tmp_path, capsys):
    """Unsorted ``--moments``: ``omega0`` is listed along the sorted principal axes, as
    ``principal_moments`` are (the report labels it so), so that ½ Σ I ω² of the two lists is
    the energy; ``omega0_given`` is ω0 as given. ``--energy`` alone is reported too."""
    args = ["polhodes", "--moments", "3", "1", "2", "--omega0", "0.05", "0.1", "1", "--json"]
    assert main([*args, "--out", str(tmp_path / "a")]) == 0
    r = json.loads(capsys.readouterr().out)
    I, w = np.array(r["principal_moments"]), np.array(r["omega0"])
    assert r["omega0_given"] == [0.05, 0.1, 1.0]
    np.testing.assert_allclose(np.abs(w), [0.1, 1.0, 0.05], rtol=0, atol=0)
    assert 0.5 * I @ w**2 == pytest.approx(r["energy"], rel=1e-14)
    assert 0.5 * np.array([3, 1, 2]) @ np.array(r["omega0_given"]) ** 2 == pytest.approx(
        r["energy"], rel=1e-14
    )
    assert r["flips"]  # near the intermediate axis (body z, moment 2): the tennis racket
    base = ["polhodes", "--moments", "1", "2", "3", "--energy", "2", "--json"]
    assert main([*base, "--out", str(tmp_path / "b")]) == 0
    assert json.loads(capsys.readouterr().out)["energy"] == 2.0


def test_negative_numbers_in_scientific_notation_are_values(tmp_path, capsys):
    """``--omega0 -1e-3 …`` is three numbers, not an unknown option (Python 3.11's argparse
    reads only ``-2`` and ``-.5`` as negative numbers)."""
    out = tmp_path / "p"
    args = ["polhodes", "--moments", "1", "2", "3", "--omega0", "-1e-3", "-1", "-1E-3"]
    assert main([*args, "--out", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["flip_interval"] == pytest.approx(27.530840553733, rel=1e-12)
    with pytest.raises(SystemExit) as exit_:  # argparse's own exit: two numbers for three
        main(["polhodes", "--moments", "1", "2", "3", "--omega0", "-1e-3", "1"])
    assert exit_.value.code == 2 and "expected 3 arguments" in capsys.readouterr().err


def test_help_explains_every_option(capsys):
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    text = capsys.readouterr().out
    for option in ("--example", "--out", "--force", "--quiet", "--json", "SCENARIO"):
        assert option in text


def test_sigint_leaves_no_partial_files(tmp_path):
    slow = tmp_path / "slow.toml"
    slow.write_text(
        GOOD.replace("span = [0.0, 1.0]", "span = [0.0, 1e5]").replace(
            "samples = 5", "samples = 50000"
        )
        + '[integrator]\nmethod = "rkmk4"\ndt = 0.001\n'
    )
    proc = subprocess.Popen(
        [sys.executable, "-m", "poinsot.app.cli", "run", str(slow), "--out", str(tmp_path / "out")],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(4.0)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "interrupted" in err
    left = [p.name for p in tmp_path.iterdir()]
    assert sorted(left) == ["slow.toml"], left


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        for d in os.environ.get("PATH", "").split(os.pathsep):
            if (Path(d) / name).exists():
                return str(Path(d) / name)
    return None


def test_report_in_a_headless_browser(tmp_path):
    browser = _chromium()
    if browser is None:
        if os.environ.get("CI"):
            pytest.fail("CI must install Chromium (.ci/run) for the report test")
        pytest.skip("no Chromium on this machine")
    assert main(["run", "--example", "tennis-racket", "--out", str(tmp_path / "r"), "--quiet"]) == 0
    assert main(["run", "--example", "atwood", "--out", str(tmp_path / "a"), "--quiet"]) == 0
    page = (tmp_path / "r" / "report.html").as_uri()
    flags = [
        browser,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--window-size=1300,1500",
        "--virtual-time-budget=10000",
        "--enable-logging=stderr",
        "--v=0",
    ]
    shot = tmp_path / "shot.png"
    res = subprocess.run(
        [*flags, f"--screenshot={shot}", page], capture_output=True, text=True, timeout=180
    )
    console = [line for line in res.stderr.splitlines() if ":CONSOLE" in line]
    errors = [line for line in console if "Uncaught" in line or "Error" in line]
    assert not errors, errors
    dom = subprocess.run(
        [*flags, "--dump-dom", page], capture_output=True, text=True, timeout=180
    ).stdout
    for i in range(3):  # body, polhodes, time series: the containers exist and were drawn
        assert f'id="poinsot-plot-{i}"' in dom
    assert dom.count('class="main-svg"') >= 3
    assert "gl-container" in dom  # WebGL scenes were created
    assert dom.count('class="slider-container"') == 1 and "updatemenu-container" in dom
    mechanism = (tmp_path / "a" / "report.html").as_uri()
    res = subprocess.run([*flags, "--dump-dom", mechanism], capture_output=True, text=True,
                         timeout=180)  # fmt: skip
    errors = [line for line in res.stderr.splitlines()
              if ":CONSOLE" in line and ("Uncaught" in line or "Error" in line)]  # fmt: skip
    assert not errors, errors
    assert res.stdout.count('class="slider-container"') == 1  # the mechanism's slider, play
    assert "updatemenu-container" in res.stdout and "mass 1" in res.stdout
    import matplotlib.image as mpimg

    img = mpimg.imread(shot)[..., :3]
    plot3d = img[150:600, 60:1100]  # the animated 3D plot's area
    colors = np.unique((plot3d * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colors) > 50  # not blank
    assert plot3d.std() > 0.03


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (
            '[model]\nname = "pendulum-cartesian"\nparams = { mass = 2.0 }\n'
            "[time]\nspan = [0, 1]\n",
            r"model\.params\.mass: unknown parameter; parameters: g, l, m",
        ),
        (
            '[model]\nname = "pendulum"\n[time]\nspan = [0, 1]\n',
            r"model\.name: expected one of .*did you mean",
        ),
        (
            '[model]\nname = "pendulum-cartesian"\nq0 = { x = 0.5, y = 0.5 }\n[time]\n'
            "span = [0, 1]\n",
            r"model: `q0`: inconsistent initial conditions",
        ),
        (
            '[model]\nname = "atwood"\n[integrator]\nstabilization = "springs"\n[time]\n'
            "span = [0, 1]\n",
            r"integrator\.stabilization: expected one of",
        ),
    ],
)
def test_malformed_model_scenarios(text, match, tmp_path, capsys):
    path = tmp_path / "m.toml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    import re

    assert re.search(match, capsys.readouterr().err)


def test_lagrangian_example_outputs_match_the_library(tmp_path):
    from poinsot import models

    assert main(["run", "--example", "atwood", "--out", str(tmp_path / "a"), "--quiet"]) == 0
    data = np.load(tmp_path / "a" / "solution.npz")
    mdl = models.atwood_machine()
    sol = mdl.simulate((0, 2), t_eval=np.linspace(0, 2, 201))
    np.testing.assert_allclose(data["multipliers"], sol.multipliers, rtol=1e-12)
    assert list(data["coordinates"]) == ["y1", "y2", "phi"]


def test_ensemble_example_writes_statistics_against_the_exact_flips(tmp_path, capsys):
    """The bundled Monte Carlo of Dzhanibekov flips: every member flips, and the measured
    intervals agree with the exact 2K(m)/λ to RK4's accuracy (dt = 1e-3)."""
    xr = pytest.importorskip("xarray")
    out = tmp_path / "mc"
    assert main(["run", "--example", "tennis-racket-ensemble", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "members" in text and "flip interval against the exact" in text
    summary = json.loads((out / "summary.json").read_text())
    e = summary["ensemble"]
    assert e["members"] == e["succeeded"] == 2000
    assert e["statistics"]["first_flip"]["members_with_a_flip"] == 2000
    flips = summary["flips_against_exact"]
    assert flips["members_compared"] > 1900
    assert flips["relative_error"]["max"] < 1e-3
    for name in ("histograms.png", "flip_intervals.png", "report.html", "ensemble.nc"):
        assert (out / name).stat().st_size > 10_000, name
    ds = xr.open_dataset(out / "ensemble.nc", engine="scipy")
    assert ds.sizes["member"] == 2000
    np.testing.assert_allclose(ds["omega0"].values[:, 1], 2 * np.pi)
    ratio = ds["flip_interval"].values / ds["exact_flip_interval"].values - 1
    assert np.nanmax(np.abs(ratio)) < 1e-3
    ds.close()


def test_ensemble_statistics_are_over_the_samples_kept_or_not(tmp_path, capsys):
    """``[time].samples`` sets the times the members' statistics run over, whether their
    states are kept or not (the command line had dropped them without ``keep_states``: the
    drifts compared only t0 and t1). The energy errors equal the largest relative change of
    ½ ω·Iω over the kept samples, computed here from the states themselves."""
    from scipy.io import netcdf_file

    from poinsot.app.scenario import example_text

    text = example_text("tennis-racket-ensemble")
    text = re.sub(r"members = \d+", "members = 20", text)
    errors = {}
    for keep in (False, True):
        path = tmp_path / f"e{keep}.toml"
        path.write_text(
            text.replace("[ensemble]", f"[ensemble]\nkeep_states = {str(keep).lower()}")
        )
        assert main(["run", str(path), "--out", str(tmp_path / f"o{keep}"), "--quiet"]) == 0
        summary = json.loads((tmp_path / f"o{keep}" / "summary.json").read_text())
        assert summary["ensemble"]["samples"] == 201  # [time]'s default
        with netcdf_file(tmp_path / f"o{keep}" / "ensemble.nc", "r", mmap=False) as nc:
            errors[keep] = nc.variables["energy_error"].data.copy()
            if keep:
                w = nc.variables["omega"].data  # (member, time, axis), body frame
                I = np.array([0.00121, 0.01638, 0.01748])
                E = 0.5 * np.einsum("mti,i,mti->mt", w, I, w)
                mine = np.abs(E / E[:, :1] - 1).max(axis=1)
    np.testing.assert_array_equal(errors[False], errors[True])
    np.testing.assert_allclose(errors[True], mine, rtol=1e-6, atol=1e-15)


def test_polhodes_refuses_conflicting_energy_and_honours_omega0(tmp_path, capsys):
    """--energy and --omega0 that disagree are refused; with --omega0 alone the figure's
    ellipsoid is the energy of ω0, the value polhodes.json reports (issue 12/13)."""
    base = ["polhodes", "--moments", "1", "2", "3", "--omega0", "1", "1", "1"]
    assert main([*base, "--energy", "1", "--out", str(tmp_path / "a")]) == 2
    assert "--energy 1 conflicts with --omega0, whose energy is 3" in capsys.readouterr().err
    assert not (tmp_path / "a").exists()
    assert main([*base, "--energy", "3", "--out", str(tmp_path / "b"), "--quiet"]) == 0
    assert json.loads((tmp_path / "b" / "polhodes.json").read_text())["energy"] == 3.0


def test_run_draws_the_runs_own_energy_and_the_sweep_apart(tmp_path):
    """polhodes.png: ω(t) unscaled on the run's own ellipsoid; the [analysis] energy's sweep
    is a separate, titled polhodes_sweep.png (the notebook example: k = 12.5 against 0.5)."""
    import poinsot.app.job as job
    import poinsot.app.runs.rigid as rigid

    shown = {}
    real_images = rigid.png_images

    def spy(figures, folder, **kwargs):  # each figure by its file name, as it is rendered
        def seen():
            for fig, name, caption in figures:
                shown[name] = (fig.axes[0].get_title(), fig)
                yield fig, name, caption

        return real_images(seen(), folder, **kwargs)

    from poinsot.app.scenario import load_example

    scenario = load_example("notebook")
    scenario.outputs["report"] = False
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(rigid, "png_images", spy)
        job.run_scenario(scenario, tmp_path / "o")
    title, fig = shown["polhodes.png"]
    assert "k = 12.5 J" in title
    run_line = next(ln for ln in fig.axes[0].lines if ln.get_label() == "ω(t) of this run")
    data = np.load(tmp_path / "o" / "trajectory.npz")
    E = scenario.body.principal_axes  # drawn along the principal axes e1, e2, e3
    np.testing.assert_allclose(np.array(run_line.get_data_3d()).T, data["omega"] @ E,
                               rtol=1e-15, atol=1e-15)  # fmt: skip
    assert "k = 0.5 J" in shown["polhodes_sweep.png"][0]
    assert (tmp_path / "o" / "polhodes_sweep.png").exists()


def test_mechanism_animation_has_a_frame_per_slider_step(tmp_path):
    plotly = pytest.importorskip("plotly.graph_objects")
    from poinsot import models
    from poinsot.viz.report import MAX_FRAMES, _mechanism_figure

    model = models.pendulum_on_cart()
    sol = model.simulate((0, 4), t_eval=np.linspace(0, 4, 401))
    fig = _mechanism_figure(model, sol, plotly)
    steps = fig.layout.sliders[0].steps
    assert len(fig.frames) == len(steps) == MAX_FRAMES
    assert [s.args[0][0] for s in steps] == [f.name for f in fig.frames]
    assert steps[0].label == "0" and steps[-1].label == "4"  # t [s], first and last sample
    assert {b.label for b in fig.layout.updatemenus[0].buttons} == {"▶ play", "❚❚ pause"}
    _, P = model.positions(sol)
    first = fig.frames[0].data[1]  # the named points at t = 0
    np.testing.assert_allclose(first.x, P[0, :, 0])
    assert fig.layout.xaxis.title.text == "x [m]" and fig.layout.yaxis.scaleanchor == "x"


def test_units_in_summary_and_csv_headers(tmp_path):
    assert main(["run", "--example", "atwood", "--out", str(tmp_path / "a"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    units = summary["units"]
    assert units["y1"] == "m" and units["phi_dot"] == "rad/s" and units["t"] == "s"
    assert units["tension T1 (string on mass 1)"] == "N"
    assert summary["reactions"]["tension T2 (string on mass 2)"]["unit"] == "N"
    header = (tmp_path / "a" / "solution.csv").read_text().splitlines()[0].split(",")
    assert header[:4] == ["t [s]", "y1 [m]", "y2 [m]", "phi [rad]"]
    assert "tension T1 (string on mass 1) [N]" in header and header[-1] == "energy_h [J]"
    assert main(["run", "--example", "heavy-top", "--out", str(tmp_path / "h"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "h" / "summary.json").read_text())
    units = summary["units"]
    assert units["body.mass"] == "kg" and units["initial.omega"] == "rad/s"
    assert units["integration.diagnostics.orthogonality_error"] == "1"
    invariants = summary["integration"]["diagnostics"]["invariants"]
    assert {v["symbol"]: v["unit"] for v in invariants.values()}["L_P·ĝ"] == "kg·m²/s"
    header = (tmp_path / "h" / "trajectory.csv").read_text().splitlines()[0].split(",")
    assert "omega_x [rad/s]" in header and "R_z [m]" in header


def test_report_numbers_are_grouped_with_units(tmp_path):
    from poinsot.viz.numbers import rows_of

    assert main(["run", "--example", "notebook", "--out", str(tmp_path / "n"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "n" / "summary.json").read_text())
    rows = rows_of(summary)
    groups = list(dict.fromkeys(r[0] for r in rows))
    assert groups[:4] == ["Body", "Initial state", "Invariants", "Torque-free motion"]
    by_name = {r[1]: r for r in rows}
    assert by_name["mass"][2:] == (10.0, "kg")
    assert by_name["period of ω(t)"][3] == "s"
    assert not any("a2_over_2k" in r[1] for r in rows)  # human names, not keys
    page = (tmp_path / "n" / "report.html").read_text()
    assert "<h3>Accuracy</h3>" in page and "href='summary.json'" in page
    assert "RK4 leaves SO(3)" in page.split("poinsot-plot-0")[0]  # stated before the figures


def test_shared_plotlyjs_is_written_once_beside_the_reports(tmp_path):
    import plotly

    out = tmp_path / "runs"
    for name in ("tennis-racket", "pendulum-on-cart"):
        args = ["run", "--example", name, "--out", str(out / name), "--quiet",
                "--plotly-js", "shared"]  # fmt: skip
        assert main(args) == 0
    js = out / f"plotly-{plotly.__version__}.min.js"
    assert js.is_file()
    for name in ("tennis-racket", "pendulum-on-cart"):
        page = (out / name / "report.html").read_text()
        assert f'src="../{js.name}"' in page and len(page) < 2_000_000
    js.write_text("not plotly")  # someone else's file of that name is never replaced
    args = ["run", "--example", "atwood", "--out", str(out / "a"), "--plotly-js", "shared"]
    assert main(args) == 2 and js.read_text() == "not plotly"


def test_a_run_beyond_the_step_budget_is_refused_without_a_traceback(tmp_path):
    scenario = tmp_path / "tiny.toml"
    scenario.write_text(GOOD + '[integrator]\nmethod = "rk4"\ndt = 1e-300\n')
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "poinsot.app.cli",
            "run",
            str(scenario),
            "--out",
            str(tmp_path / "o"),
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2, proc.stderr
    assert "integrator.dt: the run needs 1e+" in proc.stderr
    assert "a run may take at most 1e+08 steps" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.toml"]


def _with_integrator(text: str, integrator: str, span: str | None = None) -> str:
    """A bundled example's text with its [integrator] replaced (and its time.span)."""
    import re

    text = re.sub(r"\[integrator\][^\[]*", "", text)
    if span is not None:
        text = re.sub(r"span = \[[^\]]*\]", f"span = {span}", text)
    return text + "\n[integrator]\n" + integrator + "\n"


@pytest.mark.parametrize("example", ["notebook", "rolling-disk", "tennis-racket-ensemble",
                                     "turntable-spin-up"])  # fmt: skip
@pytest.mark.parametrize(("integrator", "span", "needs"), [
    ('method = "rk4"\ndt = 1e-300', None, r"1e\+301|2e\+301"),
    ('method = "rk4"\ndt = 0.001', "[0.0, 9.2e18]", r"9\.2e\+21"),
])  # fmt: skip
def test_every_kind_of_scenario_refuses_an_impossible_step_count_up_front(
    example, integrator, span, needs, tmp_path, capsys
):
    """A rigid body, a Lagrangian model, an ensemble and a relative motion alike: exit 2 before
    anything runs, both keys named, nothing written (the ensemble ran until killed before)."""
    from poinsot.app.scenario import example_text

    path = tmp_path / "s.toml"
    path.write_text(_with_integrator(example_text(example), integrator, span))
    with deadline(60, f"poinsot run {example}"):
        code = main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert re.search(
        rf"integrator\.dt: the run needs ({needs}) steps of dt = .* over time\.span", err
    )
    assert "a run may take at most 1e+08 steps" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_an_ensemble_whose_members_all_fail_names_the_keys(tmp_path, capsys):
    """`dt = 1.0` and `std = 1e300`: every member blows up, and the run said only "no
    statistic with a finite value to draw"."""
    from importlib.resources import files

    text = (files("poinsot.app") / "scenarios" / "tennis-racket-ensemble.toml").read_text()
    text = (text.replace("dt = 1e-3", "dt = 1.0").replace("members = 2000", "members = 20")
            .replace("std = [0.05, 0.0, 0.05]", "std = [1e300, 0.0, 1e300]"))  # fmt: skip
    path = tmp_path / "blow.toml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "every one of the 20 members failed (non-finite state: 20)" in err
    assert "`ensemble.std` = [1e+300, 0.0, 1e+300]" in err and "`integrator.dt` = 1" in err
    assert not (tmp_path / "o").exists()


def test_an_internal_error_is_one_line_without_a_traceback(tmp_path, capsys, monkeypatch):
    """A bug (here a struct.error from a writer, as 3·10⁷ members once met) reached the user
    as a traceback; it is one line naming it, exit code 70, and nothing half-written."""
    import struct

    import poinsot.app.job

    def broken(*args, **kwargs):
        raise struct.error("'i' format requires -2147483648 <= number <= 2147483647")

    monkeypatch.setattr(poinsot.app.job, "atomic_write_text", broken)
    path = tmp_path / "s.toml"
    path.write_text(BOX_SCENARIO)
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 70
    err = capsys.readouterr().err
    assert "poinsot: internal error: error: 'i' format requires" in err
    assert "Traceback" not in err and not (tmp_path / "o").exists()
    monkeypatch.setenv("POINSOT_TRACEBACK", "1")
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 70
    assert "Traceback" in capsys.readouterr().err  # asked for, for a report
