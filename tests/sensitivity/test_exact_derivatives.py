"""The exact derivatives of the torque-free closed form against an independent route: the
closed form written again in mpmath at 30 digits (Landau & Lifshitz, *Mechanics*, §37), its
derivatives by ``mp.diff``, to ≤ 1e-12 relative, including within 1e-6 of the separatrix;
and, apart, against the forward sensitivities of an integrated run."""

import mpmath as mp
import numpy as np
import pytest

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
    u = mp.ellipf(mp.atan2(sn0, cn0), m) + lam * t
    w = [s * a * mp.ellipfun(f, u, m=m) for s, a, f in zip(signs, al, order, strict=True)]
    K = mp.ellipk(m)
    return w, 4 * K / lam, 2 * K / lam


def reference(I, w0, t):
    """The derivatives by mp.diff: ∂ω/∂(I, ω0) (3, 6), ∂period, ∂flip (6,)."""
    x0 = [mp.mpf(v) for v in (*I, *w0)]

    def part(j, pick):
        def f(x):
            y = list(x0)
            y[j] = x
            return pick(closed_form(y[:3], y[3:], mp.mpf(t)))

        return mp.diff(f, x0[j])

    D = np.array([[float(part(j, lambda r, i=i: r[0][i])) for j in range(6)] for i in range(3)])
    dP = np.array([float(part(j, lambda r: r[1])) for j in range(6)])
    dF = np.array([float(part(j, lambda r: r[2])) for j in range(6)])
    return D, dP, dF


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
]  # fmt: skip


def relative(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


@pytest.mark.parametrize(("name", "I", "w0", "t"), CASES, ids=[c[0] for c in CASES])
def test_derivatives_of_the_closed_form_equal_mpmaths(name, I, w0, t):
    body = FreeRigidBody(I)
    d = body.exact_derivatives(w0, [0.0, t])
    w_ref, period, flip = closed_form([mp.mpf(x) for x in I], [mp.mpf(x) for x in w0], t)
    # the forward map itself first: the same motion, period and flip interval (near the
    # separatrix too: its distance a² − 2k I2 is formed without rounding errors)
    np.testing.assert_allclose(d.omega[-1], [float(x) for x in w_ref], rtol=1e-12, atol=1e-13)
    assert d.period == pytest.approx(float(period), rel=1e-14)
    assert d.flip_interval == pytest.approx(float(flip), rel=1e-14)
    D, dP, dF = reference(I, w0, t)
    got = np.hstack([d.d_omega_d_moments[-1], d.d_omega_d_omega0[-1]])
    assert relative(got, D) <= 1e-12, name
    assert relative(np.r_[d.d_period_d_moments, d.d_period_d_omega0], dP) <= 1e-12
    assert relative(np.r_[d.d_flip_d_moments, d.d_flip_d_omega0], dF) <= 1e-12
    # at t = 0: ω0 itself, ∂ω/∂ω0 = 1, ∂ω/∂I = 0
    np.testing.assert_allclose(d.d_omega_d_omega0[0], np.eye(3), atol=1e-13)
    np.testing.assert_allclose(d.d_omega_d_moments[0], 0.0, atol=1e-13)


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
    from scipy.spatial.transform import Rotation

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
