"""Constrained systems against PyDy and SymPy: the n-link pendulum on a cart (SymPy's
``models.n_link_pendulum_on_cart``), right-hand-side evaluation and integration.

poinsot derives the same system from its Lagrangian (point masses at the joints, link i
along ``(−sin q_i, cos q_i)`` as SymPy's ``B_i.y``, gravity along −y) and evaluates it with
the compiled engine (:mod:`poinsot.lagrange.engine`); PyDy evaluates SymPy's Kane equations
with its ``lambdify`` and ``cython`` generators. The right-hand sides are checked to agree
before they are timed. Needs ``pip install pydy cython setuptools`` (skipped without).
"""

from __future__ import annotations

import time

import numpy as np


def _n_link_lagrangian(n):
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols

    from poinsot.lagrange import LagrangianSystem, PointMass

    q = dynamicsymbols(f"q:{n + 1}")
    m = sp.symbols(f"m:{n + 1}")
    l = sp.symbols(f"l:{n}")
    g = sp.Symbol("g")
    x, y = q[0], sp.Integer(0)
    bodies = [PointMass(m[0], [x, y, 0])]
    potential = 0
    for i in range(n):
        x, y = x - l[i] * sp.sin(q[i + 1]), y + l[i] * sp.cos(q[i + 1])  # along B_i.y
        bodies.append(PointMass(m[i + 1], [x, y, 0]))
        potential += m[i + 1] * g * y
    return LagrangianSystem(list(q), bodies=bodies, potential=potential), q, m, l, g


def _timed_calls(fn, calls):
    fn()
    start = time.perf_counter()
    for _ in range(calls):
        fn()
    return (time.perf_counter() - start) / calls


def case_lagrange_engine(repeat):
    try:
        from pydy.codegen.ode_function_generators import generate_ode_function
    except ImportError:
        return [{"case": "n-link pendulum on a cart", "note": "pydy missing: pip install pydy"}]
    import sympy as sp
    from run import row  # the benchmark runner's table rows
    from sympy.physics.mechanics.models import n_link_pendulum_on_cart

    from poinsot.lagrange.engine import compile_system

    rows = []
    rng = np.random.default_rng(0)
    for n in (1, 2, 5):
        kane = n_link_pendulum_on_cart(n, cart_force=False, joint_torques=False)
        consts = sorted((kane.mass_matrix_full.free_symbols | kane.forcing_full.free_symbols)
                        - {sp.Symbol("t")}, key=str)  # fmt: skip
        values = {
            c: float(v) for c, v in zip(consts, rng.uniform(0.5, 2.0, len(consts)), strict=True)
        }
        values[sp.Symbol("g")] = 9.81
        system, _, m, l, g = _n_link_lagrangian(n)
        p_ours = {**{m[i]: values[sp.Symbol(f"m{i}")] for i in range(n + 1)},
                  **{l[i]: values[sp.Symbol(f"l{i}")] for i in range(n)}, g: 9.81}  # fmt: skip
        start = time.perf_counter()
        compiled = compile_system(system)
        pvec = compiled.parameter_vector(p_ours)
        y = np.concatenate([rng.uniform(-1, 1, n + 1), rng.uniform(-1, 1, n + 1)])
        out = np.empty_like(y)
        compiled.module.rhs(0.0, y, pvec, np.zeros(0), 0.0, 0.0, out)  # compiles (or loads)
        t_ours_setup = time.perf_counter() - start
        pydy = {}
        for generator in ("lambdify", "cython"):
            start = time.perf_counter()
            f = generate_ode_function(
                kane.forcing_full, kane.q, kane.u, consts,
                mass_matrix=kane.mass_matrix_full, generator=generator,
            )  # fmt: skip
            setup = time.perf_counter() - start
            pv = np.array([values[c] for c in consts])
            pydy[generator] = (f, pv, setup)
        ref = pydy["cython"][0](y, 0.0, pydy["cython"][1])
        err = float(np.abs(out - ref).max())
        calls = 20000 if n < 5 else 5000
        rhs, u0 = compiled.module.rhs, np.zeros(0)

        def ours(rhs=rhs, y=y, pvec=pvec, u0=u0, out=out):
            rhs(0.0, y, pvec, u0, 0.0, 0.0, out)

        t_ours = _timed_calls(ours, calls)
        for generator, (f, pv, setup) in pydy.items():
            t_peer = _timed_calls(lambda f=f, pv=pv, y=y: f(y, 0.0, pv), calls)
            note = f"set-up: poinsot {t_ours_setup:.2f} s, PyDy {setup:.2f} s"
            rows.append(row(f"{n}-link pendulum on a cart: one rhs evaluation", "compiled engine",
                            t_ours, f"PyDy {generator}", t_peer, err, None, note=note))  # fmt: skip
    return rows


CASES = {"lagrange_engine": case_lagrange_engine}
