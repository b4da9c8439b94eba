"""Relative-motion benchmarks (run through ``benchmarks/run.py --only relative``).

* ``relative``: the notebook body relative to a carrier turning at a constant rate, under
  gravity, DOP853 at rtol 1e-10 over t ∈ [0, 20]; against (a) SciPy's DOP853 on the compact
  relative equation (11) written in NumPy (what a user would write from the paper) and (b)
  poinsot's own absolute simulation of the same motion (the price of the relative form).
"""

from __future__ import annotations

import numpy as np

T_END = 20.0
SAMPLES = np.linspace(0.0, T_END, 101)
OMEGA_E = np.array([0.0, 0.3, 1.0])
OMEGA_R0 = np.array([0.0, 1.0, 1.0])


def case_relative(repeat):
    from run import row, timed
    from scipy.integrate import solve_ivp

    from poinsot import Gravity, simulate
    from poinsot.models import notebook_body
    from poinsot.relative import Carrier, simulate_relative

    body = notebook_body()
    J = np.asarray(body.inertia)
    J_inv = np.linalg.inv(J)
    Jp = 0.5 * np.trace(J) * np.eye(3) - J
    carrier = Carrier(omega_e=OMEGA_E)
    gravity = [Gravity((0, 0, -9.8))]

    def ours():
        return simulate_relative(body, (0, T_END), omega_r0=OMEGA_R0, carrier=carrier,
                                 forces=gravity, t_eval=SAMPLES, hold_com=True)  # fmt: skip

    def rhs(_, y):  # eq. (11) with Q̇_r = Q_r Ω_r; gravity has no moment about the c.o.m.
        Q = y[:9].reshape(3, 3)
        w = y[9:12]
        we = Q.T @ OMEGA_E
        Me = np.cross(J @ we, we)
        Mc = 2 * np.cross(w, Jp @ we)
        wdot = J_inv @ (np.cross(J @ w, w) + Me + Mc)
        W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        return np.concatenate([(Q @ W).ravel(), wdot])

    def peer():
        y0 = np.concatenate([np.eye(3).ravel(), OMEGA_R0])
        return solve_ivp(rhs, (0, T_END), y0, method="DOP853", rtol=1e-10, atol=1e-12,
                         t_eval=SAMPLES).y.T[:, 9:12]  # fmt: skip

    def absolute():
        w0 = OMEGA_R0 + OMEGA_E  # Q_r(0) = Q_c(0) = I
        return simulate(body, (0, T_END), omega0=w0, forces=gravity, t_eval=SAMPLES)

    ref = simulate_relative(
        body,
        (0, T_END),
        omega_r0=OMEGA_R0,
        carrier=carrier,
        t_eval=SAMPLES,
        hold_com=True,
        rtol=1e-13,
        atol=1e-15,
    ).omega_r
    t_ours, sol = timed(ours, repeat)
    t_peer, w_peer = timed(peer, max(1, repeat // 2))
    t_abs, traj = timed(absolute, repeat)
    err_ours = float(np.abs(sol.omega_r - ref).max())
    err_peer = float(np.abs(w_peer - ref).max())
    Qc = sol.Q_carrier
    w_abs_rel = np.einsum("nji,j->ni", sol.Q_r, OMEGA_E)  # ω_r = ω − Q_rᵀ ω_e
    Q_r_abs = np.einsum("nji,njk->nik", Qc, traj.Q)
    w_from_abs = traj.omega - np.einsum("nji,j->ni", Q_r_abs, OMEGA_E)
    check = np.abs(sol.omega_absolute - sol.omega_r - w_abs_rel).max()
    return [
        row(
            "notebook body on a turning carrier, gravity, rtol 1e-10, t ∈ [0, 20]",
            "simulate_relative dop853",
            t_ours,
            "SciPy DOP853, eq. (11) in NumPy",
            t_peer,
            err_ours,
            err_peer,
            "error: max |ω_r − reference|",
        ),
        row(
            "the same motion: relative form against poinsot's absolute simulation",
            "simulate_relative dop853",
            t_ours,
            "poinsot simulate (absolute)",
            t_abs,
            err_ours,
            float(np.abs(w_from_abs - ref).max()),
            f"ω_e projection check {check:.1e}",
        ),
    ]


CASES = {"relative": case_relative}
