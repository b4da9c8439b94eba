"""Issue 43: any Lagrangian system from a scenario file (``[lagrangian]``). The bundled models
written as scenario files run bit for bit as the Python models do; a system written only in
TOML (a pendulum on a cart tied to a wall by a spring) agrees with the same system in Python;
expressions are read from their syntax tree, so code in a file is refused, not run."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

from poinsot import models
from poinsot.app.scenario import ScenarioError, example_text, load_scenario
from poinsot.lagrange import LagrangianSystem, PointMass

#: The bundled examples, every one written as a [lagrangian] file.
WRITTEN = ("pendulum-cartesian", "double-pendulum", "spherical-pendulum", "bead-on-hoop",
           "atwood", "pendulum-on-cart", "rolling-disk", "knife-edge", "sliding-ladder",
           "heavy-top-euler", "rolling-coin")  # fmt: skip


def _by_name(mapping):
    return {str(k).replace("(t)", ""): v for k, v in mapping.items()}


@pytest.mark.parametrize("name", WRITTEN)
def test_a_bundled_model_written_as_a_file_runs_as_the_python_model(name):
    """The file's system, run with the file's values, equals the Python model's
    (``poinsot.models``), run with the same values: coordinates, speeds and the drawn points
    bit for bit, the reactions to round-off (the coin's disc is a rigid body in the file and
    SymPy's RigidBody in Python: its normal force differs by 1e-17 N)."""
    text = example_text(name)
    assert "[lagrangian]" in text and "[model]" not in text
    s = load_scenario(text)
    model = models.MODELS[name]()
    assert set(_by_name(model.params)) == set(_by_name(s.params))
    params = {p: _by_name(s.params)[str(p)] for p in model.params}
    q0 = {q: _by_name(s.q0)[str(q).replace("(t)", "")] for q in model.system.coordinates
          if str(q).replace("(t)", "") in _by_name(s.q0)}  # fmt: skip
    qd0 = {q: _by_name(s.qd0)[str(q).replace("(t)", "")] for q in model.system.coordinates
           if str(q).replace("(t)", "") in _by_name(s.qd0)}  # fmt: skip
    ours = s.simulate()
    theirs = model.system.simulate(s.t_span, q0=q0, qd0=qd0, params=params, t_eval=s.t_eval,
                                   guess=model.guess or None,
                                   **s.run_options())  # fmt: skip
    np.testing.assert_array_equal(ours.q, theirs.q)
    np.testing.assert_array_equal(ours.qd, theirs.qd)
    mine, reference = s.model.reaction_values(ours), model.reaction_values(theirs)
    assert list(mine) == list(reference)
    for key in reference:
        scale = np.abs(reference[key][0]).max()
        np.testing.assert_allclose(mine[key][0], reference[key][0], rtol=0, atol=1e-13 * scale)
        assert mine[key][1:] == reference[key][1:]
    theirs.model = model
    names, drawn = s.model.positions(ours)
    names_ref, drawn_ref = model.positions(theirs)
    assert names == names_ref
    np.testing.assert_array_equal(drawn, drawn_ref)
    assert (s.model.view, s.model.trail, set(s.model.links)) == (model.view, model.trail,
                                                                 set(model.links))  # fmt: skip
    assert {str(k): u for k, u in s.model.param_units.items()} == {
        str(k): u for k, u in model.param_units.items()
    }


def test_a_rigid_body_in_the_file_is_a_second_formulation_of_the_heavy_top():
    """The heavy top as a rigid body (inertia about its centre of mass, turned by its z-x-z
    Euler angles) against the heavy-top-euler example (A, C about the tip, written as
    energies): the same motion over 4 s to 1e-11."""
    text = """
[lagrangian]
coordinates = { psi = "rad", theta = "rad", phi = "rad" }
parameters = { M = "1 kg", g = "9.81 m/s^2", l = "0.5 m", AG = 0.025833333333333333, C = 0.045 }
potential = "M*g*l*cos(theta)"
q0 = { psi = 0.0, theta = 0.6, phi = 0.0 }
qd0 = { psi = 1.0, theta = 1.5, phi = 100.0 }
[[lagrangian.bodies]]
type = "rigid"
mass = "M"
position = ["l*sin(psi)*sin(theta)", "-l*cos(psi)*sin(theta)", "l*cos(theta)"]
inertia = ["AG", "AG", "C"]
orientation = { euler = ["psi", "theta", "phi"], seq = "ZXZ" }
[integrator]
rtol = 1e-11
atol = 1e-12
[time]
span = [0.0, 4.0]
samples = 201
"""
    rigid = load_scenario(text).simulate()
    euler = load_scenario(
        example_text("heavy-top-euler").replace("samples = 801", "samples = 201")
    ).simulate()
    np.testing.assert_allclose(rigid.q, euler.q, rtol=0, atol=1e-11)
    np.testing.assert_allclose(rigid.qd, euler.qd, rtol=0, atol=1e-9)


def _cart_in_python():
    x, th = dynamicsymbols("x theta")
    M, m, l, g, k = sp.symbols("M m l g k", positive=True)
    system = LagrangianSystem([x, th], bodies=[PointMass(M, [x, 0, 0]),
                                               PointMass(m, [x + l * sp.sin(th), -l * sp.cos(th),
                                                             0])],
                              potential=k * x**2 / 2 - m * g * l * sp.cos(th),
                              units={x: "m", th: "rad"})  # fmt: skip
    return system, (x, th), {M: 2.0, m: 1.0, l: 1.0, g: 9.81, k: 20.0}


def test_a_system_written_only_in_toml_agrees_with_python():
    """The cart-spring-pendulum example: a pendulum on a cart tied to a wall by a spring,
    given only as TOML (with units: "10 cm", "30 deg", "20 N/m"), against the same system
    built in Python."""
    s = load_scenario(example_text("cart-spring-pendulum"))
    system, (x, th), params = _cart_in_python()
    ref = system.simulate(s.t_span, q0={x: 0.1, th: math.pi / 6}, qd0={x: 0.0, th: 0.0},
                          params=params, t_eval=s.t_eval, **s.run_options())  # fmt: skip
    ours = s.simulate()
    np.testing.assert_allclose(ours.q, ref.q, rtol=0, atol=1e-13)
    np.testing.assert_allclose(ours.qd, ref.qd, rtol=0, atol=1e-13)
    assert {str(k): u for k, u in s.model.param_units.items()}["k"] == "N/m"
    assert s.quantities["lagrangian.q0.theta"]["value"] == pytest.approx(math.pi / 6, rel=1e-15)


BASE = """
[lagrangian]
coordinates = {{ x = "m" }}
parameters = {{ m = "1 kg", k = "4 N/m" }}
kinetic = "{kinetic}"
potential = "{potential}"
q0 = {{ x = {q0} }}
[time]
span = [0, 1]
"""


def _text(kinetic="m*x_dot^2/2", potential="k*x^2/2", q0="0.1"):
    return BASE.format(kinetic=kinetic, potential=potential, q0=q0)


@pytest.mark.parametrize(("change", "words"), [
    ({"potential": "__import__('os').system('echo hacked')"},
     "lagrangian.potential: calling anything but a function by its name is not allowed"),
    ({"potential": "__import__('os')"}, "lagrangian.potential: unknown function '__import__'"),
    ({"potential": "().__class__.__bases__"}, "an attribute is not allowed"),
    ({"potential": "k.real*x"}, "an attribute is not allowed"),
    ({"potential": "k*y^2"}, "lagrangian.potential: unknown name 'y'"),
    ({"potential": "kk*x^2"}, "did you mean 'k'?"),
    ({"potential": "snh(x)"}, "unknown function 'snh' (did you mean 'sinh'?)"),
    ({"kinetic": "m*x_dot^2/2 +"}, "lagrangian.kinetic: not an expression"),
    ({"q0": '"3 kg"'}, "lagrangian.q0.x = '3 kg': kg is [mass], not m"),
])  # fmt: skip
def test_code_and_mistakes_in_a_file_are_refused_by_name(change, words):
    with pytest.raises(ScenarioError) as err:
        load_scenario(_text(**change))
    assert words in str(err.value)


def test_nothing_in_an_expression_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = _text(potential="__import__('pathlib').Path('pwned').touch() or k*x^2/2")
    with pytest.raises(ScenarioError):
        load_scenario(text)
    assert not (tmp_path / "pwned").exists()


def test_the_tables_other_keys_are_checked(tmp_path):
    ok = load_scenario(_text())
    assert ok.model.system.coordinates[0].name == "x"
    for bad, words in (
        (_text().replace('coordinates = { x = "m" }', 'coordinates = { sin = "m" }'), "taken"),
        (_text().replace("q0 = { x = 0.1 }", "q0 = { y = 0.1 }"), "unknown coordinate"),
        (_text().replace('k = "4 N/m"', 'k = "4 N/m", x = 1'), "already a coordinate"),
        (_text() + '[lagrangian.draw]\nlinks = [["a", "b"]]\n', "expected two of the points"),
        (
            _text().replace("[time]", '[lagrangian.reactions.F]\nexpression = "lambda1"\n[time]'),
            "unknown name 'lambda1'",
        ),
    ):
        with pytest.raises(ScenarioError, match=words):
            load_scenario(bad)


def test_inputs_and_generalized_forces():
    """A driven, damped oscillator ``m ẍ = −k x − c ẋ + F sin t`` from inputs and forces, against
    SciPy's DOP853 on the same equation."""
    from scipy.integrate import solve_ivp

    text = _text().replace('parameters = { m = "1 kg", k = "4 N/m" }',
                           'parameters = { m = "1 kg", k = "4 N/m", c = "0.3 N*s/m", '
                           'F = "0.5 N" }\ninputs = { u = "F*sin(t)" }\n'
                           'forces = { x = "u - c*x_dot" }')  # fmt: skip
    s = load_scenario(text.replace("span = [0, 1]", "span = [0, 5]\nsamples = 11"))
    sol = s.simulate()
    ref = solve_ivp(
        lambda t, y: [y[1], -4 * y[0] - 0.3 * y[1] + 0.5 * np.sin(t)],
        (0, 5),
        [0.1, 0.0],
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        t_eval=sol.t,
    )
    np.testing.assert_allclose(sol.q[:, 0], ref.y[0], atol=1e-7)
