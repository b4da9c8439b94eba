"""What a Lagrangian run's sensitivities cost, against peers, in one run (medians of N
repeats after a warm-up).

    python benchmarks/lagrange_sensitivities.py [--repeat N] [--t-end T]

The system is SymPy's double pendulum on a cart (``models.n_link_pendulum_on_cart(2)``'s
geometry and constants: masses m0, m1, m2, lengths l0, l1, g = 9.81), released near the
hanging position, over [0, T] with 201 samples; the derivatives of the state with respect to
the p = 5 parameters (the masses and lengths). Routes, each timed after its set-up:

* poinsot with sensitivities (DOP853 at rtol 1e-8, atol 1e-10; and RK4 at dt = 1e-3), against
  the plain poinsot run;
* PyDy (``KanesMethod`` + ``System.integrate``, LSODA at the same tolerances) with central
  differences: 2p + 1 runs;
* ``jax.jacfwd`` through a diffrax solve (``Dopri8``, PID controller at the same tolerances)
  of the same equations (SymPy's M and f lambdified to jax), float64, jit-compiled (the
  compile time reported apart).

It prints each route's time, its ratio to poinsot's, and each route's largest difference from
poinsot's sensitivities at the end (relative to their largest entry).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import sympy as sp
from run import timed  # the benchmarks' one timer (benchmarks/run.py)
from sympy import cos, sin
from sympy.physics.mechanics import dynamicsymbols

N_LINKS = 2
RTOL, ATOL = 1e-8, 1e-10
WRT_NAMES = ("m0", "m1", "m2", "l0", "l1")


def values(symbols):
    return {s: (9.81 if str(s) == "g" else (1.0 if str(s).startswith("m") else 0.5))
            for s in symbols}  # fmt: skip


def x0():
    return np.concatenate([[0.0], np.pi + 0.1 * np.arange(1, N_LINKS + 1), np.zeros(N_LINKS + 1)])


def poinsot_system():
    from poinsot.lagrange import LagrangianSystem, PointMass

    n = N_LINKS
    q = dynamicsymbols(f"q:{n + 1}")
    ms, ls, g = sp.symbols(f"m:{n + 1}"), sp.symbols(f"l:{n}"), sp.Symbol("g")
    pts = [sp.Matrix([q[0], 0, 0])]
    for i in range(n):  # SymPy's model's geometry: q_i = 0 upright
        pts.append(pts[-1] + ls[i] * sp.Matrix([-sin(q[i + 1]), cos(q[i + 1]), 0]))
    pairs = list(zip(ms, pts, strict=True))
    system = LagrangianSystem(q, bodies=[PointMass(mi, p) for mi, p in pairs],
                              potential=sum(mi * g * p[1] for mi, p in pairs))  # fmt: skip
    return system, q


def case_poinsot(t_end, repeat):
    system, q = poinsot_system()
    params = values(system.parameters)
    q0 = {c: v for c, v in zip(q, x0()[: N_LINKS + 1], strict=True)}
    wrt = tuple(f"params[{s}]" for s in WRT_NAMES)
    tev = np.linspace(0, t_end, 201)
    out = {}
    for method, kw in (("dop853", {"rtol": RTOL, "atol": ATOL}), ("rk4", {"dt": 1e-3})):
        plain = system.prepare((0, t_end), params=params, method=method, t_eval=tev, **kw)
        sens = system.prepare((0, t_end), params=params, method=method, t_eval=tev,
                              sensitivities=wrt, **kw)  # fmt: skip
        t_plain, _ = timed(lambda p=plain: p.run(q0=q0), repeat)
        t_sens, sol = timed(lambda p=sens: p.run(q0=q0), repeat)
        out[method] = (t_plain, t_sens, sol.sensitivity("state")[-1])
    return out


def case_pydy(t_end, repeat):
    import sympy.physics.mechanics.models as models
    from pydy.system import System

    kane = models.n_link_pendulum_on_cart(N_LINKS, cart_force=False, joint_torques=False)
    consts = [c for c in sp.ordered(kane.forcing_full.free_symbols
                                    | kane.mass_matrix_full.free_symbols)
              if c != dynamicsymbols._t]  # fmt: skip
    vals = values(consts)
    times = np.linspace(0, t_end, 201)
    start = dict(zip(kane.q[:] + kane.u[:], x0(), strict=True))
    sysm = System(kane, constants=dict(vals), times=times, initial_conditions=start)
    sysm.generate_ode_function()
    by_name = {str(c): c for c in consts}

    def final(moved):
        sysm.constants = {**vals, **moved}
        return sysm.integrate(rtol=RTOL, atol=ATOL)[-1]

    def differences(h=1e-5):
        base = final({})
        cols = []
        for name in WRT_NAMES:
            c = by_name[name]
            up, down = final({c: vals[c] + h}), final({c: vals[c] - h})
            cols.append((up - down) / (2 * h))
        return base, np.array(cols).T

    t_fd, (_, S) = timed(differences, repeat)
    # PyDy's state is [q, u] with u = q̇ for this model
    return t_fd, S


def case_jax(t_end, repeat):
    import jax

    jax.config.update("jax_enable_x64", True)
    import diffrax
    import jax.numpy as jnp

    system, _ = poinsot_system()
    names = system.plain
    M = sp.Matrix(system.mass_matrix).applyfunc(names.of)
    f = sp.Matrix(system.forcing).applyfunc(names.of)
    args = (list(names.q), list(names.v), list(system.parameters))
    M_fn = sp.lambdify(args, M, modules="jax")
    f_fn = sp.lambdify(args, f, modules="jax")
    n = N_LINKS + 1
    params = values(system.parameters)
    p0 = jnp.array([params[s] for s in system.parameters])
    at = [[str(s) for s in system.parameters].index(w) for w in WRT_NAMES]

    def field(t, y, p):
        qq, vv = y[:n], y[n:]
        point = (list(qq), list(vv), list(p))
        acc = jnp.linalg.solve(jnp.asarray(M_fn(*point)), jnp.asarray(f_fn(*point)).reshape(n))
        return jnp.concatenate([vv, acc])

    y0 = jnp.array(x0())

    def final(sub):
        p = p0.at[jnp.array(at)].set(sub)
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(field), diffrax.Dopri8(), 0.0, t_end, 1e-3, y0, args=p,
            stepsize_controller=diffrax.PIDController(rtol=RTOL, atol=ATOL),
            saveat=diffrax.SaveAt(t1=True), max_steps=1_000_000, adjoint=diffrax.ForwardMode(),
        )  # fmt: skip
        return sol.ys[-1]

    jac = jax.jit(jax.jacfwd(final))
    sub = p0[jnp.array(at)]
    start = time.perf_counter()
    jac(sub).block_until_ready()
    t_compile = time.perf_counter() - start
    t_run, S = timed(lambda: jac(sub).block_until_ready(), repeat)
    return t_compile, t_run, np.asarray(S)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--t-end", type=float, default=10.0)
    a = ap.parse_args()
    ours = case_poinsot(a.t_end, a.repeat)
    ref = ours["dop853"][2]
    scale = np.abs(ref).max()
    print(f"double pendulum on a cart, T = {a.t_end:g} s, p = {len(WRT_NAMES)} parameters "
          f"({', '.join(WRT_NAMES)})")  # fmt: skip
    for method, (t_plain, t_sens, S) in ours.items():
        print(f"poinsot {method:7s} plain {t_plain * 1e3:8.2f} ms  with sensitivities "
              f"{t_sens * 1e3:8.2f} ms  = {t_sens / t_plain:5.2f}× the plain run  "
              f"(vs DOP853's {np.abs(S - ref).max() / scale:.1e})")  # fmt: skip
    t_ours = ours["dop853"][1]
    try:
        t_fd, S = case_pydy(a.t_end, a.repeat)
        print(f"PyDy + central differences ({2 * len(WRT_NAMES) + 1} runs) {t_fd * 1e3:9.2f} ms "
              f"= {t_fd / t_ours:7.1f}× poinsot's DOP853 with sensitivities; "
              f"difference {np.abs(S - ref).max() / scale:.1e}")  # fmt: skip
    except ImportError as exc:
        print(f"PyDy: not installed ({exc})")
    try:
        t_compile, t_run, S = case_jax(a.t_end, a.repeat)
        diff = np.abs(S - ref).max() / scale
        print(f"jax.jacfwd through diffrax (Dopri8) {t_run * 1e3:9.2f} ms = "
              f"{t_run / t_ours:7.1f}× poinsot's DOP853 with sensitivities (jit compile "
              f"{t_compile:.1f} s apart); difference {diff:.1e}")  # fmt: skip
    except ImportError as exc:
        print(f"jax/diffrax: not installed ({exc})")


if __name__ == "__main__":
    main()
