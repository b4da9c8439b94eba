"""The exact derivatives of the torque-free closed form against an independent route: the
closed form written again in mpmath at 30 digits (Landau & Lifshitz, *Mechanics*, §37: ω(t),
the period, the flip interval and the attitude's Euler angles), its derivatives by
``mp.diff``, to ≤ 1e-12 relative, including within 1e-6 of the separatrix; and, apart,
against the forward sensitivities of an integrated run."""

import mpmath as mp
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from poinsot import FreeRigidBody, simulate
from poinsot.bodies import RigidBody

mp.mp.dps = 30


def closed_form(I, w0, t):
    """ω(t) (sorted principal frame, three distinct moments I ascending) and the period and
    the flip interval, from ω0 (mpmath numbers): the Jacobi form around e3 or e1."""
    I1, I2, I3 = I
    k2 = sum(i * w * w for i, w in zip(I, w0, strict=True))  # 2k
    a2 = sum(i * i * w * w for i, w in zip(I, w0, strict=True))
    P3, P1 = k2 * I3 - a2, a2 - k2 * I1
    if a2 > k2 * I2:  # around e3: ω = (α1 cn u, σ α2 sn u, σ α3 dn u), σ = sign ω3
        al = [mp.sqrt(P3 / (I1 * (I3 - I1))), mp.sqrt(P3 / (I2 * (I3 - I2))),
              mp.sqrt(P1 / (I3 * (I3 - I1)))]  # fmt: skip
        lam = mp.sqrt((I3 - I2) * P1 / (I1 * I2 * I3))
        m = (I2 - I1) * P3 / ((I3 - I2) * P1)
        sg = mp.sign(w0[2])
        sn0, cn0 = sg * w0[1] / al[1], w0[0] / al[0]
        signs, order = (1, sg, sg), ("cn", "sn", "dn")
    else:  # around e1: ω = (σ α1 dn u, σ α2 sn u, α3 cn u), σ = sign ω1
        al = [mp.sqrt(P3 / (I1 * (I3 - I1))), mp.sqrt(P1 / (I2 * (I2 - I1))),
              mp.sqrt(P1 / (I3 * (I3 - I1)))]  # fmt: skip
        lam = mp.sqrt((I2 - I1) * P3 / (I1 * I2 * I3))
        m = (I3 - I2) * P1 / ((I2 - I1) * P3)
        sg = mp.sign(w0[0])
        sn0, cn0 = sg * w0[1] / al[1], w0[2] / al[2]
        signs, order = (sg, sg, 1), ("dn", "sn", "cn")
    u0 = mp.ellipf(mp.atan2(sn0, cn0), m)
    u = u0 + lam * t
    w = [s * a * mp.ellipfun(f, u, m=m) for s, a, f in zip(signs, al, order, strict=True)]
    K = mp.ellipk(m)
    return w, 4 * K / lam, 2 * K / lam, (u0, u, m, lam, a2 > k2 * I2)


B = mp.matrix([[0, 0, 1], [0, -1, 0], [1, 0, 0]])  # e1's right-handed relabelling (e3, −e2, e1)


def euler_zxz(psi, theta, phi):
    """Rz(ψ) Rx(θ) Rz(φ)."""

    def rz(a):
        return mp.matrix([[mp.cos(a), -mp.sin(a), 0], [mp.sin(a), mp.cos(a), 0], [0, 0, 1]])

    rx = mp.matrix([[1, 0, 0], [0, mp.cos(theta), -mp.sin(theta)],
                    [0, mp.sin(theta), mp.cos(theta)]])  # fmt: skip
    return rz(psi) * rx * rz(phi)


def third_kind(n, u, m):
    """``∫₀^u du/(1 − n sn² u)`` = Π(n; am u | m), with ``am u = jπ + am v``, ``u = 2jK + v``."""
    K = mp.ellipk(m)
    j = mp.nint(u / (2 * K))
    v = u - 2 * j * K
    phi = mp.atan2(mp.ellipfun("sn", v, m=m), mp.ellipfun("cn", v, m=m))
    return 2 * j * mp.ellippi(n, m) + mp.ellippi(n, phi, m)


