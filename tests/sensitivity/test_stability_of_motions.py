"""Stability of motions from the sensitivities: the Floquet picture of periodic torque-free
motions (every multiplier 1, one Jordan block) and the growth rate about the intermediate axis
against its closed form."""

import math

import numpy as np
import pytest

from poinsot import FreeRigidBody, RigidBody, simulate

MOMENTS = (1.0, 2.0, 3.0)


def euler_rate(moments, w):
    """ω̇ = A⁻¹ (Aω × ω), written here independently of the library."""
    I = np.asarray(moments, float)
    return np.cross(I * w, w) / I


@pytest.mark.parametrize(
    "omega0",
    [(0.1, 1.0, 0.1), (1.0, 0.3, 0.2), (0.2, 0.3, 1.0), (1e-3, 1.0, 1e-3), (-0.7, 0.2, 0.9)],
    ids=["tennis racket", "around e1", "around e3", "near the separatrix", "mixed signs"],
)
def test_a_periodic_torque_free_motion_has_every_floquet_multiplier_one(omega0):
    # (integrated: within ε of the separatrix the run passes the saddle and its error grows
    # as 1/ε; 1e-3 keeps it below 1e-9 at rtol 1e-13)
    body = FreeRigidBody(MOMENTS)
    f = body.floquet(omega0)
    M, I = f.monodromy, np.eye(3)
    scale = max(np.abs(M).max(), 1.0)
    # the characteristic polynomial (λ − 1)³: trace 3, det 1, and one Jordan block
    assert abs(np.trace(M) - 3) <= 1e-9 * scale
    assert abs(np.linalg.det(M) - 1) <= 1e-9 * scale**3
    assert np.abs((M - I) @ (M - I)).max() <= 1e-9 * scale**2
    # the flow direction is carried onto itself
    v = euler_rate(MOMENTS, np.asarray(omega0, float))
    assert np.abs(M @ v - v).max() <= 1e-9 * scale * np.abs(v).max()
    # ... and the block is not trivial: a neighbour on another polhode drifts in phase
    assert np.abs(M - I).max() > 1e-3


@pytest.mark.parametrize("w2", [1.0, -2.5, 1e-3])
@pytest.mark.parametrize("moments", [MOMENTS, (0.5, 2.2, 2.4)])
def test_the_growth_rate_about_the_intermediate_axis(moments, w2):
    I1, I2, I3 = moments
    sigma = abs(w2) * math.sqrt((I2 - I1) * (I3 - I2) / (I1 * I3))
    f = FreeRigidBody(moments).floquet((0.0, w2, 0.0))
    assert abs(f.exponents[0] - sigma) <= 1e-6 * sigma
    assert abs(f.exponents[2] + sigma) <= 1e-6 * sigma
    assert abs(f.exponents[1]) <= 1e-9 * sigma


def test_finite_time_lyapunov_exponents_approach_the_growth_rate():
    body = RigidBody.box(1.0, (1, 2, 3))
    I1, I2, I3 = body.principal_moments
    sigma = math.sqrt((I2 - I1) * (I3 - I2) / (I1 * I3))
    traj = simulate(body, (0, 40), omega0=(0, 1, 0), method="dop853", rtol=1e-12,
                    atol=1e-14, sensitivities="omega0", t_eval=np.linspace(0, 40, 5))  # fmt: skip
    lam = traj.lyapunov_exponents()
    assert np.isnan(lam[0]).all()
    # λ(t) = σ + ln c/t: the error falls as 1/t
    err = np.abs(lam[1:, 0] - sigma)
    assert np.all(np.diff(err) < 0) and err[-1] < 0.01 * sigma
    assert abs(lam[1, 0] + lam[1, 1] + lam[1, 2]) < 1e-9  # volume preserved


def test_floquet_refuses_what_has_no_period():
    body = FreeRigidBody(MOMENTS)
    with pytest.raises(ValueError, match="at rest"):
        body.floquet((0, 0, 0))
    with pytest.raises(ValueError, match="period"):
        body.floquet((0.1, 1, 0.1), period=-1.0)
