"""Forward sensitivities of Lagrangian runs against independent routes: central finite
differences of plain runs (Richardson-extrapolated) for the three models of the issue — the
pendulum on a cart (unconstrained), the rolling disk (non-holonomic) and the sliding ladder
before the wall lets go (holonomic, one of them one-sided) — and the compiled Jacobian
against differences of the compiled model itself."""

import numpy as np
import pytest

from poinsot.lagrange.engine import compile_system, compile_tangent
from poinsot.models import pendulum_cartesian, pendulum_on_cart, rolling_disk, sliding_ladder

MODELS = {
    "pendulum-on-cart": (pendulum_on_cart, 1.5, {}),
    "rolling-disk": (rolling_disk, 1.5, {}),
    "sliding-ladder": (sliding_ladder, 0.4, {}),
}
WRT = ("q0", "qd0", "params")


def richardson(f, h):
    """``f'(0)`` by central differences at ``h`` and ``h/2``, Richardson-extrapolated."""
    d1 = (f(h) - f(-h)) / (2 * h)
    d2 = (f(h / 2) - f(-h / 2)) / h
    return (4 * d2 - d1) / 3


def final(mdl, t_end, opts, **moved):
    sol = mdl.simulate((0, t_end), t_eval=[0, t_end], **opts, **moved)
    return np.hstack([sol.q[-1], sol.qd[-1]])


def moves(mdl, label):
    """The run's arguments moved by ``h`` along one column (its label)."""
    which, item = label[:-1].split("[")
    if which == "params":
        (sym,) = [s for s in mdl.params if str(s) == item]
        return lambda h: {"params": {**mdl.params, sym: mdl.params[sym] + h}}
    given = mdl.q0 if which == "q0" else mdl.qd0
    coords = {str(c.func): c for c in mdl.system.coordinates}
    c = coords[item]
    return lambda h: {which: {**given, c: given.get(c, 0.0) + h}}


def check(name, opts, tol, h=1e-3):
    make, t_end, _ = MODELS[name]
    mdl = make()
    sol = mdl.simulate((0, t_end), t_eval=[0, t_end], sensitivities=WRT, **opts)
    S = sol.sensitivity("state")[-1]
    labels = sol.sensitivities.directions.labels
    assert S.shape == (2 * mdl.system.n_coordinates, len(labels))
    for j, label in enumerate(labels):
        move = moves(mdl, label)
        fd = richardson(lambda x, move=move: final(mdl, t_end, opts, **move(x)), h)
        scale = max(np.abs(fd).max(), 1.0)
        err = np.abs(S[:, j] - fd).max() / scale
        assert err <= tol, f"{name}: d state/d {label} off by {err:.2e}"


@pytest.mark.parametrize("name", MODELS)
def test_rk4_sensitivities_are_the_derivatives_of_the_computed_motion(name):
    # a fixed step: the derivative of the discrete map; differences of plain runs (the same
    # map) agree to their own error
    check(name, {"method": "rk4", "dt": 1e-3}, 1e-8)


@pytest.mark.parametrize("name", MODELS)
def test_dop853_sensitivities_agree_with_differences_of_tight_runs(name):
    check(name, {"method": "dop853", "rtol": 1e-12, "atol": 1e-14}, 1e-7)


@pytest.mark.parametrize("name", ["rolling-disk", "sliding-ladder"])
def test_the_projection_carries_its_derivative_to_the_columns(name):
    # after every step the state is projected onto the constraints, and each column by the
    # projection's derivative: differences of projected runs agree
    check(name, {"method": "rk4", "dt": 1e-3, "stabilization": "projection"}, 1e-8)


def test_unstabilised_runs_too():
    check("sliding-ladder", {"method": "rk4", "dt": 1e-3, "stabilization": None}, 1e-8)


