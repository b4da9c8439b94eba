"""The Rust geometry (``poinsot._core``: ``crates/core/src/{so3,inertia,shapes}.rs``) against
the numba kernels it was ported from (``poinsot.kernels.so3``, ``.inertia``, ``.shapes``).

The ports are formula for formula, so they agree to round-off (on the development machine:
bit for bit, except ``rotate_inertia``, whose numba twin multiplies through BLAS, and the
principal decomposition, where LAPACK's ``eigh`` meets a cyclic Jacobi method: moments within
a few ulps of ``I3``, axes within a few ulps divided by the relative gap between moments).
Inputs are random batches of every leading shape, including the small-angle series branches.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from poinsot import _core as rs
from poinsot.kernels import inertia as ni
from poinsot.kernels import shapes as ns
from poinsot.kernels import so3 as nb

EPS = np.finfo(float).eps
leading = hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=5)
angle = st.floats(-4, 4, allow_nan=False) | st.floats(-1e-4, 1e-4, allow_nan=False)
unit = st.floats(-1, 1, allow_nan=False)


def roundoff(actual, reference, ulps=4.0):
    """Equal shapes, and values within ``ulps`` units of round-off of the reference's scale."""
    actual, reference = np.asarray(actual), np.asarray(reference)
    assert actual.shape == reference.shape
    scale = max(1.0, float(np.max(np.abs(reference), initial=0.0)))
    np.testing.assert_allclose(actual, reference, rtol=0, atol=ulps * EPS * scale)


def batch(shape, tail, elements):
    return hnp.arrays(float, shape + tail, elements=elements)


@st.composite
def batches(draw, tail, elements=angle):
    return draw(batch(draw(leading), tail, elements))


@st.composite
def pairs(draw, tails, elements=(angle, angle)):
    """Two batches with equal leading shapes, or one of them a single item of the same number
    of axes (numba cannot type a mix of ranks; the Rust functions also take a bare item, see
    :func:`test_pairs_take_a_single_item_of_any_rank`)."""
    shape = draw(leading)
    a = draw(batch(shape, tails[0], elements[0]))
    b = draw(batch(shape, tails[1], elements[1]))
    which = draw(st.sampled_from(["both", "first single", "second single"]))
    ones = (1,) * len(shape)
    if which == "first single" and a.size:
        a = a.reshape(-1, *tails[0])[0].reshape(ones + tails[0])
    elif which == "second single" and b.size:
        b = b.reshape(-1, *tails[1])[0].reshape(ones + tails[1])
    return a, b


# --------------------------------------------------------------------------- SO(3)
@pytest.mark.parametrize(
    ("name", "tail"),
    [
        ("hat", (3,)),
        ("vee", (3, 3)),
        ("exp_so3", (3,)),
        ("rotvec_to_quat", (3,)),
        ("quat_conjugate", (4,)),
        ("quat_to_matrix", (4,)),
        ("quat_to_rotvec", (4,)),
    ],
)
@given(data=st.data())
def test_unary_maps_agree(name, tail, data):
    x = data.draw(batches(tail, angle if tail == (3,) else unit))
    roundoff(getattr(rs, name)(x), getattr(nb, name)(x))


@given(batches((4,), unit))
def test_quat_normalize_agrees(q):
    q = np.where(np.linalg.norm(q, axis=-1, keepdims=True) > 1e-3, q, 1.0)
    roundoff(rs.quat_normalize(q), nb.quat_normalize(q))


@given(batches((3,)))
def test_log_and_matrix_to_quat_agree_on_rotations(w):
    R = nb.exp_so3(w)
    roundoff(rs.log_so3(R), nb.log_so3(R))
    roundoff(rs.matrix_to_quat(R), nb.matrix_to_quat(R))


@given(batches((3, 3), unit))
def test_log_and_matrix_to_quat_agree_on_any_matrix(B):
    # not rotations: the same formulas still run, branch for branch
    roundoff(rs.matrix_to_quat(B), nb.matrix_to_quat(B))
    roundoff(rs.log_so3(B), nb.log_so3(B))


