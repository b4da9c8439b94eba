"""poinsot against its peers, timed in the same run: medians and ratios.

    python benchmarks/run.py [--repeat N]

The machine is shared and noisy, so each case runs N times (default 5) and the table reports
medians and the ratio peer/poinsot (> 1: poinsot is faster). Accuracy is printed beside the
timings: a faster answer that is less accurate is no win. Peers are what a user would otherwise
write with the same tools: SciPy's solve_ivp on Euler's equations or the notebook's 18-component
state, a per-particle loop for the inertia (the notebook's Sage code, in Python), and SymPy's
LagrangesMethod + lambdify + solve_ivp for a double pendulum (the PyDy route).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np


def timed(fn, repeat):
    times, out = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), out


def case_torque_free(repeat):
    from scipy.integrate import solve_ivp

    from poinsot.torquefree import FreeRigidBody

    I = np.array([1.0, 2.0, 3.0])
    w0 = np.array([0.3, 1.0, 0.5])
    t = np.linspace(0, 100, 10_001)
    fb = FreeRigidBody(I)

    def peer():
        def rhs(_, w):
            return np.array(
                [
                    (I[1] - I[2]) / I[0] * w[1] * w[2],
                    (I[2] - I[0]) / I[1] * w[2] * w[0],
                    (I[0] - I[1]) / I[2] * w[0] * w[1],
                ]
            )

        return solve_ivp(rhs, (0, 100), w0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t).y.T

    t_ours, ours = timed(lambda: fb.exact_omega(w0, t), repeat)
    t_peer, theirs = timed(peer, repeat)
    ref = solve_ivp(
        lambda _, w: np.array(
            [
                (I[1] - I[2]) / I[0] * w[1] * w[2],
                (I[2] - I[0]) / I[1] * w[2] * w[0],
                (I[0] - I[1]) / I[2] * w[0] * w[1],
            ]
        ),
        (0, 100),
        w0,
        method="DOP853",
        rtol=2.5e-14,
        atol=1e-16,
        t_eval=t,
    ).y.T
    return (
        "ω(t), torque-free, 10⁴ times over t ∈ [0, 100]",
        "exact_omega",
        "solve_ivp DOP853 rtol 1e-10",
        t_ours,
        t_peer,
        np.abs(ours - ref).max(),
        np.abs(theirs - ref).max(),
    )


def case_rigid_body(repeat):
    from scipy.integrate import solve_ivp

    from poinsot import Gravity, simulate
    from poinsot.models import notebook_body

    body = notebook_body()
    t = np.linspace(0, 20, 101)
    A, Ainv, M, u = body.inertia, np.linalg.inv(body.inertia), body.mass, body.u
    F = np.tile([0, 0, -9.8 * 10 / 27], (27, 1))

    def peer():  # the notebook's right-hand side, in NumPy, with SciPy's DOP853
        def rhs(_, y):
            w = y[6:9]
            Q = y[9:18].reshape(3, 3)
            W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
            torque = np.cross(u, F @ Q).sum(0)
            wdot = Ainv @ (-np.cross(w, A @ w) + torque)
            return np.concatenate([y[3:6], F.sum(0) / M, wdot, (Q @ W).ravel()])

        y0 = np.concatenate([body.center_of_mass, np.zeros(3), [0, 1, 1], np.eye(3).ravel()])
        return solve_ivp(rhs, (0, 20), y0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t).y.T[
            :, 6:9
        ]

    def ours():
        return simulate(
            body, (0, 20), omega0=(0, 1, 1), forces=[Gravity((0, 0, -9.8))], t_eval=t
        ).omega

    t_ours, w_ours = timed(ours, repeat)
    t_peer, w_peer = timed(peer, repeat)
    exact = (
        __import__("poinsot.torquefree", fromlist=["x"])
        .FreeRigidBody.from_body(body)
        .exact_omega((0, 1, 1), t)
    )
    return (
        "27-particle body under gravity, t ∈ [0, 20]",
        "simulate dop853",
        "solve_ivp on the 18-state",
        t_ours,
        t_peer,
        np.abs(w_ours - exact).max(),
        np.abs(w_peer - exact).max(),
    )


def case_inertia(repeat):
    from poinsot import RigidBody

    rng = np.random.default_rng(0)
    m = rng.uniform(1, 2, 20_000)
    r = rng.normal(size=(20_000, 3))

    def peer():  # the notebook's loop: A_jk = Σ m (|u|² δ_jk − u_j u_k)
        c = (m[:, None] * r).sum(0) / m.sum()
        A = np.zeros((3, 3))
        for mi, ri in zip(m, r, strict=True):
            ui = ri - c
            A += mi * (ui @ ui * np.eye(3) - np.outer(ui, ui))
        return A

    t_ours, A_ours = timed(lambda: RigidBody.from_particles(m, r).inertia, repeat)
    t_peer, A_peer = timed(peer, max(1, repeat // 2))
    return (
        "inertia of 2·10⁴ particles",
        "RigidBody.from_particles",
        "per-particle loop",
        t_ours,
        t_peer,
        0.0,
        np.abs(A_ours - A_peer).max(),
    )


def case_lagrange(repeat):
    import sympy as sp
    from scipy.integrate import solve_ivp
    from sympy.physics.mechanics import LagrangesMethod

    from poinsot import models

    t = np.linspace(0, 10, 201)

    def ours():
        mdl = models.double_pendulum()
        return mdl.simulate((0, 10), t_eval=t).q

    def peer():
        mdl = models.double_pendulum()
        system = mdl.system
        lm = LagrangesMethod(system.lagrangian, system.coordinates)
        lm.form_lagranges_equations()
        q, v = system.coordinates, system.speeds
        qs, vs = sp.symbols("a0:2"), sp.symbols("b0:2")
        sub = {**dict(zip(v, vs, strict=True)), **dict(zip(q, qs, strict=True))}
        Mf = sp.lambdify([qs, vs], lm.mass_matrix_full.subs(sub).subs(mdl.params))
        ff = sp.lambdify([qs, vs], lm.forcing_full.subs(sub).subs(mdl.params))

        def rhs(_, y):
            return np.linalg.solve(
                np.array(Mf(y[:2], y[2:]), float), np.array(ff(y[:2], y[2:]), float).ravel()
            )

        y0 = [2.0, 1.0, 0.0, 0.0]
        return solve_ivp(rhs, (0, 10), y0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t).y.T[
            :, :2
        ]

    reps = max(1, repeat // 2)
    t_ours, q_ours = timed(ours, reps)
    t_peer, q_peer = timed(peer, reps)
    return (
        "double pendulum: derive + integrate t ∈ [0, 10]",
        "LagrangianSystem",
        "sympy LagrangesMethod + solve_ivp",
        t_ours,
        t_peer,
        0.0,
        np.abs(q_ours - q_peer).max(),
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    rows = [
        case(args.repeat)
        for case in (case_torque_free, case_rigid_body, case_inertia, case_lagrange)
    ]
    print(f"{'case':50s} {'poinsot':>10s} {'peer':>10s} {'peer/poinsot':>13s}   accuracy")
    for name, ours, peer, t_ours, t_peer, err_ours, err_peer in rows:
        print(
            f"{name:50s} {t_ours * 1e3:8.1f}ms {t_peer * 1e3:8.1f}ms {t_peer / t_ours:12.2f}x"
            f"   poinsot ({ours}) {err_ours:.1e}, peer ({peer}) {err_peer:.1e}"
        )


if __name__ == "__main__":
    main()
