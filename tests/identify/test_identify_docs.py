"""The tutorial ``docs/identify.md``: its Python runs, its map file is accepted, and the
command it shows exists."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "identify.md"


def test_the_tutorials_python_runs(capsys):
    text = DOC.read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, str(DOC), "exec"), namespace)  # our own docs
    assert "ratios" in dir(namespace["res"])


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
