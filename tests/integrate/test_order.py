"""Every registered integrator: empirical convergence order and tableau invariants.

Like diffrax's ``test_ode_order``: errors at the end of a fixed interval for steps h = T/2^k
against a tight reference, slope fitted on a log–log scale, compared with ``Solver.order``.
"""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import Gravity, RigidBody, Spring, simulate
from poinsot.dynamics import RigidBodySystem
from poinsot.integrate import METHODS, ExplicitRungeKutta, Solver, get_solver
from poinsot.integrate.driver import integrate

T = 2.0
BODY = RigidBody.box(2.0, (1.0, 0.6, 0.3))
# a spring couples translation and rotation; both forces are position-only (splitting applies)
FORCES = [Spring((0.5, 0.3, 0.15), (1.0, 0.5, 0.0), 3.0, 0.2), Gravity((0, 0, -1.0))]
OMEGA0, V0 = (0.3, 1.2, -0.5), (0.1, 0.0, 0.2)


@pytest.fixture(scope="module")
def reference():
    system = RigidBodySystem(BODY, FORCES)
    y0 = system.initial_state(omega0=OMEGA0, V0=V0)
    return system, y0, integrate(system, "dop853", (0, T), y0, t_eval=[T], rtol=3e-14, atol=1e-16)


@pytest.mark.parametrize("name", sorted(METHODS))
def test_convergence_order(name, reference):
    system, y0, ref = reference
    cls = METHODS[name]
    # the asymptotic range of each order, above the reference's own error (about 1e-13)
    ks = (3, 6) if cls.order >= 8 else (4, 6) if cls.order >= 6 else (3, 7)
    hs = T / 2.0 ** np.arange(*ks)
    errors = []
    for h in hs:
        if cls.adaptive:  # huge tolerances + max_step = h: the method's fixed-step behaviour
            out = integrate(
                system,
                cls,
                (0, T),
                y0,
                t_eval=[T],
                dt=h,
                rtol=1e3,
                atol=1e3,
                solver_options={"max_step": h},
            )
        else:
            out = integrate(system, cls, (0, T), y0, t_eval=[T], dt=h)
        errors.append(np.abs(out.y[-1] - ref.y[-1]).max())
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert cls.order - 0.3 < slope < cls.order + 1.5, (name, slope, errors)


def test_every_method_declares_its_contract():
    for name, cls in METHODS.items():
        assert issubclass(cls, Solver) and cls.name == name
        assert cls.order >= 1
        assert cls.requires in ("ode", "rigid")
    assert get_solver("rk4") is METHODS["rk4"]
    assert get_solver(METHODS["rkmk4"]) is METHODS["rkmk4"]


def test_unknown_method_lists_valid_names():
    with pytest.raises(
        ValueError,
        match=r"`method` must be one of \{'dop853', 'exact-splitting', 'exact-splitting4', "
        r"'exact-splitting6', 'rk4', 'rkmk4', 'splitting'\} or a Solver class, found 'euler'",
    ):
        get_solver("euler")


@pytest.mark.parametrize(
    "cls", [c for c in METHODS.values() if issubclass(c, ExplicitRungeKutta)], ids=lambda c: c.name
)
def test_tableau_invariants(cls):
    A, B, C = cls.A, cls.B, cls.C
    assert np.allclose(np.triu(A), 0)  # explicit
    assert B.sum() == pytest.approx(1.0, abs=1e-15)
    np.testing.assert_allclose(A.sum(axis=1), C, atol=1e-15)
    # order conditions up to 4 (Butcher, Numerical Methods for ODEs, §31)
    if cls.order >= 4:
        assert B @ C == pytest.approx(1 / 2)
        assert B @ C**2 == pytest.approx(1 / 3)
        assert B @ A @ C == pytest.approx(1 / 6)
        assert B @ C**3 == pytest.approx(1 / 4)
        assert B @ (C * (A @ C)) == pytest.approx(1 / 8)
        assert B @ A @ C**2 == pytest.approx(1 / 12)
        assert B @ A @ A @ C == pytest.approx(1 / 24)


def test_generic_ode_with_a_projector():
    """rk4 and dop853 take any object with rhs(t, y) (called back from the core, the slow
    path); a projector(y0) keeps the state on its manifold after every step."""

    class Harmonic:
        def rhs(self, t, y):
            return np.array([y[1], -y[0]])

    for method in ("rk4", "dop853"):
        out = integrate(Harmonic(), method, (0, 2 * np.pi), [1.0, 0.0], dt=0.01,
                        t_eval=np.linspace(0, 2 * np.pi, 9))  # fmt: skip
        np.testing.assert_allclose(out.y[:, 0], np.cos(out.t), atol=1e-8)
        assert out.backend == "python"

    class OnCircle(Harmonic):  # the same flow, projected back onto |y| = 1 after each step
        def projector(self, y0):
            return lambda y, t=None: y / np.linalg.norm(y)

    out = integrate(OnCircle(), "rk4", (0, 50), [1.0, 0.0], dt=0.5, t_eval=[50.0])
    free = integrate(Harmonic(), "rk4", (0, 50), [1.0, 0.0], dt=0.5, t_eval=[50.0])
    assert abs(np.linalg.norm(out.y[-1]) - 1) < 1e-15
    assert abs(np.linalg.norm(free.y[-1]) - 1) > 1e-4  # RK4 alone drifts off the circle
    with pytest.raises(TypeError, match="rhs"):
        integrate(object(), "rk4", (0, 1), [1.0], dt=0.1)


def test_splitting_refuses_velocity_dependent_forces():
    from poinsot import LinearDrag

    with pytest.raises(ValueError, match="depend on velocities: LinearDrag"):
        simulate(BODY, (0, 1), omega0=OMEGA0, forces=[LinearDrag(0.1)], method="splitting", dt=0.1)


def test_fixed_step_needs_dt():
    with pytest.raises(ValueError, match="`method` 'rk4' is fixed-step: `dt` must be given"):
        simulate(BODY, (0, 1), omega0=OMEGA0, method="rk4")