@pytest.mark.parametrize("make", [pendulum_on_cart, rolling_disk, sliding_ladder])
def test_the_compiled_jacobian_is_the_derivative_of_the_compiled_model(make):
    # SymPy's derivatives, lowered and compiled with the model's expressions, against
    # central differences of the model's own compiled program at a generic point
    mdl = make()
    system = mdl.system
    tangent, model = compile_tangent(system), compile_system(system).model
    n, _, _, k, nu = model.sizes
    rng = np.random.default_rng(4)
    q, v = rng.uniform(0.2, 0.9, n), rng.uniform(-1, 1, n)
    p = np.array([float(mdl.params[s]) for s in system.parameters]) * rng.uniform(0.8, 1.2, k)
    u = np.zeros(nu)
    out = tangent.evaluate(0.3, q, v, p, u)

    def parts(z):
        M, f, G, b, gam, g, h = model.parts(0.3, z[:n], z[n : 2 * n], z[2 * n :], u)
        return np.concatenate([M.ravel(), f, G.ravel(), b, gam, g, [h]])

    z = np.concatenate([q, v, p])
    plain = parts(z)
    no = plain.size
    np.testing.assert_allclose(out[:no], plain, rtol=1e-14, atol=1e-14)
    J = out[no:].reshape(no - 1, 2 * n + k)
    for c in range(2 * n + k):
        e = np.eye(2 * n + k)[c]
        fd = richardson(lambda h, e=e: parts(z + h * e)[:-1], 1e-3)
        np.testing.assert_allclose(J[:, c], fd, rtol=1e-8, atol=1e-9)


def test_columns_of_a_constrained_start_follow_the_constraints():
    # the ladder's q0 gives theta only: x_c and y_c are solved from the floor and the wall,
    # so the column of q0[theta] moves them along the constraints' tangent, and the solved
    # coordinates have no column of their own
    mdl = sliding_ladder()
    sol = mdl.simulate((0, 0.2), method="rk4", dt=1e-3, sensitivities=("q0", "params[L]"))
    assert sol.sensitivities.directions.labels == ("q0[theta]", "params[L]")
    S0 = sol.sensitivity("q")[0]
    L, th = mdl.params[mdl.symbols["L"]], mdl.q0[mdl.symbols["theta"]]
    # x_c = L/2 sin θ, y_c = L/2 cos θ
    np.testing.assert_allclose(S0[:, 0], [L / 2 * np.cos(th), -L / 2 * np.sin(th), 1.0],
                               atol=1e-13)  # fmt: skip
    np.testing.assert_allclose(S0[:, 1], [np.sin(th) / 2, np.cos(th) / 2, 0.0], atol=1e-13)
    # a single column of a name asked for
    assert sol.sensitivity("qd", "q0[theta]").shape == (201, 3, 1)
    # "params" means all of them, in the order of `params`: a run that asked one has not
    # them all, and is refused (it had given that one column alone, as if it were all)
    with pytest.raises(ValueError, match=r"'params': this run asked only part of it "
                                         r"\('params\[L\]'\)"):  # fmt: skip
        sol.sensitivity("q", "params")


def test_the_pendulum_on_a_cart_keeps_its_conserved_momentum_to_first_order():
    # p_x = (M + m) ẋ + m l θ̇ cos θ is conserved for every parameter value: its derivative
    # along each column is constant in time (the chain rule on the sensitivities)
    mdl = pendulum_on_cart()
    sol = mdl.simulate((0, 3), method="dop853", rtol=1e-12, atol=1e-14,
                       sensitivities=("q0", "qd0", "params"))  # fmt: skip
    P = {str(s): mdl.params[s] for s in mdl.system.parameters}
    th, xd, thd = sol.q[:, 1], sol.qd[:, 0], sol.qd[:, 1]
    Sq, Sv = sol.sensitivity("q"), sol.sensitivity("qd")
    labels = sol.sensitivities.directions.labels
    M, m, l = P["M"], P["m"], P["l"]
    for j, label in enumerate(labels):
        dp = {"M": 0.0, "m": 0.0, "l": 0.0}
        if label.startswith("params["):
            dp[label[7:-1]] = dp.get(label[7:-1], 0.0) + 1.0
        c, s = np.cos(th), np.sin(th)
        d = ((dp["M"] + dp["m"]) * xd + (M + m) * Sv[:, 0, j]
             + (dp["m"] * l + m * dp["l"]) * thd * c
             + m * l * (Sv[:, 1, j] * c - thd * s * Sq[:, 1, j]))  # fmt: skip
        np.testing.assert_allclose(d, d[0], atol=1e-9, err_msg=label)


