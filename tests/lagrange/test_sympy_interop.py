"""SymPy mechanics models handed over (LagrangesMethod, System, Particle, RigidBody) and
SymPy loads (forces at points, torques on frames) give the same equations as SymPy."""

from __future__ import annotations

import numpy as np
import sympy as sp
from sympy.physics.mechanics import (
    Force,
    LagrangesMethod,
    Lagrangian,
    Particle,
    Point,
    ReferenceFrame,
    RigidBody,
    System,
    Torque,
    dynamicsymbols,
    inertia,
)

from poinsot.lagrange import LagrangianSystem


def _pendulum():
    q = dynamicsymbols("q")
    m, l, g, c = sp.symbols("m l g c", positive=True)
    N = ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [q, N.z])
    O = Point("O")
    O.set_vel(N, 0)
    P = O.locatenew("P", -l * A.y)
    P.v2pt_theory(O, N, A)
    bob = Particle("bob", P, m)
    bob.potential_energy = m * g * P.pos_from(O).dot(N.y)
    from types import SimpleNamespace

    return SimpleNamespace(q=q, m=m, l=l, g=g, c=c, N=N, A=A, O=O, P=P, bob=bob)


def _sympy_rhs(lm, values):
    lm.form_lagranges_equations()
    return sp.simplify(lm.mass_matrix.inv() * lm.forcing).subs(values)


def test_lagranges_method_and_system_are_taken_as_they_are():
    p = _pendulum()
    q, m, l, g, c, N, A, O, bob = p.q, p.m, p.l, p.g, p.c, p.N, p.A, p.O, p.bob
    damping = (A, -c * q.diff() * N.z)
    lm = LagrangesMethod(Lagrangian(N, bob), [q], forcelist=[damping], frame=N)
    ours = LagrangianSystem.from_sympy(lm)
    ref = _sympy_rhs(LagrangesMethod(Lagrangian(N, bob), [q], forcelist=[damping], frame=N), {})
    assert sp.simplify(ours.mass_matrix.inv() * ours.forcing - ref) == sp.zeros(1, 1)
    system = System(N, O)
    system.add_coordinates(q)
    system.add_bodies(bob)
    system.add_loads(Torque(A, -c * q.diff() * N.z))
    from_system = LagrangianSystem.from_sympy(system, units={q: "rad"})
    assert sp.simplify(from_system.forcing[0] - ours.forcing[0]) == 0
    assert from_system.unit_of(q) == "rad"
    sol = from_system.simulate((0, 1), q0={q: 0.5}, params={m: 1, l: 1, g: 9.81, c: 0.2})
    assert sol.energy[-1] < sol.energy[0]  # the torque damps it


def test_sympy_loads_give_generalized_forces_by_partial_velocities():
    p = _pendulum()
    q, l, N, P, bob = p.q, p.l, p.N, p.P, p.bob
    F = sp.symbols("F")
    # a horizontal push F at the bob: Q = F · ∂v_P/∂q̇ = F l cos q (6.61)
    system = LagrangianSystem([q], bodies=[bob], potential=bob.potential_energy, frame=N,
                              forces=[Force(P, F * N.x)])  # fmt: skip
    assert sp.simplify(system.generalized_forces[0] - F * l * sp.cos(q)) == 0
    tup = LagrangianSystem([q], bodies=[bob], frame=N, forces=[(P, F * N.x)])
    assert sp.simplify(tup.generalized_forces[0] - F * l * sp.cos(q)) == 0


def test_rigid_body_in_euler_angles_matches_sympy():
    psi, th, ph = dynamicsymbols("psi theta phi")
    I1, I2, I3, m = sp.symbols("I1 I2 I3 m", positive=True)
    N = ReferenceFrame("N")
    B = N.orientnew("B", "Body", [psi, th, ph], "ZXZ")
    O = Point("O")
    O.set_vel(N, 0)
    rb = RigidBody("rb", O, B, m, (inertia(B, I1, I2, I3), O))
    from_sympy_body = LagrangianSystem([psi, th, ph], bodies=[rb], frame=N)
    lm = LagrangesMethod(Lagrangian(N, rb), [psi, th, ph], frame=N)
    lm.form_lagranges_equations()
    values = {I1: 1.0, I2: 2.0, I3: 3.0, psi: 0.3, th: 0.7, ph: -0.2}
    ours = np.array(from_sympy_body.mass_matrix.subs(values), dtype=float)
    ref = np.array(lm.mass_matrix.subs(values), dtype=float)
    np.testing.assert_allclose(ours, ref, atol=1e-14)
    # the same body as a poinsot RigidBody with its attitude matrix Q(ψ, θ, φ)
    from poinsot import RigidBody as PoinsotBody

    body = PoinsotBody(1.0, np.diag([1.0, 2.0, 3.0]))
    Q = N.dcm(B)  # columns: the body axes in N
    ours2 = LagrangianSystem([psi, th, ph], bodies=[(body, [0, 0, 0], Q)])
    np.testing.assert_allclose(np.array(ours2.mass_matrix.subs(values), dtype=float), ref,
                               atol=1e-14)  # fmt: skip
