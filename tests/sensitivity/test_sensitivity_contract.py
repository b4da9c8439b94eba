"""The sensitivities through the run contract: how they are asked, refused, framed and
exported."""

import re

import numpy as np
import pytest
from scipy.io import netcdf_file
from scipy.spatial.transform import Rotation

from poinsot import RigidBody, simulate
from poinsot.forces import CustomForce, Gravity, Spring
from poinsot.integrate.base import Solver
from poinsot.simulation import prepare

BODY = RigidBody(2.0, [[2.0, 0.3, -0.1], [0.3, 3.0, 0.2], [-0.1, 0.2, 4.5]], (0.1, -0.2, 0.3))
Q0 = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()


class LieHeun(Solver):
    """A Lie-group method of the user's own (Heun's tableau, Munthe-Kaas): it runs, but its
    step has no derivative in the core."""

    name = "lie-heun"
    order = 2
    kind = "rkmk"
    A = np.array([[0.0, 0.0], [1.0, 0.0]])
    B = np.array([0.5, 0.5])
    C = np.array([0.0, 1.0])


def run(**kw):
    args = {"omega0": (0.4, -1.1, 0.7), "method": "rk4", "dt": 1e-2} | kw
    return simulate(BODY, (0, 1), **args)


def test_the_shapes_follow_the_outputs_and_the_parameters():
    traj = run(forces=[Gravity(), Spring((0, 0, 0), (0, 0, 1), 3.0)],
               sensitivities=("omega0", "inertia", "forces[1]", "forces[0].g"))  # fmt: skip
    n = len(traj)
    assert traj.sensitivity("omega", "omega0").shape == (n, 3, 3)
    assert traj.sensitivity("omega", "inertia").shape == (n, 3, 3)
    assert traj.sensitivity("Q", "forces[1]").shape == (n, 9, 9)  # point, anchor, k, ℓ0, c
    assert traj.sensitivity("R", "forces[0].g").shape == (n, 3, 3)
    assert traj.sensitivity("state").shape == (n, 18, 18)
    labels = traj.sensitivities.directions.labels
    assert labels[:3] == ("omega0[0]", "omega0[1]", "omega0[2]")
    assert "forces[1].stiffness" in labels and "forces[1].anchor[2]" in labels
    # at t0 the initial state's own derivatives
    assert np.abs(traj.sensitivity("omega", "omega0")[0] - np.eye(3)).max() < 1e-15
    assert not traj.sensitivity("omega", "inertia")[0].any()


def test_the_motion_is_the_plain_runs():
    # the augmented run's motion is the same equations by the same method (torque-free, the
    # plain run takes the free body's own stage-point RK4: equal to round-off)
    plain, sens = run(), run(sensitivities="omega0")
    assert np.abs(plain.state - sens.state).max() < 1e-13
    # RK4's and RKMK4's register steps and the splitting step on dual numbers: under forces
    # their values are the plain steps', bit for bit
    for method in ("rk4", "rkmk4", "splitting"):
        kw = {"method": method, "forces": [Gravity()], "pivot": (0.0, 0.0, -0.5)}
        plain, sens = run(**kw), run(**kw, sensitivities=("omega0", "inertia"))
        assert np.array_equal(plain.state, sens.state), method


def test_omega0_and_Q0_in_the_space_frame():
    # with omega_frame="space" the directions are those of the ω0 the run read
    def final(w, q):
        return run(omega0=w, Q0=q, omega_frame="space").state[-1]

    w0 = np.array([0.4, -1.1, 0.7])
    traj = run(omega0=w0, Q0=Q0, omega_frame="space", sensitivities=("omega0", "Q0"))
    S = traj.sensitivity("state")[-1]
    h = 1e-5
    for k in range(3):
        e = np.eye(3)[k]
        fd_w = (final(w0 + h * e, Q0) - final(w0 - h * e, Q0)) / (2 * h)
        turn = [Rotation.from_rotvec(s * h * e).as_matrix() @ Q0 for s in (1, -1)]
        fd_q = (final(w0, turn[0]) - final(w0, turn[1])) / (2 * h)
        assert np.abs(S[:, k] - fd_w).max() < 1e-8
        assert np.abs(S[:, 3 + k] - fd_q).max() < 1e-8


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"method": LieHeun, "dt": 0.1}, "'rk4', 'rkmk4', 'splitting'"),
        ({"sensitivities": "mass"}, "unknown parameter 'mass'"),
        ({"sensitivities": ("omega0", "omega0")}, "named twice"),
        ({"sensitivities": "forces[3]"}, "names force 3"),
        ({"sensitivities": "forces[0].k"}, "no parameter 'k'"),
        ({"sensitivities": ()}, "at least one"),
        ({"pivot": (0, 0, 0), "sensitivities": "R0"}, "no effect about a pivot"),
        ({"events": lambda t, y: y[0]}, "events"),
        ({"control_sensitivities": False, "sensitivities": None}, "no effect without"),
        ({"control_sensitivities": False}, "no effect with the fixed-step method 'rk4'"),
        ({"control_sensitivities": False, "method": "splitting"}, "fixed-step method"),
        ({"sensitivities": ("forces[0]", "forces[0].g")}, r"'forces\[0\]\.g\[0\]' of `sens"),
        ({"sensitivities": ("forces[0].g", "forces[00]")}, "asks again"),
    ],
)
def test_what_cannot_be_differentiated_is_refused_up_front(kw, match):
    kw = {"sensitivities": "omega0", "forces": [Gravity()]} | kw
    if kw["sensitivities"] is None:
        del kw["sensitivities"]
    with pytest.raises(ValueError, match=match):
        run(**kw)