def test_control_of_the_sensitivities_is_a_choice():
    mdl = rolling_disk()
    kw = {"method": "dop853", "rtol": 1e-8, "atol": 1e-10, "sensitivities": "params"}
    with_s = mdl.simulate((0, 2), **kw)
    without = mdl.simulate((0, 2), control_sensitivities=False, **kw)
    plain = mdl.simulate((0, 2), method="dop853", rtol=1e-8, atol=1e-10)
    # the error of the motion alone: the plain run's steps; weighing the sensitivities too
    # (the largest of the state's and each direction's norm) never takes fewer
    assert without.nfev == plain.nfev
    assert with_s.nfev >= plain.nfev
    # the model's expressions evaluated with their Jacobian (other common subexpressions, so
    # other round-off, so steps of other lengths by round-off): the same motion to the
    # tolerance
    np.testing.assert_allclose(without.q, plain.q, rtol=0, atol=1e-7)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"sensitivities": "omega0"}, "unknown parameter 'omega0'"),
        ({"sensitivities": ("q0", "q0")}, "named twice"),
        ({"sensitivities": "params[k]"}, "'k' is not a parameter"),
        ({"sensitivities": "q0[x_c]"}, "solved from the constraints"),
        ({"sensitivities": 3}, "a name or a sequence of names"),
        ({"sensitivities": [3]}, "must be a name"),
        ({"sensitivities": ()}, "at least one"),
        ({"control_sensitivities": False}, "no effect without `sensitivities`"),
        ({"sensitivities": "q0", "control_sensitivities": "yes"}, "True or False"),
        ({"sensitivities": "q0", "events": lambda t, y: y[2] - 0.2}, "`events` cannot"),
        ({"sensitivities": "q0", "control_sensitivities": False}, "fixed-step method 'rk4'"),
        ({"sensitivities": ("q0", "q0[theta]")}, r"asks again for columns of `sensitivities\[0\]`"),
        ({"sensitivities": ("params[g]", "params")}, "asks again"),
        ({"sensitivities": {"q0", "params"}}, "ordered sequence"),
    ],
)
def test_what_a_run_cannot_differentiate_is_refused_and_named(kwargs, message):
    mdl = sliding_ladder()
    with pytest.raises((ValueError, TypeError), match=message):
        mdl.simulate((0, 0.3), method="rk4", dt=1e-3, **kwargs)


def test_a_column_the_constraints_hold_still_is_named_by_its_label():
    # the Cartesian pendulum's default start gives x, y and both velocities: moving q0[x]
    # alone leaves x² + y² = l² broken (the message had named "direction 0")
    mdl = pendulum_cartesian()
    with pytest.raises(ValueError, match=r"the column 'q0\[x\]': the constraints do not let "
                                         r"it move alone .* give fewer coordinates"):  # fmt: skip
        mdl.simulate((0, 0.1), method="rk4", dt=1e-3, sensitivities="q0")
    with pytest.raises(ValueError, match=r"the column 'params\[l\]'"):
        mdl.simulate((0, 0.1), method="rk4", dt=1e-3, sensitivities="params")


def test_a_run_through_a_release_is_refused():
    # the wall lets go at cos θ = ⅔ cos θ0: the sensitivities across it are not computed
    with pytest.raises(ValueError, match=r"lets go by t = 0\.6"):
        sliding_ladder().simulate((0, 3), method="rk4", dt=1e-3, sensitivities="params")


