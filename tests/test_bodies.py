"""RigidBody: the notebook's examples, primitives, composition, display, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import RigidBody
from poinsot._core import exp_so3, matrix_to_quat


def test_notebook_worked_example():
    # docs/theory.md §1 worked example (with the erratum e3 = (0,0,1), not (0,0,1)/√2).
    body = RigidBody.from_particles([1, 1, 1], [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    np.testing.assert_allclose(body.center_of_mass, [1 / 3, 1 / 3, 0], atol=1e-15)
    np.testing.assert_allclose(
        body.inertia, [[2 / 3, 1 / 3, 0], [1 / 3, 2 / 3, 0], [0, 0, 4 / 3]], atol=1e-15
    )
    np.testing.assert_allclose(body.principal_moments, [1 / 3, 1, 4 / 3], rtol=1e-14)
    expected = [np.array([-1, 1, 0]) / np.sqrt(2), np.array([1, 1, 0]) / np.sqrt(2), [0, 0, 1]]
    for j, e in enumerate(expected):
        assert abs(abs(body.principal_axes[:, j] @ e) - 1) < 1e-14
    # the documented sign rule: largest component positive for e1, e2; e3 = e1 × e2
    np.testing.assert_allclose(body.principal_axes[:, 0], [1 / np.sqrt(2), -1 / np.sqrt(2), 0])
    np.testing.assert_allclose(body.principal_axes[:, 2], [0, 0, 1], atol=1e-15)
    assert body.symmetry == "asymmetric"
    np.testing.assert_allclose(body.particle_masses @ body.u, 0, atol=1e-15)


def test_notebook_27_particle_body(notebook_body):
    # docs/theory.md §1: principal moments 25/3, 50/3, 65/3.
    np.testing.assert_allclose(
        notebook_body.principal_moments, [25 / 3, 50 / 3, 65 / 3], rtol=1e-12
    )
    np.testing.assert_allclose(notebook_body.center_of_mass, [0.5, 1, 1.5], rtol=1e-14)
    assert notebook_body.mass == pytest.approx(10)
    assert notebook_body.n_particles == 27


def test_principal_axes_orthonormal_right_handed(notebook_body):
    E = notebook_body.principal_axes
    np.testing.assert_allclose(E.T @ E, np.eye(3), atol=1e-14)
    assert np.linalg.det(E) == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(
        E @ np.diag(notebook_body.principal_moments) @ E.T, notebook_body.inertia, atol=1e-12
    )


def test_mass_properties_constructor_and_inertia_about():
    J = np.diag([1.0, 2.0, 2.5])
    body = RigidBody(2.0, J, center_of_mass=(1, 0, 0))
    # about the origin, offset d = (−1, 0, 0): adds M(|d|² 𝟙 − d dᵀ) = 2 diag(0, 1, 1)
    np.testing.assert_allclose(body.inertia_about((0, 0, 0)), np.diag([1.0, 4.0, 4.5]))
    assert body.moment_of_inertia((0, 0, 5)) == pytest.approx(2.5)
    assert body.moment_of_inertia((0, 1, 0), point=(0, 0, 0)) == pytest.approx(4.0)
    assert not body.has_particles
    with pytest.raises(AttributeError, match="only for bodies built from particles"):
        body.u


def test_planar_inertia_matches_particle_sum(notebook_body):
    rho = notebook_body.u
    m = notebook_body.particle_masses
    direct = (m[:, None, None] * rho[:, :, None] * rho[:, None, :]).sum(0)  # Σ m ρ ρᵀ, eq. (3)
    np.testing.assert_allclose(notebook_body.planar_inertia, direct, atol=1e-12)
    # principal-axis form (4): A' = (B + C − A)/2 etc.
    A, B, C = notebook_body.principal_moments
    E = notebook_body.principal_axes
    np.testing.assert_allclose(
        np.diag(E.T @ notebook_body.planar_inertia @ E),
        [(B + C - A) / 2, (C + A - B) / 2, (A + B - C) / 2],
        atol=1e-12,
    )


# --------------------------------------------------------------------------- primitives
def _grid_body(inside, lo, hi, n, mass):
    """Equal-mass particles at the midpoints of an n³ grid cells inside a solid."""
    axes = [lo[k] + (np.arange(n) + 0.5) * (hi[k] - lo[k]) / n for k in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    pts = pts[inside(pts)]
    return RigidBody.from_particles(np.full(len(pts), mass / len(pts)), pts)


def _fibonacci_sphere(n, r):
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (1 + 5**0.5) * k
    s = np.sqrt(1 - z * z)
    return r * np.column_stack([s * np.cos(phi), s * np.sin(phi), z])


SOLIDS = {
    # name: (closed-form body, inside(points), bounding box lo, hi)
    "box": (
        lambda: RigidBody.box(3.0, (1.0, 2.0, 0.5)),
        lambda p: np.ones(len(p), bool),
        (-0.5, -1, -0.25),
        (0.5, 1, 0.25),
    ),
    "sphere": (
        lambda: RigidBody.sphere(2.0, 1.5),
        lambda p: (p**2).sum(1) <= 1.5**2,
        (-1.5,) * 3,
        (1.5,) * 3,
    ),
    "cylinder": (
        lambda: RigidBody.cylinder(2.0, 0.5, 3.0),
        lambda p: p[:, 0] ** 2 + p[:, 1] ** 2 <= 0.25,
        (-0.5, -0.5, -1.5),
        (0.5, 0.5, 1.5),
    ),
    "ellipsoid": (
        lambda: RigidBody.ellipsoid(2.0, (1.0, 2.0, 3.0)),
        lambda p: (p[:, 0] / 1) ** 2 + (p[:, 1] / 2) ** 2 + (p[:, 2] / 3) ** 2 <= 1,
        (-1, -2, -3),
        (1, 2, 3),
    ),
    "cone": (  # base disc at z = 0, apex at z = h = 2, radius 1
        lambda: RigidBody.cone(2.0, 1.0, 2.0),
        lambda p: np.sqrt(p[:, 0] ** 2 + p[:, 1] ** 2) <= 1.0 * (1 - p[:, 2] / 2.0),
        (-1, -1, 0),
        (1, 1, 2),
    ),
}


@pytest.mark.parametrize("name", sorted(SOLIDS))
def test_primitive_against_converging_discretisation(name):
    make, inside, lo, hi = SOLIDS[name]
    exact = make()
    errors = []
    for n in (16, 32, 64):
        approx = _grid_body(inside, lo, hi, n, exact.mass)
        errors.append(np.max(np.abs(approx.inertia - exact.inertia)) / exact.principal_moments[2])
    assert errors[-1] < 2e-2
    assert errors[2] < errors[0], errors  # converging
    if name == "cone":
        # the centre of mass of the cone sits h/4 above its base
        assert approx.center_of_mass[2] == pytest.approx(0.5, rel=2e-2)


def test_box_exact_closed_form():
    # Meriam & Kraige, Appendix B: I_xx = m(b² + c²)/12
    body = RigidBody.box(12.0, (1.0, 2.0, 3.0))
    np.testing.assert_allclose(body.inertia, np.diag([13.0, 10.0, 5.0]))
    # a midpoint grid on a box converges as 1 − 1/n² per axis: exactly computable
    n = 10
    approx = _grid_body(lambda p: np.ones(len(p), bool), (-0.5, -1, -1.5), (0.5, 1, 1.5), n, 12)
    a2 = np.array([1.0, 4.0, 9.0]) * (1 - 1 / n**2)
    np.testing.assert_allclose(
        np.diag(approx.inertia), [a2[1] + a2[2], a2[0] + a2[2], a2[0] + a2[1]], rtol=1e-12
    )


def test_spherical_shell_against_fibonacci_points():
    exact = RigidBody.spherical_shell(3.0, 2.0)
    errs = []
    for n in (200, 2000, 20000):
        p = _fibonacci_sphere(n, 2.0)
        approx = RigidBody.from_particles(np.full(n, 3.0 / n), p)
        errs.append(np.max(np.abs(approx.inertia - exact.inertia)))
    assert errs[-1] < 1e-3 * exact.principal_moments[0]
    assert errs[2] < errs[0]
    assert exact.symmetry == "spherical"


def test_rod_is_degenerate_and_matches_midpoint_rule():
    rod = RigidBody.rod(2.0, 3.0)
    assert rod.is_degenerate
    assert rod.symmetry == "prolate"
    np.testing.assert_allclose(rod.principal_moments, [0, 1.5, 1.5], atol=1e-15)
    n = 50
    z = (np.arange(n) + 0.5) / n * 3.0
    pts = np.column_stack([np.zeros(n), np.zeros(n), z])
    approx = RigidBody.from_particles(np.full(n, 2.0 / n), pts)
    assert approx.is_degenerate
    # midpoint rule: Σ (l/n)(z − l/2)² = l³/12 (1 − 1/n²)
    np.testing.assert_allclose(approx.inertia[0, 0], 1.5 * (1 - 1 / n**2), rtol=1e-12)


def test_symmetry_classes():
    assert RigidBody.cylinder(1, 1, 10).symmetry == "prolate"
    assert RigidBody.cylinder(1, 1, 0.1).symmetry == "oblate"
    assert RigidBody.sphere(1, 1).symmetry == "spherical"
    assert RigidBody.box(1, (1, 2, 3)).symmetry == "asymmetric"
    almost = RigidBody(1.0, np.diag([1.0, 1.0 + 1e-6, 1.5]))
    assert almost.symmetry == "asymmetric"
    assert almost.classify_symmetry(rtol=1e-5) == "oblate"


def test_placement_rotates_inertia_and_moves_center():
    R = exp_so3([0.3, -0.2, 0.9])
    body = RigidBody.box(2.0, (1, 2, 3), position=(1, 2, 3), orientation=R)
    local = RigidBody.box(2.0, (1, 2, 3))
    np.testing.assert_allclose(body.inertia, R @ local.inertia @ R.T, atol=1e-14)
    np.testing.assert_allclose(body.center_of_mass, [1, 2, 3])
    by_quat = RigidBody.box(2.0, (1, 2, 3), orientation=matrix_to_quat(R))
    np.testing.assert_allclose(by_quat.inertia, body.inertia, atol=1e-14)
    np.testing.assert_allclose(body.principal_moments, local.principal_moments, rtol=1e-13)


def test_compose_box_from_two_halves():
    half_a = RigidBody.box(1.0, (1, 2, 1.5), position=(0, 0, -0.75))
    half_b = RigidBody.box(1.0, (1, 2, 1.5), position=(0, 0, 0.75))
    whole = RigidBody.compose([half_a, half_b])
    np.testing.assert_allclose(whole.inertia, RigidBody.box(2.0, (1, 2, 3)).inertia, atol=1e-14)
    np.testing.assert_allclose(whole.center_of_mass, 0, atol=1e-15)
    assert not whole.has_particles


def test_compose_particles_keeps_particles(notebook_body):
    parts = [
        (m, r)
        for m, r in zip(
            notebook_body.particle_masses, notebook_body.particle_positions, strict=False
        )
    ]
    body = RigidBody.compose(parts)
    assert body.n_particles == 27
    np.testing.assert_allclose(body.inertia, notebook_body.inertia, atol=1e-13)


def test_repr_and_html(notebook_body):
    text = repr(notebook_body)
    assert "RigidBody(mass=10" in text and "particles=27" in text and "8.333333" in text
    html = notebook_body._repr_html_()
    assert html.startswith("<table>") and "principal moments" in html
    import re

    units = dict(re.findall(r"<th style='text-align:left'>([^<]+)</th><td>.*?</td>"
                            r"<td style='color:#555'>([^<]*)</td>", html))  # fmt: skip
    assert units["mass"] == "kg" and units["centre of mass (body frame)"] == "m"
    assert units["principal moments I₁ ≤ I₂ ≤ I₃"] == "kg·m²"  # issue 43: no units before


def test_arrays_are_read_only(notebook_body):
    with pytest.raises(ValueError, match="read-only"):
        notebook_body.inertia[0, 0] = 1.0


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("masses", "positions", "match"),
    [
        ([1, -1, 1], np.zeros((3, 3)), r"`masses\[1\]` must be a positive number, found -1"),
        ([1, 0], np.zeros((2, 3)), r"`masses\[1\]` must be a positive number"),
        ([1, np.nan], np.zeros((2, 3)), r"`masses\[1\]` must be finite"),
        ([1, 1], [[0, 0, 0], [0, np.inf, 0]], r"`positions\[1\]\[1\]` must be finite"),
        ([], np.zeros((0, 3)), "at least one particle, found N = 0"),
        ([1, 1], np.zeros((3, 3)), "same length, found 2 and 3"),
        ([1, 1], np.zeros((2, 2)), r"`positions` must have shape \(N, 3\), found shape \(2, 2\)"),
        ([[1, 1]], np.zeros((2, 3)), r"`masses` must have shape \(N,\)"),
        (1.0, np.zeros((1, 3)), r"`masses` must have shape \(N,\), found shape \(\)"),
        ("abc", np.zeros((1, 3)), "`masses` must be numeric"),
    ],
)
def test_from_particles_bad_input(masses, positions, match):
    with pytest.raises((ValueError, TypeError), match=match):
        RigidBody.from_particles(masses, positions)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((0.0, np.eye(3)), "`mass` must be a positive number, found 0"),
        ((np.inf, np.eye(3)), "`mass` must be finite"),
        ((True, np.eye(3)), "`mass` must be a real number"),
        ((1.0, np.eye(2)), r"`inertia` must have shape \(3, 3\)"),
        ((1.0, [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]), "`inertia` must be symmetric"),
        ((1.0, np.diag([-1.0, 1, 1])), "positive semi-definite"),
        ((1.0, np.diag([1.0, 1, 3])), r"I1 \+ I2 ≥ I3"),
        ((1.0, np.eye(3), (0, 0)), r"`center_of_mass` must have shape \(3,\)"),
    ],
)
def test_constructor_bad_input(args, match):
    with pytest.raises((ValueError, TypeError), match=match):
        RigidBody(*args)


@pytest.mark.parametrize(
    ("orientation", "match"),
    [
        (np.diag([1.0, 1, -1]), r"not a rotation: needs RᵀR = I and det R = \+1"),
        (2 * np.eye(3), "not a rotation"),
        ([1.0, 0, 0, 0.5], "quaternion .* has norm 1.118"),
        ([1.0, 0, 0], r"`orientation` must be a 3×3 rotation matrix or a unit quaternion"),
    ],
)
def test_non_rotation_orientation_refused(orientation, match):
    with pytest.raises(ValueError, match=match):
        RigidBody.box(1.0, (1, 1, 1), orientation=orientation)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: RigidBody.box(1.0, (1, 0, 1)), r"`size\[1\]` must be a positive number"),
        (lambda: RigidBody.sphere(1.0, -2), "`radius` must be a positive number"),
        (lambda: RigidBody.cylinder(1.0, 1, 0), "`height` must be a positive number"),
        (lambda: RigidBody.ellipsoid(1.0, (1, 2)), r"`semi_axes` must have shape \(3,\)"),
        (lambda: RigidBody.rod(-1.0, 1), "`mass` must be a positive number"),
        (lambda: RigidBody.cone(1.0, 1, np.nan), "`height` must be finite"),
        (lambda: RigidBody.box(1, (1, 1, 1), position=(0, 0)), "`position` must have shape"),
        (lambda: RigidBody.compose([]), "at least one body"),
        (lambda: RigidBody.compose([RigidBody.sphere(1, 1), "x"]), r"`parts\[1\]` must be"),
        (lambda: RigidBody.compose([(1.0, (0, 0, 0)), (-1, (1, 0, 0))]), r"parts\[1\] mass"),
        (lambda: RigidBody.sphere(1, 1).moment_of_inertia((0, 0, 0)), "non-zero vector"),
    ],
)
def test_other_bad_input(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_mass_properties_dict(notebook_body):
    import json

    info = notebook_body.mass_properties()
    assert json.loads(json.dumps(info)) == info  # JSON-ready
    np.testing.assert_allclose(info["principal_moments"], [25 / 3, 50 / 3, 65 / 3], rtol=1e-12)
    assert info["particles"] == 27 and info["symmetry"] == "asymmetric"
    assert info["degenerate"] is False