def test_names_come_as_any_sequence_and_the_switch_is_a_bool():
    traj = run(sensitivities=np.array(["omega0", "inertia"]))
    assert traj.sensitivities.directions.names == ("omega0", "inertia")
    assert all(type(n) is str for n in traj.sensitivities.directions.names)
    with pytest.raises(TypeError, match="a name or a sequence of names"):
        run(sensitivities=123)
    with pytest.raises(TypeError, match="must be a name"):
        run(sensitivities=("omega0", 5))
    with pytest.raises(TypeError, match="True or False"):
        run(sensitivities="omega0", control_sensitivities="yes")
    # an unordered collection would order the columns by Python's string hashes
    for unordered in ({"omega0", "inertia"}, {"omega0": 1}, frozenset({"omega0"})):
        with pytest.raises(TypeError, match="ordered sequence"):
            run(sensitivities=unordered)
    kw = {"method": "dop853", "rtol": 1e-8, "sensitivities": "omega0"}
    assert (
        run(**kw, control_sensitivities=np.bool_(False)).nsteps
        == run(method="dop853", rtol=1e-8).nsteps
    )


def test_forces_evaluated_in_python_are_refused():
    custom = CustomForce(lambda t, R, V, Q, w: (np.zeros(3), np.zeros(3)))
    with pytest.raises(ValueError, match="evaluated in Python"):
        run(forces=[custom], sensitivities="omega0")


def test_asking_what_the_run_did_not_carry():
    with pytest.raises(ValueError, match="no sensitivities"):
        run().sensitivity("omega", "omega0")
    traj = run(sensitivities="omega0")
    with pytest.raises(ValueError, match="was not asked"):
        traj.sensitivity("omega", "inertia")
    # a column the name asked for does not have is named as such, with the ones it has
    with pytest.raises(ValueError, match=r"'omega0\[5\]': no such column; .*'omega0\[2\]'"):
        traj.sensitivity("omega", "omega0[5]")
    assert traj.sensitivity("omega", "omega0[2]").shape[-1] == 1
    # a name that covers more than was asked is refused, naming what was: 'forces' had
    # silently given the columns of 'forces[0].g'
    forced = run(forces=[Gravity()], sensitivities=("omega0", "forces[0].g"))
    for wrt in ("forces", "forces[0]"):
        with pytest.raises(ValueError, match=rf"`wrt` '{re.escape(wrt)}': this run asked only "
                                             r"part of it \('forces\[0\]\.g'\)"):  # fmt: skip
            forced.sensitivity("omega", wrt)
    assert forced.sensitivity("omega", "forces[0].g[2]").shape[-1] == 1
    with pytest.raises(ValueError, match="`output`"):
        traj.sensitivity("L", "omega0")
    with pytest.raises(ValueError, match="`output`"):
        traj.sensitivity(["omega"], "omega0")
    for wrt in (("omega0",), ["omega0"], 0):
        with pytest.raises(TypeError, match="`wrt` must be one name"):
            traj.sensitivity("omega", wrt)


def test_a_prepared_run_keeps_its_directions_and_refuses_a_method_without_them():
    p = prepare(BODY, (0, 1), method="rk4", dt=1e-2, sensitivities="inertia")
    a = p.run(omega0=(0, 1, 0.1)).sensitivity("omega", "inertia")
    b = p.with_method("dop853").run(omega0=(0, 1, 0.1)).sensitivity("omega", "inertia")
    assert np.abs(a[-1] - b[-1]).max() < 1e-7
    with pytest.raises(ValueError, match="'rk4', 'rkmk4', 'splitting'"):
        p.with_method(LieHeun)


