"""Ensemble benchmarks (run through ``benchmarks/run.py --only ensemble ...``).

* ``ensemble``: 10⁵ members × 1000 RK4 steps at dt = 1e-3, torque-free, the notebook body,
  random ω0, against (a) the vector unit's ceiling, a numba kernel written for this one
  problem and timed in the same run (RK4 on ω and the quaternion, renormalised each step,
  members in structure-of-arrays chunks with the member loop innermost, ``prange`` over
  chunks: the reference measurement's own kernel) and (b) MuJoCo's ``rollout`` on all threads (RK4;
  on fewer members, since it stores every step: compared per body-step).
* ``ensemble_methods``: the throughput of the other methods on the same problem.
* ``exact_ensemble``: 10⁶ closed-form ω at one time, against a loop of single evaluations.
* ``exact_families``: the period, flip interval and polhode family of 10⁶ motions, against a
  loop of single evaluations.
* ``exact_attitudes``: Q(t) of 10⁵ members at 10 times (in SIMD lanes), against a loop of
  single evaluations.
* ``dop853_lanes``: DOP853 members (each its own step sizes) in lanes against the same members
  run one at a time (chunks of 15, too few for lanes), the tolerances of a grading run.
* ``forced_lanes``: bodies under forces in lanes (a heavy top: uniform gravity about a
  pivot; a satellite: central gravity with its gradient torque; every method, the exact-flow
  splittings at dt = 0.05 (their free flows in SIMD lanes); a body on a
  tether under four forces, RK4, RKMK4 and DOP853; on an undamped tether under three,
  splitting), against the same members run one at a time
  (chunks of 15), bit for bit.
* ``dask``: the same RK4 ensemble on a 2-worker ``LocalCluster``, beside the local run.
"""

from __future__ import annotations

import math

import numpy as np

N_MEMBERS = 100_000
ENSEMBLE_STEPS = 1000
DT = 1e-3
# members per chunk for the one-at-a-time runs: a chunk under a quarter of the core's block
# of 64 lanes runs member by member (crates/core/src/ensemble/blocks.rs, run_lanes)
ALONE = 15


def _inputs(n=N_MEMBERS, seed=0):
    from poinsot.models import notebook_body

    body = notebook_body()
    rng = np.random.default_rng(seed)
    return body, rng.normal(size=(n, 3))


