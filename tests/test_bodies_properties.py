"""Property tests (hypothesis): identities of the inertia operator that hold for every body."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from conftest import point_clouds, rotations
from poinsot import RigidBody

vectors = hnp.arrays(float, 3, elements=st.floats(-5, 5))


def _scale(body):
    return max(body.principal_moments[2], 1e-12)


@given(point_clouds(), rotations())
def test_rotation_covariance(cloud, R):
    m, r = cloud
    a = RigidBody.from_particles(m, r)
    b = RigidBody.from_particles(m, r @ R.T)
    np.testing.assert_allclose(b.inertia, R @ a.inertia @ R.T, atol=1e-10 * _scale(a))


@given(point_clouds(), vectors)
def test_parallel_axis_theorem(cloud, point):
    m, r = cloud
    body = RigidBody.from_particles(m, r)
    d = r - point
    direct = (
        m[:, None, None]
        * ((d * d).sum(1)[:, None, None] * np.eye(3) - d[:, :, None] * d[:, None, :])
    ).sum(0)
    np.testing.assert_allclose(
        body.inertia_about(point), direct, atol=1e-9 * max(1, abs(direct).max())
    )


@given(point_clouds())
def test_triangle_inequality_and_ordering(cloud):
    body = RigidBody.from_particles(*cloud)
    I1, I2, I3 = body.principal_moments
    tol = 1e-12 * _scale(body)
    assert I1 <= I2 <= I3
    assert I1 >= -tol
    assert I1 + I2 >= I3 - tol


@given(point_clouds(), vectors.filter(lambda v: np.linalg.norm(v) > 1e-3))
def test_moment_about_any_axis_is_bounded(cloud, v):
    body = RigidBody.from_particles(*cloud)
    I1, _, I3 = body.principal_moments
    Iv = body.moment_of_inertia(v)
    tol = 1e-10 * _scale(body)
    assert I1 - tol <= Iv <= I3 + tol
    # I(v) = Σ m_i d_i(v)², d_i the distance of particle i from the axis
    n = v / np.linalg.norm(v)
    u = body.u
    dist2 = (u * u).sum(1) - (u @ n) ** 2
    assert Iv == pytest.approx(body.particle_masses @ dist2, rel=1e-12, abs=tol)


@given(point_clouds())
def test_planar_inertia_identity(cloud):
    body = RigidBody.from_particles(*cloud)
    rho, m = body.u, body.particle_masses
    direct = (m[:, None, None] * rho[:, :, None] * rho[:, None, :]).sum(0)
    expected = 0.5 * np.trace(body.inertia) * np.eye(3) - body.inertia
    np.testing.assert_allclose(body.planar_inertia, expected, atol=1e-12 * _scale(body))
    np.testing.assert_allclose(direct, expected, atol=1e-10 * max(1, _scale(body)))


@given(point_clouds(min_size=2), st.integers(1, 10), rotations())
@settings(max_examples=60)
def test_composition_equals_union_of_particles(cloud, k, R):
    m, r = cloud
    k = k % len(m) or 1
    whole = RigidBody.from_particles(m, r)
    a = RigidBody.from_particles(m[:k], r[:k])
    b = RigidBody.from_particles(m[k:], r[k:])
    # mix a mass-properties body (no particles) in too
    b_props = RigidBody(b.mass, b.inertia, b.center_of_mass)
    for parts in ([a, b], [a, b_props], [(mi, ri) for mi, ri in zip(m, r, strict=False)]):
        comp = RigidBody.compose(parts)
        assert comp.mass == pytest.approx(whole.mass, rel=1e-12)
        np.testing.assert_allclose(comp.center_of_mass, whole.center_of_mass, atol=1e-10)
        np.testing.assert_allclose(comp.inertia, whole.inertia, atol=1e-9 * max(1, _scale(whole)))
    # placing rotates about the centre of mass: same as rotating the particles about it
    placed = whole.placed(orientation=R)
    c = whole.center_of_mass
    rotated = RigidBody.from_particles(m, (r - c) @ R.T + c)
    np.testing.assert_allclose(placed.inertia, rotated.inertia, atol=1e-9 * max(1, _scale(whole)))
    np.testing.assert_allclose(placed.u, rotated.u, atol=1e-10)


@given(point_clouds(min_size=3))
def test_principal_axes_diagonalise(cloud):
    body = RigidBody.from_particles(*cloud)
    E = body.principal_axes
    np.testing.assert_allclose(E.T @ E, np.eye(3), atol=1e-12)
    assert np.linalg.det(E) > 0
    np.testing.assert_allclose(
        E.T @ body.inertia @ E, np.diag(body.principal_moments), atol=1e-10 * max(1, _scale(body))
    )