def body_angles(J, p):
    """(θ, φ) of the relabelled body momentum ``p``: ``π = a (sin θ sin φ, sin θ cos φ, cos θ)``."""
    return mp.atan2(mp.hypot(p[0], p[1]), p[2]), mp.atan2(p[0], p[1])


def closed_attitude(I, w0, t, Q0, psi_by_quadrature=False):
    """Q(t) (sorted principal frame → space) from ``Q(0) = Q0`` (Landau & Lifshitz §37): the
    body frame relative to the invariable frame (z along L) by the z-x-z angles
    ``cos θ = π3/a``, ``tan φ = π1/π2`` and ``ψ̇ = a (J1 ω1² + J2 ω2²)/(J1² ω1² + J2² ω2²)``,
    in the frame relabelled about e1 where the polhode circles it. ψ is the closed form
    ``a t/J3 + a (J3 − J1)/(J3 J1 λ) [Π(u) − Π(u0)]``, ``n = −J3 (J2 − J1)/(J1 (J3 − J2))``,
    or, to check that form, the quadrature of ψ̇."""
    w, _, _, (u0, u, m, lam, e3) = closed_form(I, w0, t)
    relabel = (lambda x: list(x)) if e3 else (lambda x: [x[2], -x[1], x[0]])
    J = list(I) if e3 else [I[2], I[1], I[0]]
    Bm = mp.eye(3) if e3 else B
    p0 = [j * x for j, x in zip(J, relabel(w0), strict=True)]
    p = [j * x for j, x in zip(J, relabel(w), strict=True)]
    a = mp.sqrt(sum(x * x for x in p0))
    if psi_by_quadrature:

        def rate(s):
            x = relabel(closed_form(I, w0, s)[0])
            return (
                a
                * (J[0] * x[0] ** 2 + J[1] * x[1] ** 2)
                / (J[0] ** 2 * x[0] ** 2 + J[1] ** 2 * x[1] ** 2)
            )

        psi = mp.quad(rate, mp.linspace(0, t, 9))
    else:
        n = -J[2] * (J[1] - J[0]) / (J[0] * (J[2] - J[1]))
        psi = a * t / J[2] + a * (J[2] - J[0]) / (J[2] * J[0] * lam) * (
            third_kind(n, u, m) - third_kind(n, u0, m)
        )
    R0 = euler_zxz(0, *body_angles(J, p0))
    R = euler_zxz(psi, *body_angles(J, p))
    return Q0 * Bm * R0.T * R * Bm


def reference(I, w0, t, Q0):
    """The derivatives by mp.diff: ∂ω/∂(I, ω0) (3, 6), ∂period, ∂flip (6,), ∂Q (3, 3, 6)."""
    x0 = [mp.mpf(v) for v in (*I, *w0)]
    Q0 = mp.matrix(Q0.tolist())
    seen = {}

    def outputs(j, x):  # every output at once, each point once (mp.diff revisits them)
        if (j, x) not in seen:
            y = list(x0)
            y[j] = x
            w, period, flip, _ = closed_form(y[:3], y[3:], mp.mpf(t))
            Q = closed_attitude(y[:3], y[3:], mp.mpf(t), Q0)
            seen[j, x] = [*w, period, flip, *(Q[r, c] for r in range(3) for c in range(3))]
        return seen[j, x]

    d = np.array([[float(mp.diff(lambda x, j=j, k=k: outputs(j, x)[k], x0[j]))
                   for j in range(6)] for k in range(14)])  # fmt: skip
    return d[:3], d[3], d[4], d[5:].reshape(3, 3, 6)


def near_separatrix(I, eps, side):
    """ω0 whose a²/2k is I2 (1 ± eps): around e3 (side +1) or e1 (−1)."""
    I1, I2, I3 = I
    w3 = 0.5
    w1 = np.sqrt(I3 * (I3 - I2) / (I1 * (I2 - I1))) * w3 * (1 - side * eps)
    return (w1, 1.0, w3)


