"""A ``[lagrangian]`` scenario's checks and outputs: a coordinate's unit is m or rad (a value in
degrees was integrated as radians and labelled deg); a system with nothing to draw writes the
rest; a parameter has an effect somewhere (equations, drawing, reactions, bodies) or is refused
by its key, and the system gets only its own; a body's mass and inertia are positive; the
solution files carry the same fields, with units, the reactions included."""

from __future__ import annotations

import json

import numpy as np
import pytest

from poinsot.app.cli import main
from poinsot.app.scenario import ScenarioError, load_scenario

CART = """
name = "cart"
[lagrangian]
coordinates = { x = "m", theta = "rad" }
parameters = { M = "2 kg", m = "0.5 kg", l = "0.8 m", g = "9.81 m/s^2" }
potential = "-m*g*l*cos(theta)"
q0 = { x = 0.0, theta = "20 deg" }
qd0 = { x = 0.0, theta = 0.0 }

[[lagrangian.bodies]]
name = "cart"
mass = "M"
position = ["x", 0, 0]

[[lagrangian.bodies]]
name = "bob"
mass = "m"
position = ["x + l*sin(theta)", "-l*cos(theta)", 0]

[time]
span = [0.0, 1.0]
samples = 11
"""

SPHERE = """
name = "sphere"
[lagrangian]
coordinates = { x = "m", y = "m", z = "m" }
parameters = { m = "2 kg", g = "9.81 m/s^2", l = "1.5 m" }
kinetic = "m*(x_dot^2 + y_dot^2 + z_dot^2)/2"
potential = "m*g*z"
holonomic = ["x^2 + y^2 + z^2 - l^2"]
q0 = { x = 0.9, y = 0.0 }
qd0 = { x = 0.0, y = 2.0 }
guess = { z = -1.0 }

[lagrangian.reactions."rod tension T"]
expression = "-2*lambda1*l"
unit = "N"

[time]
span = [0.0, 1.0]
samples = 21
[output]
report = false
"""


