"""Attitude conversions against scipy (peer) and eq. (13) against finite differences."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from scipy.spatial.transform import Rotation

from poinsot import rotation as rot
from poinsot._core import vee

angles3 = hnp.arrays(float, 3, elements=st.floats(-3.0, 3.0))


@pytest.mark.parametrize("seq", rot.EULER_SEQUENCES)
def test_every_sequence_roundtrips(seq):
    rng = np.random.default_rng(abs(hash(seq)) % 2**32)
    R = Rotation.random(50, random_state=rng).as_matrix()
    angles = rot.euler_from_matrix(R, seq)
    np.testing.assert_allclose(rot.matrix_from_euler(angles, seq), R, atol=1e-12)
    np.testing.assert_allclose(angles, Rotation.from_matrix(R).as_euler(seq), atol=1e-12)
    q = rot.quat_from_euler(angles, seq)
    np.testing.assert_allclose(rot.matrix_from_quat(q), R, atol=1e-12)
    np.testing.assert_allclose(rot.euler_from_quat(q, seq), angles, atol=1e-10)


def test_intrinsic_vs_extrinsic():
    a = np.array([0.3, -0.7, 1.1])
    # intrinsic XYZ = extrinsic zyx with reversed angles
    np.testing.assert_allclose(
        rot.matrix_from_euler(a, "XYZ"), rot.matrix_from_euler(a[::-1], "zyx"), atol=1e-15
    )


@pytest.mark.parametrize(
    ("seq", "angles"),
    [
        ("ZXZ", [0.4, 0.0, 0.3]),
        ("ZXZ", [0.4, np.pi, 0.3]),
        ("XYZ", [0.2, np.pi / 2, 0.5]),
        ("zyx", [0.1, -np.pi / 2, 0.9]),
    ],
)
def test_gimbal_lock_is_finite_and_recomposes(seq, angles):
    R = rot.matrix_from_euler(angles, seq)
    out = rot.euler_from_matrix(R, seq)
    assert np.all(np.isfinite(out))
    assert out[2] == 0.0  # documented choice: third angle zero
    np.testing.assert_allclose(rot.matrix_from_euler(out, seq), R, atol=1e-12)


@given(angles3.filter(lambda a: 0.05 < abs(np.sin(a[1]))), angles3)
def test_eq13_body_rates_match_finite_differences(angles, rates):
    # ω_body = vee(Qᵀ Q̇) with Q = Rz(ψ) Rx(θ) Rz(φ); central differences in time
    h = 1e-6
    Qp = rot.matrix_from_euler(angles + h * rates, "ZXZ")
    Qm = rot.matrix_from_euler(angles - h * rates, "ZXZ")
    Q = rot.matrix_from_euler(angles, "ZXZ")
    omega_fd = vee(Q.T @ (Qp - Qm) / (2 * h))
    omega = rot.body_rates_from_euler(angles, rates)
    np.testing.assert_allclose(omega, omega_fd, atol=1e-7 * (1 + np.abs(rates).max()))
    np.testing.assert_allclose(
        rot.euler_rates_from_body(angles, omega),
        rates,
        atol=1e-9 * (1 + np.abs(rates).max()) / abs(np.sin(angles[1])),
    )


def test_rotvec_conversions():
    w = np.array([0.3, -1.2, 2.0])
    np.testing.assert_allclose(
        rot.matrix_from_rotvec(w), Rotation.from_rotvec(w).as_matrix(), atol=1e-15
    )
    np.testing.assert_allclose(rot.rotvec_from_matrix(rot.matrix_from_rotvec(w)), w, atol=1e-14)
    np.testing.assert_allclose(rot.quat_from_matrix(np.eye(3)), [1, 0, 0, 0])


def test_bad_input():
    with pytest.raises(ValueError, match="`seq` must be one of XYX"):
        rot.matrix_from_euler([0, 0, 0], "ZZZ")
    with pytest.raises(ValueError, match=r"`angles` must have shape \(..., 3\)"):
        rot.matrix_from_euler([0, 0], "ZXZ")
    with pytest.raises(ValueError, match="gimbal lock"):
        rot.euler_rates_from_body([0.1, 0.0, 0.2], [1, 2, 3])
