"""Reading logs: a phone app's export (phyphox: time and gyroscope x/y/z in rad/s, comma or
semicolon with decimal commas) and a flight controller's blackbox export (gyroADC[0..2] in
counts of 1/16.384 deg/s, time in µs) through a map file; every refusal names the file, the
key or the column, and the line."""

from __future__ import annotations

import math

import numpy as np
import pytest
from identify_throws import throw

from poinsot.identify import LogMap, LogMapError, identify, load_map, read_log
from poinsot.identify.log import parse_scale

BLACKBOX_MAP = """\
# Betaflight blackbox_decode CSV
[columns]
time = "time (us)"
gyro = ["gyroADC[0]", "gyroADC[1]", "gyroADC[2]"]
accel = ["accSmooth[0]", "accSmooth[1]", "accSmooth[2]"]
rotor_speed = "rotor"

[scale]
time = "1 us"
gyro = "1/16.384 deg/s"
accel = "1/2048 g"
rotor_speed = "1 rpm"

[rotor]
axis = [0, 0, 1]
inertia = 1.7e-6
"""


def _phyphox(path, th, *, sep=",", decimal="."):
    head = ["Time (s)", "Gyroscope x (rad/s)", "Gyroscope y (rad/s)", "Gyroscope z (rad/s)",
            "Absolute (rad/s)"]  # fmt: skip
    lines = [sep.join(f'"{h}"' for h in head)]
    for t, w in zip(th.t, th.omega, strict=True):
        cells = [f"{x:.9E}" for x in (t, *w, np.linalg.norm(w))]
        if decimal == ",":
            cells = [c.replace(".", ",") for c in cells]
        lines.append(sep.join(cells))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def _blackbox(path, th):
    counts = np.round(np.degrees(th.omega) * 16.384).astype(int)
    acc = np.round(th.accel / 9.80665 * 2048).astype(int)
    rpm = np.round(th.rotor_speed * 60 / (2 * math.pi), 3)
    head = ("loopIteration, time (us), axisP[0], gyroADC[0], gyroADC[1], gyroADC[2], "
            "accSmooth[0], accSmooth[1], accSmooth[2], rotor")  # fmt: skip
    rows = [head]
    for k in range(len(th.t)):
        us = 1_000_000 + round(th.t[k] * 1e6)
        rows.append(f"{k}, {us}, 0, {counts[k, 0]}, {counts[k, 1]}, {counts[k, 2]}, "
                    f"{acc[k, 0]}, {acc[k, 1]}, {acc[k, 2]}, {rpm[k]}")  # fmt: skip
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def test_a_phone_apps_export_is_read_without_a_map(tmp_path):
    th = throw(rotor=False, seed=41)
    for sep, decimal in ((",", "."), (";", ","), ("\t", ".")):
        p = tmp_path / f"phone{ord(sep)}.csv"
        _phyphox(p, th, sep=sep, decimal=decimal)
        log = read_log(p, decimal=decimal)
        np.testing.assert_allclose(log.t, th.t, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(log.omega, th.omega, rtol=1e-9)
        assert log.columns["gyro.z"] == "Gyroscope z (rad/s)" and log.accel is None
        assert any("unit read from the header" in n for n in log.notes)
    res = log.identify()
    assert np.all(np.abs(res.ratios / th.ratios - 1) < 0.005)


def test_a_blackbox_log_through_a_map_file(tmp_path):
    th = throw(seed=42, accel=True, hand=True)
    p, m = tmp_path / "btfl.csv", tmp_path / "btfl.toml"
    _blackbox(p, th)
    m.write_text(BLACKBOX_MAP, encoding="utf-8")
    log = read_log(p, load_map(m))
    np.testing.assert_allclose(log.t - log.t[0], th.t - th.t[0], atol=1e-6)
    np.testing.assert_allclose(log.omega, th.omega, atol=0.5 * math.radians(1 / 16.384))
    np.testing.assert_allclose(log.accel, th.accel, atol=0.5 * 9.80665 / 2048)
    np.testing.assert_allclose(log.rotor_speed, th.rotor_speed, atol=1e-3)
    assert log.rotor_axis == (0.0, 0.0, 1.0) and log.rotor_inertia == 1.7e-6
    assert log.columns["gyro.x"] == "gyroADC[0]" and not log.notes
    res = log.identify()
    assert res.absolute and res.found_by == "accelerometer"
    assert np.all(np.abs(res.ratios / th.ratios - 1) < 0.005)
    assert abs(res.trace / np.trace(th.inertia) - 1) < 0.02


def test_scales():
    assert parse_scale("1/16.384 deg/s", "rate") == pytest.approx(math.pi / 180 / 16.384)
    assert parse_scale("us", "time") == 1e-6 and parse_scale("2 ms", "time") == 2e-3
    assert parse_scale("1/2048 g", "accel") == pytest.approx(9.80665 / 2048)
    assert parse_scale("60 rpm", "rate") == pytest.approx(2 * math.pi)
    assert parse_scale(0.25, "rate") == 0.25
    with pytest.raises(LogMapError, match=r"`scale.gyro` = '1 furlong/s': unknown unit"):
        parse_scale("1 furlong/s", "rate", "scale.gyro")
    with pytest.raises(LogMapError, match=r"`s` must be positive"):
        parse_scale(-1.0, "time", "s")
    with pytest.raises(LogMapError, match=r"not a number or a fraction"):
        parse_scale("1/0 deg/s", "rate")
    with pytest.raises(LogMapError, match=r"`x` must be a number or a string"):
        parse_scale(True, "rate", "x")


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("[colums]\ntime = 't'", r"unknown section \[colums\]"),
        ("[columns]\ntim = 't'", r"unknown key `columns.tim`"),
        ("[columns]\ngyro = ['a', 'b']", r"`columns.gyro` must list three columns"),
        ("[columns]\ntime = 1.5", r"`columns.time` must be a column name"),
        ("[scale]\ngyro = '3 parsecs'", r"`scale.gyro` = '3 parsecs': unknown unit"),
        ("[rotor]\naxis = [0, 1]", r"`rotor.axis` must be three numbers"),
        ("[rotor]\ninertia = -2", r"`rotor.inertia` must be a positive number"),
        ("[identify]\nwindow = [1]", r"`identify.window` must be two times"),
        ("[csv]\ndecimal = ';'", r"`csv.decimal`"),
        ("[csv]\nskip_rows = -1", r"`csv.skip_rows`"),
        ("columns = 3", r"`columns` must be a table"),
        ("[columns\n", r"TOML syntax error"),
    ],
)
def test_map_files_are_checked_key_by_key(tmp_path, text, match):
    p = tmp_path / "map.toml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(LogMapError, match=match) as err:
        load_map(p)
    assert str(p) in str(err.value)


