"""Issue 43, units in as well as out: a scenario value or a CLI number may be a quantity with a
unit, parsed by pint and converted to SI; a wrong dimension or an unknown unit is refused naming
the key and the units; a bare angle beyond 2π is warned about; what was converted is echoed in
``summary.json``."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest

from poinsot.app import tables
from poinsot.app.cli import main
from poinsot.app.scenario import ScenarioError, load_scenario

pytest.importorskip("pint")

BOX = """
name = "u"
[body]
type = "box"
mass = {mass}
size = {size}
[initial]
omega = {omega}
orientation = {{ euler = {euler} }}
[integrator]
method = "rk4"
dt = {dt}
[time]
span = [0, 0.1]
samples = 3
"""


def _box(mass="2.0", size="[0.1, 0.2, 0.3]", omega="[0.0, 1.0, 0.0]", euler="[0.0, 0.1, 0.0]",
         dt="0.001"):  # fmt: skip
    return BOX.format(mass=mass, size=size, omega=omega, euler=euler, dt=dt)


def test_quantities_are_converted_to_si_and_recorded():
    s = load_scenario(_box(mass='"2000 g"', size='["10 cm", "0.2 m", 0.3]',
                           omega='["1 rpm", "100 rpm", 0]', euler='[0, "10 deg", 0]',
                           dt='"1 ms"'))  # fmt: skip
    plain = load_scenario(_box(omega=f"[{2 * math.pi / 60!r}, {200 * math.pi / 60!r}, 0]",
                               euler=f"[0, {math.radians(10)!r}, 0]"))  # fmt: skip
    assert s.body.mass == pytest.approx(2.0, rel=1e-15) and s.dt == pytest.approx(1e-3)
    np.testing.assert_allclose(s.initial["omega0"], plain.initial["omega0"], rtol=1e-15)
    np.testing.assert_allclose(s.initial["Q0"], plain.initial["Q0"], atol=1e-16)
    np.testing.assert_allclose(s.body.inertia, plain.body.inertia, rtol=1e-14)
    assert s.quantities["initial.omega[1]"] == {"given": "100 rpm",
                                                "value": pytest.approx(10.471975511965976),
                                                "unit": "rad/s"}  # fmt: skip
    assert s.quantities["initial.orientation.euler[1]"]["unit"] == "rad"
    assert "initial.omega[2]" not in s.quantities and plain.quantities == {}


def test_a_density_with_units_and_the_echo_in_summary_json(tmp_path):
    text = _box(mass='"1.5 kg"', omega='["60 rpm", 0, 0]')
    path = tmp_path / "u.toml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    echoed = summary["scenario"]["quantities"]
    assert echoed["initial.omega[0]"]["value"] == pytest.approx(2 * math.pi)
    assert echoed["body.mass"] == {"given": "1.5 kg", "value": 1.5, "unit": "kg"}
    assert summary["initial"]["omega"][0] == pytest.approx(2 * math.pi)


@pytest.mark.parametrize(("value", "words"), [
    ('"2 kg"', ["initial.omega[0]", "'2 kg'", "kg", "rad/s"]),
    ('"3 m/s"', ["initial.omega[0]", "m/s is [length] / [time], not rad/s"]),
    ('"100 rmp"', ["initial.omega[0]", "unknown unit 'rmp'", "did you mean", "'rpm'"]),
    ('"__import__(\'os\')"', ["initial.omega[0]"]),
    ('"().__class__"', ["initial.omega[0]"]),
    ('"1 rpm + 2 kg"', ["initial.omega[0]"]),
])  # fmt: skip
def test_refusals_name_the_key_and_the_units(value, words):
    with pytest.raises(ScenarioError) as err:
        load_scenario(_box(omega=f"[{value}, 0, 0]"))
    for word in words:
        assert word in str(err.value), (word, str(err.value))


def test_a_bare_angle_beyond_2pi_is_warned_about_naming_the_key():
    with pytest.warns(
        UserWarning, match=r"initial\.orientation\.euler\[0\] = 34\.4.*\"34\.4 deg\""
    ):
        load_scenario(_box(euler="[34.4, 0.1, 0]"))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_scenario(_box(euler="[6.0, 0.1, 0]"))  # within 2π: no warning
        load_scenario(_box(euler='["34.4 deg", 0.1, 0]'))


def test_model_values_take_their_declared_units():
    text = (
        '[model]\nname = "pendulum-polar"\nparams = {{ l = "50 cm", m = "200 g" }}\n'
        "q0 = {{ theta = {q} }}\nqd0 = {{ theta = {qd} }}\n[time]\nspan = [0, 1]\n"
    )
    s = load_scenario(text.format(q='"30 deg"', qd='"60 deg/s"'))
    plain = load_scenario(text.format(q=repr(math.pi / 6), qd=repr(math.pi / 3)))
    assert [float(v) for v in s.q0.values()] == pytest.approx([math.pi / 6], rel=1e-15)
    assert [float(v) for v in s.qd0.values()] == pytest.approx([math.pi / 3], rel=1e-15)
    assert {str(k): float(v) for k, v in s.params.items()}["l"] == 0.5
    assert s.q0 == pytest.approx(plain.q0)
    with pytest.raises(ScenarioError, match=r"model\.params\.l = '50 kg'.*kg.*not m"):
        load_scenario(text.format(q="0.5", qd="0").replace("50 cm", "50 kg"))


def test_cli_numbers_take_units(tmp_path, capsys):
    assert main(["polhodes", "--moments", "1e7 g*cm^2", "2", "3", "--omega0", "60 rpm", "0",
                 "0", "--json", "--quiet", "--out", str(tmp_path / "p")]) == 0  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert out["principal_moments"][0] == pytest.approx(1.0)
    assert out["omega0"][0] == pytest.approx(2 * math.pi)
    with pytest.raises(SystemExit) as exc:
        main(["polhodes", "--moments", "1 kg", "2", "3"])
    assert exc.value.code == 2
    assert "--moments = '1 kg'" in capsys.readouterr().err


def test_without_pint_a_unit_is_refused_cleanly(monkeypatch):
    monkeypatch.setattr(tables, "_UREG", None)
    monkeypatch.setitem(sys.modules, "pint", None)  # import pint raises ImportError
    with pytest.raises(ScenarioError, match=r"initial\.omega\[0\] = '60 rpm'.*poinsot\[units\]"):
        load_scenario(_box(omega='["60 rpm", 0, 0]'))
    assert load_scenario(_box()).initial["omega0"][1] == 1.0  # bare numbers need nothing
