"""The memory layouts the compiled core reads, as the Python package sees them.

The state of one body is the flat 18-vector of the source notebook (``docs/theory.md`` §1,
eqs (07)–(09))::

    y = [R (3), V (3), Q (9, row-major), ω (3)]

centre of mass and its velocity (space frame), attitude (body → space) and angular velocity
(body frame). The offsets, the body's parameter vector and the codes of the built-in forces
are defined once, in the core (``crates/core/src/layout.rs``, ``forces.rs``), and read from it
here; everything in Python that reads or writes a state uses these names, never literal
numbers.

Examples
--------
>>> import numpy as np
>>> y = pack_state(np.zeros(3), np.ones(3), np.eye(3), np.full(3, 2.0))
>>> R, V, Q, w = unpack_state(y)
>>> Q.shape, w.tolist()
((3, 3), [2.0, 2.0, 2.0])
"""

from __future__ import annotations

import numpy as np

from . import _core

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
    "pack_state",
    "unpack_state",
]

STATE_SIZE: int = _core.STATE_SIZE
R_AT: int = _core.R_AT
V_AT: int = _core.V_AT
Q_AT: int = _core.Q_AT
OMEGA_AT: int = _core.OMEGA_AT
# The body's parameter vector (BODY_SIZE numbers, ``crates/core/src/layout.rs``), offsets of:
MASS: int = _core.MASS  # M
INV_MASS: int = _core.INV_MASS  # 1/M
MOMENTS: int = _core.MOMENTS  # the principal moments about the reference point (3)
INV_MOMENTS: int = _core.INV_MOMENTS  # their inverses (3), zero where a moment is zero
COM_OFFSET: int = _core.COM_OFFSET  # c, centre of mass − reference point (3)
INERTIA_COM: int = _core.INERTIA_COM  # the inertia about the centre of mass (9, row-major)
PIVOT: int = _core.PIVOT  # the fixed point in space (3)
HAS_PIVOT: int = _core.HAS_PIVOT  # 1.0 when the body turns about a fixed point
ROTOR: int = _core.ROTOR  # the free-rotor flow: −1 asymmetric, k symmetric about axis k
BODY_SIZE: int = _core.BODY_SIZE
FORCE_PARAMS: int = _core.FORCE_PARAMS
#: Built-in force kinds: name → code.
FORCE_KINDS: dict[str, int] = dict(_core.FORCE_KINDS)

#: Named blocks of a state, for NumPy code: ``y[..., STATE_SLICES["omega"]]``.
STATE_SLICES = {
    "R": slice(R_AT, R_AT + 3),
    "V": slice(V_AT, V_AT + 3),
    "Q": slice(Q_AT, Q_AT + 9),
    "omega": slice(OMEGA_AT, OMEGA_AT + 3),
}


def pack_state(R, V, Q, omega) -> np.ndarray:
    """The flat state (..., 18) from ``R``, ``V``, ``omega`` (..., 3) and ``Q`` (..., 3, 3)."""
    omega = np.asarray(omega, dtype=float)
    y = np.empty((*omega.shape[:-1], STATE_SIZE))
    y[..., STATE_SLICES["R"]] = R
    y[..., STATE_SLICES["V"]] = V
    y[..., STATE_SLICES["Q"]] = np.asarray(Q, dtype=float).reshape(*omega.shape[:-1], 9)
    y[..., STATE_SLICES["omega"]] = omega
    return y


def unpack_state(y):
    """Views ``R, V, Q, omega`` of states ``y`` (..., 18); ``Q`` has shape (..., 3, 3)."""
    y = np.asarray(y)
    s = STATE_SLICES
    return (
        y[..., s["R"]],
        y[..., s["V"]],
        y[..., s["Q"]].reshape(*y.shape[:-1], 3, 3),
        y[..., s["omega"]],
    )
