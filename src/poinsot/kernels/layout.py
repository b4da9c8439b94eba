"""Memory layouts shared by every module: the rigid-body state, the body's parameters as the
compiled engine reads them, and the lowered forces.

The state of one body is the flat 18-vector of the source notebook (``docs/theory.md`` §1,
eqs (07)–(09))::

    y = [R (3), V (3), Q (9, row-major), ω (3)]

centre of mass and its velocity (space frame), attitude (body → space) and angular velocity
(body frame). Everything that reads or writes a state uses the offsets and slices below, never
literal numbers.

Inside the compiled engine the same layout is used in the body's *principal* frame (the frame
of the principal axes of the inertia about the reference point: the centre of mass, or the
pivot): ``Q`` then maps principal axes to space and ω has principal components, so Euler's
equation takes the component form (27)–(29). :mod:`poinsot.kernels.rigid` converts between the
two frames.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = [
    "BODY_SIZE",
    "COM_OFFSET",
    "FORCE_KINDS",
    "FORCE_PARAMS",
    "HAS_PIVOT",
    "INERTIA_COM",
    "INV_MASS",
    "INV_MOMENTS",
    "MASS",
    "MOMENTS",
    "OMEGA_AT",
    "PIVOT",
    "Q_AT",
    "ROTOR",
    "R_AT",
    "STATE_SIZE",
    "STATE_SLICES",
    "V_AT",
    "body_vector",
    "load_state",
    "pack_state",
    "store_state",
    "unpack_state",
]

# ------------------------------------------------------------------ the 18-component state
STATE_SIZE = 18
R_AT = 0  #: centre of mass, space frame (3)
V_AT = 3  #: its velocity (3)
Q_AT = 6  #: attitude, row-major (9)
OMEGA_AT = 15  #: angular velocity, body (or principal) frame (3)

#: Named blocks of a state, for NumPy code: ``y[..., STATE_SLICES["omega"]]``.
STATE_SLICES = {
    "R": slice(R_AT, R_AT + 3),
    "V": slice(V_AT, V_AT + 3),
    "Q": slice(Q_AT, Q_AT + 9),
    "omega": slice(OMEGA_AT, OMEGA_AT + 3),
}

# ------------------------------------------------------------------ body parameters
# One float vector per body, in the principal frame of the inertia about the reference point.
MASS = 0  #: M
INV_MASS = 1  #: 1/M
MOMENTS = 2  #: principal moments about the reference point (3), zero on a degenerate line
INV_MOMENTS = 5  #: their inverses (3), zero where the moment is zero (minimum-norm ω̇)
COM_OFFSET = 8  #: c = centre of mass − reference point (3); zero for a free body
INERTIA_COM = 11  #: inertia about the centre of mass (9, row-major; gravity gradient)
PIVOT = 20  #: the fixed point in space (3), with a pivot
HAS_PIVOT = 23  #: 1.0 when the body turns about a fixed point, else 0.0
ROTOR = 24  #: free-rotor flow: -1 asymmetric, k in {0, 2} symmetric about axis k, 3 spherical
BODY_SIZE = 25

# ------------------------------------------------------------------ lowered forces
#: Parameters per lowered force (rows of ``force_params``); see :mod:`poinsot.kernels.forces`.
FORCE_PARAMS = 10
#: Built-in force kinds: name → code of ``force_kind``.
FORCE_KINDS = {
    "gravity": 1,
    "central_gravity": 2,
    "spring": 3,
    "linear_drag": 4,
    "quadratic_drag": 5,
    "point_force": 6,
    "torque": 7,
}


@kernel
def pack_state(R, V, Q, omega):
    """The flat state from ``R`` (3,), ``V`` (3,), ``Q`` (3, 3) and ``omega`` (3,) → (18,).

    Examples
    --------
    >>> import numpy as np
    >>> pack_state(np.zeros(3), np.ones(3), np.eye(3), np.full(3, 2.0))[15:].tolist()
    [2.0, 2.0, 2.0]
    """
    y = np.empty(STATE_SIZE)
    for i in range(3):
        y[R_AT + i] = R[i]
        y[V_AT + i] = V[i]
        y[OMEGA_AT + i] = omega[i]
        for j in range(3):
            y[Q_AT + 3 * i + j] = Q[i, j]
    return y


def unpack_state(y):
    """Views ``R, V, Q, omega`` of states ``y`` (..., 18); ``Q`` has shape (..., 3, 3).

    (Plain NumPy, not compiled: it returns views for any number of leading axes.)
    """
    y = np.asarray(y)
    s = STATE_SLICES
    return (
        y[..., s["R"]],
        y[..., s["V"]],
        y[..., s["Q"]].reshape(*y.shape[:-1], 3, 3),
        y[..., s["omega"]],
    )


@kernel
def body_vector(mass, moments, com_offset, inertia_com, pivot, has_pivot, rotor):
    """The body parameter vector (BODY_SIZE,) from its parts (all in the principal frame of
    the inertia about the reference point): ``mass``, ascending principal ``moments`` (3,),
    ``com_offset`` (3,) the centre of mass from the reference point, ``inertia_com`` (3, 3)
    about the centre of mass, ``pivot`` (3,) the fixed point in space (used when ``has_pivot``)
    and the free-rotor ``rotor`` code. Inverse moments are 0 where a moment is 0."""
    out = np.zeros(BODY_SIZE)
    out[MASS] = mass
    out[INV_MASS] = 1.0 / mass
    for k in range(3):
        out[MOMENTS + k] = moments[k]
        out[INV_MOMENTS + k] = 1.0 / moments[k] if moments[k] != 0.0 else 0.0
        out[COM_OFFSET + k] = com_offset[k]
        out[PIVOT + k] = pivot[k]
        for j in range(3):
            out[INERTIA_COM + 3 * k + j] = inertia_com[k, j]
    out[HAS_PIVOT] = 1.0 if has_pivot else 0.0
    out[ROTOR] = rotor
    return out


@kernel(inline=True)
def load_state(z, lane, lanes):
    """The 18-component state of member ``lane`` of a chunk of ``lanes`` members stored
    component-major (``z[c · lanes + lane]``; one body: ``lanes = 1``), as a tuple of scalars
    (the fixed-step engine steps it in registers)."""
    return (
        z[0 * lanes + lane],
        z[1 * lanes + lane],
        z[2 * lanes + lane],
        z[3 * lanes + lane],
        z[4 * lanes + lane],
        z[5 * lanes + lane],
        z[6 * lanes + lane],
        z[7 * lanes + lane],
        z[8 * lanes + lane],
        z[9 * lanes + lane],
        z[10 * lanes + lane],
        z[11 * lanes + lane],
        z[12 * lanes + lane],
        z[13 * lanes + lane],
        z[14 * lanes + lane],
        z[15 * lanes + lane],
        z[16 * lanes + lane],
        z[17 * lanes + lane],
    )


@kernel(inline=True)
def store_state(z, lane, lanes, y):
    """Write the 18-tuple ``y`` as member ``lane`` of a component-major chunk ``z``."""
    z[0 * lanes + lane] = y[0]
    z[1 * lanes + lane] = y[1]
    z[2 * lanes + lane] = y[2]
    z[3 * lanes + lane] = y[3]
    z[4 * lanes + lane] = y[4]
    z[5 * lanes + lane] = y[5]
    z[6 * lanes + lane] = y[6]
    z[7 * lanes + lane] = y[7]
    z[8 * lanes + lane] = y[8]
    z[9 * lanes + lane] = y[9]
    z[10 * lanes + lane] = y[10]
    z[11 * lanes + lane] = y[11]
    z[12 * lanes + lane] = y[12]
    z[13 * lanes + lane] = y[13]
    z[14 * lanes + lane] = y[14]
    z[15 * lanes + lane] = y[15]
    z[16 * lanes + lane] = y[16]
    z[17 * lanes + lane] = y[17]