def _hand_kernel():
    """RK4 on (ω, q) for many members, written for this one problem: the vector unit's
    ceiling on this machine (the kernel of the project's reference measurement,
    ``speed_ensemble.py``: members in structure-of-arrays chunks of 256, the member loop
    innermost over 1-D views, ω and q in registers, the quaternion renormalised each step,
    ``prange`` over chunks). numba is the peer's compiler here, not a poinsot dependency."""
    import numba

    @numba.njit(inline="always")
    def f(w1, w2, w3, q0, q1, q2, q3, c1, c2, c3):
        return (
            c1 * w2 * w3,
            c2 * w3 * w1,
            c3 * w1 * w2,
            0.5 * (-q1 * w1 - q2 * w2 - q3 * w3),
            0.5 * (q0 * w1 + q2 * w3 - q3 * w2),
            0.5 * (q0 * w2 + q3 * w1 - q1 * w3),
            0.5 * (q0 * w3 + q1 * w2 - q2 * w1),
        )

    @numba.njit(inline="always")
    def rk4(w1, w2, w3, q0, q1, q2, q3, c1, c2, c3, h):
        h2 = 0.5 * h
        a = f(w1, w2, w3, q0, q1, q2, q3, c1, c2, c3)
        b = f(w1 + h2 * a[0], w2 + h2 * a[1], w3 + h2 * a[2], q0 + h2 * a[3], q1 + h2 * a[4],
              q2 + h2 * a[5], q3 + h2 * a[6], c1, c2, c3)  # fmt: skip
        d = f(w1 + h2 * b[0], w2 + h2 * b[1], w3 + h2 * b[2], q0 + h2 * b[3], q1 + h2 * b[4],
              q2 + h2 * b[5], q3 + h2 * b[6], c1, c2, c3)  # fmt: skip
        e = f(w1 + h * d[0], w2 + h * d[1], w3 + h * d[2], q0 + h * d[3], q1 + h * d[4],
              q2 + h * d[5], q3 + h * d[6], c1, c2, c3)  # fmt: skip
        s = h / 6.0
        w1 += s * (a[0] + 2 * b[0] + 2 * d[0] + e[0])
        w2 += s * (a[1] + 2 * b[1] + 2 * d[1] + e[1])
        w3 += s * (a[2] + 2 * b[2] + 2 * d[2] + e[2])
        q0 += s * (a[3] + 2 * b[3] + 2 * d[3] + e[3])
        q1 += s * (a[4] + 2 * b[4] + 2 * d[4] + e[4])
        q2 += s * (a[5] + 2 * b[5] + 2 * d[5] + e[5])
        q3 += s * (a[6] + 2 * b[6] + 2 * d[6] + e[6])
        inv = 1.0 / math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
        return w1, w2, w3, q0 * inv, q1 * inv, q2 * inv, q3 * inv

    @numba.njit(parallel=True, cache=True)
    def hand(W, Q, I, dt, steps, chunk):
        n = W.shape[1]
        c1, c2, c3 = (I[1] - I[2]) / I[0], (I[2] - I[0]) / I[1], (I[0] - I[1]) / I[2]
        for c in numba.prange((n + chunk - 1) // chunk):
            lo = c * chunk
            hi = min(n, lo + chunk)
            w1, w2, w3 = W[0, lo:hi], W[1, lo:hi], W[2, lo:hi]
            q0, q1, q2, q3 = Q[0, lo:hi], Q[1, lo:hi], Q[2, lo:hi], Q[3, lo:hi]
            for _ in range(steps):
                for i in range(hi - lo):
                    (w1[i], w2[i], w3[i], q0[i], q1[i], q2[i], q3[i]) = rk4(
                        w1[i], w2[i], w3[i], q0[i], q1[i], q2[i], q3[i], c1, c2, c3, dt
                    )
        return W, Q

    return hand


def case_ensemble(repeat):
    from run import row, timed

    from poinsot.ensemble import simulate_ensemble

    body, W0 = _inputs()
    # the notebook body is diagonal in its own axes: principal frame = body frame
    I = np.ascontiguousarray(np.diag(body.inertia))
    t_end = ENSEMBLE_STEPS * DT
    body_steps = N_MEMBERS * ENSEMBLE_STEPS

    def ours():
        return simulate_ensemble(body, (0, t_end), omega0=W0, dt=DT, progress=False)

    def ours_no_flips():
        return simulate_ensemble(body, (0, t_end), omega0=W0, dt=DT, progress=False, flips=False)

    hand = _hand_kernel()

    def peer():
        q = np.zeros((4, N_MEMBERS))
        q[0] = 1.0
        return hand(np.ascontiguousarray(W0.T), q, I, DT, ENSEMBLE_STEPS, 256)

    t_ours, res = timed(ours, repeat)
    t_plain, _ = timed(ours_no_flips, repeat)
    t_hand, (W_hand, _) = timed(peer, repeat)
    agree = float(np.abs(res.final_omega - W_hand.T).max())
    rate = body_steps / t_ours
    rows = [
        row(
            f"ensemble: 10⁵ members × 10³ RK4 steps, torque-free ({rate:.3g} body-steps/s)",
            "simulate_ensemble rk4 (flips recorded)",
            t_ours,
            "ceiling: numba SoA quaternion RK4 for this problem",
            t_hand,
            agree,
            None,
            "goal ≥ 0.8×; error column: |Δω| between the two",
        ),
        row(
            "same, flips not recorded",
            "simulate_ensemble rk4 flips=False",
            t_plain,
            "ceiling: numba SoA quaternion RK4 for this problem",
            t_hand,
        ),
    ]
    try:
        import mujoco
        from mujoco import rollout
    except ImportError:
        rows.append(row("ensemble vs MuJoCo rollout", "", t_ours, "MuJoCo (not installed)", None))
        return rows
    n_mj = 2000  # rollout stores every step: fewer members, compared per body-step
    xml = f"""<mujoco><option integrator="RK4" timestep="{DT}" gravity="0 0 0"/>
      <worldbody><body><freejoint/><inertial pos="0 0 0" mass="{body.mass}"
      diaginertia="{I[0]} {I[1]} {I[2]}"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    import os

    datas = [mujoco.MjData(model) for _ in range(os.cpu_count() or 1)]
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    size = mujoco.mj_stateSize(model, spec)
    data = datas[0]
    init = np.empty((n_mj, size))
    for i in range(n_mj):
        mujoco.mj_resetData(model, data)
        data.qvel[3:6] = W0[i]
        mujoco.mj_getState(model, data, init[i], spec)
    out = np.empty((n_mj, ENSEMBLE_STEPS, size))

    def mj():
        state, _ = rollout.rollout(model, datas, init, nstep=ENSEMBLE_STEPS, state=out)
        return state

    t_mj, state = timed(mj, max(1, repeat // 2))
    per_step_mj = t_mj / (n_mj * ENSEMBLE_STEPS)
    per_step_ours = t_ours / body_steps
    # qvel of the free joint: after time and qpos (1 + 7), the angular part is qvel[3:6]
    w_mj = state[:, -1, 1 + 7 + 3 : 1 + 7 + 6]
    rows.append(
        row(
            "same problem, per body-step, against MuJoCo rollout (RK4, all threads, 2000 members)",
            f"simulate_ensemble rk4: {per_step_ours * 1e9:.3g} ns per body-step",
            per_step_ours,
            f"MuJoCo {mujoco.__version__} rollout: {per_step_mj * 1e9:.3g} ns per body-step",
            per_step_mj,
            float(np.abs(res.final_omega[:n_mj] - w_mj).max()),
            None,
            "goal ≥ 1000×; error column: |Δω| against MuJoCo",
        )
    )
    return rows


def case_ensemble_methods(repeat):
    from run import timed

    from poinsot.ensemble import simulate_ensemble

    n = 10_000
    body, W0 = _inputs(n)
    rows = []
    for method, kw in (
        ("rk4", {"dt": DT}),
        ("rkmk4", {"dt": DT}),
        ("splitting", {"dt": DT}),
        ("dop853", {"rtol": 1e-10, "atol": 1e-12}),
    ):

        def run(method=method, kw=kw):
            return simulate_ensemble(
                body, (0, ENSEMBLE_STEPS * DT), omega0=W0, method=method, progress=False, **kw
            )

        t, res = timed(run, max(1, repeat // 2))
        steps = int(res.nsteps.sum())
        rows.append(
            {
                "case": f"ensemble {method}, 10⁴ members, t = 1",
                "poinsot_s": t,
                "steps_per_s": steps / t,
                "energy_error": float(np.median(res.energy_error)),
                "momentum_error": float(np.median(res.momentum_error)),
                "orthogonality_error": float(np.median(res.orthogonality_error)),
                "members_per_s": n / t,
            }
        )
    return rows


def case_exact_ensemble(repeat):
    from run import row, timed

    from poinsot.torquefree import FreeRigidBody

    free = FreeRigidBody((1.0, 2.0, 3.0))
    rng = np.random.default_rng(3)
    W = rng.normal(size=(1_000_000, 3))
    t = [7.5]

    t_vec, omega = timed(lambda: free.exact_omega(W, t), repeat)
    sample = rng.choice(len(W), 300, replace=False)

    def loop():
        return np.array([free.exact_omega(W[i], t)[0] for i in sample])

    t_loop, single = timed(loop, max(1, repeat // 2))
    err = float(np.abs(omega[sample, 0] - single).max())
    per_loop = t_loop / len(sample) * len(W)
    return [
        row(
            f"exact ω(t) of 10⁶ members at one time ({len(W) / t_vec:.3g} members/s)",
            "FreeRigidBody.exact_omega((10⁶, 3), t)",
            t_vec,
            "one call per member (extrapolated from 300)",
            per_loop,
            err,
            None,
            "goal ≥ 10⁷ closed forms/s; error column: vectorised vs single",
        )
    ]


def case_exact_families(repeat):
    from run import row, timed

    from poinsot.torquefree import FreeRigidBody

    free = FreeRigidBody((1.0, 2.0, 3.0))
    rng = np.random.default_rng(4)
    W = rng.normal(size=(1_000_000, 3))
    sample = rng.choice(len(W), 300, replace=False)
    rows = []
    for name in ("period", "flip_interval", "classify"):
        f = getattr(free, name)
        t_vec, out = timed(lambda f=f: f(W), repeat)

        def loop(f=f):
            return np.array([f(W[i]) for i in sample])

        t_loop, single = timed(loop, max(1, repeat // 2))
        if name == "classify":
            err = float(np.sum(out[sample] != single))
        else:
            err = float(np.abs(out[sample] - single).max())
        rows.append(
            row(
                f"exact {name} of 10⁶ motions ({len(W) / t_vec:.3g} motions/s)",
                f"FreeRigidBody.{name}((10⁶, 3))",
                t_vec,
                "one call per member (extrapolated from 300)",
                t_loop / len(sample) * len(W),
                err,
                None,
                "error column: vectorised vs single (classify: names that differ)",
            )
        )
    return rows


def case_exact_attitudes(repeat):
    from run import row, timed

    from poinsot.torquefree import FreeRigidBody

    free = FreeRigidBody((1.0, 2.0, 3.0))
    rng = np.random.default_rng(5)
    W = rng.normal(size=(100_000, 3))
    t = np.linspace(0.0, 20.0, 10)
    t_vec, Q = timed(lambda: free.exact_attitude(W, t), repeat)
    sample = rng.choice(len(W), 300, replace=False)

    def loop():
        return np.array([free.exact_attitude(W[i], t) for i in sample])

    t_loop, single = timed(loop, max(1, repeat // 2))
    err = float(np.abs(Q[sample] - single).max())
    n = len(W) * len(t)
    return [
        row(
            f"exact Q(t) of 10⁵ members at 10 times ({n / t_vec:.3g} attitudes/s)",
            "FreeRigidBody.exact_attitude((10⁵, 3), t)",
            t_vec,
            "one call per member (extrapolated from 300)",
            t_loop / len(sample) * len(W),
            err,
            None,
            "error column: vectorised vs single",
        )
    ]


def case_dop853_lanes(repeat):
    from run import row, timed

    from poinsot.ensemble import simulate_ensemble

    body, W0 = _inputs(4000)

    def run(chunk):
        return simulate_ensemble(body, (0, 100.0), omega0=W0, method="dop853", rtol=1e-10,
                                 atol=1e-12, chunk_size=chunk, progress=False)  # fmt: skip

    t_lanes, a = timed(lambda: run(None), max(1, repeat // 2))
    t_alone, b = timed(lambda: run(ALONE), max(1, repeat // 2))
    err = float(np.abs(a.state - b.state).max())
    steps = int(a.nsteps.sum())
    return [
        row(
            f"DOP853 ensemble, 4000 members over [0, 100], rtol 1e-10 ({steps / t_lanes:.3g} "
            "body-steps/s)",
            "lanes, each member its own steps",
            t_lanes,
            f"the same members one at a time (chunks of {ALONE})",
            t_alone,
            err,
            None,
            "error column: lanes vs one at a time (bit for bit: 0)",
        )
    ]


def case_forced_lanes(repeat):
    from run import row, timed

    from poinsot.ensemble import simulate_ensemble
    from poinsot.forces import CentralGravity, Gravity, QuadraticDrag, Spring, Torque

    body, W0 = _inputs(4000)
    rows = []
    # the exact-flow splittings at their own step (fifteen flows a step for the sixth order)
    every = ("rk4", "rkmk4", "splitting", "dop853", "exact-splitting", "exact-splitting6")
    cases = (
        (
            "heavy top (gravity about a pivot)",
            {"forces": [Gravity()], "pivot": (0.0, 0.0, 0.0)},
            every,
        ),
        (
            "satellite (central gravity and its gradient torque)",
            {"forces": [CentralGravity(4.0e5, (-7000.0, 0.0, 0.0))], "V0": (0.0, 7.56, 0.0)},
            every,
        ),
        (
            # several forces: each force for the whole block at once
            "body on a tether (gravity, a damped spring, quadratic drag, a couple)",
            {
                "forces": [
                    Gravity(),
                    Spring((0.2, 0.0, 0.0), (0.0, 0.0, 3.0), 50.0, 2.0, damping=0.5),
                    QuadraticDrag(0.05, 0.02),
                    Torque((0.0, 0.0, 0.3)),
                ]
            },
            ("rk4", "rkmk4", "dop853"),
        ),
        (
            # forces a kick can take (the splitting method refuses velocity-dependent ones)
            "body on an undamped tether (gravity, a spring, a couple)",
            {
                "forces": [
                    Gravity(),
                    Spring((0.2, 0.0, 0.0), (0.0, 0.0, 3.0), 50.0, 2.0),
                    Torque((0.0, 0.0, 0.3)),
                ]
            },
            ("splitting",),
        ),
    )
    kws = {
        "dop853": {"rtol": 1e-10, "atol": 1e-12},
        "exact-splitting": {"dt": 0.05},
        "exact-splitting6": {"dt": 0.05},
    }
    for label, setup, methods in cases:
        for method in methods:
            kw = kws.get(method, {"dt": DT})

            def run(chunk, method=method, kw=kw, setup=setup):
                return simulate_ensemble(body, (0, ENSEMBLE_STEPS * DT), omega0=W0,
                                         method=method, chunk_size=chunk, progress=False,
                                         **setup, **kw)  # fmt: skip

            t_lanes, a = timed(lambda run=run: run(None), max(1, repeat // 2))
            t_alone, b = timed(lambda run=run: run(ALONE), max(1, repeat // 2))
            same = bool(np.array_equal(a.state, b.state, equal_nan=True))
            steps = int(a.nsteps.sum())
            rows.append(
                row(
                    f"{label}, {method}, 4000 members over [0, 1] ({steps / t_lanes:.3g} "
                    f"body-steps/s; bit for bit the members alone: {same})",
                    "lanes",
                    t_lanes,
                    f"the same members one at a time (chunks of {ALONE})",
                    t_alone,
                    float(np.nanmax(np.abs(a.state - b.state))),
                    None,
                    "error column: lanes vs one at a time",
                )
            )
    return rows


def case_dask(repeat):
    from run import row, timed

    from poinsot.ensemble import simulate_ensemble

    try:
        from distributed import Client, LocalCluster
    except ImportError:
        return [row("dask", "", None, "dask.distributed (not installed)", None)]
    body, W0 = _inputs(50_000)
    t_end = ENSEMBLE_STEPS * DT

    def local():
        return simulate_ensemble(body, (0, t_end), omega0=W0, dt=DT, progress=False)

    t_local, res_local = timed(local, repeat)
    rows = []
    steps = len(W0) * ENSEMBLE_STEPS
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True) as cluster:
            with Client(cluster) as client:

                def remote(client=client):
                    return simulate_ensemble(
                        body, (0, t_end), omega0=W0, dt=DT, progress=False, client=client
                    )

                t_dask, res_dask = timed(remote, repeat)
        same = bool(np.array_equal(res_local.final_state, res_dask.final_state))
        rows.append(
            row(
                f"5·10⁴ members × 10³ RK4 steps, Dask LocalCluster with {workers} worker(s): "
                f"{steps / t_dask:.3g} body-steps/s (bit-identical to local: {same})",
                f"local, 2 threads: {steps / t_local:.3g} body-steps/s",
                t_local,
                f"Dask LocalCluster(n_workers={workers}, threads_per_worker=1)",
                t_dask,
                None,
                None,
                "ratio: Dask's time over the local run's",
            )
        )
    return rows


CASES = {
    "ensemble": case_ensemble,
    "ensemble_methods": case_ensemble_methods,
    "exact_ensemble": case_exact_ensemble,
    "exact_families": case_exact_families,
    "exact_attitudes": case_exact_attitudes,
    "dop853_lanes": case_dop853_lanes,
    "forced_lanes": case_forced_lanes,
    "dask": case_dask,
}
