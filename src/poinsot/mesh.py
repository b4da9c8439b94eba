"""Closed triangle meshes: loading, validation, and exact mass properties.

A mesh is accepted as a path to an STL/OBJ/PLY file (read with the optional ``trimesh``
dependency: ``pip install 'poinsot[mesh]'``), a ``trimesh.Trimesh``, or a ``(vertices, faces)``
pair of arrays. The integrals are poinsot's own
(``polyhedron_mass_properties`` of ``crates/core/src/inertia.rs``); trimesh, when present, only
reads files, and the tests use its ``mass_properties`` as an independent peer.
"""

from __future__ import annotations

import os

import numpy as np

from ._bindings.inertia import polyhedron_mass_properties

__all__ = ["check_closed_oriented", "load_mesh_arrays", "mesh_mass_properties"]


def load_mesh_arrays(mesh) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(vertices (V, 3) float, faces (F, 3) int)`` from any accepted mesh input."""
    if isinstance(mesh, str | os.PathLike):
        path = os.fspath(mesh)
        if not os.path.exists(path):
            raise ValueError(f"`mesh`: no such file: {path!r}")
        try:
            import trimesh
        except ImportError as exc:  # pragma: no cover - depends on the environment
            raise ImportError(
                "reading mesh files needs trimesh: pip install 'poinsot[mesh]'"
            ) from exc
        unreadable = f"`mesh`: {path!r} is not a readable triangle mesh (STL, OBJ or PLY)"
        try:
            # unprocessed first, so that non-finite vertices are seen before trimesh drops them
            loaded = trimesh.load(path, force="mesh", process=False)
        except ImportError:  # trimesh met bytes it tried to read as text in another encoding
            raise ValueError(unreadable) from None
        except Exception as exc:
            raise ValueError(f"{unreadable}: {exc}") from None
        faces = getattr(loaded, "faces", None)
        if faces is None or len(faces) == 0:
            raise ValueError(f"{unreadable}: no triangles found")
        _checked(np.asarray(loaded.vertices, float), np.asarray(faces, np.int64))
        loaded.merge_vertices()  # STL repeats each corner per triangle
        return np.asarray(loaded.vertices, float), np.asarray(loaded.faces, np.int64)
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        return _checked(np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64))
    if isinstance(mesh, tuple | list) and len(mesh) == 2:
        vertices = np.asarray(mesh[0], dtype=float)
        faces = np.asarray(mesh[1])
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"`mesh` vertices must have shape (V, 3), found {vertices.shape}")
        if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
            raise ValueError(
                f"`mesh` faces must be integers of shape (F, 3), found {faces.dtype} {faces.shape}"
            )
        return _checked(vertices, faces.astype(np.int64))
    raise TypeError(
        "`mesh` must be a file path, a trimesh.Trimesh or a (vertices, faces) pair, "
        f"found {type(mesh).__name__}"
    )


def _checked(vertices, faces):
    """Finite vertices and faces that index them, whatever the mesh came from."""
    if not np.all(np.isfinite(vertices)):
        bad = int(np.argwhere(~np.isfinite(vertices))[0, 0])
        raise ValueError(
            f"`mesh` has non-finite vertices: vertices[{bad}] = {vertices[bad].tolist()}"
        )
    if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise ValueError(f"`mesh` faces index vertices outside 0..{len(vertices) - 1}")
    return vertices, faces


def check_closed_oriented(faces: np.ndarray) -> None:
    """Refuse a mesh that is not closed or whose triangles are not consistently wound.

    In a closed, consistently oriented 2-manifold every directed edge ``i → j`` occurs exactly
    once and its reverse ``j → i`` exactly once. Raises ``ValueError`` stating which rule fails.
    """
    if len(faces) < 4:
        raise ValueError(
            f"`mesh` is not closed: a closed polyhedron needs ≥ 4 faces, found {len(faces)}"
        )
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    n = int(faces.max()) + 1
    directed = edges[:, 0] * n + edges[:, 1]
    uniq, counts = np.unique(directed, return_counts=True)
    if np.any(counts > 1):
        raise ValueError(
            f"`mesh` has inconsistent winding: {int(np.sum(counts > 1))} directed edges are "
            "shared by two faces in the same direction (or the mesh is not manifold)"
        )
    reverse = edges[:, 1] * n + edges[:, 0]
    missing = int(np.sum(~np.isin(reverse, uniq)))
    if missing:
        raise ValueError(
            f"`mesh` is not watertight: {missing} boundary edges have no opposite edge "
            "(if vertices are duplicated, merge them first)"
        )


def mesh_mass_properties(mesh) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centroid (3,) and unit-density inertia (3, 3) about the centroid of a closed mesh.

    A mesh wound consistently inward (negative signed volume) is accepted and turned outward.
    """
    vertices, faces = load_mesh_arrays(mesh)
    check_closed_oriented(faces)
    volume, centroid, inertia = polyhedron_mass_properties(vertices, faces)
    if volume < 0:
        volume, centroid, inertia = polyhedron_mass_properties(vertices, faces[:, ::-1])
    if not volume > 0:
        raise ValueError(f"`mesh` encloses no volume (signed volume {volume})")
    return float(volume), centroid, inertia
