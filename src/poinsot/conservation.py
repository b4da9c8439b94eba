"""The constants of the motion of a rigid-body problem, and their values along a trajectory.

Which quantities a problem conserves follows from its forces and its constraint, not from
the integrator (``docs/theory.md``, "Conservation laws"):

* **total energy** ``E = K + U`` (eq. (12) plus the potentials) when every force is
  conservative (:attr:`poinsot.forces.Force.conservative`);
* **angular momentum about the centre of mass** ``L_G = Q A ω`` (the first term of eq. (03)),
  as a spatial vector and as its length ``|L_G|``, when no force has a torque about the centre
  of mass: no force, or uniform gravity on a free body (or on a body held at its centre of
  mass). The rotational energy ``½ ω·Aω`` (eq. (30)) is then conserved by itself;
* **linear momentum** ``M Ṙ`` of a free body with no force at all;
* **angular momentum about a fixed pivot** ``L_P = Q A ω + M (R − P) × Ṙ`` (eq. (03) about
  ``P``) with no force; with uniform gravity only its **vertical component** ``L_P·ĝ``
  (the torque of gravity about the pivot is horizontal) and, for a **symmetric top** (two
  equal moments about the pivot, the centre of mass on the other axis, the symmetry axis
  ``a``), also ``L_P·a = C ω·a`` (Euler–Lagrange top);
* **angular momentum about the attracting centre** (orbit plus spin) under one
  :class:`~poinsot.forces.CentralGravity`, whose force and gravity-gradient torque derive
  from one potential that is invariant under rotations about the centre.

Every value is computed by the compiled core (``poinsot._core``); this module only
decides which of them the problem conserves and says why.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._bindings import invariants as core_invariants

__all__ = [
    "Invariant",
    "angular_momentum_body",
    "invariants_of",
    "orthogonality_error",
    "rotational_energy",
]

#: Two moments about the pivot are equal (a symmetric top) when they differ by at most this
#: fraction of the largest: looser than the body's symmetry class, since the moments about a
#: pivot come through the parallel-axis shift and carry its rounding.
TOP_RTOL = 1e-9


def _c(a):
    return np.ascontiguousarray(a, dtype=float)


def _momentum_com(A, Q, w):
    """``Q A ω`` per sample (n, 3): the angular momentum about the centre of mass, space frame."""
    return core_invariants.angular_momenta(_c(A), _c(w).reshape(-1, 3), _c(Q).reshape(-1, 3, 3))


def _momentum(A, M, R, V, Q, w):
    """``Q A ω + M R × V`` per sample (n, 3), eq. (03)."""
    return core_invariants.angular_momenta(
        _c(A), _c(w).reshape(-1, 3), _c(Q).reshape(-1, 3, 3), float(M),
        _c(R).reshape(-1, 3), _c(V).reshape(-1, 3),
    )  # fmt: skip


def rotational_energy(inertia, omega) -> np.ndarray:
    """The rotational kinetic energy ``½ ω·Aω`` (eq. (30)) of body-frame ω (..., 3) with the
    inertia ``A`` (3, 3) about the same point, in J: an array of shape (...).

    Examples
    --------
    >>> float(rotational_energy(np.diag([1.0, 2.0, 3.0]), [1.0, 1.0, 1.0]))
    3.0
    """
    w = np.asarray(omega, dtype=float)
    return core_invariants.rotational_energies(_c(inertia), _c(w).reshape(-1, 3)).reshape(
        w.shape[:-1]
    )


def angular_momentum_body(inertia, omega) -> np.ndarray:
    """The angular momentum ``A ω`` (eq. (03), the body's own part) in the body frame, in
    kg m²/s: (..., 3) for ω (..., 3).

    Examples
    --------
    >>> angular_momentum_body(np.diag([1.0, 2.0, 3.0]), [1.0, 1.0, 1.0]).tolist()
    [1.0, 2.0, 3.0]
    """
    w = np.asarray(omega, dtype=float)
    return core_invariants.angular_momenta(_c(inertia), _c(w).reshape(-1, 3)).reshape(w.shape)


def orthogonality_error(Q) -> np.ndarray:
    """``max |QᵀQ − I|`` of attitude matrices Q (..., 3, 3): how far each is from SO(3).

    Examples
    --------
    >>> float(orthogonality_error(np.eye(3)))
    0.0
    """
    Q = np.asarray(Q, dtype=float)
    return core_invariants.orthogonality_errors(_c(Q).reshape(-1, 3, 3)).reshape(Q.shape[:-2])


_rotational_energy = rotational_energy


@dataclass(frozen=True)
class Invariant:
    """One quantity of a motion, with whether the problem conserves it.

    Attributes
    ----------
    name : str
        What it is, in words ("total energy", "L about the pivot · vertical").
    symbol : str
        A short label for legends ("E", "L_P·ĝ").
    unit : str
        SI unit of the values ("J", "kg·m²/s").
    values : ndarray, shape (n,) or (n, 3)
        The quantity at each sample (vectors in the space frame).
    conserved : bool
        True when the problem conserves it (whatever the integrator does).
    reason : str
        Why it is (or is not) conserved.
    scale : float
        The size its change is measured against (``|value(0)|``, or a natural scale of the
        problem when that is zero).
    """

    name: str
    symbol: str
    unit: str
    values: np.ndarray
    conserved: bool
    reason: str
    scale: float

    @property
    def change(self) -> np.ndarray:
        """Relative change ``|x(t) − x(0)| / scale`` per sample (n,): the integrator's error
        when :attr:`conserved`, the physics otherwise. Divided before subtracting, so values
        near the double range do not overflow; a value that is itself infinite gives NaN."""
        v = np.asarray(self.values, dtype=float)
        scale = self.scale if np.isfinite(self.scale) and self.scale else 1.0
        with np.errstate(invalid="ignore", over="ignore"):
            d = v / scale - v[0] / scale
            return np.abs(d) if d.ndim == 1 else _row_norms(d)

    def describe(self) -> dict:
        """JSON-ready: unit, initial value, largest change, whether it is conserved and why.

        ``max_change`` is the largest ``|x(t) − x(0)|`` in :attr:`unit`; ``max_relative_change``
        is that over ``|x(0)|``, or None when ``x(0) = 0`` (a relative change of a zero
        reference means nothing: the absolute change says it, with its unit)."""
        v0 = np.asarray(self.values[0], dtype=float)
        change = self.change
        zero = not np.any(v0)
        scale = self.scale if np.isfinite(self.scale) and self.scale else 1.0
        with np.errstate(over="ignore"):
            absolute = float(change.max() * scale)
        return {
            "symbol": self.symbol,
            "unit": self.unit,
            "initial": v0.tolist() if v0.ndim else float(v0),
            "max_change": absolute,
            "max_relative_change": None if zero else float(change.max()),
            "expected_conserved": self.conserved,
            "reason": self.reason,
        }


def change_text(described: dict) -> str:
    """``"E 1.2e-09 (relative)"`` or, for a zero initial value, ``"h 6.4e-10 J (absolute;
    h(0) = 0)"``: the largest change of an invariant as :meth:`Invariant.describe` gives it."""
    sym, rel = described["symbol"], described["max_relative_change"]
    if rel is not None:
        return f"{sym} {rel:.2e} (relative)"
    return f"{sym} {described['max_change']:.2e} {described['unit']} (absolute; {sym}(0) = 0)"


