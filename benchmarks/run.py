"""poinsot against its peers, timed in the same run: medians and ratios.

    python benchmarks/run.py [--repeat N] [--only NAME ...] [--json FILE]

The machine is shared and noisy, so each case runs N times (default 7) and the table reports
medians and the ratio peer/poinsot (> 1: poinsot is faster). Accuracy is printed beside the
timings: a faster answer that is less accurate is no win. The peers are what a user would
otherwise reach for: MuJoCo's RK4, SciPy's DOP853 on the notebook's right-hand side, the
notebook's own NumPy loop, a per-particle loop for the inertia, and SymPy's LagrangesMethod +
lambdify + solve_ivp. Peers that are not installed are reported as missing (``pip install
mujoco``); the README's table names the machine it ran on.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np

T_END = 20.0
DT = 1e-3
STEPS = round(T_END / DT)
SAMPLES = np.linspace(0.0, T_END, 101)


def timed(fn, repeat):
    """Median wall time of ``fn()`` over ``repeat`` calls (after one warm-up call) and its
    last result."""
    out = fn()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), out


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:  # a peer's compiler (the hand-written reference kernels), not poinsot's
        import numba

        peer = f", numba {numba.__version__} (references only)"
    except ImportError:
        peer = ""
    return (
        f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, "
        f"NumPy {np.__version__}{peer}"
    )


def notebook():
    from poinsot.models import notebook_body
    from poinsot.torquefree import FreeRigidBody

    body = notebook_body()
    free = FreeRigidBody.from_body(body)
    return body, free


def row(name, ours_label, t_ours, peer_label, t_peer, err_ours=None, err_peer=None, note=""):
    return {
        "case": name,
        "poinsot": ours_label,
        "poinsot_s": t_ours,
        "peer": peer_label,
        "peer_s": t_peer,
        "ratio": (t_peer / t_ours) if (t_peer and t_ours) else None,
        "error_poinsot": err_ours,
        "error_peer": err_peer,
        "note": note,
    }


# --------------------------------------------------------------------------- the cases
def case_rk4_vs_mujoco(repeat):
    """The notebook body, torque-free, 20 000 RK4 steps at dt = 1e-3, 101 samples."""
    from poinsot import simulate

    body, free = notebook()
    exact = free.exact_omega((0, 1, 1), SAMPLES)

    def ours():
        return simulate(body, (0, T_END), omega0=(0, 1, 1), method="rk4", dt=DT, t_eval=SAMPLES)

    t_ours, tr = timed(ours, repeat)
    err_ours = float(np.abs(tr.omega - exact).max())
    rows = []
    try:
        import mujoco
    except ImportError:
        rows.append(row("RK4, 2·10⁴ steps", "simulate", t_ours, "MuJoCo (not installed)", None))
    else:
        I = np.diag(body.inertia)  # the notebook body is diagonal in its own axes
        xml = f"""<mujoco><option integrator="RK4" timestep="{DT}" gravity="0 0 0"/>
          <worldbody><body><freejoint/><inertial pos="0 0 0" mass="{body.mass}"
          diaginertia="{I[0]} {I[1]} {I[2]}"/></body></worldbody></mujoco>"""
        model = mujoco.MjModel.from_xml_string(xml)
        data = mujoco.MjData(model)

        def peer():
            mujoco.mj_resetData(model, data)
            data.qvel[3:6] = [0.0, 1.0, 1.0]  # the free joint's angular velocity: body frame
            mujoco.mj_step(model, data, nstep=STEPS)
            return data.qvel[3:6].copy()

        t_peer, w_peer = timed(peer, repeat)
        err_peer = float(np.abs(w_peer - exact[-1]).max())
        rows.append(
            row(
                "notebook body, torque-free, 2·10⁴ RK4 steps (dt 1e-3)",
                "simulate rk4 (101 samples)",
                t_ours,
                f"MuJoCo {mujoco.__version__} mj_step(nstep=2·10⁴)",
                t_peer,
                err_ours,
                err_peer,
                "target ≥ 100×",
            )
        )
    # the notebook's own NumPy loop (its RK4 on the 18-state, eqs (07)–(09))
    A = body.inertia
    A_inv = np.linalg.inv(A)

    def rhs(y):
        Q = y[6:15].reshape(3, 3)
        w = y[15:18]
        W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        return np.concatenate([y[3:6], np.zeros(3), (Q @ W).ravel(), A_inv @ np.cross(A @ w, w)])

    def loop():
        y = np.concatenate([body.center_of_mass, np.zeros(3), np.eye(3).ravel(), [0, 1, 1.0]])
        for _ in range(STEPS):
            k1 = rhs(y)
            k2 = rhs(y + 0.5 * DT * k1)
            k3 = rhs(y + 0.5 * DT * k2)
            k4 = rhs(y + DT * k3)
            y = y + DT / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        return y[15:18]

    t_loop, w_loop = timed(loop, max(1, repeat // 3))
    rows.append(
        row(
            "same, against the notebook's NumPy loop",
            "simulate rk4",
            t_ours,
            "NumPy RK4 loop",
            t_loop,
            err_ours,
            float(np.abs(w_loop - exact[-1]).max()),
        )
    )
    # for context: the same RK4 hand-written for this one problem and compiled (numba is a
    # peer here, installed for the comparison only)
    try:
        import numba
    except ImportError:
        return rows

    @numba.njit(cache=False)
    def hand(y, n, dt, I):
        k1 = np.empty(18)
        k2 = np.empty(18)
        k3 = np.empty(18)
        k4 = np.empty(18)
        yt = np.empty(18)

        def f(y, out):
            w1, w2, w3 = y[15], y[16], y[17]
            for i in range(3):
                out[i] = y[3 + i]
                out[3 + i] = 0.0
            for r in range(3):
                a, b, c = y[6 + 3 * r], y[7 + 3 * r], y[8 + 3 * r]
                out[6 + 3 * r] = b * w3 - c * w2
                out[7 + 3 * r] = c * w1 - a * w3
                out[8 + 3 * r] = a * w2 - b * w1
            out[15] = (I[1] - I[2]) * w2 * w3 / I[0]
            out[16] = (I[2] - I[0]) * w3 * w1 / I[1]
            out[17] = (I[0] - I[1]) * w1 * w2 / I[2]

        for _ in range(n):
            f(y, k1)
            for i in range(18):
                yt[i] = y[i] + 0.5 * dt * k1[i]
            f(yt, k2)
            for i in range(18):
                yt[i] = y[i] + 0.5 * dt * k2[i]
            f(yt, k3)
            for i in range(18):
                yt[i] = y[i] + dt * k3[i]
            f(yt, k4)
            for i in range(18):
                y[i] += dt / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i])
        return y

    y0 = np.concatenate([np.zeros(3), np.zeros(3), np.eye(3).ravel(), [0, 1, 1.0]])
    I_body = np.ascontiguousarray(np.diag(body.inertia))
    t_hand, y_hand = timed(lambda: hand(y0.copy(), STEPS, DT, I_body), repeat)
    rows.append(
        row(
            "same, against RK4 hand-written for this problem in numba (no samples)",
            "simulate rk4",
            t_ours,
            "hand-written numba RK4",
            t_hand,
            err_ours,
            float(np.abs(y_hand[15:18] - exact[-1]).max()),
            "the cost of generality",
        )
    )
    return rows


def case_dop853_vs_scipy(repeat):
    """The default adaptive method at rtol 1e-10, atol 1e-12, against SciPy's DOP853 on the
    notebook's right-hand side (per-particle forces and torques), under gravity."""
    from scipy.integrate import solve_ivp

    from poinsot import Gravity, simulate

    body, free = notebook()
    exact = free.exact_omega((0, 1, 1), SAMPLES)  # gravity has no torque about the c.o.m.
    m, u = body.particle_masses, body.u
    A, A_inv, M = body.inertia, np.linalg.inv(body.inertia), body.mass
    F_i = np.outer(m, [0.0, 0.0, -9.8])

    def rhs(_, y):  # the notebook's right-hand side: Σ F_i and Σ u_i × Qᵀ F_i, eqs (07)–(09)
        Q = y[6:15].reshape(3, 3)
        w = y[15:18]
        W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        torque = np.cross(u, F_i @ Q).sum(0)
        wdot = A_inv @ (torque - np.cross(w, A @ w))
        return np.concatenate([y[3:6], F_i.sum(0) / M, (Q @ W).ravel(), wdot])

    y0 = np.concatenate([body.center_of_mass, np.zeros(3), np.eye(3).ravel(), [0, 1, 1.0]])

    def peer():
        return solve_ivp(
            rhs, (0, T_END), y0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=SAMPLES
        ).y.T[:, 15:18]

    def ours():
        return simulate(
            body, (0, T_END), omega0=(0, 1, 1), forces=[Gravity((0, 0, -9.8))], t_eval=SAMPLES
        ).omega

    t_ours, w_ours = timed(ours, repeat)
    t_peer, w_peer = timed(peer, max(1, repeat // 2))
    return [
        row(
            "notebook body under gravity, adaptive, rtol 1e-10, t ∈ [0, 20]",
            "simulate dop853",
            t_ours,
            "SciPy solve_ivp DOP853, notebook RHS",
            t_peer,
            float(np.abs(w_ours - exact).max()),
            float(np.abs(w_peer - exact).max()),
            "target ≥ 20×, error ≤ 1e-9",
        )
    ]


def case_methods(repeat):
    """Steps per second of every fixed-step method beside RK4, with the invariants each keeps:
    the notebook body, torque-free, 2·10⁴ steps."""
    from poinsot import simulate

    body, _ = notebook()
    rows = []
    for method in ("rk4", "rkmk4", "splitting"):

        def run(method=method):
            return simulate(body, (0, T_END), omega0=(0, 1, 1), method=method, dt=DT,
                            t_eval=SAMPLES)  # fmt: skip

        t, tr = timed(run, repeat)
        d = tr.diagnostics()
        L = np.linalg.norm(tr.angular_momentum_com, axis=1)
        rows.append(
            {
                "case": f"{method}: {STEPS / t / 1e6:.2f}·10⁶ steps/s",
                "method": method,
                "steps_per_s": STEPS / t,
                "poinsot_s": t,
                "energy_error": d["energy_drift"],
                "momentum_error": float(np.abs(L / L[0] - 1).max()),
                "orthogonality_error": d["orthogonality_error"],
            }
        )
    return rows


def case_slow_path(repeat):
    """The 27-particle body under gravity: built-in Gravity (compiled) against the same force
    written as a per-particle ParticleForce (a Python callable: the slow path)."""
    from poinsot import Gravity, ParticleForce, simulate

    body, _ = notebook()
    m = body.particle_masses
    weights = ParticleForce(lambda t, r, v: np.outer(m, [0.0, 0.0, -9.8]), position_only=True)
    kw = dict(omega0=(0, 1, 1), t_eval=SAMPLES)
    t_fast, a = timed(lambda: simulate(body, (0, T_END), forces=[Gravity((0, 0, -9.8))], **kw),
                      repeat)  # fmt: skip
    t_slow, b = timed(lambda: simulate(body, (0, T_END), forces=[weights], **kw),
                      max(1, repeat // 3))  # fmt: skip
    return [
        row(
            "27 particles under gravity, dop853: Gravity vs ParticleForce",
            "Gravity (compiled)",
            t_fast,
            "ParticleForce (Python callable)",
            t_slow,
            None,
            float(np.abs(a.state - b.state).max()),
            "what a Python callable costs",
        )
    ]


LATENCY = textwrap.dedent(
    """
    import time
    t0 = time.perf_counter()
    from poinsot import simulate
    from poinsot.models import notebook_body
    body = notebook_body()
    t1 = time.perf_counter()
    simulate(body, (0, 20), omega0=(0, 1, 1), method="{method}", dt=1e-3)
    t2 = time.perf_counter()
    print(t1 - t0, t2 - t1)
    """
)


def case_latency(repeat):
    """First call in a fresh process, twice (the second with whatever the first left in the
    caches): nothing is compiled at run time, so both cost the same."""
    rows = []
    for method in ("rk4", "dop853"):
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, POINSOT_CACHE_DIR=cache)
            runs = []
            for _ in range(2):
                out = subprocess.run(
                    [sys.executable, "-c", LATENCY.format(method=method)],
                    capture_output=True,
                    text=True,
                    env=env,
                    check=True,
                )
                runs.append([float(x) for x in out.stdout.split()])
        (_, cold), (imp_warm, warm) = runs
        rows.append(
            {
                "case": f"first simulate({method!r}) in a new process",
                "cold_cache_s": cold,
                "warm_cache_s": warm,
                "import_s": imp_warm,
            }
        )
    return rows


def case_exact_omega(repeat):
    from scipy.integrate import solve_ivp

    from poinsot.torquefree import FreeRigidBody

    I = np.array([1.0, 2.0, 3.0])
    w0 = np.array([0.3, 1.0, 0.5])
    t = np.linspace(0, 100, 10_001)
    fb = FreeRigidBody(I)

    def rhs(_, w):
        return np.array(
            [
                (I[1] - I[2]) / I[0] * w[1] * w[2],
                (I[2] - I[0]) / I[1] * w[2] * w[0],
                (I[0] - I[1]) / I[2] * w[0] * w[1],
            ]
        )

    def peer():
        return solve_ivp(rhs, (0, 100), w0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t).y.T

    t_ours, ours = timed(lambda: fb.exact_omega(w0, t), repeat)
    t_peer, theirs = timed(peer, repeat)
    ref = solve_ivp(rhs, (0, 100), w0, method="DOP853", rtol=2.5e-14, atol=1e-16, t_eval=t).y.T
    return [
        row(
            "ω(t), torque-free, 10⁴ times over t ∈ [0, 100]",
            "exact_omega",
            t_ours,
            "solve_ivp DOP853 rtol 1e-10",
            t_peer,
            float(np.abs(ours - ref).max()),
            float(np.abs(theirs - ref).max()),
        )
    ]


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
    t_peer, A_peer = timed(peer, max(1, repeat // 3))
    return [
        row(
            "inertia of 2·10⁴ particles",
            "RigidBody.from_particles",
            t_ours,
            "per-particle loop",
            t_peer,
            None,
            float(np.abs(A_ours - A_peer).max()),
        )
    ]


def case_lagrange(repeat):
    import sympy as sp
    from scipy.integrate import solve_ivp
    from sympy.physics.mechanics import LagrangesMethod

    from poinsot import models

    t = np.linspace(0, 10, 201)

    def ours():
        return models.double_pendulum().simulate((0, 10), t_eval=t).q

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
        sol = solve_ivp(rhs, (0, 10), y0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t)
        return sol.y.T[:, :2]

    reps = max(1, repeat // 3)
    t_ours, q_ours = timed(ours, reps)
    t_peer, q_peer = timed(peer, reps)
    return [
        row(
            "double pendulum: derive + integrate t ∈ [0, 10]",
            "LagrangianSystem",
            t_ours,
            "SymPy LagrangesMethod + solve_ivp",
            t_peer,
            None,
            float(np.abs(q_ours - q_peer).max()),
        )
    ]


def case_euler_body(repeat):
    """Deriving M and f of a rigid body given by z-x-z Euler angles: poinsot from the attitude
    matrix Q(ψ, θ, φ), SymPy's LagrangesMethod from its frames (the issue's 13 s vs 2 s)."""
    import sympy as sp
    from sympy.physics.mechanics import (
        LagrangesMethod,
        Lagrangian,
        Point,
        ReferenceFrame,
        RigidBody,
        dynamicsymbols,
        inertia,
    )

    from poinsot import RigidBody as Body
    from poinsot.lagrange import LagrangianSystem

    psi, th, ph = dynamicsymbols("psi theta phi")
    N = ReferenceFrame("N")
    B = N.orientnew("B", "Body", [psi, th, ph], "ZXZ")
    body = Body(1.0, np.diag([1.0, 2.0, 3.0]))

    def ours():
        system = LagrangianSystem([psi, th, ph], bodies=[(body, [0, 0, 0], N.dcm(B))])
        return system.mass_matrix, system.forcing

    def peer():
        O = Point("O")
        O.set_vel(N, 0)
        rb = RigidBody("rb", O, B, sp.Integer(1), (inertia(B, 1, 2, 3), O))
        lm = LagrangesMethod(Lagrangian(N, rb), [psi, th, ph], frame=N)
        lm.form_lagranges_equations()
        return lm.mass_matrix, lm.forcing

    reps = max(3, repeat // 2)
    t_ours, (M, _) = timed(ours, reps)
    t_peer, (Mp, _) = timed(peer, reps)
    at = {psi: 0.3, th: 0.7, ph: -0.2}
    diff = float(np.abs(np.array((M - Mp).subs(at), float)).max())
    return [row("Euler-angle rigid body: derive M and f", "LagrangianSystem", t_ours,
                "SymPy LagrangesMethod", t_peer, None, diff)]  # fmt: skip


CASES = {
    "rk4": case_rk4_vs_mujoco,
    "dop853": case_dop853_vs_scipy,
    "methods": case_methods,
    "slow_path": case_slow_path,
    "latency": case_latency,
    "exact_omega": case_exact_omega,
    "inertia": case_inertia,
    "lagrange": case_lagrange,
    "euler_body": case_euler_body,
}
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ensemble_cases import CASES as _ENSEMBLE_CASES  # noqa: E402

CASES.update(_ENSEMBLE_CASES)
from lagrange_cases import CASES as _LAGRANGE_CASES  # noqa: E402
from relative_cases import CASES as _RELATIVE_CASES  # noqa: E402

CASES.update(_RELATIVE_CASES)
CASES.update(_LAGRANGE_CASES)


def _fmt_time(s):
    if s is None:
        return "—"
    return f"{s * 1e3:.3g} ms" if s < 1 else f"{s:.3g} s"


def _fmt_err(e):
    return "—" if e is None else f"{e:.1e}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--only", nargs="*", choices=sorted(CASES), default=None)
    parser.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    args = parser.parse_args(argv)
    names = args.only or list(CASES)
    results = {"machine": machine(), "repeat": args.repeat, "cases": {}}
    print(f"machine: {results['machine']}; medians of {args.repeat} runs\n")
    print("| case | poinsot | peer | peer/poinsot | max error (poinsot, peer) |")
    print("|---|---|---|---|---|")
    for name in names:
        rows = CASES[name](args.repeat)
        results["cases"][name] = rows
        for r in rows:
            if "ratio" in r:
                ratio = "—" if r["ratio"] is None else f"{r['ratio']:.3g}×"
                note = f" ({r['note']})" if r.get("note") else ""
                print(
                    f"| {r['case']}{note} | {_fmt_time(r['poinsot_s'])} ({r['poinsot']}) | "
                    f"{_fmt_time(r['peer_s'])} ({r['peer']}) | {ratio} | "
                    f"{_fmt_err(r['error_poinsot'])}, {_fmt_err(r['error_peer'])} |"
                )
            elif "steps_per_s" in r:
                print(
                    f"| {r['case']} | {_fmt_time(r['poinsot_s'])} | energy "
                    f"{r['energy_error']:.1e}, abs L {r['momentum_error']:.1e}, "
                    f"QᵀQ−I {r['orthogonality_error']:.1e} | | |"
                )
            elif "cold_cache_s" not in r:  # not measured: a peer is missing (the row says which)
                print(f"| {r['case']} | not measured: {r.get('note', 'no figures')} | | | |")
            else:
                print(
                    f"| {r['case']} | cold cache {_fmt_time(r['cold_cache_s'])}, warm cache "
                    f"{_fmt_time(r['warm_cache_s'])} (import {_fmt_time(r['import_s'])}) | | | |"
                )
        sys.stdout.flush()
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=2)


if __name__ == "__main__":
    main()