@given(pairs(((3,), (3,))))
def test_dexpinv_agrees(uv):
    u, v = uv
    roundoff(rs.dexpinv(u, v), nb.dexpinv(u, v))


@given(pairs(((4,), (4,)), (unit, unit)))
def test_quat_multiply_agrees(pq):
    p, q = pq
    roundoff(rs.quat_multiply(p, q), nb.quat_multiply(p, q))


@given(pairs(((4,), (3,)), (unit, angle)))
def test_quat_rotate_agrees(qv):
    q, v = qv
    roundoff(rs.quat_rotate(q, v), nb.quat_rotate(q, v))


@given(data=st.data())
def test_zxz_agrees(data):
    shape = data.draw(leading)
    angles = data.draw(batch(shape, (3,), angle))
    rates = data.draw(batch(shape, (3,), angle))
    angles[..., 1] = np.where(np.abs(np.sin(angles[..., 1])) > 1e-3, angles[..., 1], 1.0)
    roundoff(rs.zxz_body_rates(angles, rates), nb.zxz_body_rates(angles, rates))
    roundoff(rs.zxz_angle_rates(angles, rates), nb.zxz_angle_rates(angles, rates))
    out = np.empty((3, 3))
    ref = np.empty((*shape, 3, 3))
    for idx in np.ndindex(shape):
        nb.zxz_matrix_into(*angles[idx], out)
        ref[idx] = out
    roundoff(rs.zxz_matrix(angles), ref)


def test_pairs_take_a_single_item_of_any_rank():
    rng = np.random.default_rng(7)
    q = rng.normal(size=(2, 5, 4))
    v = rng.normal(size=(2, 5, 3))
    np.testing.assert_array_equal(rs.quat_multiply(q, q[0, 0]), nb.quat_multiply(q, q[:1, :1]))
    np.testing.assert_array_equal(rs.quat_multiply(q[0, 0], q), nb.quat_multiply(q[:1, :1], q))
    np.testing.assert_array_equal(rs.quat_rotate(q[1, 2], v), nb.quat_rotate(q[1:2, 2:3], v))
    np.testing.assert_array_equal(rs.quat_rotate(q, v[1, 2]), nb.quat_rotate(q, v[1:2, 2:3]))
    np.testing.assert_array_equal(rs.dexpinv(v[0, 0], v), nb.dexpinv(v[:1, :1], v))


@given(st.integers(0, 2), angle)
def test_axis_rotation_agrees(axis, theta):
    roundoff(rs.axis_rotation(axis, theta), nb.axis_rotation(axis, theta))


def test_large_batches_agree_and_layouts_do_not_matter():
    rng = np.random.default_rng(20240601)
    w = rng.uniform(-4, 4, (20000, 3))
    w[:2000] *= 1e-5  # the series branches
    roundoff(rs.exp_so3(w), nb.exp_so3(w))
    R = nb.exp_so3(w)
    roundoff(rs.log_so3(R), nb.log_so3(R))
    roundoff(rs.matrix_to_quat(R), nb.matrix_to_quat(R))
    q = rng.normal(size=(20000, 4))
    roundoff(rs.quat_normalize(q), nb.quat_normalize(q))
    # Fortran order, reversed strides and integer input give the same items
    wf = np.asfortranarray(w[:50])
    roundoff(rs.exp_so3(wf), nb.exp_so3(np.ascontiguousarray(wf)))
    roundoff(rs.hat(w[::-1]), nb.hat(np.ascontiguousarray(w[::-1])))
    np.testing.assert_array_equal(rs.hat([[1, 2, 3]]), nb.hat(np.array([[1.0, 2.0, 3.0]])))
    J = np.array([[2.0, 0.3, -0.1], [0.3, 3.0, 0.2], [-0.1, 0.2, 4.0]])
    roundoff(rs.rotate_inertia(J, np.asfortranarray(R[7])), ni.rotate_inertia(J, R[7]), ulps=16)
    roundoff(rs.rotate_inertia(np.asfortranarray(J + 0.1 * R[3]), R[7]),
             ni.rotate_inertia(J + 0.1 * R[3], R[7]), ulps=16)  # fmt: skip