def _row_norms(V):
    """``|V_i|`` per row (n,), without overflow near the double range (``hypot``)."""
    return np.hypot.reduce(np.asarray(V, dtype=float), axis=1)


def _norm_scale(v0):
    """The scale of a vector quantity: ``|v(0)|`` without overflow near 1e300."""
    return float(np.hypot.reduce(np.asarray(v0, dtype=float)))


def _symmetry_axis(system):
    """The body-frame unit symmetry axis ``a`` of a symmetric top about the pivot (two equal
    moments about the pivot and the centre of mass on the other axis), or None."""
    axis = core_invariants.symmetric_top_axis(  # the one criterion of a symmetric top (tops.rs)
        [float(x) for x in system.principal_moments],
        np.asarray(system.principal_axes, float).tolist(),
        [float(x) for x in system.c],
        TOP_RTOL,
    )
    return None if axis is None else np.array(axis)


#: The name and SI unit of each quantity :func:`invariants_of` can report, by symbol.
_QUANTITIES = {
    "E": ("total energy", "J"),
    "L_G": ("angular momentum about the centre of mass (space frame)", "kg·m²/s"),
    "|L_G|": ("|angular momentum| about the centre of mass", "kg·m²/s"),
    "K_rot": ("rotational energy ½ ω·Aω", "J"),
    "p": ("linear momentum M Ṙ", "kg·m/s"),
    "L_P": ("angular momentum about the pivot (space frame)", "kg·m²/s"),
    "L_P·ĝ": ("angular momentum about the pivot · vertical", "kg·m²/s"),
    "L_P·a": ("angular momentum about the pivot · symmetry axis", "kg·m²/s"),
    "L_O": ("angular momentum about the attracting centre (orbit + spin)", "kg·m²/s"),
}


def _invariant(symbol, values, conserved, reason, scale) -> Invariant:
    """The :class:`Invariant` ``symbol``, its name and unit taken from :data:`_QUANTITIES`."""
    name, unit = _QUANTITIES[symbol]
    return Invariant(name, symbol, unit, values, conserved, reason, scale)


def _energy(traj, conservative) -> Invariant:
    """The total energy, conserved when every force is conservative."""
    E = np.asarray(traj.total_energy)
    return _invariant(
        "E",
        E,
        conservative,
        "every force has a potential and none dissipates"
        if conservative
        else "a force does work that no potential accounts for (drag, a torque, damping)",
        float(abs(E[0])) or float(np.abs(traj.kinetic_energy).max()),
    )