def test_leaving_the_sensitivities_out_of_the_error_control():
    kw = {"method": "dop853", "rtol": 1e-9, "atol": 1e-12, "sensitivities": "omega0"}
    full = run(**kw)
    out = run(**kw, control_sensitivities=False)
    assert out.nsteps <= full.nsteps
    plain = run(method="dop853", rtol=1e-9, atol=1e-12)
    assert out.nsteps == plain.nsteps  # the steps of the motion alone
    assert np.abs(out.sensitivity("omega")[-1] - full.sensitivity("omega")[-1]).max() < 1e-6


def test_lyapunov_exponents_count_time_from_the_runs_start():
    # the derivatives are with respect to the state at t0 = 5, whether or not it is sampled
    kw = {"method": "dop853", "rtol": 1e-10, "atol": 1e-12, "sensitivities": "omega0"}
    box = RigidBody.box(1.0, (1, 2, 3))
    with_start = simulate(box, (5, 15), omega0=(0.01, 1, 0), t_eval=[5, 10, 15], **kw)
    without = simulate(box, (5, 15), omega0=(0.01, 1, 0), t_eval=[10, 15], **kw)
    np.testing.assert_allclose(without.lyapunov_exponents(), with_start.lyapunov_exponents()[1:],
                               rtol=1e-9)  # fmt: skip
    assert np.isnan(with_start.lyapunov_exponents()[0]).all()
    sigma = np.linalg.svd(without.sensitivity("omega", "omega0")[-1], compute_uv=False)
    np.testing.assert_allclose(without.lyapunov_exponents()[-1], np.log(sigma) / 10, rtol=1e-12)


def test_the_export_names_the_dimensions(tmp_path):
    traj = run(sensitivities=("omega0", "inertia"))
    path = tmp_path / "run.nc"
    traj.to_netcdf(path)
    with netcdf_file(path, mmap=False) as f:
        v = f.variables["sensitivity"]
        assert v.dimensions == ("time", "state_component", "parameter")
        assert np.array_equal(v[:], traj.sensitivity("state"))
        names = [b"".join(row).decode() for row in f.variables["parameter"][:]]
        assert names[3] == "inertia[0]"
        # what the columns are taken at: the initial state's time and ω0's frame
        assert v.t0 == 0.0 and v.omega0_frame == b"body"
    later = simulate(BODY, (0.5, 1), omega0=(0.4, -1.1, 0.7), method="rk4", dt=1e-2,
                     t_eval=[0.75, 1.0], omega_frame="space", sensitivities="omega0")  # fmt: skip
    later.to_netcdf(tmp_path / "later.nc")
    with netcdf_file(tmp_path / "later.nc", mmap=False) as f:
        v = f.variables["sensitivity"]
        assert v.t0 == 0.5 and v.omega0_frame == b"space"  # the first sample is at 0.75
    traj.to_csv(tmp_path / "run.csv")  # a table: the sensitivities stay out of it
    header = (tmp_path / "run.csv").read_text().splitlines()[0]
    assert "sensitivity" not in header


def test_the_npz_export_labels_the_sensitivitys_rows_and_columns(tmp_path):
    """The .npz wrote the sensitivity array without saying which row is which state
    component nor which column which parameter, labels the NetCDF export carries."""
    traj = run(sensitivities=("omega0", "inertia"))
    traj.to_npz(tmp_path / "run.npz")
    traj.to_netcdf(tmp_path / "run.nc")
    with np.load(tmp_path / "run.npz", allow_pickle=False) as npz:
        assert np.array_equal(npz["sensitivity"], traj.sensitivity("state"))
        rows, cols = npz["state_component"], npz["parameter"]
    assert rows.dtype.kind == cols.dtype.kind == "U"  # no pickle needed
    with netcdf_file(tmp_path / "run.nc", mmap=False) as f:
        for name, labels in (("state_component", rows), ("parameter", cols)):
            nc = [b"".join(row).decode() for row in f.variables[name][:]]
            assert labels.tolist() == nc
    assert cols.tolist() == list(traj.sensitivities.directions.labels)
    assert cols[0] == "omega0[0]" and cols[3] == "inertia[0]"
    assert rows.shape == (traj.sensitivity("state").shape[1],)
    assert rows[0] == "R_x" and rows[-1] == "omega_z"