@pytest.mark.parametrize(
    "call",
    [
        lambda m: m.hat(np.ones(4)),
        lambda m: m.vee(np.ones((3, 2))),
        lambda m: m.quat_to_matrix(np.ones((2, 3))),
        lambda m: m.quat_normalize(np.zeros((2, 4))),
        lambda m: m.quat_multiply(np.ones((2, 4)), np.ones((3, 4))),
        lambda m: m.dexpinv(np.ones((2, 3)), np.ones((3, 3))),
    ],
)
def test_bad_shapes_are_value_errors_in_both(call):
    with pytest.raises(ValueError):
        call(nb)
    with pytest.raises(ValueError):
        call(rs)


# --------------------------------------------------------------------------- inertia
masses = st.floats(0.1, 10, allow_nan=False)
coords = st.floats(-10, 10, allow_nan=False)


@st.composite
def clouds(draw):
    n = draw(st.integers(1, 20))
    return (
        draw(hnp.arrays(float, n, elements=masses)),
        draw(hnp.arrays(float, (n, 3), elements=coords)),
    )


@given(clouds(), hnp.arrays(float, 3, elements=coords), st.floats(0.1, 10))
def test_particle_mass_properties_agree(cloud, d, mass):
    m, r = cloud
    com = ni.center_of_mass(m, r)
    roundoff(rs.center_of_mass(m, r), com)
    u = r - com
    J = ni.particle_inertia(m, u)
    roundoff(rs.particle_inertia(m, u), J)
    roundoff(rs.parallel_axis(J, mass, d), ni.parallel_axis(J, mass, d))
    roundoff(rs.planar_inertia(J), ni.planar_inertia(J))


@st.composite
def rotation_matrices(draw):
    q = draw(hnp.arrays(float, 4, elements=unit))
    n = np.linalg.norm(q)
    return nb.quat_to_matrix(q / n if n > 1e-3 else np.array([1.0, 0, 0, 0]))


@given(clouds(), rotation_matrices())
def test_rotation_and_principal_decomposition_agree(cloud, R):
    m, r = cloud
    J = ni.particle_inertia(m, r - ni.center_of_mass(m, r))
    roundoff(rs.rotate_inertia(J, R), ni.rotate_inertia(J, R), ulps=16)
    m1, a1 = rs.principal_decomposition(J)
    m2, a2 = ni.principal_decomposition(J)
    scale = max(float(m2[2]), np.finfo(float).tiny)
    np.testing.assert_allclose(m1, m2, rtol=0, atol=64 * EPS * scale)
    assert np.all(np.diff(m1) >= 0)
    # the axes are unique (up to the sign rule) only where the moments are apart
    gap = float(np.min(np.diff(m2))) / scale
    if gap > 1e-6:
        np.testing.assert_allclose(a1, a2, rtol=0, atol=64 * EPS / gap)
    # whatever the gaps: right-handed, orthonormal, and a decomposition of J
    np.testing.assert_allclose(a1.T @ a1, np.eye(3), atol=1e-14)
    assert np.linalg.det(a1) > 0
    np.testing.assert_allclose(a1 @ np.diag(m1) @ a1.T, J, rtol=0, atol=1e-13 * scale)


