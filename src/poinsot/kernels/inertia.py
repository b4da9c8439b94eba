"""Inertia kernels: plain arrays in, plain arrays out (THEORY.md §1, eqs (04), (10)–(15)).

Nothing here validates input or knows about classes; :mod:`poinsot.bodies` does that and calls
down. All functions are written in the subset of NumPy that numba compiles.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "center_of_mass",
    "parallel_axis",
    "particle_inertia",
    "planar_inertia",
    "polyhedron_mass_properties",
    "principal_decomposition",
    "rotate_inertia",
]


def center_of_mass(masses, positions):
    """``R = Σ m_i r_i / Σ m_i``. masses (N,), positions (N, 3) → (3,)."""
    return (masses[:, None] * positions).sum(axis=0) / masses.sum()


def particle_inertia(masses, offsets):
    """Inertia operator about the origin of ``offsets``, eqs (04), (13)–(15).

    ``A_jk = Σ_i m_i (|u_i|² δ_jk − u_ij u_ik)``, i.e. ``A v = Σ m_i u_i × (v × u_i)``
    (THEORY.md erratum: the notebook prints ``v u`` for ``v × u``).

    masses (N,), offsets (N, 3) → (3, 3).
    """
    second = (masses[:, None, None] * offsets[:, :, None] * offsets[:, None, :]).sum(axis=0)
    return np.trace(second) * np.eye(3) - second


def parallel_axis(inertia_com, mass, d):
    """Inertia about the point at ``d`` from the centre of mass (Huygens–Steiner).

    ``A_P = A_G + M (|d|² 𝟙 − d dᵀ)``. inertia_com (3, 3), d (3,) → (3, 3).
    """
    return inertia_com + mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))


def planar_inertia(inertia):
    """Planar inertia tensor ``J' = Σ m ρ ρᵀ = ½ tr(J) 𝟙 − J`` (paper eqs (3)–(4)). (3,3)→(3,3)."""
    return 0.5 * np.trace(inertia) * np.eye(3) - inertia


def rotate_inertia(inertia, R):
    """Inertia of a body rotated by ``R``: ``R J Rᵀ`` (rotation covariance). (3,3) → (3,3)."""
    return R @ inertia @ R.T


def principal_decomposition(inertia):
    """Principal moments (ascending) and axes of a symmetric inertia matrix.

    Returns ``moments`` (3,) with ``I1 ≤ I2 ≤ I3`` and ``axes`` (3, 3) whose columns
    ``e1, e2, e3`` are orthonormal and right-handed, ``inertia ≈ axes @ diag(moments) @ axes.T``.

    Sign rule (deterministic): ``e1`` and ``e2`` are flipped so that their component of largest
    magnitude is positive (the first such component when several tie within 1e-9), then
    ``e3 = e1 × e2``. For repeated moments the eigenspace basis is whatever the symmetric
    eigensolver returns, normalised by the same rule.
    """
    sym = 0.5 * (inertia + inertia.T)
    moments, axes = np.linalg.eigh(sym)
    axes = axes.copy()
    for j in range(2):
        col = axes[:, j]
        mag = np.abs(col)
        k = int(np.argmax(mag >= mag.max() - 1e-9))
        if col[k] < 0:
            axes[:, j] = -col
    axes[:, 2] = np.cross(axes[:, 0], axes[:, 1])
    return moments, axes


def polyhedron_mass_properties(vertices, faces):
    """Exact volume, centroid and inertia (unit density) of a closed triangulated polyhedron.

    Each outward-wound triangle ``(a, b, c)`` spans a signed tetrahedron with the origin, of
    volume ``V = a·(b × c)/6``, first moment ``V (a+b+c)/4`` and second moment
    ``C = V/20 (aaᵀ + bbᵀ + ccᵀ + (a+b+c)(a+b+c)ᵀ)`` (the closed form of ∫ x xᵀ over a
    tetrahedron with one vertex at the origin; Tonon 2004, J. Math. Stat. 1(1)). Summing over
    faces gives the solid's integrals by the divergence theorem; the inertia about the centroid
    follows from ``tr(C) 𝟙 − C`` and the parallel-axis theorem.

    vertices (V, 3), faces (F, 3) integer → (volume, centroid (3,), inertia (3, 3) about the
    centroid). A consistently inward-wound mesh gives a negative volume; the caller decides.
    """
    a = vertices[faces[:, 0]]
    b = vertices[faces[:, 1]]
    c = vertices[faces[:, 2]]
    vol6 = (a * np.cross(b, c)).sum(axis=1)  # 6 V per tetrahedron
    volume = vol6.sum() / 6.0
    s = a + b + c
    centroid = (vol6[:, None] * s).sum(axis=0) / (24.0 * volume)
    outer = (
        a[:, :, None] * a[:, None, :]
        + b[:, :, None] * b[:, None, :]
        + c[:, :, None] * c[:, None, :]
        + s[:, :, None] * s[:, None, :]
    )
    second = (vol6[:, None, None] * outer).sum(axis=0) / 120.0  # Σ V/20 (…)
    inertia_origin = np.trace(second) * np.eye(3) - second
    # shift from the origin to the centroid (parallel axis, run backwards)
    d = centroid
    inertia = inertia_origin - volume * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return volume, centroid, inertia
