"""simulate_ensemble: every member equals a single-body simulate of it; chunking, threads and
Dask change nothing; reductions equal the statistics of stored trajectories; bad input named.

Independent routes: :func:`poinsot.simulate` one member at a time (the single-body engine),
:class:`~poinsot.trajectory.Trajectory`'s own diagnostics, the exact torque-free solution
(:class:`~poinsot.torquefree.FreeRigidBody`), and the exact flip interval.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poinsot import RigidBody, simulate
from poinsot.ensemble import STATISTICS, simulate_ensemble
from poinsot.forces import (
    CentralGravity,
    Gravity,
    LinearDrag,
    PointForce,
    QuadraticDrag,
    Spring,
    Torque,
)
from poinsot.torquefree import FreeRigidBody

N = 13
T_END = 2.0
T_EVAL = np.linspace(0.0, T_END, 5)
BODY = RigidBody(2.0, np.diag([1.0, 2.0, 3.0]), center_of_mass=(0.1, 0.2, 0.3))
RNG = np.random.default_rng(42)
W0 = RNG.normal(size=(N, 3))
Q0 = Rotation.random(N, random_state=4).as_matrix()
MOMENTS = RNG.uniform(1.0, 2.0, (N, 3))
SYMMETRIC_MOMENTS = MOMENTS[:, [0, 0, 2]]  # symmetric about the third axis
# every other member symmetric: a block of lanes whose free rotors take both branches
MIXED_MOMENTS = np.where((np.arange(N) % 2 == 0)[:, None], SYMMETRIC_MOMENTS, MOMENTS)

# every built-in force but the gravities at once: a damped tether, quadratic drag, a
# body-fixed thrust at a body point, a couple fixed in space
TETHERED = [
    Spring((0.5, 0, 0), (1, 1, 1), 3.0, 0.5, damping=0.2, tether=True),
    QuadraticDrag(0.05, 0.02),
    PointForce((0.0, 0.2, 0.0), (0.3, 0.0, 0.1), frame="body"),
    Torque((0.05, 0.0, 0.02), frame="space"),
]

# the forces a kick can take (position and attitude only): an undamped tether, gravity, a
# body-fixed thrust at a body point, a couple fixed in space
KICKED = [
    Spring((0.5, 0, 0), (1, 1, 1), 3.0, 0.5, tether=True),
    Gravity((0.0, 0.0, -9.8)),
    PointForce((0.0, 0.2, 0.0), (0.3, 0.0, 0.1), frame="body"),
    Torque((0.05, 0.0, 0.02), frame="space"),
]

CASES = {
    "free rk4": {"method": "rk4", "dt": 1e-2},
    "free dop853": {"method": "dop853"},
    "free splitting": {"method": "splitting", "dt": 1e-2},
    "free rkmk4": {"method": "rkmk4", "dt": 1e-2},
    "heavy top rk4": {
        "method": "rk4",
        "dt": 1e-2,
        "pivot": (0.0, 0.0, 0.0),
        "forces": [Gravity((0.0, 0.0, -9.8))],
    },
    "spring dop853": {"method": "dop853", "forces": [Spring((0.5, 0, 0), (1, 1, 1), 3.0)]},
    "heavy top dop853": {
        "method": "dop853",
        "pivot": (0.0, 0.0, 0.0),
        "forces": [Gravity((0.0, 0.0, -9.8))],
    },
    "own moments rk4": {"method": "rk4", "dt": 1e-2, "moments": MOMENTS},
    "own moments rkmk4": {"method": "rkmk4", "dt": 1e-2, "moments": MOMENTS},
    "own moments splitting": {"method": "splitting", "dt": 1e-2, "moments": MOMENTS},
    "own moments dop853": {"method": "dop853", "moments": MOMENTS},
    "heavy top rkmk4": {
        "method": "rkmk4",
        "dt": 1e-2,
        "pivot": (0.0, 0.0, 0.0),
        "forces": [Gravity((0.0, 0.0, -9.8))],
    },
    "heavy top splitting": {
        "method": "splitting",
        "dt": 1e-2,
        "pivot": (0.0, 0.0, 0.0),
        "forces": [Gravity((0.0, 0.0, -9.8))],
    },
    "satellite rk4": {"method": "rk4", "dt": 1e-2, "forces": [CentralGravity(400.0, (-20, 0, 0))]},
    "satellite rkmk4": {
        "method": "rkmk4",
        "dt": 1e-2,
        "forces": [CentralGravity(400.0, (-20, 0, 0))],
    },
    "satellite splitting": {
        "method": "splitting",
        "dt": 1e-2,
        "forces": [CentralGravity(400.0, (-20, 0, 0))],
    },
    "satellite dop853": {"method": "dop853", "forces": [CentralGravity(400.0, (-20, 0, 0))]},
    "symmetric heavy top splitting": {
        "method": "splitting",
        "dt": 1e-2,
        "pivot": (0.0, 0.0, 0.0),
        "forces": [Gravity((0.0, 0.0, -9.8))],
        "moments": SYMMETRIC_MOMENTS,
    },
    "pivot alone rkmk4": {"method": "rkmk4", "dt": 1e-2, "pivot": (0.0, 0.0, 0.0)},
    "gravity and drag rkmk4": {
        "method": "rkmk4",
        "dt": 1e-2,
        "pivot": (0.0, 0.0, 0.0),
        "forces": [Gravity((0.0, 0.0, -9.8)), LinearDrag(0.1, 0.05)],
    },
    "tethered rk4": {"method": "rk4", "dt": 1e-2, "forces": TETHERED},
    "tethered dop853": {"method": "dop853", "forces": TETHERED},
    "tethered own moments rk4": {
        "method": "rk4",
        "dt": 1e-2,
        "forces": TETHERED,
        "moments": MOMENTS,
    },
    "tethered rkmk4": {"method": "rkmk4", "dt": 1e-2, "forces": TETHERED},
    "kicked splitting": {"method": "splitting", "dt": 1e-2, "forces": KICKED},
    "symmetric kicked splitting": {
        "method": "splitting",
        "dt": 1e-2,
        "forces": KICKED,
        "moments": SYMMETRIC_MOMENTS,
    },
    "mixed rotors kicked splitting": {
        "method": "splitting",
        "dt": 1e-2,
        "forces": KICKED,
        "moments": MIXED_MOMENTS,
    },
    "mixed rotors heavy top splitting": {
        "method": "splitting",
        "dt": 1e-2,
        "pivot": (0.0, 0.0, 0.0),
        "forces": [Gravity((0.0, 0.0, -9.8))],
        "moments": MIXED_MOMENTS,
    },
    "pivot and couples splitting": {
        "method": "splitting",
        "dt": 1e-2,
        "pivot": (0.0, 0.0, 0.0),
        "forces": [
            Torque((0.0, 0.1, 0.0)),
            Gravity((0.0, 0.0, -9.8)),
            Torque((0.2, 0, 0), frame="space"),
        ],
    },
    "pivot and couples dop853": {
        "method": "dop853",
        "pivot": (0.0, 0.0, 0.0),
        "forces": [
            Torque((0.0, 0.1, 0.0)),
            Gravity((0.0, 0.0, -9.8)),
            Torque((0.2, 0, 0), frame="space"),
        ],
    },
}


def _single(case, i, t_eval=T_EVAL):
    kw = dict(CASES[case])
    moments = kw.pop("moments", None)
    body = BODY if moments is None else RigidBody(2.0, np.diag(moments[i]), BODY.center_of_mass)
    return simulate(body, (0, T_END), omega0=W0[i], Q0=Q0[i], t_eval=t_eval, **kw)


def _ensemble(case, **extra):
    kw = {"progress": False, **CASES[case], **extra}
    return simulate_ensemble(BODY, (0, T_END), omega0=W0, Q0=Q0, **kw)


@pytest.mark.parametrize("case", list(CASES))
def test_every_member_equals_a_single_simulate(case):
    res = _ensemble(case, t_eval=T_EVAL, chunk_size=5, threads=2)
    assert res.success.all() and res.state.shape == (N, len(T_EVAL), 18)
    for i in (0, 6, N - 1):
        tr = _single(case, i)
        np.testing.assert_allclose(
            res.state[i], tr.state, rtol=0, atol=2e-15 * np.abs(tr.state).max()
        )
        # reductions equal the statistics of the stored trajectory
        assert res.energy_error[i] == pytest.approx(
            np.abs(tr.energy_drift).max(), rel=1e-12, abs=1e-15
        )
        assert res.momentum_error[i] == pytest.approx(tr.momentum_drift.max(), rel=1e-12, abs=1e-15)
        assert res.orthogonality_error[i] == pytest.approx(
            tr.orthogonality_error.max(), rel=1e-12, abs=1e-16
        )
        assert res.nsteps[i] == tr.nsteps


@pytest.mark.parametrize(
    "case",
    [
        "free rk4",
        "heavy top rk4",
        "own moments rk4",
        "free rkmk4",
        "own moments rkmk4",
        "free splitting",
        "own moments splitting",
        "heavy top rkmk4",
        "heavy top splitting",
        "satellite rk4",
        "satellite rkmk4",
        "satellite splitting",
        "satellite dop853",
        "symmetric heavy top splitting",
        "pivot alone rkmk4",
        "gravity and drag rkmk4",
        "free dop853",
        "own moments dop853",
        "spring dop853",
        "heavy top dop853",
        "tethered rk4",
        "tethered dop853",
        "tethered own moments rk4",
        "tethered rkmk4",
        "kicked splitting",
        "symmetric kicked splitting",
        "mixed rotors kicked splitting",
        "mixed rotors heavy top splitting",
        "pivot and couples splitting",
        "pivot and couples dop853",
    ],
)
def test_members_in_simd_lanes_equal_their_single_runs(case):
    """Members run in blocks of SIMD lanes (the core's ``lanes``: 64 members a block, a short
    last block padded): free bodies with every method; one uniform or central gravity, or a
    pivot alone, with every method (the force's kind compiled into the lanes); other forces,
    one or several, with every method (each force for the whole block at once; the stages of
    RK4 and RKMK4 and the kicks of the splitting method formed across the lanes; the free
    rotor's branch per lane where a block mixes symmetric and triaxial members). Every
    member equals its single ``simulate`` bit for bit, and chunks of 40 or 7 (the latter too
    few for lanes: member by member) change nothing, step counts included."""
    n = 150
    rng = np.random.default_rng(7)
    w0 = rng.normal(size=(n, 3))
    q0 = Rotation.random(n, random_state=8).as_matrix()
    kw = {"progress": False, **CASES[case]}
    moments = kw.pop("moments", None)
    if moments is not None:
        symmetric = moments is SYMMETRIC_MOMENTS
        mixed = moments is MIXED_MOMENTS
        moments = rng.uniform(1.0, 2.0, (n, 3))
        if symmetric:
            moments[:, 1] = moments[:, 0]
        if mixed:
            moments[::2, 1] = moments[::2, 0]
        kw["moments"] = moments
    runs = [simulate_ensemble(BODY, (0, T_END), omega0=w0, Q0=q0, t_eval=T_EVAL, chunk_size=c,
                              threads=th, **kw) for c, th in ((n, 2), (40, 1), (7, 2))]  # fmt: skip
    for other in runs[1:]:
        np.testing.assert_array_equal(other.state, runs[0].state)
        np.testing.assert_array_equal(other.flip_count, runs[0].flip_count)
        np.testing.assert_array_equal(other.nsteps, runs[0].nsteps)
        np.testing.assert_array_equal(other.nfev, runs[0].nfev)
    kw.pop("moments", None)
    for i in (0, 63, 64, 77, 127, 128, n - 1):
        body = BODY if moments is None else RigidBody(2.0, np.diag(moments[i]),
                                                      BODY.center_of_mass)  # fmt: skip
        tr = simulate(body, (0, T_END), omega0=w0[i], Q0=q0[i], t_eval=T_EVAL,
                      **{k: v for k, v in kw.items() if k != "progress"})  # fmt: skip
        np.testing.assert_array_equal(runs[0].state[i], tr.state)


@pytest.mark.parametrize("case", ["free rk4", "heavy top rk4", "free dop853"])
def test_chunks_and_threads_change_nothing(case):
    """Bit for bit: one chunk on one thread, small chunks on two threads, final-only."""
    one = _ensemble(case, t_eval=T_EVAL, chunk_size=N, threads=1)
    many = _ensemble(case, t_eval=T_EVAL, chunk_size=3, threads=2)
    np.testing.assert_array_equal(one.state, many.state)
    for name in STATISTICS:
        np.testing.assert_array_equal(one.statistic(name), many.statistic(name))
    final = _ensemble(case, chunk_size=4, threads=2)
    np.testing.assert_array_equal(final.t, [T_END])
    # no intermediate samples to land on: other steps, the same end to round-off
    scale = np.abs(one.state).max()
    np.testing.assert_allclose(final.state[:, 0], one.state[:, -1], rtol=0, atol=1e-13 * scale)


def test_final_only_and_keep_states_false():
    res = _ensemble("free rk4", keep_states=False)
    assert res.final_state.shape == (N, 18)
    with pytest.raises(AttributeError, match="keep_states=False"):
        res.omega
    tr = _single("free rk4", 3, t_eval=None)
    np.testing.assert_array_equal(res.final_omega[3], tr.omega[-1])


def test_flips_against_the_exact_flip_interval():
    """Members near the intermediate axis flip every 2K(m)/λ (exact); RK4 at dt = 1e-3 finds
    the flip times to O(dt²)."""
    body = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
    free = FreeRigidBody((1.0, 2.0, 3.0))
    rng = np.random.default_rng(0)
    W = np.c_[rng.normal(0, 0.05, 40), np.ones(40), rng.normal(0, 0.05, 40)]
    res = simulate_ensemble(body, (0, 60.0), omega0=W, dt=1e-3, progress=False)
    exact = free.flip_interval(W)
    ok = res.flip_count >= 3
    assert ok.sum() > 30
    np.testing.assert_allclose(res.flip_interval[ok], exact[ok], rtol=1e-5)
    expected_count = np.floor((60.0 - res.first_flip) / exact) + 1
    assert np.all(np.abs(res.flip_count - expected_count)[ok] <= 1)


def test_grading_against_the_exact_solution():
    res = simulate_ensemble(
        BODY,
        (0, 5.0),
        omega0=W0,
        Q0=Q0,
        method="dop853",
        rtol=1e-12,
        atol=1e-14,
        t_eval=np.linspace(0, 5, 11),
        progress=False,
    )
    err = res.exact_errors()
    assert err["omega"].max() < 1e-9 and err["attitude"].max() < 1e-9
    own = simulate_ensemble(
        BODY,
        (0, 5.0),
        omega0=W0,
        moments=MOMENTS,
        method="rk4",
        dt=1e-2,
        t_eval=np.linspace(0, 5, 11),
        progress=False,
    )
    err = own.exact_errors()
    assert 1e-12 < err["omega"].max() < 1e-5  # RK4's O(dt⁴) error, measured


def test_user_reductions_compiled_and_python():
    numba = pytest.importorskip("numba", reason="a user's own numba function (no dependency)")

    @numba.njit
    def spin_z(t, y):
        return y[17]

    def mean_speed(chunk):
        return np.linalg.norm(chunk.omega, axis=2).mean(axis=1)

    res = _ensemble(
        "free rk4",
        t_eval=T_EVAL,
        chunk_size=4,
        reductions={"spin_z": spin_z, "mean_speed": mean_speed},
    )
    np.testing.assert_array_equal(res.reductions["spin_z"], res.omega[:, :, 2])
    np.testing.assert_allclose(
        res.reductions["mean_speed"], np.linalg.norm(res.omega, axis=2).mean(axis=1)
    )
    assert "mean_speed" in res.summary()["statistics"]


def test_summary_and_xarray():
    res = _ensemble("free rk4", t_eval=T_EVAL)
    summary = res.summary()
    assert summary["members"] == N and summary["succeeded"] == N
    assert summary["statistics"]["energy_error"]["max"] == pytest.approx(res.energy_error.max())
    assert "angle_from_mean" in summary["final_attitude"]
    ds = res.to_xarray()
    assert ds["omega"].dims == ("member", "time", "component")
    np.testing.assert_array_equal(ds["omega"].values, res.omega)
    q = res.quaternion
    assert q.shape == (N, len(T_EVAL), 4)
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-12)


def test_progress_callback_counts_members():
    seen = []
    _ensemble("free rk4", chunk_size=4, threads=1, progress=lambda done, total: seen.append(done))
    assert seen == [4, 8, 12, 13]


def test_a_member_that_fails_gets_its_own_status():
    """A member whose state overflows stops alone; its block-mates finish unchanged."""
    W = W0.copy()
    W[5] = [1e200, 1e200, 1e200]
    res = simulate_ensemble(BODY, (0, 1.0), omega0=W, dt=1e-2, progress=False)
    assert not res.success[5] and res.success[np.arange(N) != 5].all()
    assert np.isnan(res.final_state[5]).all()
    good = simulate_ensemble(BODY, (0, 1.0), omega0=W0, dt=1e-2, progress=False)
    keep = np.arange(N) != 5
    np.testing.assert_array_equal(res.final_state[keep], good.final_state[keep])
    assert res.summary()["failed"] == {"non-finite state": 1}


# --------------------------------------------------------------------------- Dask
@pytest.fixture(scope="module")
def dask_client():
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(
        processes=False, n_workers=2, threads_per_worker=1, dashboard_address=None
    )
    client = distributed.Client(cluster)
    yield client
    client.close(timeout=30)
    cluster.close(timeout=30)


@pytest.mark.parametrize("case", ["free rk4", "spring dop853"])
def test_dask_is_bit_identical_to_the_local_run(dask_client, case):
    local = _ensemble(case, t_eval=T_EVAL, chunk_size=4)
    remote = _ensemble(case, t_eval=T_EVAL, chunk_size=4, client=dask_client)
    np.testing.assert_array_equal(local.state, remote.state)
    np.testing.assert_array_equal(local.energy_error, remote.energy_error)
    np.testing.assert_array_equal(local.first_flip, remote.first_flip)


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"omega0": np.ones((N, 2))}, ValueError, r"`omega0` must have shape \(N, 3\)"),
        ({"omega0": np.ones(3)}, ValueError, r"`omega0` must have shape \(N, 3\)"),
        ({"Q0": np.stack([np.eye(3)] * (N - 1))}, ValueError, rf"`Q0` .*\({N}, 3, 3\)"),
        ({"R0": np.ones((N + 1, 3))}, ValueError, rf"`R0` must have shape \(3,\) or \({N}, 3\)"),
        ({"moments": np.ones((N, 2))}, ValueError, rf"`moments` must have shape \({N}, 3\)"),
        ({"inertia": np.ones((N, 3))}, ValueError, rf"`inertia` must have shape \({N}, 3, 3\)"),
        ({"method": "rk4", "dt": None}, ValueError, r"'rk4' is fixed-step: `dt` must be given"),
        ({"client": object()}, ValueError, r"`client` must be a dask.distributed.Client"),
        ({"chunk_size": 0}, ValueError, r"`chunk_size` must be a positive integer"),
        ({"threads": 0}, ValueError, r"`threads` must be a positive integer"),
        ({"t_eval": [0.5, 0.2]}, ValueError, r"`t_eval` must be strictly increasing"),
        ({"t_eval": [0.0, np.inf]}, ValueError, r"`t_eval\[1\]` must be finite"),
    ],
)
def test_bad_input_is_named(kwargs, error, match):
    base = {"omega0": W0, "method": "rk4", "dt": 1e-2, "progress": False}
    with pytest.raises(error, match=match):
        simulate_ensemble(BODY, (0, 1.0), **{**base, **kwargs})


def test_bad_member_entries_are_named_with_their_index():
    W = W0.copy()
    W[7, 2] = np.inf
    with pytest.raises(ValueError, match=r"`omega0\[7\]\[2\]` must be finite"):
        simulate_ensemble(BODY, (0, 1.0), omega0=W, dt=1e-2)
    Q = Q0.copy()
    Q[4] *= 1.5
    with pytest.raises(ValueError, match=r"`Q0\[4\]` is not a rotation"):
        simulate_ensemble(BODY, (0, 1.0), omega0=W0, Q0=Q, dt=1e-2)
    q = np.tile([1.0, 0, 0, 0], (N, 1))
    q[9] = [1.0, 1.0, 0, 0]
    with pytest.raises(
        ValueError, match=r"`Q0\[9\]` is not a rotation: the quaternion .* has norm"
    ):
        simulate_ensemble(BODY, (0, 1.0), omega0=W0, Q0=q, dt=1e-2)
    M = MOMENTS.copy()
    M[11] = [1.0, 1.0, 5.0]
    with pytest.raises(ValueError, match=r"`moments\[11\]`: principal moments must satisfy"):
        simulate_ensemble(BODY, (0, 1.0), omega0=W0, moments=M, dt=1e-2)
    J = np.stack([np.eye(3)] * N)
    J[2, 0, 1] = 0.5
    with pytest.raises(ValueError, match=r"`inertia\[2\]` must be symmetric"):
        simulate_ensemble(BODY, (0, 1.0), omega0=W0, inertia=J, dt=1e-2)
    M[11] = [0.0, 1.0, 1.0]
    with pytest.raises(ValueError, match=r"`moments\[11\]` must be positive definite"):
        simulate_ensemble(BODY, (0, 1.0), omega0=W0, moments=M, dt=1e-2)


def test_python_forces_and_velocity_forces_refused():
    from poinsot.forces import CustomForce, LinearDrag

    custom = CustomForce(lambda ctx: (np.zeros(3), np.zeros(3)))
    with pytest.raises(ValueError, match="`forces`: an ensemble runs built-in forces only"):
        simulate_ensemble(BODY, (0, 1.0), omega0=W0, dt=1e-2, forces=[custom])
    with pytest.raises(ValueError, match="'splitting' needs forces that depend only on"):
        simulate_ensemble(
            BODY, (0, 1.0), omega0=W0, dt=1e-2, method="splitting", forces=[LinearDrag(0.1)]
        )


# --------------------------------------------------------------------------- the compiled core
def _fresh_process(code):
    import subprocess
    import sys
    import textwrap

    run = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr
    return run.stdout.split()


def test_an_ensemble_compiles_nothing():
    """Ensembles run on the Rust core: a fresh process runs every kind of ensemble, its
    summary and its exact grading without importing numba."""
    out = _fresh_process(
        """
        import sys
        import numpy as np
        from poinsot import Gravity, RigidBody
        from poinsot.ensemble import simulate_ensemble
        body = RigidBody.box(1.0, (1.0, 2.0, 3.0))
        w = np.random.default_rng(0).normal(size=(40, 3))
        res = simulate_ensemble(body, (0, 1), omega0=w, dt=1e-2, t_eval=[0.5, 1.0])
        res.summary(), res.exact_errors()
        simulate_ensemble(body, (0, 1), omega0=w, method="dop853", keep_states=False)
        simulate_ensemble(body, (0, 1), omega0=w, dt=1e-2, method="splitting",
                          moments=0.2 * np.abs(w) + 1.0)
        simulate_ensemble(body, (0, 1), omega0=w, dt=1e-2, pivot=(0, 0, -0.5),
                          forces=[Gravity()])
        print("numba" in sys.modules)
        """
    )
    assert out == ["False"]


def test_ctrl_c_stops_a_running_ensemble():
    """An interrupt during a long run stops every worker and raises KeyboardInterrupt."""
    out = _fresh_process(
        """
        import _thread, threading
        import numpy as np
        from poinsot import RigidBody
        from poinsot.ensemble import simulate_ensemble
        body = RigidBody.box(1.0, (1.0, 2.0, 3.0))
        w = np.random.default_rng(0).normal(size=(8, 3))
        threading.Timer(1.0, _thread.interrupt_main).start()
        try:  # 10⁸ steps per member (the whole step budget): minutes, unless interrupted
            simulate_ensemble(body, (0, 1e5), omega0=w, dt=1e-3, threads=2, progress=False)
        except KeyboardInterrupt:
            print("interrupted")
        """
    )
    assert out == ["interrupted"]


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"method": "euler"}, r"`method` must be one of"),
        ({"y0": np.zeros((3, 17))}, r"`y0` must have shape \(m, 18\)"),
        ({"bodies": np.zeros((2, 25))}, r"`bodies` must have shape \(1, 25\) or \(3, 25\)"),
        ({"axes": np.zeros((3, 3, 2))}, r"`axes` must have shape \(n, 3, 3\)"),
        ({"force_kind": np.array([99])}, r"`force_params` must have shape \(n, 1, 10\)"),
        ({"dt": 0.0}, r"`dt` must be a positive number"),
        ({"t_eval": np.array([1.0, 0.5])}, r"`t_eval` must be non-decreasing"),
        ({"t_eval": np.array([2.0])}, r"`t_eval` must lie within"),
        ({"threads": 0}, r"`threads` must be a positive integer"),
        ({"samples_out": np.zeros((3, 2, 18))}, r"`samples_out` must have shape \(3, 1, 18\)"),
        ({"samples_out": np.zeros((3, 1, 18)), "keep_samples": False}, r"with `keep_samples`"),
        ({"samples_out": np.zeros((18, 1, 3)).T}, r"`samples_out` must be C-contiguous"),
        ({"finals_out": np.zeros((2, 18))}, r"`finals_out` must have shape \(3, 18\)"),
        ({"finals_out": np.zeros((18, 3)).T}, r"`finals_out` must be C-contiguous"),
    ],
)
def test_the_core_names_bad_arguments(change, match):
    from poinsot import _core

    body = np.zeros(25)
    run = {"method": "rk4", "t_end": 1.0, "dt": 0.1, "t_eval": np.array([1.0])}
    args = {
        "t0": 0.0, "inertia": np.eye(3)[None], "bodies": body[None], "axes": np.eye(3)[None],
        "force_kind": np.zeros(0, dtype=np.int64), "force_params": np.zeros((1, 0, 10)),
        "y0": np.zeros((3, 18)), "threads": 1,
    }  # fmt: skip
    of_run = {k: v for k, v in change.items() if k in run}  # the RunSpec checks these
    rest = {k: v for k, v in change.items() if k not in run}
    with pytest.raises(ValueError, match=match):
        spec = _core.RunSpec(**{**run, **of_run})
        _core.run_ensemble(spec=spec, **{**args, **rest})


def _unaligned(a):
    """A copy of ``a`` one byte into a buffer: C-contiguous but not aligned, as an array can
    arrive on a Dask worker (unpickled from a message)."""
    raw = np.zeros(a.nbytes + 1, dtype=np.uint8)
    out = np.frombuffer(raw.data, dtype=a.dtype, count=a.size, offset=1).reshape(a.shape)
    out[...] = a
    assert not out.flags.aligned
    return out


@pytest.mark.parametrize("case", ["free rk4", "own moments rk4", "heavy top rk4"])
def test_a_chunk_runs_the_same_from_unaligned_arrays(case):
    # a Dask worker in another process can receive the chunk's arrays at odd offsets of the
    # message; the core reads aligned memory, so they are realigned (copied) at the call
    import dataclasses

    from poinsot.ensemble.run import _members, prepare_ensemble
    from poinsot.ensemble.tasks import run_chunk

    kw = dict(CASES[case])
    moments = kw.pop("moments", None)
    prepared = prepare_ensemble(BODY, (0, T_END), t_eval=T_EVAL, **kw)
    spec, members = _members(prepared.spec, prepared.system, W0, Q0, None, None, moments, None)
    task = members.task(2, 9)

    def odd(obj):
        fields = {
            f.name: _unaligned(v)
            for f in dataclasses.fields(obj)
            if isinstance(v := getattr(obj, f.name), np.ndarray) and v.size
        }
        return dataclasses.replace(obj, **fields)

    want, got = run_chunk(spec, task), run_chunk(odd(spec), odd(task))
    assert np.isfinite(want.final).all()
    np.testing.assert_array_equal(got.final, want.final)
    np.testing.assert_array_equal(got.Y, want.Y)


@pytest.mark.parametrize("keep_states", [True, False])
@pytest.mark.parametrize("case", ["free rk4", "free dop853", "heavy top rk4"])
def test_a_chunk_written_in_place_equals_its_returned_arrays(case, keep_states):
    # run in this process, a chunk writes its states into the result's arrays (MuJoCo's
    # rollout style); on a Dask worker it returns new ones: the two are bit-identical
    from poinsot.ensemble.run import _members, prepare_ensemble
    from poinsot.ensemble.tasks import ChunkViews, run_chunk

    kw = dict(CASES[case])
    kw.pop("moments", None)
    prepared = prepare_ensemble(BODY, (0, T_END), t_eval=T_EVAL, keep_states=keep_states, **kw)
    spec, members = _members(prepared.spec, prepared.system, W0, Q0, None, None, None, None)
    task = members.task(2, 9)
    m = task.stop - task.start
    views = ChunkViews(
        np.full((m, len(T_EVAL), 18), np.nan) if keep_states else None,
        np.full((m, 18), np.nan),
    )
    want, got = run_chunk(spec, task), run_chunk(spec, task, out=views)
    assert got.in_place and not want.in_place
    assert got.final is views.final
    assert np.isfinite(want.final).all()
    np.testing.assert_array_equal(views.final, want.final)
    np.testing.assert_array_equal(got.Y0, want.Y0)
    if keep_states:
        np.testing.assert_array_equal(views.Y, want.Y)
    else:
        assert got.Y is None and want.Y is None
    for name in ("energy", "momentum", "first_flip", "status", "nsteps"):
        np.testing.assert_array_equal(getattr(got, name), getattr(want, name))


@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_a_member_whose_rates_overflow_fails_alike_in_lanes_and_alone(method):
    # ω so large that Euler's equation overflows: the adaptive step's error norm is NaN, which
    # the lanes must reject as the single run does (`err < 1` fails), so that each member ends
    # with the single run's status and counts in lanes (40 members) and alone (chunks of 7)
    w0 = np.tile([1e200, 1e200, 1e200], (40, 1))
    w0[::3] = [0.1, 1.0, 0.2]
    kw = {"method": method, "dt": 1e-2} if method == "rk4" else {"method": method}
    lanes, alone = (
        simulate_ensemble(BODY, (0, 1), omega0=w0, chunk_size=c, progress=False, **kw)
        for c in (None, 7)
    )
    np.testing.assert_array_equal(lanes.status, alone.status)
    np.testing.assert_array_equal(lanes.nsteps, alone.nsteps)
    np.testing.assert_array_equal(lanes.nfev, alone.nfev)
    np.testing.assert_array_equal(lanes.state, alone.state)
    assert lanes.success[::3].all() and not lanes.success[1::3].any()