def _about_com(motion, E, uniform, free) -> list[Invariant]:
    """What no torque about the centre of mass conserves: ``L_G``, ``|L_G|``, ``K_rot`` and,
    for a ``free`` body with no force, the linear momentum ``p``."""
    A, M, R, V, Q, w = motion
    L = _momentum_com(A, Q, w)
    why = "no force has a torque about the centre of mass" + (
        " (uniform gravity acts at it)" if uniform else ""
    )
    scale = _norm_scale(L[0])
    k = _rotational_energy(A, w)
    out = [
        _invariant("L_G", L, True, why, scale),
        _invariant("|L_G|", _row_norms(L), True, why, scale),
        _invariant("K_rot", k, True, why, float(k[0]) or float(np.abs(E[0])) or 1.0),
    ]
    if free:
        P = M * V
        scale = _norm_scale(P[0]) or M * float(np.abs(R).max() or 1.0)
        out.append(_invariant("p", P, True, "no force acts", scale))
    return out


def _about_pivot(traj, motion, g, uniform) -> list[Invariant]:
    """The momenta about a fixed pivot with no force or uniform gravity ``g`` only."""
    A, M, R, V, Q, w = motion
    system = traj.system
    point = system.pivot_point(traj.state[0])
    L = _momentum(A, M, R - point, V, Q, w)
    scale = _norm_scale(L[0])
    if not uniform or not np.any(g):
        why = "no force acts; the pivot's reaction has no moment about it"
        return [_invariant("L_P", L, True, why, scale)]
    down = g / np.linalg.norm(g)
    why = "gravity's torque about the pivot is horizontal"
    out = [_invariant("L_P·ĝ", L @ down, True, why, scale)]
    axis = _symmetry_axis(system)
    if axis is not None:
        Lb = np.einsum("nji,nj->ni", Q, L)  # body components Qᵀ L_P
        why = "symmetric top: gravity's torque about the pivot is perpendicular to its axis a"
        out.append(_invariant("L_P·a", Lb @ axis, True, why, scale))
    out.append(_invariant("L_P", L, False, "gravity has a torque about the pivot", scale))
    return out


def invariants_of(traj) -> list[Invariant]:
    """The quantities of ``traj``'s problem worth watching, conserved ones first.

    Parameters
    ----------
    traj : poinsot.trajectory.Trajectory

    Returns
    -------
    list of Invariant
        Total energy always (marked not conserved when a force does work); then, by the rules
        of the module docstring, the momenta the problem conserves.

    Examples
    --------
    >>> import numpy as np
    >>> from poinsot import Gravity, RigidBody, simulate
    >>> top = RigidBody.cylinder(1.0, 0.1, 0.2, position=(0, 0, 0.1))
    >>> traj = simulate(top, (0, 1), omega0=(0.5, 0, 30), pivot=(0, 0, 0),
    ...                 Q0=[0.96, 0.28, 0, 0], forces=[Gravity((0, 0, -9.8))])
    >>> [i.symbol for i in invariants_of(traj) if i.conserved]
    ['E', 'L_P·ĝ', 'L_P·a']
    """
    from .forces import CentralGravity, Gravity

    system = traj.system
    forces = system.forces
    A = np.asarray(traj.body.inertia, float)
    M = float(traj.body.mass)
    R, V, Q, w = (np.ascontiguousarray(a) for a in (traj.R, traj.V, traj.Q, traj.omega))
    motion = (A, M, R, V, Q, w)
    energy = _energy(traj, system.conservative)
    uniform = [f for f in forces if isinstance(f, Gravity)]
    only_gravity = len(uniform) == len(forces)
    g = sum((f.g for f in uniform), np.zeros(3))
    pivot = system.pivot
    at_com = pivot is None or not np.any(system.c)
    if only_gravity and at_com:  # no torque about the centre of mass
        free = pivot is None and not forces
        return [energy, *_about_com(motion, energy.values, bool(uniform), free)]
    if pivot is not None and only_gravity:
        return [energy, *_about_pivot(traj, motion, g, bool(uniform))]
    central = [f for f in forces if isinstance(f, CentralGravity)]
    if pivot is None and forces and len(central) == len(forces):
        centres = {tuple(f.center) for f in central}
        if len(centres) == 1:
            point = np.array(next(iter(centres)))
            L = _momentum(A, M, R - point, V, Q, w)
            why = "the potential is invariant under rotations about the centre"
            return [energy, _invariant("L_O", L, True, why, _norm_scale(L[0]))]
    L = _momentum_com(A, Q, w)
    why = "a force has a torque about the centre of mass"
    return [energy, _invariant("L_G", L, False, why, _norm_scale(L[0]))]