CASES = [
    ("around e3", (1.0, 2.0, 3.0), (0.3, -0.4, 1.1), 2.7),
    ("around e1", (1.0, 2.0, 3.0), (1.2, 0.5, -0.2), 5.3),
    ("tennis racket", (1.0, 2.2, 3.1), (0.01, 1.0, -0.01), 7.0),
    ("mixed signs", (0.7, 1.3, 1.9), (-0.5, -0.8, 0.6), 11.0),
    ("1e-6 above the separatrix", (1.0, 2.0, 3.0), near_separatrix((1.0, 2.0, 3.0), 1e-6, 1), 9.0),
    ("1e-6 below the separatrix", (1.0, 2.0, 3.0), near_separatrix((1.0, 2.0, 3.0), 1e-6, -1),
     9.0),
    # u0 in its second half period (cn u0 < 0): the 2n ∂K/∂m of u0 and u had cancelled, to
    # 1.5e-10 at 1e-6 from the separatrix
    ("1e-6 above the separatrix, cn u0 < 0", (1.0, 2.0, 3.0),
     np.array(near_separatrix((1.0, 2.0, 3.0), 1e-6, 1)) * (-1, 1, 1), 4.0),
    # 1e-3 from the intermediate axis (1e-6 from the separatrix): 1 − m sn² by subtraction
    # had cost ε/|ω⊥|² (4e-9 at 1e-4, 5e-6 at 1e-6; below, closer still)
    ("near the intermediate axis", (1.0, 2.0, 3.0), (1e-3, 1.0, 1e-3), 2.0),
    # I2 − I1 rounds where I1 < I2/2: the separatrix distance now carries it exactly (the
    # period had been 2e-12 off at 1e-6, its gradient 4e-11)
    ("a light axis, near the separatrix", (0.3, 1.0, 1.2),
     near_separatrix((0.3, 1.0, 1.2), 1e-6, 1), 3.0),
]  # fmt: skip