def test_inputs_given_as_functions_are_refused():
    import sympy as sp

    from poinsot.lagrange import LagrangianSystem

    t = sp.Symbol("t")
    x = sp.Function("x")(t)
    F = sp.Function("F")(t)
    system = LagrangianSystem([x], kinetic=x.diff(t) ** 2 / 2, forces=[{x: F}])
    with pytest.raises(ValueError, match="constant inputs"):
        system.simulate((0, 1), q0={x: 0.0}, inputs={F: lambda t: t}, sensitivities="q0")
    sol = system.simulate((0, 1), q0={x: 0.0}, qd0={x: 0.5}, inputs={F: 2.0},
                          sensitivities=("q0", "qd0"), method="rk4", dt=0.01)  # fmt: skip
    # x = x0 + v0 t + t²: ∂x/∂x0 = 1, ∂x/∂v0 = t
    np.testing.assert_allclose(sol.sensitivity("q")[:, 0], np.c_[np.ones(201), sol.t],
                               atol=1e-12)  # fmt: skip


def test_the_linearisation_is_exact():
    # the pendulum on a free cart about the hanging position: ω² = g (M + m)/(M l) (the cart
    # recoils), and a zero pair (the cart's free drift); the exact Jacobian gives the
    # frequency to round-off, where central differences gave ~1e-9
    mdl = pendulum_on_cart()
    s = mdl.symbols
    lin = mdl.system.linearize({s["x"]: 0.0, s["theta"]: 0.0}, params=mdl.params)
    P = {str(k): v for k, v in mdl.params.items()}
    w = np.sqrt(P["g"] * (P["M"] + P["m"]) / (P["M"] * P["l"]))
    assert np.abs(lin.eigenvalues.imag).max() == pytest.approx(w, rel=1e-14)
    assert lin.frequencies == pytest.approx([w], rel=1e-10)  # (rounded to 10 decimals)
    # against central differences of the compiled rates (the route before), to their error
    tangent = compile_tangent(mdl.system)
    model = compile_system(mdl.system)
    p = model.parameter_vector(mdl.params)
    y0 = np.array([0.0, 0.3, 0.2, -0.5])
    J = tangent.rates_jacobian(0.0, y0, p, np.zeros(0))[0]
    fd = np.column_stack([
        richardson(lambda h, e=e: model.model.rhs(0.0, y0 + h * e, p, np.zeros(0)), 1e-3)
        for e in np.eye(4)
    ])  # fmt: skip
    np.testing.assert_allclose(J, fd, rtol=1e-9, atol=1e-9)


def test_the_netcdf_export_carries_them_with_named_dimensions(tmp_path):
    from scipy.io import netcdf_file

    mdl = sliding_ladder()
    sol = mdl.simulate((0, 0.3), method="rk4", dt=1e-3, t_eval=[0, 0.1, 0.3],
                       sensitivities=("q0", "params"))  # fmt: skip
    path = tmp_path / "ladder.nc"
    sol.to_netcdf(path)
    with netcdf_file(path, mmap=False) as f:
        v = f.variables["sensitivity"]
        assert v.dimensions == ("time", "state_component", "parameter")
        np.testing.assert_array_equal(v[:], sol.sensitivities.S)
        labels = [b"".join(r).decode() for r in f.variables["parameter"][:]]
        assert labels == list(sol.sensitivities.directions.labels)
        comps = [b"".join(r).decode() for r in f.variables["state_component"][:]]
        assert comps[:3] == ["q[x_c]", "q[y_c]", "q[theta]"] and comps[3] == "qd[x_c]"
        assert f.variables["q"].dimensions == ("time", "coordinate")
        assert f.variables["multipliers"].dimensions == ("time", "constraint")
        np.testing.assert_array_equal(f.variables["q"][:], sol.q)
    # without constraints, the constraint dimensions are left out
    cart = pendulum_on_cart().simulate((0, 0.1), method="rk4", dt=1e-3, t_eval=[0, 0.1])
    cart.to_netcdf(tmp_path / "cart.nc")
    with netcdf_file(tmp_path / "cart.nc", mmap=False) as f:
        assert "multipliers" not in f.variables and "sensitivity" not in f.variables
