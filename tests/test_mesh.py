"""RigidBody.from_mesh: exact polyhedral integrals against closed forms and trimesh (peer)."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import RigidBody

trimesh = pytest.importorskip("trimesh")


def test_box_mesh_equals_closed_form():
    mesh = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    body = RigidBody.from_mesh(mesh, mass=12.0)
    np.testing.assert_allclose(body.inertia, RigidBody.box(12.0, (1, 2, 3)).inertia, atol=1e-13)
    np.testing.assert_allclose(body.center_of_mass, 0, atol=1e-15)


def test_translated_rotated_box_mesh():
    mesh = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    T = trimesh.transformations.rotation_matrix(0.7, [1, 2, 3])
    T[:3, 3] = [5.0, -1.0, 2.0]
    mesh.apply_transform(T)
    body = RigidBody.from_mesh(mesh, density=2.0)
    assert body.mass == pytest.approx(12.0, rel=1e-13)
    np.testing.assert_allclose(body.center_of_mass, [5, -1, 2], atol=1e-13)
    R = T[:3, :3]
    np.testing.assert_allclose(
        body.inertia, R @ RigidBody.box(12.0, (1, 2, 3)).inertia @ R.T, atol=1e-12
    )


def test_icosphere_converges_to_sphere_and_matches_trimesh():
    errors = []
    for sub in (2, 3, 4):
        mesh = trimesh.creation.icosphere(subdivisions=sub, radius=1.5)
        body = RigidBody.from_mesh(mesh, density=1.0)
        # peer: trimesh's own mass properties of the same polyhedron
        props = mesh.mass_properties
        np.testing.assert_allclose(body.mass, props["mass"], rtol=1e-12)
        np.testing.assert_allclose(body.inertia, props["inertia"], rtol=1e-10, atol=1e-12)
        exact = RigidBody.sphere(body.mass, 1.5)
        errors.append(np.max(np.abs(body.inertia - exact.inertia)) / exact.inertia[0, 0])
    assert errors[2] < errors[1] < errors[0]
    assert errors[2] < 1e-2


def test_mesh_from_file(tmp_path):
    mesh = trimesh.creation.box(extents=(2.0, 1.0, 0.5))
    path = tmp_path / "plate.stl"
    mesh.export(path)
    body = RigidBody.from_mesh(path, mass=3.0)
    np.testing.assert_allclose(body.inertia, RigidBody.box(3.0, (2, 1, 0.5)).inertia, atol=1e-12)
    obj = tmp_path / "plate.obj"
    mesh.export(obj)
    np.testing.assert_allclose(RigidBody.from_mesh(str(obj), mass=3.0).inertia, body.inertia)


def test_arrays_and_inward_winding():
    mesh = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    out = RigidBody.from_mesh((v, f))
    inward = RigidBody.from_mesh((v, f[:, ::-1]))
    assert out.mass == pytest.approx(1.0)
    np.testing.assert_allclose(inward.inertia, out.inertia)


def test_open_mesh_refused():
    mesh = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="not watertight: 3 boundary edges"):
        RigidBody.from_mesh((mesh.vertices, mesh.faces[1:]))


def test_inconsistent_winding_refused():
    mesh = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    f = np.array(mesh.faces)
    f[0] = f[0, ::-1]
    with pytest.raises(ValueError, match="inconsistent winding"):
        RigidBody.from_mesh((mesh.vertices, f))


@pytest.mark.parametrize(
    ("mesh", "kwargs", "match"),
    [
        ("/no/such/file.stl", {}, "no such file"),
        (42, {}, "`mesh` must be a file path"),
        ((np.zeros((4, 2)), np.zeros((4, 3), int)), {}, r"vertices must have shape \(V, 3\)"),
        ((np.zeros((4, 3)), np.zeros((4, 3))), {}, "faces must be integers"),
        ((np.zeros((4, 3)), np.full((4, 3), 7)), {}, "outside 0..3"),
        ((np.zeros((3, 3)), np.array([[0, 1, 2]])), {}, "needs ≥ 4 faces"),
    ],
)
def test_mesh_bad_input(mesh, kwargs, match):
    with pytest.raises((ValueError, TypeError), match=match):
        RigidBody.from_mesh(mesh, **kwargs)


def test_mass_and_density_exclusive():
    mesh = trimesh.creation.box()
    with pytest.raises(ValueError, match="`mass` or `density`, not both"):
        RigidBody.from_mesh(mesh, mass=1.0, density=1.0)
    with pytest.raises(ValueError, match="`density` must be a positive number"):
        RigidBody.from_mesh(mesh, density=-1.0)
