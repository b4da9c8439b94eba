"""Inertia kernels (``docs/theory.md`` §1, eqs (04), (10)–(15); paper eqs (3)–(4)).

Nothing here validates input or knows about classes; :mod:`poinsot.bodies` does that and calls
down. The symmetry class and degeneracy of a body are decided here, once, with one tolerance,
for every class that reports them.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = [
    "DEGENERATE_RTOL",
    "SYMMETRY_CLASSES",
    "SYMMETRY_RTOL",
    "center_of_mass",
    "is_degenerate",
    "parallel_axis",
    "particle_inertia",
    "planar_inertia",
    "polyhedron_mass_properties",
    "principal_decomposition",
    "rotate_inertia",
    "symmetry_code",
]

#: Two principal moments closer than this, relative to the largest, are equal: the body is
#: symmetric (the exact torque-free solution then takes its symmetric form).
SYMMETRY_RTOL = 1e-12
#: A smallest moment below this, relative to the largest, is zero: the body is a line.
DEGENERATE_RTOL = 1e-12
#: Names of the codes returned by :func:`symmetry_code`.
SYMMETRY_CLASSES = ("asymmetric", "prolate", "oblate", "spherical")


@kernel
def center_of_mass(masses, positions):
    """``R = Σ m_i r_i / Σ m_i``. masses (N,), positions (N, 3) → (3,)."""
    total = 0.0
    out = np.zeros(3)
    for i in range(masses.shape[0]):
        total += masses[i]
        for k in range(3):
            out[k] += masses[i] * positions[i, k]
    return out / total


@kernel
def particle_inertia(masses, offsets):
    """Inertia operator about the origin of ``offsets``, eqs (04), (13)–(15).

    ``A_jk = Σ_i m_i (|u_i|² δ_jk − u_ij u_ik)``, i.e. ``A v = Σ m_i u_i × (v × u_i)``
    (erratum corrected: the notebook prints ``v u`` for ``v × u``).

    masses (N,), offsets (N, 3) → (3, 3).
    """
    second = np.zeros((3, 3))
    for i in range(masses.shape[0]):
        for j in range(3):
            for k in range(3):
                second[j, k] += masses[i] * offsets[i, j] * offsets[i, k]
    tr = second[0, 0] + second[1, 1] + second[2, 2]
    out = -second
    for j in range(3):
        out[j, j] += tr
    return out


@kernel
def parallel_axis(inertia_com, mass, d):
    """Inertia about the point at ``d`` from the centre of mass (Huygens–Steiner).

    ``A_P = A_G + M (|d|² 𝟙 − d dᵀ)``. inertia_com (3, 3), d (3,) → (3, 3).
    """
    dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    out = inertia_com.copy()
    for j in range(3):
        for k in range(3):
            out[j, k] -= mass * d[j] * d[k]
        out[j, j] += mass * dd
    return out


@kernel
def planar_inertia(inertia):
    """Planar inertia tensor ``J' = Σ m ρ ρᵀ = ½ tr(J) 𝟙 − J`` (paper eqs (3)–(4)). (3,3)→(3,3).

    Examples
    --------
    >>> import numpy as np
    >>> np.diag(planar_inertia(np.diag([1.0, 2.0, 3.0]))).tolist()   # A' = (B + C − A)/2 …
    [2.0, 1.0, 0.0]
    """
    half = 0.5 * (inertia[0, 0] + inertia[1, 1] + inertia[2, 2])
    out = -inertia.astype(np.float64)
    for j in range(3):
        out[j, j] += half
    return out


@kernel
def rotate_inertia(inertia, R):
    """Inertia of a body rotated by ``R``: ``R J Rᵀ`` (rotation covariance). (3,3) → (3,3)."""
    return R @ inertia @ R.T


@kernel
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
    moments, vectors = np.linalg.eigh(sym)
    axes = np.ascontiguousarray(vectors)
    for j in range(2):
        biggest = 0.0
        for i in range(3):
            biggest = max(biggest, abs(axes[i, j]))
        k = 0
        while abs(axes[k, j]) < biggest - 1e-9:
            k += 1
        if axes[k, j] < 0.0:
            for i in range(3):
                axes[i, j] = -axes[i, j]
    axes[0, 2] = axes[1, 0] * axes[2, 1] - axes[2, 0] * axes[1, 1]
    axes[1, 2] = axes[2, 0] * axes[0, 1] - axes[0, 0] * axes[2, 1]
    axes[2, 2] = axes[0, 0] * axes[1, 1] - axes[1, 0] * axes[0, 1]
    return moments, axes


@kernel
def symmetry_code(moments, rtol):
    """Symmetry class of ascending principal moments, as an index into
    :data:`SYMMETRY_CLASSES`: 0 asymmetric, 1 prolate (I1 < I2 = I3), 2 oblate (I1 = I2 < I3),
    3 spherical (I1 = I3); moments are equal when they differ by at most ``rtol · I3``."""
    tol = rtol * moments[2]
    if moments[2] - moments[0] <= tol:
        return 3
    if moments[1] - moments[0] <= tol:
        return 2
    if moments[2] - moments[1] <= tol:
        return 1
    return 0


@kernel
def is_degenerate(moments, rtol):
    """True when the smallest of the ascending ``moments`` vanishes (relative ``rtol``): all
    the mass lies on one line and the spin about that line is undefined (singular ``A``)."""
    return moments[0] <= rtol * moments[2] or moments[2] == 0.0


@kernel
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
    vol6_total = 0.0
    first = np.zeros(3)
    second = np.zeros((3, 3))
    for f in range(faces.shape[0]):
        a = vertices[faces[f, 0]]
        b = vertices[faces[f, 1]]
        c = vertices[faces[f, 2]]
        vol6 = (
            a[0] * (b[1] * c[2] - b[2] * c[1])
            + a[1] * (b[2] * c[0] - b[0] * c[2])
            + a[2] * (b[0] * c[1] - b[1] * c[0])
        )
        vol6_total += vol6
        for j in range(3):
            s_j = a[j] + b[j] + c[j]
            first[j] += vol6 * s_j
            for k in range(3):
                s_k = a[k] + b[k] + c[k]
                second[j, k] += vol6 * (a[j] * a[k] + b[j] * b[k] + c[j] * c[k] + s_j * s_k)
    volume = vol6_total / 6.0
    centroid = first / (24.0 * volume)
    second = second / 120.0
    tr = second[0, 0] + second[1, 1] + second[2, 2]
    inertia_origin = -second
    for j in range(3):
        inertia_origin[j, j] += tr
    # shift from the origin to the centroid (the parallel-axis theorem, run backwards)
    return volume, centroid, parallel_axis(inertia_origin, -volume, centroid)