@given(
    hnp.arrays(float, 3, elements=st.floats(0.5, 5)),
    rotation_matrices(),
    st.sampled_from([(0, 0), (0, 1), (1, 1), (1, 2), (0, 2)]),
)
def test_principal_axes_agree_with_separated_and_repeated_moments(moments, R, ties):
    # moments with a controlled gap (or an exact tie) in random axes
    moments = np.sort(moments) + np.array([0.0, 1.0, 2.0])
    i, j = ties
    moments[j] = moments[i]
    J = ni.rotate_inertia(np.diag(moments), R)
    m1, a1 = rs.principal_decomposition(J)
    m2, a2 = ni.principal_decomposition(J)
    np.testing.assert_allclose(m1, m2, rtol=0, atol=64 * EPS * m2[2])
    if i == j:  # three distinct moments, at least 1 apart
        np.testing.assert_allclose(a1, a2, rtol=0, atol=1e-13)
    elif (i, j) != (0, 2):  # a repeated pair: the single axis agrees up to sign
        k = 2 if (i, j) == (0, 1) else 0
        assert abs(abs(a1[:, k] @ a2[:, k]) - 1.0) < 1e-13


@given(
    hnp.arrays(float, 3, elements=st.floats(0, 10)),
    st.sampled_from([1e-12, 1e-6, 0.1]),
    st.booleans(),
)
def test_symmetry_code_and_degeneracy_agree(moments, rtol, tie):
    moments = np.sort(moments)
    if tie:
        moments[1] = moments[0]
    assert rs.symmetry_code(moments, rtol) == ni.symmetry_code(moments, rtol)
    assert rs.is_degenerate(moments, rtol) == ni.is_degenerate(moments, rtol)
    assert rs.SYMMETRY_CLASSES == ni.SYMMETRY_CLASSES
    assert (rs.SYMMETRY_RTOL, rs.DEGENERATE_RTOL) == (ni.SYMMETRY_RTOL, ni.DEGENERATE_RTOL)


@settings(max_examples=50)
@given(st.integers(4, 30), st.integers(1, 60), st.integers(0, 2**32 - 1))
def test_polyhedron_integrals_agree(nv, nf, seed):
    # any triangle soup runs the same sums; closedness is the caller's business
    rng = np.random.default_rng(seed)
    vertices = rng.uniform(-3, 3, (nv, 3))
    faces = rng.integers(0, nv, (nf, 3)).astype(np.int64)
    v1, c1, j1 = rs.polyhedron_mass_properties(vertices, faces)
    v2, c2, j2 = ni.polyhedron_mass_properties(vertices, faces)
    if not abs(v2) > 1e-3:  # the centroid divides by the volume
        return
    roundoff(v1, v2, ulps=16)
    roundoff(c1, c2, ulps=16 * max(1.0, 1.0 / abs(v2)))
    roundoff(j1, j2, ulps=64 * max(1.0, 1.0 / abs(v2)))


def test_polyhedron_refuses_bad_faces():
    with pytest.raises(ValueError, match="faces"):
        rs.polyhedron_mass_properties(np.eye(3), np.array([[0, 1, 3]]))
    with pytest.raises(ValueError, match="faces"):
        rs.polyhedron_mass_properties(np.eye(3), np.array([[0, -1, 2]]))


# --------------------------------------------------------------------------- shapes
@given(
    st.floats(0.01, 100),
    st.floats(0.01, 10),
    st.floats(0.01, 10),
    hnp.arrays(float, 3, elements=st.floats(0.01, 10)),
)
def test_uniform_solids_agree(m, r, h, size):
    roundoff(rs.box_inertia(m, size), ns.box_inertia(m, size))
    roundoff(rs.sphere_inertia(m, r), ns.sphere_inertia(m, r))
    roundoff(rs.spherical_shell_inertia(m, r), ns.spherical_shell_inertia(m, r))
    roundoff(rs.cylinder_inertia(m, r, h), ns.cylinder_inertia(m, r, h))
    roundoff(rs.ellipsoid_inertia(m, size), ns.ellipsoid_inertia(m, size))
    roundoff(rs.rod_inertia(m, h), ns.rod_inertia(m, h))
    roundoff(rs.cone_inertia(m, r, h), ns.cone_inertia(m, r, h))
    moments = np.diag(ns.box_inertia(m, size)).copy()
    roundoff(rs.equivalent_box_half_extents(moments, m), ns.equivalent_box_half_extents(moments, m))
