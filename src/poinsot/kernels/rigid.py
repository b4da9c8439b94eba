"""Rigid-body equations of motion on plain arrays (THEORY.md §1, eqs (07)–(09)).

The flat state is the notebook's 18-vector ``y = [R (3), V (3), Q (9, row-major), ω (3)]``:
centre of mass, its velocity (space frame), attitude matrix and body angular velocity.
"""

from __future__ import annotations

import numpy as np

from .so3 import rodrigues

__all__ = [
    "STATE_SIZE",
    "axis_rotation",
    "euler_omega_dot",
    "free_rotor_step",
    "free_rotor_strang",
    "free_rotor_symmetric",
    "pack_state",
    "unpack_state",
]

STATE_SIZE = 18
# the symmetric composition H1(h/2) H2(h/2) H3(h) H2(h/2) H1(h/2), as homogeneous tuples
_STRANG_AXES = (0, 1, 2, 1, 0)
_STRANG_FRACTIONS = (0.5, 0.5, 1.0, 0.5, 0.5)


def pack_state(R, V, Q, omega):
    """Flat 18-state from ``R`` (3,), ``V`` (3,), ``Q`` (3, 3), ``omega`` (3,)."""
    y = np.empty(STATE_SIZE)
    y[0:3] = R
    y[3:6] = V
    y[6:15] = Q.reshape(9)
    y[15:18] = omega
    return y


def unpack_state(y):
    """Views ``R, V, Q, omega`` into a flat state ``y`` (..., 18)."""
    return (
        y[..., 0:3],
        y[..., 3:6],
        y[..., 6:15].reshape(*y.shape[:-1], 3, 3),
        y[..., 15:18],
    )


def euler_omega_dot(A, A_inv, omega, torque):
    """``ω̇ = A⁻¹ (τ − ω × Aω)``: Euler's equation (08) in the body frame.

    ``A_inv`` may be a pseudo-inverse for a degenerate (collinear) body, giving the minimum-norm
    ``ω̇`` (no spin acceleration about the body's line).
    """
    return A_inv @ (torque - np.cross(omega, A @ omega))


def axis_rotation(axis, angle):
    """Rotation matrix by ``angle`` about coordinate axis ``axis`` ∈ {0, 1, 2}."""
    c, s = np.cos(angle), np.sin(angle)
    R = np.eye(3)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    R[i, i] = c
    R[j, j] = c
    R[i, j] = -s
    R[j, i] = s
    return R


def free_rotor_strang(moments, pi, Qp, h):
    """Torque-free rotor advanced by ``h`` with the symmetric split of McLachlan (1993).

    In the principal frame the Hamiltonian ``H = Σ π_i²/(2 I_i)`` splits into three exactly
    solvable flows: under ``H_i`` the body momentum turns about ``e_i`` by ``−θ`` and the
    attitude by ``+θ``, ``θ = h π_i / I_i``. The composition
    ``H1(h/2) H2(h/2) H3(h) H2(h/2) H1(h/2)`` is symmetric, second order, symplectic, and keeps
    both ``|π|`` and the spatial momentum ``Qp π`` exactly (each sub-flow is a rotation).
    Axes with ``I_i = 0`` (a degenerate body's line) carry no flow.

    Parameters
    ----------
    moments : (3,) principal moments; pi : (3,) body angular momentum in principal axes;
    Qp : (3, 3) attitude of the principal frame; h : step.
    Returns the new ``(pi, Qp)``.
    """
    pi = pi.copy()
    Qp = Qp.copy()
    for k in range(5):
        axis = _STRANG_AXES[k]
        frac = _STRANG_FRACTIONS[k]
        if moments[axis] > 0:
            theta = frac * h * pi[axis] / moments[axis]
            Rot = axis_rotation(axis, theta)
            pi = Rot.T @ pi
            Qp = Qp @ Rot
    return pi, Qp


def free_rotor_symmetric(moments, pi, Qp, h, axis):
    """Exact torque-free flow of a symmetric rotor (two equal moments) over ``h``.

    With ``I_e`` the repeated moment and ``axis`` the distinct one,
    ``H = |π|²/(2 I_e) + (1/I_axis − 1/I_e) π_axis²/2``; the two terms commute and each flow is
    a rotation: about ``π`` itself by ``h|π|/I_e`` (``π`` fixed, ``Q ← Q exp(h π/I_e)``), and
    about ``e_axis`` by ``θ = h (1/I_axis − 1/I_e) π_axis``. Their product is the exact flow
    (for a spherical rotor the second term vanishes). A zero moment (a rod) has no spin flow.
    """
    Ie = moments[(axis + 1) % 3]
    Qp = Qp @ rodrigues(h * pi / Ie)
    Ia = moments[axis]
    if Ia > 0:
        theta = h * (1.0 / Ia - 1.0 / Ie) * pi[axis]
        Rot = axis_rotation(axis, theta)
        pi = Rot.T @ pi
        Qp = Qp @ Rot
    return pi.copy(), Qp


def free_rotor_step(moments, pi, Qp, h, rtol=1e-12):
    """Torque-free rotor step: exact for symmetric rotors, McLachlan's split otherwise.

    ``moments`` ascending. Returns the new ``(pi, Qp)``; see :func:`free_rotor_symmetric` and
    :func:`free_rotor_strang`.
    """
    scale = moments[2]
    if moments[1] - moments[0] <= rtol * scale and moments[0] > 0:
        return free_rotor_symmetric(moments, pi, Qp, h, 2)
    if moments[2] - moments[1] <= rtol * scale:
        return free_rotor_symmetric(moments, pi, Qp, h, 0)
    return free_rotor_strang(moments, pi, Qp, h)
