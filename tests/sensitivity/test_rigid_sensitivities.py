"""Forward sensitivities of rigid-body runs against an independent route: central finite
differences of plain runs, Richardson-extrapolated, for every built-in force, free and about
a pivot, and for every kind of parameter (initial state, inertia, the forces' parameters)."""

import dataclasses

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poinsot import RigidBody, simulate
from poinsot.dynamics import RigidBodySystem
from poinsot.forces import (
    CentralGravity,
    Gravity,
    LinearDrag,
    PointForce,
    QuadraticDrag,
    Spring,
    Torque,
)

INERTIA = np.array([[2.0, 0.3, -0.1], [0.3, 3.0, 0.2], [-0.1, 0.2, 4.5]])
COM = np.array([0.1, -0.2, 0.3])
OMEGA0 = np.array([0.4, -1.1, 0.7])
Q0 = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
R0 = np.array([3.0, -1.0, 2.0])
V0 = np.array([0.2, 0.5, -0.3])


@dataclasses.dataclass
class Case:
    name: str
    forces: tuple
    pivot: object = None
    wrt: tuple = ("omega0", "Q0", "R0", "V0", "inertia")
    t_end: float = 1.0


CASES = [
    Case("gravity", (Gravity((0.1, -0.2, -9.8)),),
         wrt=("omega0", "Q0", "R0", "V0", "inertia", "forces[0]")),
    Case("heavy top", (Gravity((0.0, 0.0, -9.8)),), pivot=(0.0, 0.0, -0.4),
         wrt=("omega0", "Q0", "inertia", "forces[0]")),
    Case("central gravity", (CentralGravity(20.0, (0.5, 0.2, -0.1)),),
         wrt=("omega0", "Q0", "R0", "V0", "inertia", "forces[0]")),
    Case("damped spring", (Spring((0.2, 0.1, -0.3), (1.0, 0.5, 2.5), 7.0, 0.5, damping=0.3),),
         wrt=("omega0", "Q0", "R0", "V0", "inertia", "forces[0]")),
    Case("drags", (LinearDrag(0.2, 0.1), QuadraticDrag(0.3, 0.05)),
         wrt=("omega0", "V0", "inertia", "forces[0]", "forces[1].rotational")),
    Case("point force and torque",
         (PointForce((0.3, 0.1, -0.2), (1.0, 2.0, -0.5), frame="body"),
          Torque((0.2, -0.1, 0.3), frame="space")),
         wrt=("omega0", "Q0", "inertia", "forces[0]", "forces[1]")),
]  # fmt: skip


def body(inertia=INERTIA):
    return RigidBody(2.0, inertia, COM)


def start(case):
    kw = {"omega0": OMEGA0, "Q0": Q0}
    if case.pivot is None:
        kw |= {"R0": R0, "V0": V0}
    return kw


def final(case, method="rk4", *, inertia=INERTIA, forces=None, **moved):
    """The body-frame state at the end of a plain run."""
    kw = start(case) | moved
    opts = {"rtol": 1e-13, "atol": 1e-15} if method == "dop853" else {"dt": 1e-2}
    traj = simulate(body(inertia), (0, case.t_end), forces=forces or case.forces,
                    pivot=case.pivot, method=method, **opts, **kw)  # fmt: skip
    return traj.state[-1]


def moves(case, name):
    """Each column of ``name``: a function of a step ``h`` giving the moved run's arguments."""
    system = RigidBodySystem(body(), case.forces, case.pivot)
    if name in ("omega0", "R0", "V0"):
        base = start(case)[name]
        return [lambda h, k=k: {name: base + h * np.eye(3)[k]} for k in range(3)]
    if name == "Q0":
        return [lambda h, k=k: {"Q0": Rotation.from_rotvec(h * np.eye(3)[k]).as_matrix() @ Q0}
                for k in range(3)]  # fmt: skip
    if name == "inertia":
        E = system.principal_axes
        return [lambda h, k=k: {"inertia": INERTIA + h * np.outer(E[:, k], E[:, k])}
                for k in range(3)]  # fmt: skip
    i, which = int(name[7]), name.partition(".")[2]
    force = case.forces[i]
    out = []
    for pname, _, size, _ in force.sensitive_parameters():
        if which and pname != which:
            continue
        for c in range(size):

            def moved(h, pname=pname, c=c, size=size):
                value = np.array(getattr(force, pname), dtype=float)
                value = value + h * (np.eye(size)[c] if size > 1 else 1.0)
                f = _rebuilt(force, pname, value)
                forces = tuple(f if j == i else g for j, g in enumerate(case.forces))
                return {"forces": forces}

            out.append(moved)
    return out


