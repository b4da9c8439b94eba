"""`poinsot identify LOG.csv [--map MAP.toml] [--json]`: the numbers, the JSON keys, the report,
and exit 2 with a message naming the column or the argument (never a traceback)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from identify_throws import throw
from test_identify_log import BLACKBOX_MAP, _blackbox, _phyphox

from poinsot.app.cli import main


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("logs")
    th = throw(seed=42, accel=True, hand=True)
    _blackbox(d / "btfl.csv", th)
    (d / "btfl.toml").write_text(BLACKBOX_MAP, encoding="utf-8")
    phone = throw(rotor=False, seed=43)
    _phyphox(d / "phone.csv", phone)
    return d, th, phone


def test_json_has_the_fixed_keys(files, capsys):
    d, th, _ = files
    assert main(["identify", str(d / "btfl.csv"), "--map", str(d / "btfl.toml"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {"ratios", "axes", "inertia", "absolute", "window"} <= set(data)
    assert data["absolute"] is True and data["ok"] is True
    assert np.all(np.abs(np.array(data["ratios"]) / th.ratios - 1) < 0.005)
    assert abs(np.trace(data["inertia"]) / np.trace(th.inertia) - 1) < 0.02
    t0 = 1.0  # the log's clock starts at 1 000 000 µs
    assert th.window[0] <= data["window"][0] - t0 < data["window"][1] - t0 <= th.window[1]
    assert data["log"]["columns"]["gyro.x"] == "gyroADC[0]"


def test_text_output_and_the_report(files, capsys, tmp_path):
    d, _, _ = files
    out = tmp_path / "out"
    assert main(["identify", str(d / "phone.csv"), "--out", str(out), "--box", "0.07", "0.06",
                 "0.03"]) == 0  # fmt: skip
    text = capsys.readouterr().out
    assert "I1/I3 = " in text and "(up to scale, trace 1)" in text and "axis e3" in text
    assert "unit read from the header 'Time (s)'" in text
    for name in ("report.html", "result.json", "fit.png", "polhode.png", "axes.png"):
        assert (out / name).stat().st_size > 2000, name
    saved = json.loads((out / "result.json").read_text())
    assert len(saved["series"]["t"]) == saved["samples"]
    page = (out / "report.html").read_text()
    assert "I1/I3" in page and "data:image/png;base64" in page
    # the folder is poinsot's now: again only with --force
    assert main(["identify", str(d / "phone.csv"), "--out", str(out)]) == 2
    assert main(["identify", str(d / "phone.csv"), "--out", str(out), "--force"]) == 0


def test_options_override_the_map(files, capsys):
    d, th, _ = files
    args = ["identify", str(d / "btfl.csv"), "--map", str(d / "btfl.toml"), "--json"]
    assert main([*args, "--rotor-inertia", "3.4e-6"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["rotor_inertia"] == 3.4e-6  # twice J: twice the inertia
    assert abs(np.trace(data["inertia"]) / np.trace(th.inertia) - 2) < 0.04


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--gyro", "a", "b", "c"], "the column 'a' (gyro x) is not in the header"),
        (["--window", "0", "30"], "`window` (0, 30) s reaches outside the log"),
        (["--gyro-scale", "2 furlongs"], "`--gyro-scale` = '2 furlongs': unknown unit"),
        (["--rotor-inertia", "-1"], "--rotor-inertia must be a positive number"),
        (["--map", "missing.toml"], "missing.toml: no such file"),
    ],
)
def test_bad_input_exits_2_naming_it(files, capsys, extra, message):
    d, _, _ = files
    assert main(["identify", str(d / "btfl.csv"), "--map", str(d / "btfl.toml"), *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_a_log_read_in_the_wrong_units_is_flagged(files, capsys):
    """Without its map the blackbox log's counts are taken as rad/s (and said so): the fit is
    flagged, not reported as fine."""
    d, _, _ = files
    assert main(["identify", str(d / "btfl.csv")]) == 0
    captured = capsys.readouterr()
    assert "no scale and no unit in the header 'gyroADC[0]': taken as rad/s" in captured.out
    assert "poinsot: warning: the residuals are" in captured.err


def test_bad_log_in_a_subprocess_has_no_traceback(tmp_path):
    p = tmp_path / "log.csv"
    p.write_text("t,gx,gy,gz\n0,1,2,3\n0,1,2,3\n", encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "poinsot", "identify", str(p), "--gyro", "gx",
                           "gy", "gz"], capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == 2
    assert "column 't' must increase strictly: line 3 (0.0) repeats" in done.stderr
    assert "Traceback" not in done.stderr
