"""The port of the ensembles to the compiled core: every chunk equals the numba kernels'
(``poinsot.kernels.ensemble``, which it replaces) — the samples, final and initial states, the
per-member statistics, the flips and the counters, for every method, free bodies, bodies
about a pivot, built-in forces and members with their own inertia (forces lowered per member).

The numba route below is the chunk runner as it was before the port (block RK4 over members,
member by member for the other methods, ``chunk_statistics``); it goes when the kernels go.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

pytest.importorskip("numba")

from poinsot import RigidBody
from poinsot.ensemble.run import _prepare
from poinsot.ensemble.tasks import run_chunk
from poinsot.forces import Gravity, PointForce, Spring

N = 11
T_EVAL = np.linspace(0.0, 3.0, 7)
BODY = RigidBody(2.0, [[1.5, 0.1, 0.0], [0.1, 2.0, 0.2], [0.0, 0.2, 3.0]],
                 center_of_mass=(0.1, 0.2, 0.3))  # fmt: skip
RNG = np.random.default_rng(7)
W0 = np.c_[RNG.normal(0, 0.05, N), RNG.normal(1, 0.1, N), RNG.normal(0, 0.05, N)]
Q0 = Rotation.random(N, random_state=3).as_matrix()
MOMENTS = RNG.uniform(1.0, 2.0, (N, 3))
GRAVITY = [Gravity((0.0, 0.0, -9.8))]

CASES = {
    "free rk4": {"method": "rk4", "dt": 1e-2},
    "free dop853": {"method": "dop853"},
    "free splitting": {"method": "splitting", "dt": 1e-2},
    "free rkmk4": {"method": "rkmk4", "dt": 1e-2},
    "heavy top rk4": {"method": "rk4", "dt": 1e-2, "pivot": (0.0, 0.0, 0.0), "forces": GRAVITY},
    "heavy top dop853": {"method": "dop853", "pivot": (0.0, 0.0, 0.0), "forces": GRAVITY},
    "spring dop853": {"method": "dop853", "forces": [Spring((0.5, 0, 0), (1, 1, 1), 3.0)]},
    "own moments rk4": {"method": "rk4", "dt": 1e-2, "moments": MOMENTS},
    "own moments, forces at body points": {
        "method": "rk4",
        "dt": 1e-2,
        "moments": MOMENTS,
        "forces": [PointForce((0.3, 0.0, 0.1), (0.0, 0.5, 0.0), frame="body")],
    },
    "final only, no flips": {"method": "rk4", "dt": 1e-2, "t_eval": None, "flips": False},
}


def _spec_and_task(case):
    kw = {"t_eval": T_EVAL, "flips": True, **CASES[case]}
    spec, members = _prepare(
        BODY, (0.0, 3.0), W0, Q0, None, None, kw.get("moments"), None, kw.get("forces", ()),
        kw.get("pivot"), kw["method"], kw.get("dt"), None, None, kw["t_eval"], kw["flips"],
        None, True,
    )  # fmt: skip
    return spec, members.task(0, N)


def _numba_chunk(spec, task):
    """The chunk as the numba kernels ran it before the port."""
    from poinsot.kernels import ensemble as ke
    from poinsot.kernels import steppers as st
    from poinsot.kernels import systems as ks
    from poinsot.kernels.observers import NoObserver, flip_observer
    from poinsot.kernels.rigid import initial_states

    m = task.stop - task.start
    n = len(spec.t_eval)
    Y0 = initial_states(task.Q, task.omega, task.R, task.V, spec.com, spec.c, spec.pivot,
                        spec.has_pivot, np.zeros(3))  # fmt: skip
    if task.inertia is not None:
        bodies, axes, _ = ke.member_bodies(spec.mass, task.inertia, spec.c, spec.has_pivot)
        inertia = task.inertia
    else:
        bodies, axes, inertia = spec.body_params[None], spec.axes, spec.inertia
    Z0, bodies = ke.principal_members(bodies, axes, Y0, spec.has_pivot)
    if spec.kind == "free":
        template = ks.TorqueFreeLanes(spec.body_params, m)
    elif spec.kind == "free_varied":
        template = ks.TorqueFreeLanesVaried(bodies, m)
    else:
        params = task.force_params
        if params is None:
            params = np.broadcast_to(spec.force_params, (m, *spec.force_params.shape))
        template = ks.RigidLanes(bodies, spec.force_kind, np.ascontiguousarray(params), m)
    axes, inertia = np.ascontiguousarray(axes), np.ascontiguousarray(inertia)
    observer = flip_observer(m) if spec.flips else NoObserver(0.0)
    Y = np.empty((m, n, 18))
    status, nsteps, nfev = (np.zeros(m, dtype=np.int64) for _ in range(3))
    args = (axes, Z0, spec.t0, spec.t1)
    outs = (Y, status, nsteps, nfev)
    code = {"rk4": st.RK4, "erk": st.ERK, "rkmk": st.RKMK, "splitting": st.SPLITTING,
            "dop853": st.DOP853}[spec.method_kind]  # fmt: skip
    if code == st.DOP853:
        ke.chunk_dop853(template, observer, spec.control, *args, spec.t_eval, *outs)
    else:
        chunk = {st.RK4: ke.chunk_rk4, st.ERK: ke.chunk_erk, st.RKMK: ke.chunk_rkmk,
                 st.SPLITTING: ke.chunk_splitting}[code]  # fmt: skip
        chunk(template, observer, spec.A, spec.B, spec.C, *args, spec.dt, spec.t_eval, *outs)
    stats = np.empty((3, m))
    ke.chunk_statistics(template, axes, inertia, spec.mass, spec.t0, Y0, spec.t_eval, Y,
                        *stats)  # fmt: skip
    if spec.flips:
        flips = (observer.first, observer.last, observer.count.astype(np.int64))
    else:
        flips = (np.full(m, np.nan), np.full(m, np.nan), np.full(m, -1, dtype=np.int64))
    return Y, Y0, stats, flips, status, nsteps, nfev


@pytest.mark.parametrize("case", list(CASES))
def test_a_chunk_equals_the_numba_kernels(case):
    spec, task = _spec_and_task(case)
    new = run_chunk(spec, task, threads=2)
    Y, Y0, stats, flips, status, nsteps, nfev = _numba_chunk(spec, task)
    assert (new.status == 1).all()
    np.testing.assert_array_equal(new.status, status)
    np.testing.assert_array_equal(new.nsteps, nsteps)
    np.testing.assert_array_equal(new.nfev, nfev)
    np.testing.assert_array_equal(new.Y0, Y0)
    # the same arithmetic: the core's steps are the numba engine's, bit for bit
    np.testing.assert_array_equal(new.Y, Y)
    np.testing.assert_array_equal(new.final, Y[:, -1])
    for got, want in zip((new.energy, new.momentum, new.orthogonality), stats, strict=True):
        np.testing.assert_array_equal(got, want)
    for got, want in zip((new.first_flip, new.last_flip, new.flip_count), flips, strict=True):
        np.testing.assert_array_equal(got, want)
    if spec.flips:
        assert (new.flip_count >= 0).all()


def test_a_failing_member_equals_the_numba_kernels():
    """A member that overflows: its own status, NaN samples and statistics, as before."""
    spec, task = _spec_and_task("free rk4")
    task.omega[4] = 1e200
    new = run_chunk(spec, task)
    Y, _, stats, _, status, nsteps, _ = _numba_chunk(spec, task)
    np.testing.assert_array_equal(new.status, status)
    assert status[4] == 2 and (np.delete(status, 4) == 1).all()
    np.testing.assert_array_equal(new.nsteps, nsteps)
    np.testing.assert_array_equal(new.Y, Y)
    np.testing.assert_array_equal(new.energy, stats[0])