def _rebuilt(force, pname, value):
    """The force with one parameter replaced."""
    if isinstance(force, Gravity):
        return Gravity(value)
    if isinstance(force, CentralGravity):
        kw = {"mu": force.mu, "center": force.center} | {pname: value}
        return CentralGravity(kw["mu"], kw["center"], gradient=force.gradient)
    if isinstance(force, Spring):
        kw = {"point": force.point, "anchor": force.anchor, "stiffness": force.stiffness,
              "rest_length": force.rest_length, "damping": force.damping}  # fmt: skip
        kw[pname] = value
        return Spring(kw["point"], kw["anchor"], kw["stiffness"], kw["rest_length"],
                      damping=kw["damping"], tether=force.tether)  # fmt: skip
    if isinstance(force, LinearDrag | QuadraticDrag):
        kw = {"coefficient": force.coefficient, "rotational": force.rotational} | {pname: value}
        return type(force)(kw["coefficient"], kw["rotational"])
    if isinstance(force, PointForce):
        kw = {"point": force.point, "force": force.force} | {pname: value}
        return PointForce(kw["point"], kw["force"], frame=force.frame)
    return Torque(value, frame=force.frame)


def richardson(f, h):
    """``f'(0)`` by central differences at ``h`` and ``h/2``, Richardson-extrapolated."""
    d1 = (f(h) - f(-h)) / (2 * h)
    d2 = (f(h / 2) - f(-h / 2)) / h
    return (4 * d2 - d1) / 3


def check_against_differences(case, method, tol):
    opts = {"rtol": 1e-13, "atol": 1e-15} if method == "dop853" else {"dt": 1e-2}
    traj = simulate(body(), (0, case.t_end), forces=case.forces, pivot=case.pivot,
                    method=method, sensitivities=case.wrt, **opts, **start(case))  # fmt: skip
    for name in case.wrt:
        S = traj.sensitivity("state", name)[-1]
        cols = moves(case, name)
        assert S.shape == (18, len(cols)), name
        for c, move in enumerate(cols):
            fd = richardson(lambda h, move=move: final(case, method, **move(h)), 1e-3)
            scale = max(np.abs(fd).max(), 1.0)
            err = np.abs(S[:, c] - fd).max() / scale
            assert err <= tol, f"{case.name}: d state/d {name}[{c}] off by {err:.2e}"


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_rk4_sensitivities_are_the_derivatives_of_the_computed_motion(case):
    # RK4 at a fixed step: the derivative of the discrete map, to round-off; the differences
    # of plain runs (the same map) agree to their own error
    check_against_differences(case, "rk4", 1e-9)


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_rkmk4_sensitivities_are_the_derivatives_of_its_step_on_SO3(case):
    # the register step on dual numbers: the derivative of the Lie-group map itself
    check_against_differences(case, "rkmk4", 1e-9)


@pytest.mark.parametrize("case", [c for c in CASES if c.name not in ("damped spring", "drags")],
                         ids=lambda c: c.name)  # fmt: skip
def test_splitting_sensitivities_are_the_derivatives_of_its_step(case):
    # kicks and the free rotor's sub-flows on dual numbers (position-only forces: kicks)
    check_against_differences(case, "splitting", 1e-9)


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_dop853_sensitivities_agree_with_differences_of_tight_runs(case):
    # the steps are chosen by the controller (weighing the sensitivities): differences of
    # plain runs take other steps, and agree to the tolerance's order
    check_against_differences(case, "dop853", 1e-9)


