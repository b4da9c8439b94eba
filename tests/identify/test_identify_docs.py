"""The tutorial ``docs/identify.md``: its map file is accepted, the commands it shows parse,
and its walk-through runs verbatim on the sample log that ships with poinsot, printing what the
page shows (its Python blocks run with every page's in ``tests/test_docs.py``)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

DOC = Path(__file__).resolve().parents[2] / "docs" / "identify.md"


def test_the_tutorials_map_files_are_accepted(tmp_path):
    from poinsot.identify import load_map

    text = DOC.read_text(encoding="utf-8")
    maps = re.findall(r"```toml\n(.*?)```", text, re.S)
    assert len(maps) == 2
    first = tmp_path / "btfl.toml"
    first.write_text(maps[0], encoding="utf-8")
    m = load_map(first)
    assert m.gyro == ("gyroADC[0]", "gyroADC[1]", "gyroADC[2]") and m.time == "time (us)"
    assert abs(m.gyro_scale - 3.141592653589793 / 180 / 16.384) < 1e-15
    assert m.time_scale == 1e-6
    rotor = tmp_path / "rotor.toml"
    rotor.write_text(maps[1], encoding="utf-8")
    r = load_map(rotor)
    assert (
        r.rotor_inertia == 1.7e-6
        and abs(r.rotor_speed_scale - 100 / 7 * 2 * 3.14159265358979 / 60) < 1e-12
    )


def test_the_commands_parse():
    from poinsot.app.cli import _parser

    text = DOC.read_text(encoding="utf-8")
    for line in re.findall(r"^poinsot (identify .*)$", text, re.M):
        args = _parser().parse_args(line.split())
        assert args.command == "identify"


def _numbers(line):
    return [float(x) for x in re.findall(r"[-+]?\d+\.?\d*(?:[eE][-+]?\d+)?", line)]


def test_the_walk_through_runs_verbatim_on_the_shipped_sample(tmp_path, monkeypatch, capsys):
    """``poinsot examples --data gyro.csv > gyro.csv`` then ``poinsot identify gyro.csv …``, as
    the page writes them, print the page's output: the same lines, the numbers within the last
    digit shown (another BLAS may round the fit's last digits otherwise)."""
    from poinsot.app.cli import main

    text = DOC.read_text(encoding="utf-8")
    section = text[text.index("## 3. Identify") : text.index("## The same in Python")]
    commands = re.findall(r"```bash\n(.*?)```", section, re.S)[0].strip().splitlines()
    shown = re.findall(r"```text\n(.*?)```", section, re.S)[0].strip().splitlines()
    monkeypatch.chdir(tmp_path)
    assert commands[0] == "poinsot examples --data gyro.csv > gyro.csv"
    assert main(commands[0].split()[1:4]) == 0
    (tmp_path / "gyro.csv").write_text(capsys.readouterr().out, encoding="utf-8")
    assert main(commands[1].split()[1:]) == 0
    printed = capsys.readouterr().out.strip().splitlines()
    assert len(printed) == len(shown)
    for got, want in zip(printed, shown, strict=True):
        assert re.sub(r"[-+\d.eE]+", "#", got) == re.sub(r"[-+\d.eE]+", "#", want), (got, want)
        for a, b in zip(_numbers(got), _numbers(want), strict=True):
            assert abs(a - b) <= 2e-4 * max(1.0, abs(b)), (got, want)


def test_the_robust_loss_output_is_the_pages():
    """The page's two residual lines of a robust fit (its Python section's phone log, every
    30th sample knocked by 0.3 rad/s, ``loss="huber"``), the numbers within the last digit
    shown."""
    from poinsot import RigidBody
    from poinsot.identify import identify, synthetic_throw

    text = DOC.read_text(encoding="utf-8")
    section = text[text.index("A log with spikes") : text.index("## The same in Python")]
    shown = re.findall(r"```text\n(.*?)```", section, re.S)[0].strip().splitlines()
    phone = RigidBody.box(0.19, (0.0715, 0.147, 0.0078))
    th = synthetic_throw(rotor=False, body=phone, rate=200.0, noise=0.005, saturation=None, seed=3)
    w = th.omega.copy()
    w[::30] += 0.3
    printed = identify(th.t, w, loss="huber").summary()[-2:]
    for got, want in zip(printed, shown, strict=True):
        assert re.sub(r"[-+\d.eE]+", "#", got) == re.sub(r"[-+\d.eE]+", "#", want), (got, want)
        for a, b in zip(_numbers(got), _numbers(want), strict=True):
            assert abs(a - b) <= 2e-4 * max(1.0, abs(b)), (got, want)


def test_the_shipped_sample_is_the_generators_output_and_identifies_the_truth():
    from importlib.resources import files

    from poinsot.identify import identify, read_log
    from poinsot.identify.synthetic import SAMPLE_PHONE, sample_log_text

    shipped = files("poinsot.identify").joinpath("samples", "gyro.csv").read_text("utf-8")
    assert shipped == sample_log_text()
    path = Path(__file__).resolve().parents[2] / "src/poinsot/identify/samples/gyro.csv"
    log = read_log(path)
    a, b, c = SAMPLE_PHONE["size"]
    I = np.array([b * b + c * c, a * a + c * c, a * a + b * b])  # a box, up to m/12
    truth = np.sort(I)[:2] / np.sort(I)[2]
    res = identify(log.t, log.omega, window=(0.32, 0.78))
    assert np.all(np.abs(res.ratios - truth) < 3 * np.asarray(res.ratios_stderr))
    tilt = np.degrees(np.arccos(abs(res.axes[:, 2] @ [0, 0, 1])))  # e3 through the screen
    assert abs(tilt - SAMPLE_PHONE["misalignment_deg"]) < 0.1