LOG = "t,gx,gy,gz\n0.0,1,2,3\n0.1,1,2,3\n0.2,1,2,3\n"


@pytest.mark.parametrize(
    ("text", "options", "match"),
    [
        (LOG, {"gyro": ("gx", "gy", "gq")}, r"the column 'gq' \(gyro z\) is not in the header"),
        (LOG, {"time": 9, "gyro": (1, 2, 3)}, r"column number 9 \(time\) is beyond"),
        (
            LOG.replace("0.1,1,2,3", "0.1,1,x,3"),
            {"gyro": ("gx", "gy", "gz")},
            r"line 3, column 'gy': 'x' is not a number",
        ),
        (
            LOG.replace("0.1,1,2,3", "0.1,1,,3"),
            {"gyro": ("gx", "gy", "gz")},
            r"line 3, column 'gy': is empty",
        ),
        (
            LOG.replace("0.1,1,2,3", "0.1,1,nan,3"),
            {"gyro": ("gx", "gy", "gz")},
            r"line 3, column 'gy': 'nan' is not a finite number \(NaN sample\)",
        ),
        (
            LOG.replace("0.2,", "0.1,"),
            {"gyro": ("gx", "gy", "gz")},
            r"column 't' must increase strictly: line 4 \(0.1\) repeats the time of line 3",
        ),
        (
            LOG.replace("0.2,", "0.05,"),
            {"gyro": ("gx", "gy", "gz")},
            r"column 't' must increase strictly: line 4 \(0.05\) goes back",
        ),
        (LOG, {}, r"no gyro x, y, z columns recognised"),
        ("a,b\n1,2\n", {"gyro": ("a", "a", "a")}, r"no time column recognised"),
        (
            LOG,
            {"gyro": ("gx", "gy", "gz"), "decimal": ",", "delimiter": ","},
            r"`csv.decimal` \",\" needs another `csv.delimiter`",
        ),
        ("t,gx\n", {}, r"expected a header line and samples"),
        (
            LOG.replace("0.1,1,2,3", "0.1,1"),
            {"gyro": ("gx", "gy", "gz")},
            r"line 3: the row has 2 fields, so no column 'gy'",
        ),
    ],
)
def test_bad_logs_are_refused_naming_column_and_line(tmp_path, text, options, match):
    p = tmp_path / "log.csv"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(LogMapError, match=match):
        read_log(p, **options)


def test_a_log_without_units_is_taken_as_si_and_says_so(tmp_path):
    p = tmp_path / "log.csv"
    p.write_text(LOG, encoding="utf-8")
    log = read_log(p, LogMap(gyro=("gx", "gy", "gz")))
    assert log.omega[0].tolist() == [1.0, 2.0, 3.0]
    assert any("taken as rad/s" in n for n in log.notes)
    assert any("taken as s" in n for n in log.notes)
    with pytest.raises(LogMapError, match=r"unknown map key `gyro_scal`"):
        LogMap().updated(gyro_scal=1.0)
    with pytest.raises(LogMapError, match="no such file"):
        read_log(tmp_path / "missing.csv")


def test_identify_refuses_what_the_reader_lets_through_by_name():
    """The reader names the column; identify, given arrays, names the argument."""
    with pytest.raises(ValueError, match=r"`t` must increase strictly"):
        identify([0.0, 1.0, 1.0], np.zeros((3, 3)))