@pytest.mark.parametrize("method", ["exact-splitting", "exact-splitting4", "exact-splitting6"])
@pytest.mark.parametrize("case", [c for c in CASES if c.name not in ("damped spring", "drags")],
                         ids=lambda c: c.name)  # fmt: skip
def test_exact_splitting_sensitivities_are_the_derivatives_of_its_step(case, method):
    # kicks on dual numbers and, for each free flow, the closed form's exact derivatives
    # (along the moments, ω0 = π/I, and the turn of Q0) chained with the columns'
    check_against_differences(case, method, 1e-9)


SYMMETRIC_TOP = Case("symmetric heavy top", (Gravity((0.0, 0.0, -9.8)),), pivot=(0.0, 0.0, -0.4),
                     wrt=("omega0", "Q0", "forces[0]"))  # fmt: skip


@pytest.mark.parametrize("method", ["exact-splitting", "exact-splitting6"])
def test_a_symmetric_tops_exact_splitting_sensitivities_are_its_steps_derivatives(method):
    # a symmetric top (its centre of mass and the pivot on the axis: oblate about the pivot)
    # whose free flow is its own closed form, the precession, on dual numbers
    case = SYMMETRIC_TOP
    top = RigidBody(2.0, np.diag([2.0, 2.0, 3.5]), (0.0, 0.0, 0.3))
    assert RigidBodySystem(top, case.forces, case.pivot).principal_moments[0] == pytest.approx(
        RigidBodySystem(top, case.forces, case.pivot).principal_moments[1]
    )

    def run(**kw):
        return simulate(top, (0, case.t_end), forces=kw.pop("forces", case.forces),
                        pivot=case.pivot, method=method, dt=1e-2, **(start(case) | kw))  # fmt: skip

    traj = run(sensitivities=case.wrt)
    for name in case.wrt:
        S = traj.sensitivity("state", name)[-1]
        for c, move in enumerate(moves(case, name)):
            fd = richardson(lambda h, move=move: run(**move(h)).state[-1], 1e-3)
            err = np.abs(S[:, c] - fd).max() / max(np.abs(fd).max(), 1.0)
            assert err <= 1e-9, f"d state/d {name}[{c}] off by {err:.2e}"


@pytest.mark.parametrize("method", ["rk4", "rkmk4", "dop853"])
def test_the_damping_of_an_undamped_spring_has_its_derivative(method):
    # at damping = 0 the damper's term is skipped; along a derivative of the damping it is
    # not (its column had been exactly 0, where differences give about 1)
    case = Case("undamped spring", (Spring((0.2, 0.1, -0.3), (1.0, 0.5, 2.5), 7.0, 0.5),),
                wrt=("forces[0].damping",), t_end=1.5)  # fmt: skip
    opts = {"rtol": 1e-13, "atol": 1e-15} if method == "dop853" else {"dt": 1e-2}
    traj = simulate(body(), (0, case.t_end), forces=case.forces, method=method,
                    sensitivities=case.wrt, **opts, **start(case))  # fmt: skip
    S = traj.sensitivity("state", "forces[0].damping")[-1, :, 0]
    # one-sided (damping ≥ 0): f'(0) ≈ (−3 f(0) + 4 f(h) − f(2h))/(2h), Richardson'd
    (move,) = moves(case, "forces[0].damping")

    def one_sided(h):
        f = [final(case, method, **move(a)) for a in (0.0, h, 2 * h)]
        return (-3 * f[0] + 4 * f[1] - f[2]) / (2 * h)

    h = 1e-4
    fd = (4 * one_sided(h / 2) - one_sided(h)) / 3  # their O(h²) errors cancel
    err = np.abs(S - fd).max() / np.abs(fd).max()
    assert np.abs(fd).max() > 0.1
    assert err <= 1e-7, f"{method}: d state/d damping off by {err:.2e}"


