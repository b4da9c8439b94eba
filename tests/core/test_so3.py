"""SO(3) kernels against scipy.spatial.transform.Rotation (peer) and their own identities."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from scipy.spatial.transform import Rotation

from poinsot import _core as so3

vec = hnp.arrays(float, 3, elements=st.floats(-3, 3))
quat = hnp.arrays(float, 4, elements=st.floats(-1, 1)).filter(lambda q: np.linalg.norm(q) > 0.1)


def _scipy_quat(q):  # poinsot is scalar-first
    return Rotation.from_quat(q, scalar_first=True)


@given(vec, vec)
def test_hat_vee(w, v):
    np.testing.assert_allclose(so3.hat(w) @ v, np.cross(w, v), atol=1e-14)
    np.testing.assert_allclose(so3.vee(so3.hat(w)), w, atol=0)
    B = so3.hat(w)
    # docs/theory.md §1: b = (−B23, B13, −B12) (1-based)
    np.testing.assert_allclose(so3.vee(B), [-B[1, 2], B[0, 2], -B[0, 1]])


@given(vec)
def test_exp_matches_scipy(w):
    np.testing.assert_allclose(so3.exp_so3(w), Rotation.from_rotvec(w).as_matrix(), atol=1e-14)


@given(quat)
def test_quaternion_matrix_roundtrip_matches_scipy(q):
    q = q / np.linalg.norm(q)
    R = so3.quat_to_matrix(q)
    np.testing.assert_allclose(R, _scipy_quat(q).as_matrix(), atol=1e-14)
    back = so3.matrix_to_quat(R)
    assert back[0] >= 0
    assert min(np.abs(back - q).max(), np.abs(back + q).max()) < 1e-13  # q ≡ −q


@given(quat, quat, vec)
def test_quaternion_product_composes_rotations(p, q, v):
    p, q = p / np.linalg.norm(p), q / np.linalg.norm(q)
    pq = so3.quat_multiply(p, q)
    np.testing.assert_allclose(
        so3.quat_to_matrix(pq), so3.quat_to_matrix(p) @ so3.quat_to_matrix(q), atol=1e-13
    )
    np.testing.assert_allclose(so3.quat_rotate(q, v), so3.quat_to_matrix(q) @ v, atol=1e-13)
    ident = so3.quat_multiply(q, so3.quat_conjugate(q))
    np.testing.assert_allclose(ident, [1, 0, 0, 0], atol=1e-15)


@given(vec)
def test_log_inverts_exp(w):
    theta = np.linalg.norm(w)
    if theta > np.pi - 1e-9:  # principal branch |w| ≤ π
        w = w * (np.pi - 1e-9) / theta
    np.testing.assert_allclose(so3.log_so3(so3.exp_so3(w)), w, atol=2e-12)
    np.testing.assert_allclose(so3.quat_to_rotvec(so3.rotvec_to_quat(w)), w, atol=1e-13)


@pytest.mark.parametrize("theta", [0.0, 1e-12, 1e-8, 1e-5, 1e-4, 1e-3, 1.0, np.pi - 1e-6, np.pi])
def test_exp_log_accurate_near_singular_angles(theta):
    axis = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    w = theta * axis
    R = so3.exp_so3(w)
    np.testing.assert_allclose(R, Rotation.from_rotvec(w).as_matrix(), atol=1e-15)
    got = so3.log_so3(R)
    if theta == np.pi:  # ±axis both valid
        assert min(np.abs(got - w).max(), np.abs(got + w).max()) < 1e-12
    else:
        np.testing.assert_allclose(got, w, atol=1e-14 * max(1, 1 / max(np.pi - theta, 1e-3)))


def test_batched_shapes():
    w = np.random.default_rng(0).normal(size=(5, 7, 3))
    R = so3.exp_so3(w)
    assert R.shape == (5, 7, 3, 3)
    np.testing.assert_allclose(
        so3.log_so3(R),
        Rotation.from_matrix(R.reshape(-1, 3, 3)).as_rotvec().reshape(5, 7, 3),
        atol=1e-12,
    )
    q = so3.matrix_to_quat(R)
    assert q.shape == (5, 7, 4)


@given(vec, vec)
def test_dexpinv_inverts_dexp(u, v):
    # dexp_u(v) = v + (1 − cos θ)/θ² u × v + (θ − sin θ)/θ³ u × (u × v); check dexpinv ∘ dexp = id
    th = np.linalg.norm(u)
    if th > 3.0:
        u = u * 3.0 / th
        th = 3.0
    if th < 1e-2:  # the series: (1 − cos θ)/θ² and (θ − sin θ)/θ³ cancel below
        a = 0.5 - th**2 / 24 + th**4 / 720
        b = 1 / 6 - th**2 / 120 + th**4 / 5040
    else:
        a, b = 2 * np.sin(th / 2) ** 2 / th**2, (th - np.sin(th)) / th**3
    dexp = v + a * np.cross(u, v) + b * np.cross(u, np.cross(u, v))
    np.testing.assert_allclose(so3.dexpinv(u, dexp), v, atol=1e-12 * (1 + np.abs(v).max()))


def test_dexp_by_finite_differences():
    # d/dt exp(u + t v)|₀ = exp(u) hat(dexp_{-u}(v))  (right trivialisation); check via dexpinv
    u = np.array([0.4, -1.1, 0.7])
    v = np.array([0.3, 0.2, -0.5])
    h = 1e-6
    dR = (so3.exp_so3(u + h * v) - so3.exp_so3(u - h * v)) / (2 * h)
    # left trivialisation: dR = hat(dexp_u(v)) exp(u)
    omega = so3.vee(dR @ so3.exp_so3(u).T)
    np.testing.assert_allclose(so3.dexpinv(u, omega), v, atol=1e-9)


def test_normalize_zero_refused():
    with pytest.raises(ValueError, match="must be non-zero"):
        so3.quat_normalize([0, 0, 0, 0])