def _run(text, tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text(text)
    code = main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"])
    return code, capsys.readouterr().err


@pytest.mark.parametrize("unit", ["deg", "cm", ""])
def test_a_coordinate_in_another_unit_than_m_or_rad_is_refused(unit, tmp_path, capsys):
    text = CART.replace('theta = "rad"', f'theta = "{unit}"')
    code, err = _run(text, tmp_path, capsys)
    assert code == 2 and "Traceback" not in err
    assert "lagrangian.coordinates.theta: a coordinate's unit must be 'm' or 'rad'" in err
    assert f"found {unit!r}" in err
    assert not (tmp_path / "o").exists()


def test_a_system_with_nothing_to_draw_writes_everything_else(tmp_path, capsys):
    code, err = _run(SPHERE, tmp_path, capsys)
    assert code == 0, err
    written = {p.name for p in (tmp_path / "o").iterdir()}
    assert {"summary.json", "solution.npz", "solution.csv", "solution.png"} <= written
    assert "mechanism.png" not in written


def test_a_parameter_used_by_nothing_is_refused_by_its_key():
    text = CART.replace('g = "9.81 m/s^2" }', 'g = "9.81 m/s^2", c = "0.1 N*s/m" }')
    with pytest.raises(ScenarioError) as err:
        load_scenario(text)
    assert "lagrangian.parameters.c: used by nothing" in str(err.value)
    assert "params" not in str(err.value)


def test_a_parameter_of_the_drawing_or_a_reaction_only_has_its_effect_there():
    text = CART.replace('g = "9.81 m/s^2" }', 'g = "9.81 m/s^2", W = "3 m", k = 2 }')
    text = text.replace("[time]", '[lagrangian.reactions.twice]\nexpression = "k*x"\nunit = "m"\n'
                        '[lagrangian.draw]\nlinks = [["cart", "bob"]]\n'
                        'outline = { rail = [["-W", 0, 0], ["W", 0, 0]] }\n'
                        'points = { end = ["W", 0, 0] }\n[time]')  # fmt: skip
    s = load_scenario(text)
    assert sorted(map(str, s.params)) == ["M", "g", "l", "m"]  # the system's own
    assert s.model.outlines()["rail"].tolist() == [[-3, 0, 0], [3, 0, 0]]
    sol = s.simulate()
    names, P = s.model.positions(sol)
    np.testing.assert_array_equal(P[:, names.index("end")], np.tile([3.0, 0, 0], (len(sol.t), 1)))
    np.testing.assert_array_equal(s.model.reaction_values(sol)["twice"][0], 2 * sol.q[:, 0])


def test_the_mass_of_a_body_that_does_not_move_is_accepted():
    text = """
[lagrangian]
coordinates = { a = "rad", b = "rad", c = "rad" }
parameters = { M = "3 kg" }
kinetic = "0"
q0 = { a = 0.3, b = 0.4, c = 0.2 }
qd0 = { a = 1.0, b = 0.5, c = 2.0 }
[[lagrangian.bodies]]
type = "rigid"
mass = "M"
position = [0, 0, 0]
inertia = [0.02, 0.035, 0.05]
orientation = { euler = ["a", "b", "c"], seq = "ZYX" }
[time]
span = [0.0, 0.5]
samples = 3
"""
    assert load_scenario(text).simulate().q.shape == (3, 3)


@pytest.mark.parametrize(("change", "where"), [
    (('mass = "M"', 'mass = "-M"'), "lagrangian.bodies[0].mass: must be positive"),
    (('mass = "m"', 'mass = "m - m"'), "lagrangian.bodies[1].mass: must be positive"),
    (('M = "2 kg"', "M = -2"), "lagrangian.bodies[0].mass: must be positive"),
])  # fmt: skip
def test_a_mass_that_is_not_positive_is_refused_by_its_key(change, where, tmp_path, capsys):
    code, err = _run(CART.replace(*change), tmp_path, capsys)
    assert code == 2 and where in err, err


@pytest.mark.parametrize("inertia", ["[0.02, -0.035, 0.05]",
                                     "[[1, 0, 0], [0, 1, 2], [0, 2, 1]]",
                                     "[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]"])  # fmt: skip
def test_an_inertia_that_is_not_positive_definite_is_refused_by_its_key(inertia):
    text = CART.replace('name = "bob"', f'name = "bob"\ntype = "rigid"\ninertia = {inertia}\n'
                        'orientation = { euler = ["theta", 0, 0], seq = "ZXZ" }')  # fmt: skip
    with pytest.raises(ScenarioError, match=r"lagrangian\.bodies\[1\]\.inertia: an inertia"):
        load_scenario(text)


def test_the_npz_and_the_csv_carry_the_same_fields_with_units(tmp_path, capsys):
    code, err = _run(SPHERE.replace("report = false", "report = false\nfigures = false"),
                     tmp_path, capsys)  # fmt: skip
    assert code == 0, err
    npz = np.load(tmp_path / "o" / "solution.npz")
    units = json.loads(str(npz["units"]))
    labels = {"coordinates", "constraints", "reaction_names", "units"}
    fields = [f for f in npz.files if f not in labels]
    assert set(fields) == set(units)
    assert {"reactions", "multipliers", "constraint_forces"} <= set(fields)
    assert list(npz["reaction_names"]) == ["rod tension T"] and units["reactions"] == ["N"]
    lines = (tmp_path / "o" / "solution.csv").read_text().splitlines()
    header = lines[0].split(",")
    csv = np.loadtxt(lines[1:], delimiter=",", ndmin=2)
    assert all(h.endswith("]") and " [" in h for h in header)  # every column has its unit
    start = 0
    for name in fields:  # in the npz's order, the same columns with the same values
        value = npz[name].reshape(len(npz["t"]), -1)
        cols = header[start : start + value.shape[1]]
        np.testing.assert_array_equal(csv[:, start : start + value.shape[1]], value)
        per = [units[name]] * len(cols) if isinstance(units[name], str) else units[name]
        assert [c.split(" [", 1)[1][:-1] for c in cols] == per, name
        start += value.shape[1]
    assert start == len(header)
    assert "lambda1 [J/(unit of g1)]" in header and "constraint_force_x [N]" in header
    assert "rod tension T [N]" in header and header[-1] == "energy_h [J]"
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["reactions"]["rod tension T"]["max"] == npz["reactions"][:, 0].max()
    # the tension of a pendulum of mass m: T = m (v²/l + g·(−z)/l) > 0
    x, v = npz["q"], npz["qd"]
    tension = 2.0 * ((v**2).sum(1) / 1.5 - 9.81 * x[:, 2] / 1.5)
    np.testing.assert_allclose(npz["reactions"][:, 0], tension, rtol=1e-6)


def test_a_rotation_coordinate_has_its_constraint_force_in_newton_metres():
    from poinsot.models import rolling_disk

    sol = rolling_disk().simulate((0, 0.1), t_eval=[0, 0.1])
    units = sol.export_units()
    assert units["constraint_forces"] == ["N", "N", "N·m", "N·m"]
    assert units["multipliers"] == ["W/(unit of G1 qd + b1)", "W/(unit of G2 qd + b2)"]
    attrs = sol.variables()["constraint_forces"][2]
    assert attrs["units_by_coordinate"] == "x: N, y: N, phi: N·m, theta: N·m"