@pytest.mark.parametrize("method", ["splitting", "exact-splitting"])
def test_a_springs_damping_is_refused_by_the_splittings(method):
    # their kicks take position-only forces: a derivative along the damper has no step to
    # differentiate (it had come back 0)
    with pytest.raises(ValueError, match=r"'forces\[0\]\.damping' with .*position-only"):
        simulate(body(), (0, 1), forces=[Spring((0.2, 0.1, -0.3), (1.0, 0.5, 2.5), 7.0)],
                 method=method, dt=1e-2, sensitivities=("omega0", "forces[0]"),
                 **start(CASES[0]))  # fmt: skip


@pytest.mark.parametrize("method", ["splitting", "exact-splitting4"])
def test_a_symmetric_bodys_equal_moments_are_not_moved_apart(method):
    # along one of the equal moments alone the symmetric closed form (the free flow of both
    # splittings on a symmetric body) has no derivative: refused up front, naming the remedy
    # (the splitting method had given ∂ω₃/∂I₁ = 0 where RK4 and differences give 0.037)
    with pytest.raises(ValueError, match=r"equal moments alone.*'rkmk4'"):
        simulate(RigidBody(1.0, np.diag([1.0, 1.0, 2.0])), (0, 1), omega0=OMEGA0,
                 forces=[Gravity()], pivot=(0, 0, -0.5), method=method, dt=1e-2,
                 sensitivities=("omega0", "inertia"))  # fmt: skip
    # moving them together keeps the body symmetric, and is differentiable
    traj = simulate(RigidBody(1.0, np.diag([1.0, 1.0, 2.0])), (0, 1), omega0=OMEGA0,
                    forces=[Gravity()], pivot=(0, 0, -0.5), method=method, dt=1e-2,
                    sensitivities=("omega0",))  # fmt: skip
    assert np.isfinite(traj.sensitivity("omega", "omega0")).all()


@pytest.mark.parametrize(("w0", "dt", "q_tol"), [
    (OMEGA0, 0.37, 1e-11),
    # within 1e-5 of the intermediate axis (m1 ~ 1e-10), 500 steps: each flow's derivative of
    # ω had lost ε/m1 (1 − m sn² formed by subtraction, m's derivatives from a ratio within
    # m1 of 1), 3e-5 relative by the end with `exact-splitting`, 3e-4 with
    # `exact-splitting6`; now round-off. The attitude's still lose about ε/√m1 a flow
    # (Π(u) − Π(u0) near the saddle, whose terms' derivatives grow as 1/√m1): 1.3e-10 and
    # 5.7e-9 here
    ((1e-5, 1.0, 1e-5), 0.01, 1e-8),
    # 1e-7 off the separatrix with cn u0 < 0 (u0 in its second half period), where 2n ∂K/∂m
    # had cancelled between u0 and every later u
    ((-np.sqrt(3) * 0.5 * (1 - 1e-7), 1.0, 0.5), 0.05, 1e-10),
], ids=["generic", "near e2", "cn u0 < 0 near the separatrix"])  # fmt: skip
@pytest.mark.parametrize("method", ["exact-splitting", "exact-splitting6"])
def test_torque_free_exact_splitting_sensitivities_are_the_closed_forms(method, w0, dt, q_tol):
    # no forces: every composition is the exact flow, and its sensitivities, chained flow by
    # flow, are the closed form's own derivatives (first 0.37 s, 14 steps). Each flow's ∂Q(d)
    # carries the closed form's absolute round-off (its terms cancel as d → 0), so the
    # attitude's gather about 1e-14 a flow: 6e-11 after 3500 flows (`exact-splitting6`,
    # dt = 0.01) for a generic motion
    from poinsot import FreeRigidBody

    I, t = (1.0, 2.0, 3.0), np.linspace(0, 5, 6)
    traj = simulate(RigidBody(1.0, np.diag(I)), (0, 5), omega0=w0, Q0=Q0, method=method,
                    dt=dt, t_eval=t, sensitivities=("omega0", "inertia"))  # fmt: skip
    d = FreeRigidBody(I).exact_derivatives(w0, t, Q0=Q0)
    # each output's derivatives along ω0 and the moments together, relative to their largest
    pairs = [
        (np.concatenate([traj.sensitivity("omega", "omega0"),
                         traj.sensitivity("omega", "inertia")], axis=-1),
         np.concatenate([d.d_omega_d_omega0, d.d_omega_d_moments], axis=-1)),
        (np.concatenate([traj.sensitivity("Q", "omega0"), traj.sensitivity("Q", "inertia")],
                        axis=-1).reshape(-1, 3, 3, 6),
         np.concatenate([d.d_attitude_d_omega0, d.d_attitude_d_moments], axis=-1)),
    ]  # fmt: skip
    for (got, want), tol in zip(pairs, (1e-11, q_tol), strict=True):
        assert np.abs(got - want).max() <= tol * np.abs(want).max()