def relative(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


Q0 = Rotation.from_rotvec([0.3, -0.5, 0.2]).as_matrix()


@pytest.mark.parametrize(("name", "I", "w0", "t"), CASES, ids=[c[0] for c in CASES])
def test_derivatives_of_the_closed_form_equal_mpmaths(name, I, w0, t):
    body = FreeRigidBody(I)
    d = body.exact_derivatives(w0, [0.0, t], Q0=Q0)
    Imp, w0mp = [mp.mpf(x) for x in I], [mp.mpf(x) for x in w0]
    w_ref, period, flip, _ = closed_form(Imp, w0mp, t)
    # the forward map itself first: the same motion, period and flip interval (near the
    # separatrix too: its distance a² − 2k I2 is formed without rounding errors), and the
    # same attitude
    np.testing.assert_allclose(d.omega[-1], [float(x) for x in w_ref], rtol=1e-12, atol=1e-13)
    assert d.period == pytest.approx(float(period), rel=1e-14)
    assert d.flip_interval == pytest.approx(float(flip), rel=1e-14)
    Q_ref = closed_attitude(Imp, w0mp, mp.mpf(t), mp.matrix(Q0.tolist()))
    np.testing.assert_allclose(d.attitude[-1], np.array(Q_ref.tolist(), float), atol=1e-13)
    D, dP, dF, DQ = reference(I, w0, t, Q0)
    got = np.hstack([d.d_omega_d_moments[-1], d.d_omega_d_omega0[-1]])
    assert relative(got, D) <= 1e-12, name
    assert relative(np.r_[d.d_period_d_moments, d.d_period_d_omega0], dP) <= 1e-12
    assert relative(np.r_[d.d_flip_d_moments, d.d_flip_d_omega0], dF) <= 1e-12
    got = np.concatenate([d.d_attitude_d_moments[-1], d.d_attitude_d_omega0[-1]], axis=-1)
    assert relative(got, DQ) <= 1e-12, name
    # at t = 0: ω0 itself, ∂ω/∂ω0 = 1, ∂ω/∂I = 0, and Q0 whatever the parameters
    np.testing.assert_allclose(d.d_omega_d_omega0[0], np.eye(3), atol=1e-13)
    np.testing.assert_allclose(d.d_omega_d_moments[0], 0.0, atol=1e-13)
    # (to the round-off of P0 R0, whose factors' derivatives cancel: ∂φ/∂ω0 ~ 1/|ω1| in
    # the tennis racket)
    np.testing.assert_allclose(d.attitude[0], Q0, atol=1e-15)
    size = max(1.0, np.abs(got).max())
    np.testing.assert_allclose(d.d_attitude_d_omega0[0], 0.0, atol=1e-14 * size)
    np.testing.assert_allclose(d.d_attitude_d_moments[0], 0.0, atol=1e-14 * size)


def test_a_millionth_from_the_intermediate_axis():
    # 1e-12 from the separatrix, beyond the 1e-6 promised: ω's derivatives and the period's
    # stay at round-off (they had been 5e-6 and 6e-11 off: 1 − m sn² by subtraction, and m's
    # derivatives from a ratio within m1 of 1). The attitude's lose ε/√m1: where u crosses K
    # (the saddle) within the run, 2Π(n|m) and G(v) − G(v0), whose derivatives grow as
    # 1/√m1, cancel (2.7e-10 here)
    I, w0, t = (1.0, 2.0, 3.0), (-1e-6, 1.0, 1e-6), 2.0
    d = FreeRigidBody(I).exact_derivatives(w0, [0.0, t], Q0=Q0)
    D, dP, _, DQ = reference(I, w0, t, Q0)
    assert relative(np.hstack([d.d_omega_d_moments[-1], d.d_omega_d_omega0[-1]]), D) <= 1e-14
    assert relative(np.r_[d.d_period_d_moments, d.d_period_d_omega0], dP) <= 1e-14
    got = np.concatenate([d.d_attitude_d_moments[-1], d.d_attitude_d_omega0[-1]], axis=-1)
    assert relative(got, DQ) <= 1e-9


@pytest.mark.parametrize("case", [CASES[0], CASES[1]], ids=["around e3", "around e1"])
def test_the_reference_attitudes_psi_is_the_quadrature_of_its_rate(case):
    # the mpmath reference's ψ in closed form (a third-kind integral) against the quadrature
    # of Landau & Lifshitz's ψ̇: the reference is checked by a route with no elliptic Π
    _, I, w0, t = case
    Imp, w0mp, Q = [mp.mpf(x) for x in I], [mp.mpf(x) for x in w0], mp.matrix(Q0.tolist())
    with mp.workdps(20):
        closed = closed_attitude(Imp, w0mp, mp.mpf(t), Q)
        quad = closed_attitude(Imp, w0mp, mp.mpf(t), Q, psi_by_quadrature=True)
        assert mp.mnorm(closed - quad, 1) < mp.mpf(10) ** -17


def test_near_the_separatrix_the_derivatives_grow_as_the_period_does():
    # the period grows as log(1/ε) and its derivative along ω0 as 1/ε
    body = FreeRigidBody((1.0, 2.0, 3.0))
    grads = []
    for eps in (1e-4, 1e-6, 1e-8):
        d = body.exact_derivatives(near_separatrix((1.0, 2.0, 3.0), eps, 1), [0.0])
        grads.append(np.abs(d.d_period_d_omega0).max())
    assert 50 < grads[1] / grads[0] < 200 and 50 < grads[2] / grads[1] < 200


def test_a_rotated_body_maps_the_derivatives_to_its_frame():
    # a body given by a full inertia tensor: the derivatives in its own frame equal the
    # sorted principal frame's turned by the principal axes
    R = Rotation.from_rotvec([0.3, -0.5, 0.2]).as_matrix()
    J = R @ np.diag([3.0, 1.0, 2.0]) @ R.T
    rotated = FreeRigidBody.from_body(RigidBody(1.0, J))
    plain = FreeRigidBody((1.0, 2.0, 3.0))
    S = rotated.principal_axes  # body coordinates of the sorted axes
    w_sorted = np.array([0.3, -0.4, 1.1])
    a = rotated.exact_derivatives(S @ w_sorted, [0.0, 2.0])
    b = plain.exact_derivatives(w_sorted, [0.0, 2.0])
    np.testing.assert_allclose(a.omega, b.omega @ S.T, atol=1e-13)
    np.testing.assert_allclose(a.d_omega_d_omega0[-1], S @ b.d_omega_d_omega0[-1] @ S.T,
                               atol=1e-12)  # fmt: skip
    np.testing.assert_allclose(a.d_omega_d_moments[-1], S @ b.d_omega_d_moments[-1], atol=1e-12)
    assert a.flip_interval == pytest.approx(b.flip_interval, rel=1e-14)


def test_the_closed_forms_derivatives_equal_an_integrated_runs_sensitivities():
    # a second route: DOP853 with the variational equations on the torque-free body
    I, w0 = (1.0, 2.0, 3.0), np.array([0.3, -0.4, 1.1])
    d = FreeRigidBody(I).exact_derivatives(w0, np.linspace(0, 4, 5))
    traj = simulate(RigidBody(1.0, np.diag(I)), (0, 4), omega0=w0, method="dop853",
                    rtol=1e-13, atol=1e-15, t_eval=np.linspace(0, 4, 5),
                    sensitivities=("omega0", "inertia"))  # fmt: skip
    np.testing.assert_allclose(traj.sensitivity("omega", "omega0"), d.d_omega_d_omega0,
                               atol=1e-9)  # fmt: skip
    np.testing.assert_allclose(traj.sensitivity("omega", "inertia"), d.d_omega_d_moments,
                               atol=1e-9)  # fmt: skip


@pytest.mark.parametrize(
    ("I", "w0", "message"),
    [
        ((1.0, 2.0, 2.0), (0.3, 0.4, 1.0), "three distinct"),
        ((1.0, 2.0, 3.0), (0.0, 1.0, 0.0), "fixed point or on the separatrix"),
        # I1 (I2 − I1) ω1² = I3 (I3 − I2) ω3² exactly: on the separatrix
        ((1.0, 2.0, 2.25), (0.75, 1.0, 1.0), "fixed point or on the separatrix"),
    ],
)
def test_where_the_closed_form_has_no_derivatives_it_says_so(I, w0, message):
    with pytest.raises(ValueError, match=message):
        FreeRigidBody(I).exact_derivatives(w0, [1.0])


@pytest.mark.parametrize("gap", [1e-6, 1e-9, 1e-11])
def test_a_nearly_symmetric_body_about_its_middle_axis(gap):
    """I2 − I1 = gap, spun about e2 (ψ's factor 1/λ ~ 1/√gap): the first-kind part of
    Π(u) − Π(u0), taken through the rounded arguments, had cost Q 2e-10 and ∂Q/∂ω0 2e-5 of
    its size at gap = 1e-11. Reference: DOP853's forward sensitivities at rtol 1e-13.
    (∂Q/∂(I1, I2) still loses about ε/gap: the chart's ∂m/∂I ~ m/gap cancels there.)"""
    moments = np.array([1.0, 1.0 + gap, 2.0])
    w0 = np.array([1e-7, 1.0, 1e-7])
    t = np.array([10.0, 40.0])
    d = FreeRigidBody(moments).exact_derivatives(w0, t)
    ref = simulate(RigidBody(1.0, np.diag(moments)), (0, 40), omega0=w0, method="dop853",
                   rtol=1e-13, atol=1e-16, t_eval=t, sensitivities="omega0")  # fmt: skip
    assert np.abs(d.attitude - ref.Q).max() < 2e-12
    dQ = ref.sensitivity("Q", "omega0").reshape(2, 3, 3, 3)
    assert relative(d.d_attitude_d_omega0, dQ) < 1e-10
