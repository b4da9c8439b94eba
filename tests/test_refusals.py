"""Clean refusals (issue 12, §2–§5): bad input is refused with a message that names the key or
argument and the rule it breaks; nothing is silently wrong; the API reads as SciPy and SymPy
users expect. The loader fuzz test: any bytes either load or raise ScenarioError."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from poinsot import RigidBody, simulate
from poinsot.app.scenario import ScenarioError, load_scenario
from scenario_texts import BOX_SCENARIO

BASE = BOX_SCENARIO
BOX = 'type = "box"\nmass = 1.0\nsize = [1.0, 2.0, 3.0]'


def _grid(counts):
    return BASE.replace(
        BOX, f'type = "particle_grid"\nupper = [1.0, 1.0, 1.0]\ncounts = {counts}\ntotal_mass = 1.0'
    )


# ----------------------------------------------------------------- §2 the loader
@pytest.mark.parametrize(
    ("text", "match"),
    [
        (b'name = "\xff\xfe"\n' + BASE.encode()[11:], r"not UTF-8 text: byte 0xff at line 1"),
        (BASE + "[analysis]\nx = " + "[" * 1000 + "]" * 1000 + "\n", "nested too deeply"),
        (_grid("[1e9, 1e9, 1e9]"), r"body\.counts: at most 1e\+07 particles"),
        (_grid("[9223372036854775807, 3, 3]"), r"body\.counts: at most 1e\+07 particles"),
        (BASE.replace("samples = 5", "samples = 10000000000"), r"time\.samples: at most 1e\+07"),
        (BASE + "[analysis]\nlevels = 1000000000\n", r"analysis\.levels: at most 200"),
        (BASE.replace("[0.0, 1.0]", "[-1e308, 1e308]"), r"time\.span: its length .* overflows"),
        (
            BASE + '[[forces]]\ntype = "central_gravity"\nmu = 1.0\ncenter = [0.0, 0.0, 0.0]\n',
            r"forces\[0\]: CentralGravity is undefined at the initial state",
        ),
        (
            BASE + '[[forces]]\ntype = "linear_drag"\ncoefficient = 0.1\n'
            '[integrator]\nmethod = "splitting"\ndt = 0.01\n',
            r"integrator\.method: `method` 'splitting' needs forces .* LinearDrag",
        ),
        (
            BASE.replace(
                BOX,
                "[[body.particles]]\nmass = 1.0\nposition = [0.0, 0.0, 0.0]\n"
                "[[body.particles]]\nmass = 1.0\nposition = [1.0, 0.0, 0.0]",
            ).replace(
                "omega = [0.0, 1.0, 0.1]",
                "particle_velocities = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]",
            ),
            r"initial\.particle_velocities: .* not a rigid motion",
        ),
        (BASE + "[analysis]\nenergy = 1e308\n", r"analysis\.energy: .* out of range"),
        (
            BASE.replace("size = [1.0, 2.0, 3.0]", "size = [1e200, 1.0, 1.0]"),
            r"body: the body's mass properties overflow",
        ),
        (
            BASE.replace(
                BOX,
                'type = "composite"\n[[body.parts]]\ntype = "sphere"\nmass = 1.0\n'
                "radius = 1.0\npivot = [0.0, 0.0, 1.0]",
            ),
            r"body\.parts\[0\]\.pivot: a pivot belongs to the whole body",
        ),
        (BASE + "[integrator]\natol = 0.0\n", r"integrator\.atol: expected a positive number"),
        (BASE + "[integrator]\nrtol = 1e154\n", r"integrator\.rtol: expected a number in \(0, 1\)"),
        (BASE.replace("omega =", "omgea ="), r"initial\.omgea: unknown key; did you mean 'omega'"),
        (BASE.replace("[time]", "[tmie]"), r"tmie: unknown key; did you mean 'time'"),
        (
            '[model]\nname = "double-pendulum"\nparams = {m1 = 0.0, m2 = 0.0}\n'
            "[time]\nspan = [0.0, 1.0]\n",
            r"model: `params\[m1\]` must be positive \(m1 is declared positive\), found 0",
        ),
        (
            '[model]\nname = "pendulum-cartesian"\nparams = {m = 1.0, g = 9.81, l = -1.0}\n'
            "[time]\nspan = [0.0, 1.0]\n",
            r"model: `params\[l\]` must be positive \(l is declared positive\), found -1",
        ),
    ],
)
def test_loader_refuses_with_the_key(tmp_path, text, match):
    path = tmp_path / "s.toml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(ScenarioError, match=match):
        load_scenario(path)


def test_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "s.toml"
    path.write_bytes(b"\xef\xbb\xbf" + BASE.encode())
    assert load_scenario(path).name == "t"


def test_mesh_without_trimesh(tmp_path, monkeypatch):
    (tmp_path / "b.stl").write_bytes(b"solid x\nendsolid x\n")
    monkeypatch.setitem(sys.modules, "trimesh", None)  # `import trimesh` raises ImportError
    path = tmp_path / "s.toml"
    path.write_text(BASE.replace(BOX, 'type = "mesh"\npath = "b.stl"'))
    with pytest.raises(ScenarioError, match=r"body\.path: reading mesh files needs trimesh"):
        load_scenario(path)


def test_unreadable_and_non_finite_meshes(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    garbage = tmp_path / "g.stl"
    garbage.write_bytes(np.random.default_rng(1).bytes(3000))
    with pytest.raises(ValueError, match="not a readable triangle mesh"):
        RigidBody.from_mesh(garbage)
    box = trimesh.creation.box()
    v = box.vertices.copy()
    v[0, 0] = np.nan
    trimesh.Trimesh(v, box.faces, process=False).export(tmp_path / "nan.stl")
    with pytest.raises(ValueError, match="non-finite vertices"):
        RigidBody.from_mesh(tmp_path / "nan.stl")


def test_tiny_semi_axis_and_huge_mass_run_without_a_crash(tmp_path):
    """Moments near 1e300: the run completes; the torque-free figures are left out, said."""
    import warnings

    from poinsot.app.job import run_scenario

    text = BASE.replace(BOX, 'type = "ellipsoid"\nmass = 1e300\nsemi_axes = [5e-324, 1.0, 1.0]')
    with pytest.warns(UserWarning, match="torque-free analysis and polhodes left out"):
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)  # no overflow on the way
            summary = run_scenario(load_scenario(text), tmp_path / "o")
    assert "torque_free" not in summary
    assert (tmp_path / "o" / "body.png").exists() and (tmp_path / "o" / "report.html").exists()


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.one_of(
        st.binary(max_size=400),
        st.builds(
            lambda cut, junk: BASE.encode()[:cut] + junk + BASE.encode()[cut:],
            st.integers(0, len(BASE)),
            st.binary(max_size=20),
        ),
        st.builds(
            lambda cut, text: BASE[:cut] + text + BASE[cut:],
            st.integers(0, len(BASE)),
            st.text(alphabet='[]{}=."\n0123456789e-+ abcdefghijklmnopqrstuvwxyz', max_size=30),
        ),
    )
)
def test_loader_fuzz_either_loads_or_names_a_key(data):
    """For any bytes: a scenario, or ScenarioError whose message names the source and a key or
    the rule — never another exception."""
    try:
        scenario = load_scenario(data)
    except ScenarioError as exc:
        label = "<bytes>:" if isinstance(data, bytes) else "<built-in>:"  # and a TOML error's
        assert str(exc).startswith(label)  # line and column, "<bytes>:3:7: TOML syntax error"
        assert len(str(exc)) > len(label) + 5
    else:
        assert scenario.name


# ----------------------------------------------------------------- §3 silently wrong → refused
BODY = RigidBody.box(1.0, (1.0, 2.0, 3.0))


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"atol": 0.0}, ValueError, r"`atol` must be a positive number"),
        ({"atol": True}, TypeError, r"`atol` must be a real number, found bool"),
        ({"rtol": 1e154}, ValueError, r"`rtol` must be below 1"),
        ({"rtol": {}}, TypeError, r"`rtol` must be a real number, found dict"),
        ({"t_eval": [0.0, np.inf]}, ValueError, r"`t_eval\[1\]` must be finite"),
        ({"Q0": {"w": 1}}, TypeError, r"`Q0` must be numeric, found dict"),
        ({"Q0": object()}, TypeError, r"`Q0` must be numeric, found object"),
        ({"Q0": [[1, 0], [0, 1, 0]]}, ValueError, r"`Q0` must be a regular array .* ragged"),
        ({"Q0": [2.0, 0, 0, 0]}, ValueError, r"quaternion \(w, x, y, z\), scalar first"),
        ({"omega0": (0, 1j, 0)}, TypeError, r"`omega0` must be real, found complex"),
        ({"omega0": np.array([0, 1 + 1j, 0])}, TypeError, r"`omega0` must be real"),
        ({"dt": -1.0, "method": "rk4"}, ValueError, r"`dt` must be a positive number"),
    ],
)
def test_simulate_refuses_named(kwargs, error, match):
    args = {"omega0": (0.0, 1.0, 0.1), **kwargs}
    with pytest.raises(error, match=match):
        simulate(BODY, (0.0, 1.0), **args)


def test_overflowing_bodies_are_refused():
    with pytest.raises(ValueError, match="mass properties overflow"):
        RigidBody.box(1.0, (1e200, 1.0, 1.0))
    with pytest.raises(ValueError, match="mass properties overflow"):
        RigidBody.from_particles([1e308, 1e308], [[0, 0, 0], [1, 0, 0]])


def test_complex_masses_are_refused():
    with pytest.raises(TypeError, match=r"`masses` must be real"):
        RigidBody.from_particles(np.array([1.0 + 0j, 2.0]), [[0, 0, 0], [1, 0, 0]])


# ----------------------------------------------------------------- §5 SciPy's conventions
def test_rotation_objects_and_scalar_last_quaternions():
    from scipy.spatial.transform import Rotation

    R = Rotation.from_euler("zxz", [0.3, 0.4, 0.5])
    w0 = (0.1, 1.0, 0.2)
    ref = simulate(BODY, (0, 1), omega0=w0, Q0=R.as_matrix())
    by_object = simulate(BODY, (0, 1), omega0=w0, Q0=R)
    by_scalar_last = simulate(BODY, (0, 1), omega0=w0, Q0=R.as_quat(), scalar_first=False)
    w, x, y, z = np.roll(R.as_quat(), 1)
    by_scalar_first = simulate(BODY, (0, 1), omega0=w0, Q0=[w, x, y, z])
    for other in (by_object, by_scalar_last, by_scalar_first):
        np.testing.assert_allclose(other.Q, ref.Q, atol=1e-14)


def test_scalar_first_without_a_quaternion_is_refused():
    """``scalar_first`` orders a quaternion's numbers: beside a matrix, a Rotation, no ``Q0``
    or a whole state ``y0`` it has no effect, and is refused."""
    from scipy.spatial.transform import Rotation

    from poinsot.simulation import prepare

    w0 = (0.1, 1.0, 0.2)
    for Q0, what in ((np.eye(3), r"has shape \(3, 3\)"), (Rotation.identity(), "Rotation"),
                     (None, "none is given")):  # fmt: skip
        with pytest.raises(
            ValueError, match=f"`scalar_first` applies to a quaternion `Q0`.*{what}"
        ):
            simulate(BODY, (0, 1), omega0=w0, Q0=Q0, scalar_first=False)
    p = prepare(BODY, (0, 1))
    with pytest.raises(ValueError, match="`scalar_first` has no effect with `y0`"):
        p.run(y0=p.initial_state(omega0=w0), scalar_first=False)


def test_method_names_are_case_insensitive_and_trajectory_reports_success():
    traj = simulate(BODY, (0, 1), omega0=(0, 1, 0.1), method="DOP853")
    assert traj.success is True and isinstance(traj.message, str)


# ----------------------------------------------------------------- Lagrangian boundary
@pytest.fixture(scope="module")
def pendulum():
    from poinsot.models import MODELS

    return MODELS["pendulum-cartesian"]()


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"t_eval": [0.5, 0.2]}, ValueError, r"`t_eval` must be strictly increasing"),
        ({"t_eval": [0.5, 2.0]}, ValueError, r"`t_eval` must lie within t_span"),
        ({"t_eval": 0.5}, ValueError, r"`t_eval` must have shape \(N,\)"),
        ({"dt": ""}, TypeError, r"`dt` must be a real number, found str"),
        ({"params": 5}, TypeError, r"`params` must be a dict"),
        ({"params": {"gravity": 9.8}}, ValueError, r"'gravity' is not a parameter"),
        ({"atol": 0.0}, ValueError, r"`atol` must be a positive number"),
    ],
)
def test_lagrangian_simulate_refuses_named(pendulum, kwargs, error, match):
    args = {"q0": pendulum.q0, "qd0": pendulum.qd0, "params": pendulum.params, **kwargs}
    with pytest.raises(error, match=match):
        pendulum.system.simulate((0.0, 1.0), **args)


def test_lagrangian_params_by_name(pendulum):
    by_symbol = pendulum.system.simulate((0, 1), q0=pendulum.q0, qd0=pendulum.qd0,
                                         params=pendulum.params)  # fmt: skip
    by_name = pendulum.system.simulate(
        (0, 1),
        q0=pendulum.q0,
        qd0=pendulum.qd0,
        params={str(k): v for k, v in pendulum.params.items()},
    )
    np.testing.assert_array_equal(by_symbol.q, by_name.q)


def test_lagrangian_system_arguments():
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols

    from poinsot.lagrange import LagrangianSystem

    with pytest.raises(TypeError, match=r"`coordinates` must be a sequence"):
        LagrangianSystem(None)
    x, y = dynamicsymbols("x y")
    m, g, l = sp.symbols("m g l", positive=True)
    T = m * (x.diff() ** 2 + y.diff() ** 2) / 2
    by_eq = LagrangianSystem([x, y], kinetic=T, potential=m * g * y,
                             holonomic=[sp.Eq(x**2 + y**2, l**2)])  # fmt: skip
    assert sp.simplify(by_eq.holonomic[0] - (x**2 + y**2 - l**2)) == 0
    with pytest.raises(TypeError, match=r"`holonomic\[0\]` must be an expression"):
        LagrangianSystem([x, y], kinetic=T, holonomic=[x > 0])


def test_a_huge_quaternion_is_refused_without_a_warning():
    # its norm overflows to inf: the refusal says so, and numpy's overflow warning (found by
    # the rigid-body fuzz test) does not reach the user
    import warnings

    body = RigidBody.box(1.0, (1.0, 2.0, 3.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=r"`Q0` is not a rotation: .* norm inf"):
            simulate(body, (0, 1), omega0=(0, 1, 1), Q0=(1e300, 1e300, 0.0, 0.0))


def test_an_omega_whose_square_overflows_fails_cleanly():
    """ω = 1e200: Euler's equation overflows at the start; the run is refused up front naming
    the rate (it had been left to the step-size control, "the step size fell below the
    resolution of t = 0"), and no numpy overflow warning escapes on the way (the
    degenerate-spin check used |ω|²)."""
    import warnings

    import numpy as np

    from poinsot import RigidBody, simulate

    body = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        for w in (1e200, 1e308):
            with pytest.raises(ValueError, match="the rate of omega is not finite at the initial"):
                simulate(body, (0, 1), omega0=(w, w, w), method="dop853")


def test_a2_over_2k_of_huge_moments_is_finite():
    """Moments of about 1e154: a² overflowed and summary.json said "inf" (true: 2.0e154);
    a²/2k is now a · (a / 2k), checked against the closed form D = Σ I²ω² / Σ Iω²."""
    from poinsot.app.runs.rigid import RigidRun

    text = BASE.replace(BOX, 'type = "box"\nmass = 1e154\nsize = [1.0, 2.0, 3.0]')
    run = RigidRun(load_scenario(text))
    run.simulate()
    summary = run.summarise()
    I = np.diag(run.scenario.body.inertia)
    w = run.result.omega[0]
    expected = float(np.sum((I / 1e154) ** 2 * w**2) / np.sum((I / 1e154) * w**2)) * 1e154
    assert summary["initial"]["a2_over_2k"] == pytest.approx(expected, rel=1e-12)


def test_energy_drift_of_a_huge_velocity_is_finite():
    """V0 ≈ 1e217: the energy overflows (M V²/2 > 1.8e308) and the drift was NaN; it is
    computed on the scaled energy E/s², and equals the drift of the same run at V0 = 1."""
    body = RigidBody.box(2.0, (1, 2, 3))
    huge = simulate(body, (0, 1), omega0=(0, 0, 0), V0=(1e217, 0, 0), method="rk4", dt=0.01)
    assert not np.isfinite(huge.total_energy).any()
    unit = simulate(body, (0, 1), omega0=(0, 0, 0), V0=(1.0, 0, 0), method="rk4", dt=0.01)
    assert huge.diagnostics()["energy_drift"] == unit.diagnostics()["energy_drift"] == 0.0


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ("[body]\ntype = 'box'\nsize = [1.0, 2.0\n", "s.toml:4:1: TOML syntax error: Unclosed "
                                                     "array (at the end of the file)"),
        ('name = "t\n', "s.toml:1:10: TOML syntax error: Illegal character"),
        ("[body\n", "s.toml:1:6: TOML syntax error"),
        ("x = " + "[" * 3000 + "]" * 3000 + "\n", "s.toml:1:3004: arrays or tables are nested "
                                                   "too deeply"),
    ],
)  # fmt: skip
def test_a_toml_error_gives_the_file_line_and_column(tmp_path, text, where):
    """142 of 167 unclear refusals of the campaign were TOML errors without a place."""
    path = tmp_path / "s.toml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    assert str(err.value).startswith(str(tmp_path / where.split(":")[0]))
    assert where.split(" ", 1)[0].split("s.toml")[1] in str(err.value)
    assert where.split(" ", 1)[1] in str(err.value)
