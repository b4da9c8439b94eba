"""Ensemble benchmarks (run through ``benchmarks/run.py --only ensemble ...``).

* ``ensemble``: 10⁵ members × 1000 RK4 steps at dt = 1e-3, torque-free, the notebook body,
  random ω0, against (a) a hand-written numba kernel timed in the same run (RK4 on ω and the
  quaternion, renormalised each step, members in structure-of-arrays chunks with the member
  loop innermost, ``prange`` over chunks) and (b) MuJoCo's ``rollout`` on all threads (RK4;
  on fewer members, since it stores every step: compared per body-step).
* ``ensemble_methods``: the throughput of the other methods on the same problem.
* ``exact_ensemble``: 10⁶ closed-form ω at one time, against a loop of single evaluations.
* ``dask``: the same RK4 ensemble on a 2-worker ``LocalCluster``, beside the local run.
"""

from __future__ import annotations

import math

import numpy as np

N_MEMBERS = 100_000
ENSEMBLE_STEPS = 1000
DT = 1e-3


def _inputs(n=N_MEMBERS, seed=0):
    from poinsot.models import notebook_body

    body = notebook_body()
    rng = np.random.default_rng(seed)
    return body, rng.normal(size=(n, 3))


def _hand_kernel():
    """RK4 on (ω, q) for many members, written for this one problem (the peer to beat)."""
    import numba

    @numba.njit(parallel=True, cache=True)
    def hand(W, q, I, dt, steps, chunk):
        N = W.shape[1]
        a1 = (I[1] - I[2]) / I[0]
        a2 = (I[2] - I[0]) / I[1]
        a3 = (I[0] - I[1]) / I[2]
        for c in numba.prange((N + chunk - 1) // chunk):
            lo = c * chunk
            hi = min(N, lo + chunk)
            for _ in range(steps):
                for j in range(lo, hi):  # the member loop, innermost: vectorised
                    w1, w2, w3 = W[0, j], W[1, j], W[2, j]
                    s, x, y, z = q[0, j], q[1, j], q[2, j], q[3, j]
                    # k1
                    d1 = a1 * w2 * w3
                    d2 = a2 * w3 * w1
                    d3 = a3 * w1 * w2
                    e0 = -0.5 * (x * w1 + y * w2 + z * w3)
                    e1 = 0.5 * (s * w1 + y * w3 - z * w2)
                    e2 = 0.5 * (s * w2 + z * w1 - x * w3)
                    e3 = 0.5 * (s * w3 + x * w2 - y * w1)
                    # k2
                    u1, u2, u3 = w1 + 0.5 * dt * d1, w2 + 0.5 * dt * d2, w3 + 0.5 * dt * d3
                    ps, px = s + 0.5 * dt * e0, x + 0.5 * dt * e1
                    py, pz = y + 0.5 * dt * e2, z + 0.5 * dt * e3
                    f1 = a1 * u2 * u3
                    f2 = a2 * u3 * u1
                    f3 = a3 * u1 * u2
                    g0 = -0.5 * (px * u1 + py * u2 + pz * u3)
                    g1 = 0.5 * (ps * u1 + py * u3 - pz * u2)
                    g2 = 0.5 * (ps * u2 + pz * u1 - px * u3)
                    g3 = 0.5 * (ps * u3 + px * u2 - py * u1)
                    # k3
                    u1, u2, u3 = w1 + 0.5 * dt * f1, w2 + 0.5 * dt * f2, w3 + 0.5 * dt * f3
                    ps, px = s + 0.5 * dt * g0, x + 0.5 * dt * g1
                    py, pz = y + 0.5 * dt * g2, z + 0.5 * dt * g3
                    h1 = a1 * u2 * u3
                    h2 = a2 * u3 * u1
                    h3 = a3 * u1 * u2
                    i0 = -0.5 * (px * u1 + py * u2 + pz * u3)
                    i1 = 0.5 * (ps * u1 + py * u3 - pz * u2)
                    i2 = 0.5 * (ps * u2 + pz * u1 - px * u3)
                    i3 = 0.5 * (ps * u3 + px * u2 - py * u1)
                    # k4
                    u1, u2, u3 = w1 + dt * h1, w2 + dt * h2, w3 + dt * h3
                    ps, px, py, pz = s + dt * i0, x + dt * i1, y + dt * i2, z + dt * i3
                    k1 = a1 * u2 * u3
                    k2 = a2 * u3 * u1
                    k3 = a3 * u1 * u2
                    l0 = -0.5 * (px * u1 + py * u2 + pz * u3)
                    l1 = 0.5 * (ps * u1 + py * u3 - pz * u2)
                    l2 = 0.5 * (ps * u2 + pz * u1 - px * u3)
                    l3 = 0.5 * (ps * u3 + px * u2 - py * u1)
                    h6 = dt / 6.0
                    W[0, j] = w1 + h6 * (d1 + 2 * f1 + 2 * h1 + k1)
                    W[1, j] = w2 + h6 * (d2 + 2 * f2 + 2 * h2 + k2)
                    W[2, j] = w3 + h6 * (d3 + 2 * f3 + 2 * h3 + k3)
                    s = s + h6 * (e0 + 2 * g0 + 2 * i0 + l0)
                    x = x + h6 * (e1 + 2 * g1 + 2 * i1 + l1)
                    y = y + h6 * (e2 + 2 * g2 + 2 * i2 + l2)
                    z = z + h6 * (e3 + 2 * g3 + 2 * i3 + l3)
                    r = 1.0 / math.sqrt(s * s + x * x + y * y + z * z)
                    q[0, j], q[1, j], q[2, j], q[3, j] = s * r, x * r, y * r, z * r
        return W, q

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
            "hand-written numba SoA quaternion RK4, prange",
            t_hand,
            agree,
            None,
            "target ≥ 0.6×; error column: |Δω| between the two",
        ),
        row(
            "same, flips not recorded",
            "simulate_ensemble rk4 flips=False",
            t_plain,
            "hand-written numba SoA quaternion RK4, prange",
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
            "target ≥ 500×; error column: |Δω| against MuJoCo",
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
            "target ≥ 10⁶ members/s; error column: vectorised vs single",
        )
    ]


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
    "dask": case_dask,
}
