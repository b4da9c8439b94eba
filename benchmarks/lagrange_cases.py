"""Constrained systems against PyDy and SymPy: the n-link pendulum on a cart (SymPy's
``models.n_link_pendulum_on_cart``), right-hand-side evaluation and integration.

poinsot derives the same system from its Lagrangian (point masses at the joints, link i
along ``(−sin q_i, cos q_i)`` as SymPy's ``B_i.y``, gravity along −y) and evaluates it with
the compiled engine (:mod:`poinsot.lagrange.engine`); PyDy evaluates SymPy's Kane equations
with its ``lambdify`` and ``cython`` generators. The right-hand sides are checked to agree
before they are timed. Needs ``pip install pydy cython setuptools`` (skipped without).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

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
    for n in (1, 2, 5, 10):
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
        u0 = np.zeros(0)
        out = compiled.model.rhs(0.0, y, pvec, u0)  # compiled when the model is made
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
        calls = 20000 if n < 5 else 2000
        rhs = compiled.model.rhs

        def ours(rhs=rhs, y=y, pvec=pvec, u0=u0):
            rhs(0.0, y, pvec, u0)

        t_ours = _timed_calls(ours, calls)
        for generator, (f, pv, setup) in pydy.items():
            t_peer = _timed_calls(lambda f=f, pv=pv, y=y: f(y, 0.0, pv), calls)
            note = f"set-up: poinsot {t_ours_setup:.2f} s, PyDy {setup:.2f} s"
            rows.append(row(f"{n}-link pendulum on a cart: one rhs evaluation", "compiled engine",
                            t_ours, f"PyDy {generator}", t_peer, err, None, note=note))  # fmt: skip
    return rows


def case_lagrange_integrate(repeat):
    """Integration of [0, 10] at rtol 1e-8 (101 samples): poinsot's compiled engine stepped
    by its compiled DOP853 against PyDy's ``System.integrate`` (SciPy's ``odeint``, LSODA) on
    the cython-generated right-hand side; errors at t = 10 against poinsot at rtol 1e-12. Also
    the set-up: derivation and code generation against SymPy's Kane derivation and PyDy's
    cython code generation (which compiles C), with poinsot's first run in a new cache folder
    (derivation, lowering, machine code by symjit) and a model seen before (found by its hash:
    nothing derived)."""
    try:
        from pydy.system import System
    except ImportError:
        return [{"case": "n-link pendulum on a cart", "note": "pydy missing: pip install pydy"}]
    import os
    import tempfile

    import sympy as sp
    from run import row, timed
    from sympy.physics.mechanics.models import n_link_pendulum_on_cart

    from poinsot import models
    from poinsot.lagrange import engine as engine_module
    from poinsot.lagrange.engine import compile_system

    times = np.linspace(0, 10, 101)
    tol = {"rtol": 1e-8, "atol": 1e-8}
    rows = []
    rng = np.random.default_rng(1)
    for n in (1, 2, 5, 10, "disc"):
        with tempfile.TemporaryDirectory() as cold:
            old = os.environ.get("POINSOT_CACHE_DIR")
            os.environ["POINSOT_CACHE_DIR"] = cold
            start = time.perf_counter()
            if n == "disc":
                mdl = models.rolling_coin()
                system, p_ours = mdl.system, dict(mdl.params)
                q0, qd0 = dict(mdl.q0), dict(mdl.qd0)
                qd0.pop(mdl.symbols["x"], None)
                qd0.pop(mdl.symbols["y"], None)
            else:
                system, q, m, l, g = _n_link_lagrangian(n)
                p_ours = {**{m[i]: 1.0 for i in range(n + 1)}, **{l[i]: 1.0 for i in range(n)},
                          g: 9.81}  # fmt: skip
                # near the hanging equilibrium (q_i = π: SymPy's links point along +y, up),
                # so that the motion is regular and the errors at t = 10 mean something
                angles = np.pi + rng.uniform(-0.3, 0.3, n + 1)
                angles[0] = 0.0  # the cart
                q0 = {qi: float(v) for qi, v in zip(q, angles, strict=True)}
                qd0 = {qi: 0.0 for qi in q}

            def ours(system=system, p_ours=p_ours, q0=q0, qd0=qd0, rtol=1e-8, atol=1e-8):
                return system.simulate((0, 10), q0=q0, qd0=qd0, params=p_ours, t_eval=times,
                                       rtol=rtol, atol=atol)  # fmt: skip

            compile_system(system)
            ours()
            setup_cold = time.perf_counter() - start

            def fresh(n=n):
                return models.rolling_coin().system if n == "disc" else _n_link_lagrangian(n)[0]

            from poinsot import _core

            start = time.perf_counter()  # derivation and lowering alone
            new = fresh()
            program = engine_module._program(new)
            derive_generate = time.perf_counter() - start
            sizes = (new.n_coordinates, new.n_constraints, new.n_holonomic,
                     len(new.parameters), len(new.inputs))  # fmt: skip
            start = time.perf_counter()  # the machine code of the program
            _core.LagrangianModel(*program, *sizes)
            machine_code = time.perf_counter() - start
            start = time.perf_counter()  # a model seen before: found by its hash, loaded
            compile_system(fresh())
            setup_warm = time.perf_counter() - start
            if old is None:
                del os.environ["POINSOT_CACHE_DIR"]
            else:
                os.environ["POINSOT_CACHE_DIR"] = old

        t_ours, sol = timed(ours, repeat)
        ref = ours(rtol=1e-12, atol=1e-12)
        start = time.perf_counter()
        if n == "disc":
            kane, (m_, r_, g_) = models.rolling_coin_kane()
            constants = {m_: p_ours[mdl.symbols["m"]], r_: p_ours[mdl.symbols["r"]],
                         g_: p_ours[mdl.symbols["g"]]}  # fmt: skip
            # PyDy's speeds: the independent ones (ψ̇, θ̇, φ̇), then the dependent ones (ẋ, ẏ)
            order = [2, 3, 4, 0, 1]
        else:
            kane = n_link_pendulum_on_cart(n, cart_force=False, joint_torques=False)
            constants = {sp.Symbol(f"m{i}"): 1.0 for i in range(n + 1)}
            constants.update({sp.Symbol(f"l{i}"): 1.0 for i in range(n)})
            constants[sp.Symbol("g")] = 9.81
            order = list(range(n + 1))
        peer = System(kane, constants=constants, times=times)
        peer.initial_conditions = {
            **dict(zip(kane.q, sol.q[0], strict=True)),
            **{kane.u[k]: sol.qd[0][order[k]] for k in range(len(kane.u))},
        }
        peer.generate_ode_function(generator="cython")
        peer_setup = time.perf_counter() - start
        t_peer, xs = timed(lambda peer=peer: peer.integrate(**tol), repeat)
        nq = len(kane.q)
        err_ours = float(np.abs(sol.q[-1] - ref.q[-1]).max())
        err_peer = float(np.abs(xs[-1, :nq] - ref.q[-1]).max())
        name = "rolling disc" if n == "disc" else f"{n}-link pendulum on a cart"
        rows.append(row(f"{name}: integrate [0, 10] at rtol 1e-8", "compiled engine, dop853",
                        t_ours, "PyDy System.integrate (odeint, cython)", t_peer, err_ours,
                        err_peer, note=f"{sol.nfev} rhs evaluations"))  # fmt: skip
        rows.append(row(f"{name}: derivation + code generation", "LagrangianSystem + "
                        "lowered program + machine code", derive_generate + machine_code,
                        "KanesMethod + PyDy cython (with its C compilation)", peer_setup, None,
                        None, note=f"machine code {machine_code * 1e3:.0f} ms; poinsot's "
                        f"first run {setup_cold:.2f} s; a model seen before: "
                        f"{setup_warm:.2f} s"))  # fmt: skip
    return rows


def case_lagrange_events(repeat):
    """Events located inside the core's time loop. (1) The pendulum (θ0 = 1 rad) over
    [0, 20] at rtol 1e-10 with its passages through the bottom as an event (a compiled
    expression) against SciPy's ``solve_ivp`` DOP853 with the same event on a NumPy
    right-hand side; errors: the largest event time's distance from the closed form
    (T/4 + kT/2, T = 4K(sin²(θ0/2))/√(g/l)). (2) The sliding ladder's release (the wall's
    reaction falling through zero, a one-sided constraint) on the compiled engine against the
    NumPy oracle of the tests (a detection grid, Brent's method over restarted runs); errors:
    |cos θ − ⅔ cos θ0| at the release (Kleppner & Kolenkow 7.9)."""
    from run import row, timed
    from scipy.integrate import solve_ivp
    from scipy.special import ellipk

    from poinsot import models
    from poinsot.integrate.events import Event

    rows = []
    mdl = models.pendulum_polar()
    th = mdl.symbols["theta"]
    th0, g = 1.0, 9.81
    T = 4 * ellipk(np.sin(th0 / 2) ** 2) / np.sqrt(g)
    tol = {"rtol": 1e-10, "atol": 1e-12}

    def ours():
        return mdl.simulate((0, 20), q0={th: th0}, events=Event(th), **tol)

    def rhs(t, y):
        return [y[1], -g * np.sin(y[0])]

    def bottom(t, y):
        return y[0]

    def peer():
        return solve_ivp(rhs, (0, 20), [th0, 0.0], method="DOP853", events=bottom,
                         t_eval=np.linspace(0, 20, 201), **tol)  # fmt: skip

    t_ours, sol = timed(ours, repeat)
    t_peer, ref = timed(peer, repeat)
    want = T / 4 + T / 2 * np.arange(len(sol.t_events[0]))
    err_ours = float(np.abs(sol.t_events[0] - want).max())
    err_peer = float(np.abs(ref.t_events[0] - want[: len(ref.t_events[0])]).max())
    rows.append(row("pendulum, bottom passages over [0, 20], rtol 1e-10 (201 samples)",
                    "simulate, compiled event", t_ours, "solve_ivp DOP853, events=",
                    t_peer, err_ours, err_peer,
                    note=f"{len(sol.t_events[0])} and {len(ref.t_events[0])} zeros"))  # fmt: skip

    ladder = models.sliding_ladder()
    theta = ladder.symbols["theta"]
    run = {"q0": {theta: 0.3}, "t_eval": np.linspace(0, 0.85, 86)}

    def core():
        return ladder.simulate((0, 0.85), **run)

    # the NumPy engine left the library; it is the tests' reference oracle now
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "lagrange"))
    import oracle

    def numpy_route():
        return oracle.simulate(ladder, (0, 0.85), **run)

    t_core, a = timed(core, repeat)
    t_np, b = timed(numpy_route, repeat)
    target = 2 / 3 * np.cos(0.3)
    rows.append(row("sliding ladder leaves the wall (one-sided constraint), 86 samples",
                    "compiled engine, release in the core", t_core,
                    "NumPy oracle (tests/lagrange), detection grid + Brent", t_np,
                    abs(np.cos(a.releases[0][2][2]) - target),
                    abs(np.cos(b.releases[0][2][2]) - target)))  # fmt: skip
    return rows


CASES = {"lagrange_engine": case_lagrange_engine, "lagrange_integrate": case_lagrange_integrate,
         "lagrange_events": case_lagrange_events}  # fmt: skip
