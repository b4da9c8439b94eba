"""Specified inputs (constant, f(t), feedback f(t, q, q̇), missing) and the linearisation
about steady motions with its input matrix B and stability verdict, checked against closed
forms and SymPy's own Linearizer."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols

from poinsot import models
from poinsot.lagrange import LagrangianSystem

t = dynamicsymbols._t


@pytest.fixture(scope="module")
def cart():
    """A cart of mass m pushed by a force F(t) on a spring k: m ẍ = −k x + F."""
    x, F = dynamicsymbols("x F")
    m, k = sp.symbols("m k", positive=True)
    system = LagrangianSystem([x], kinetic=m * x.diff() ** 2 / 2, potential=k * x**2 / 2,
                              forces=[{x: F}], units={x: "m"})  # fmt: skip
    return system, x, F


def test_inputs_are_found_and_a_missing_one_is_named(cart):
    system, x, F = cart
    assert system.inputs == [F] and [str(p) for p in system.parameters] == ["k", "m"]
    with pytest.raises(ValueError, match=r"`inputs` must give every input.*missing F\(t\)"):
        system.simulate((0, 1), q0={x: 0}, params={"m": 1, "k": 1})
    with pytest.raises(ValueError, match=r"`inputs`: 'G' is not an input of the system"):
        system.simulate((0, 1), q0={x: 0}, params={"m": 1, "k": 1}, inputs={"F": 1, "G": 2})
    with pytest.raises(TypeError, match=r"`inputs\[F\]` must take \(t\) or \(t, q, qd\)"):
        system.simulate((0, 1), q0={x: 0}, params={"m": 1, "k": 1},
                        inputs={"F": lambda t, q: 0})  # fmt: skip


def test_constant_and_time_inputs_match_closed_forms(cart):
    system, x, F = cart
    t_eval = np.linspace(0, 3, 31)
    # constant force F0 on a spring from rest: x = F0/k (1 − cos ωt)
    sol = system.simulate((0, 3), q0={x: 0}, params={"m": 2, "k": 8}, inputs={F: 4.0},
                          t_eval=t_eval)  # fmt: skip
    np.testing.assert_allclose(sol.q[:, 0], 0.5 * (1 - np.cos(2 * t_eval)), atol=1e-9)
    np.testing.assert_allclose(sol.inputs[:, 0], 4.0)
    # resonant forcing F = sin 2t with ω = 2: x = (sin ωt − ωt cos ωt)/(2 m ω²)
    sol = system.simulate((0, 3), q0={x: 0}, params={"m": 2, "k": 8},
                          inputs={"F": lambda s: np.sin(2 * s)}, t_eval=t_eval)  # fmt: skip
    exact = (np.sin(2 * t_eval) - 2 * t_eval * np.cos(2 * t_eval)) / (2 * 2 * 4)
    np.testing.assert_allclose(sol.q[:, 0], exact, atol=1e-9)


def test_feedback_input_is_a_damper(cart):
    system, x, F = cart
    c = 0.4  # F = −c ẋ: a damped oscillator, x = e^{−ζωt}(cos ω_d t + ζω/ω_d sin ω_d t)
    t_eval = np.linspace(0, 5, 51)
    sol = system.simulate((0, 5), q0={x: 1}, params={"m": 1, "k": 4},
                          inputs={F: lambda s, q, qd: -c * qd[0]}, t_eval=t_eval)  # fmt: skip
    w, zeta = 2.0, c / (2 * 2.0)
    wd = w * np.sqrt(1 - zeta**2)
    exact = np.exp(-zeta * w * t_eval) * (np.cos(wd * t_eval) + zeta * w / wd * np.sin(wd * t_eval))
    np.testing.assert_allclose(sol.q[:, 0], exact, atol=1e-8)
    # the energy h is no constant of the motion with an input acting
    assert [s for _, s, *_ in system.constants_of_motion()] == []


def test_linearize_gives_the_input_matrix(cart):
    system, x, F = cart
    lin = system.linearize({x: 0.0}, params={"m": 2, "k": 8}, inputs={F: 0.0})
    np.testing.assert_allclose(lin.matrix, [[0, 1], [-4, 0]], atol=1e-6)
    np.testing.assert_allclose(lin.input_matrix, [[0], [0.5]], atol=1e-15)  # 1/m
    assert lin.verdict == "spectrally stable" and lin.frequencies[0] == pytest.approx(2.0)


def _cart_pole_with_inputs():
    """The pendulum on a cart pushed by ``F`` on the cart, ``P`` horizontally on the bob and
    turned by ``τ`` at the pivot: generalized forces ``Q_x = F + P``, ``Q_θ = τ + P l cos θ``."""
    x, th, F, P, tau = dynamicsymbols("x theta F P tau")
    M, m, l, g = sp.symbols("M m l g", positive=True)
    kinetic = ((M + m) * x.diff() ** 2 / 2 + m * l * x.diff() * th.diff() * sp.cos(th)
               + m * l**2 * th.diff() ** 2 / 2)  # fmt: skip
    system = LagrangianSystem([x, th], kinetic=kinetic, potential=-m * g * l * sp.cos(th),
                              forces=[{x: F + P, th: tau + P * l * sp.cos(th)}])  # fmt: skip
    return system, (x, th), (F, P, tau)


def test_the_input_matrix_is_exact():
    """B = ∂ẏ/∂u from the compiled Jacobian along the inputs: against its closed form
    ``[0; M(q)⁻¹ ∂Q/∂u]`` held at a tilted equilibrium (τ0 = m g l sin θ0), to round-off, and
    against central differences of the compiled rates (the route before) at a moving state."""
    from poinsot.lagrange.engine import compile_system, compile_tangent

    system, (x, th), (F, P, tau) = _cart_pole_with_inputs()
    par = {"M": 2.0, "m": 0.7, "l": 1.3, "g": 9.81}
    th0 = 0.4
    tau0 = par["m"] * par["g"] * par["l"] * np.sin(th0)
    lin = system.linearize({x: 0.0, th: th0}, params=par, inputs={F: 0.0, P: 0.0, tau: tau0})
    Mq = np.array([[par["M"] + par["m"], par["m"] * par["l"] * np.cos(th0)],
                   [par["m"] * par["l"] * np.cos(th0), par["m"] * par["l"] ** 2]])  # fmt: skip
    dQ = np.array([[1.0, 1.0, 0.0], [0.0, par["l"] * np.cos(th0), 1.0]])
    want = np.vstack([np.zeros((2, 3)), np.linalg.solve(Mq, dQ)])
    assert lin.input_matrix.shape == (4, 3)
    np.testing.assert_allclose(lin.input_matrix, want, rtol=1e-14, atol=1e-15)
    # at a moving state with other inputs: the third block of rates_jacobian
    tangent, model = compile_tangent(system), compile_system(system)
    p = model.parameter_vector({k: par[str(k)] for k in system.parameters})
    y, u = np.array([0.2, 1.1, -0.4, 0.9]), np.array([0.3, -1.2, 0.5])
    ju = tangent.rates_jacobian(0.0, y, p, u)[2]

    def richardson(f, h):
        d1 = (f(h) - f(-h)) / (2 * h)
        d2 = (f(h / 2) - f(-h / 2)) / h
        return (4 * d2 - d1) / 3

    fd = np.column_stack([richardson(lambda h, e=e: model.model.rhs(0.0, y, p, u + h * e), 1e-3)
                          for e in np.eye(3)])  # fmt: skip
    np.testing.assert_allclose(ju, fd, rtol=1e-10, atol=1e-10)


def test_the_input_matrix_on_the_constraint_manifold():
    """The Cartesian pendulum pushed horizontally by ``F`` on the bob, hanging: in the chart of
    the constraint's tangent space (δx, δẋ), ``B = (0, ±1/m)`` (the polar pendulum's
    ``1/(m l)`` per radian, with ``δx = l δθ``)."""
    mdl = models.pendulum_cartesian()
    s = mdl.symbols
    F = dynamicsymbols("F")
    system = LagrangianSystem([s["x"], s["y"]], lagrangian=mdl.system.lagrangian,
                              holonomic=mdl.system.holonomic, forces=[{s["x"]: F}])  # fmt: skip
    par = {"m": 0.8, "g": 9.81, "l": 1.5}
    lin = system.linearize({s["x"]: 0.0, s["y"]: -1.5}, params=par, inputs={F: 0.0})
    assert lin.input_matrix.shape == (2, 1)
    np.testing.assert_allclose(np.abs(lin.input_matrix[:, 0]), [0.0, 1 / 0.8], atol=1e-15)


def test_free_cart_has_secular_growth_not_stability():
    mdl = models.pendulum_on_cart()
    s = mdl.symbols
    lin = mdl.system.linearize({s["x"]: 0.0, s["theta"]: 0.0}, params=mdl.params)
    assert lin.verdict == "secular growth" and not lin.stable
    assert lin.ignorable == (s["x"],) and lin.reduced_verdict == "spectrally stable"
    top = mdl.system.linearize({s["x"]: 0.0, s["theta"]: np.pi}, params=mdl.params)
    assert top.verdict == "unstable" and top.reduced_verdict == "unstable"


def test_conical_pendulum_is_a_stable_steady_motion():
    # small oscillations about a conical motion at θ0: Ω² = φ̇² (1 + 3 cos² θ0), φ̇² = g/(l cos θ0)
    # (Landau & Lifshitz, Mechanics, §14 problem 1)
    mdl = models.spherical_pendulum()
    s = mdl.symbols
    th0 = 0.6
    w = np.sqrt(9.81 / np.cos(th0))
    lin = mdl.system.linearize({s["theta"]: th0, s["phi"]: 0.0}, params=mdl.params,
                               speeds={s["phi"]: w})  # fmt: skip
    assert lin.frequencies[0] == pytest.approx(w * np.sqrt(1 + 3 * np.cos(th0) ** 2), rel=1e-7)
    assert lin.reduced_verdict == "spectrally stable" and lin.ignorable == (s["phi"],)
    with pytest.raises(ValueError, match="not a steady motion: accelerations"):
        mdl.system.linearize({s["theta"]: th0, s["phi"]: 0.0}, params=mdl.params,
                             speeds={s["phi"]: 1.0})  # fmt: skip


def _sympy_eigenvalues(L, coords, op):
    lm = LagrangesMethod(L, coords)
    lm.form_lagranges_equations()
    speeds = [q.diff(t) for q in coords]
    point = {**op, **{q.diff(t, 2): 0 for q in coords}}
    A, _, _ = lm.linearize(q_ind=coords, qd_ind=speeds, op_point=point, A_and_B=True)
    return _sorted(np.linalg.eigvals(np.array(A.evalf(), dtype=float)))


def _sorted(ev):
    """Eigenvalues in a fixed order, insensitive to round-off in their real parts."""
    ev = np.asarray(ev, dtype=complex)
    return ev[np.lexsort((np.round(ev.imag, 6), np.round(ev.real, 6)))]


@pytest.mark.parametrize("w3", [100.0, 50.0])
def test_heavy_top_steady_precession_agrees_with_sympy_linearizer(w3):
    mdl = models.heavy_symmetric_top()
    p = {str(k): v for k, v in mdl.params.items()}
    th0 = 0.6
    # steady precession Ω: A cos θ0 Ω² − C ω3 Ω + M g l = 0 (Goldstein §5.7), the slow root
    Om = min(np.roots([p["A"] * np.cos(th0), -p["C"] * w3, p["M"] * p["g"] * p["l"]]), key=abs)
    phid = w3 - Om * np.cos(th0)
    psi, th, ph = mdl.system.coordinates
    lin = mdl.system.linearize({psi: 0.0, th: th0, ph: 0.0}, params=mdl.params,
                               speeds={psi: Om, ph: phid})  # fmt: skip
    L = mdl.system.lagrangian.subs(mdl.params)
    ref = _sympy_eigenvalues(L, [psi, th, ph], {psi: 0, th: th0, ph: 0, psi.diff(t): Om,
                                                th.diff(t): 0, ph.diff(t): phid})  # fmt: skip
    np.testing.assert_allclose(_sorted(lin.eigenvalues), ref, atol=1e-5)
    assert lin.reduced_verdict == "spectrally stable"
    assert set(lin.ignorable) == {psi, ph}


def test_knife_edge_rests_across_the_slope_held_by_its_reaction():
    mdl = models.knife_edge()
    s = mdl.symbols
    p = {str(k): v for k, v in mdl.params.items()}
    eqs = mdl.system.equilibria(params=mdl.params)
    assert [round(e[s["phi"]], 9) for e in eqs] == [round(-np.pi / 2, 9), round(np.pi / 2, 9)]
    weight = p["m"] * p["g"] * np.sin(p["alpha"])
    for e in eqs:
        assert set(e.free) == {s["x"], s["y"]}  # it rests anywhere on the plane
        ((name, lam),) = e.reactions.items()
        assert name == "sin(phi)*x' - cos(phi)*y'"
        assert lam == pytest.approx(-weight * np.sin(e[s["phi"]]), rel=1e-9)  # λ sin φ = −mg sin α
    # started there at rest, it stays put; the sideways reaction carries the weight
    sol = mdl.simulate((0, 3), q0=dict(eqs[1]), qd0={s["x"]: 0, s["y"]: 0, s["phi"]: 0},
                       t_eval=np.linspace(0, 3, 31))  # fmt: skip
    assert np.abs(sol.q - sol.q[0]).max() < 1e-12
    np.testing.assert_allclose(sol.multipliers[:, 0], -weight, rtol=1e-9)


def test_knife_edge_turning_never_slides_down():
    # φ = ωt: x = g sin α sin² ωt / (2ω²), y = g sin α (t − sin 2ωt / 2ω) / (2ω)
    mdl = models.knife_edge()
    s = mdl.symbols
    w, ga = 2.0, 9.81 * np.sin(0.3)
    t_eval = np.linspace(0, 6, 61)
    sol = mdl.simulate((0, 6), q0={s["x"]: 0, s["y"]: 0, s["phi"]: 0},
                       qd0={s["x"]: 0, s["y"]: 0, s["phi"]: w}, t_eval=t_eval)  # fmt: skip
    np.testing.assert_allclose(sol[s["x"]], ga * np.sin(w * t_eval) ** 2 / (2 * w**2), atol=1e-8)
    exact_y = ga * (t_eval - np.sin(2 * w * t_eval) / (2 * w)) / (2 * w)
    np.testing.assert_allclose(sol[s["y"]], exact_y, atol=1e-8)


def _upright_rolling(mdl, spin):
    """The operating point of upright rolling at spin rate ``spin``, with the contact speeds
    that the rolling constraints require."""
    s = mdl.symbols
    point = {s[k]: 0.0 for k in ("x", "y", "psi", "theta", "phi")}
    vx, vy = sp.symbols("v_x v_y")
    rates = {s["x"].diff(): vx, s["y"].diff(): vy, s["psi"].diff(): 0, s["theta"].diff(): 0,
             s["phi"].diff(): spin}  # fmt: skip
    rows = [sp.sympify(c).subs(rates).subs(point).subs(mdl.params) for c in mdl.system.nonholonomic]
    v = sp.solve(rows, [vx, vy])
    return point, {s["x"]: float(v[vx]), s["y"]: float(v[vy]), s["phi"]: spin}


def test_rolling_coin_is_stable_upright_exactly_above_the_critical_spin():
    # thin disc: the lean obeys θ̈ = (4/5)(g/r − 3Ω²) θ, so upright rolling is stable for
    # Ω² > g/(3r) and wobbles at ω² = (4/5)(3Ω² − g/r) (Greenwood, Advanced Dynamics, §6.3)
    mdl = models.rolling_coin()
    p = {str(k): v for k, v in mdl.params.items()}
    g_r = p["g"] / p["r"]
    critical = np.sqrt(g_r / 3)
    for ratio in (0.5, 0.99, 1.01, 2.0):
        spin = ratio * critical
        point, speeds = _upright_rolling(mdl, spin)
        lin = mdl.system.linearize(point, params=mdl.params, speeds=speeds)
        rate2 = 0.8 * (3 * spin**2 - g_r)
        if ratio < 1:
            assert lin.reduced_verdict == "unstable"
            assert np.max(lin.eigenvalues.real) == pytest.approx(np.sqrt(-rate2), rel=1e-6)
        else:
            assert lin.reduced_verdict == "spectrally stable"
            assert lin.frequencies.max() == pytest.approx(np.sqrt(rate2), rel=1e-6)
        assert {str(q) for q in lin.ignorable} >= {"x(t)", "y(t)", "phi(t)"}


@pytest.mark.parametrize("ratio", [0.5, 0.9, 1.1, 2.0])
def test_rolling_coin_critical_spin_agrees_with_sympy_linearizer(ratio):
    """The same disc by SymPy's Kane's method, linearised by SymPy's ``Linearizer`` about
    upright rolling (the dependent contact speeds from the rolling constraints): the lean's
    eigenvalues, real below the critical spin √(g/3r) and imaginary above, equal ours."""
    mdl = models.rolling_coin()
    p = {str(k): v for k, v in mdl.params.items()}
    spin = ratio * np.sqrt(p["g"] / p["r"] / 3)
    point, speeds = _upright_rolling(mdl, spin)
    ours = mdl.system.linearize(point, params=mdl.params, speeds=speeds).eigenvalues
    kane, (m, r, g) = models.rolling_coin_kane()
    u_psi, u_th, u_ph, u_x, u_y = kane.u
    op = {**dict.fromkeys(kane.q, 0.0), u_psi: 0.0, u_th: 0.0, u_ph: spin,
          u_x: speeds[mdl.symbols["x"]], u_y: speeds[mdl.symbols["y"]]}  # fmt: skip
    A, _, _ = kane.linearize(op_point=[op, {u.diff(t): 0 for u in kane.u}], A_and_B=True)
    A = A.subs({m: p["m"], r: p["r"], g: p["g"]})
    theirs = np.linalg.eigvals(np.array(A.evalf(), dtype=float))
    for part in (np.real, np.imag):  # the lean's pair: the only non-zero eigenvalues
        np.testing.assert_allclose(np.sort(part(ours))[[0, -1]], np.sort(part(theirs))[[0, -1]],
                                   rtol=1e-9, atol=1e-9)  # fmt: skip
    assert np.abs(theirs).max() > 1.0