@pytest.mark.parametrize("axis", [0, 1, 2], ids=["e1", "e2 (unstable)", "e3"])
@pytest.mark.parametrize("method", ["exact-splitting", "exact-splitting4"])
def test_exact_splitting_sensitivities_of_a_steady_spin(axis, method):
    # ω0 on a principal axis: every free flow starts at a fixed point, where the plain flow
    # is Q0 exp(ω̂0 d) and its derivative is the linearised motion about the steady spin,
    # exp(G d) (growing on the intermediate axis); differences of plain runs move ω0 off the
    # axis onto the elliptic motions, an independent route
    spin = RigidBody(2.0, np.diag([2.0, 3.0, 4.5]))
    w0 = 1.3 * np.eye(3)[axis]

    def run(h=0.0, k=0, what="omega0"):
        kw = {"omega0": w0, "Q0": Q0}
        if what == "omega0":
            kw["omega0"] = w0 + h * np.eye(3)[k]
        else:
            kw["Q0"] = Rotation.from_rotvec(h * np.eye(3)[k]).as_matrix() @ Q0
        return simulate(spin, (0, 2.0), method=method, dt=0.1, **kw)

    traj = simulate(spin, (0, 2.0), method=method, dt=0.1, omega0=w0, Q0=Q0,
                    sensitivities=("omega0", "Q0", "inertia"))  # fmt: skip
    for what in ("omega0", "Q0"):
        S = traj.sensitivity("state", what)[-1]
        for k in range(3):
            fd = richardson(lambda h, k=k, what=what: run(h, k, what).state[-1], 1e-4)
            err = np.abs(S[:, k] - fd).max() / max(np.abs(fd).max(), 1.0)
            assert err <= 1e-8, f"d state/d {what}[{k}] off by {err:.2e}"
    # a steady spin stays one whatever the moments
    assert np.abs(traj.sensitivity("omega", "inertia")[-1]).max() < 1e-14


def test_a_start_on_the_separatrix_says_why_the_exact_splittings_stop():
    # I₁(I₂ − I₁) ω₁² = I₃(I₃ − I₂) ω₃²: the motion through the intermediate axis, where the
    # closed form has no derivative; the plain run goes on, the sensitive one stops and says
    # why (it had said "non-finite state", naming neither)
    from poinsot.integrate.solve import SimulationError

    b = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
    w0 = np.array([np.sqrt(3) * 0.1, 1.0, 0.1])
    plain = simulate(b, (0, 1), omega0=w0, method="exact-splitting", dt=1e-2)
    assert np.isfinite(plain.state).all()
    why = r"non-finite sensitivities at t = 0\.01: .*separatrix.*'rkmk4', 'rk4' or 'dop853'"
    with pytest.raises(SimulationError, match=why):
        simulate(b, (0, 1), omega0=w0, method="exact-splitting", dt=1e-2, sensitivities="Q0")
    # the other methods differentiate it
    S = simulate(b, (0, 1), omega0=w0, method="rk4", dt=1e-2, sensitivities="Q0")
    assert np.isfinite(S.sensitivity("state")).all()
