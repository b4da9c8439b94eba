"""Where the torque-free analysis applies to a body's motion, and where its exact solution does.

:class:`~poinsot.torquefree.FreeRigidBody` answers in closed form what Euler's equation
``A ω̇ + ω × Aω = 0`` (20) allows. Whether a given motion is such a rotation is physics, decided
here once for every caller (the command line's runs among them):

* :func:`free_rotation` — the body's torque-free analysis (its polhodes, fixed points, the
  closed-form solution), or None for a body that has none: all its mass on a line or a point,
  or held at a pivot away from its centre of mass; :func:`check_motion_energy` — whether the
  analysis can represent a given motion's energy in doubles;
* :func:`exact_solution_applies` — whether forces leave the rotation about the centre of mass
  torque-free (uniform gravity only), so that the exact solution describes it;
* :func:`flip_reference` — the free asymmetric body whose exact flip intervals ``2K(m)/λ``
  measure an ensemble's flips.
"""

from __future__ import annotations

import numpy as np

from .body import FreeRigidBody

__all__ = ["check_motion_energy", "exact_solution_applies", "flip_reference", "free_rotation"]


def free_rotation(body, pivot=None) -> FreeRigidBody | None:
    """The torque-free analysis of ``body`` (a :class:`~poinsot.bodies.RigidBody`), or None
    where it has none: a degenerate body, or a ``pivot`` other than the centre of mass (the
    rotation is then not about it).

    >>> import numpy as np
    >>> from poinsot import RigidBody
    >>> body = RigidBody.from_particles([1, 1, 1], [[1, 0, 0], [0, 2, 0], [0, 0, 3]])
    >>> free_rotation(body).symmetry
    'asymmetric'
    >>> free_rotation(body, pivot=np.zeros(3)) is None  # held away from its centre of mass
    True
    """
    if body.is_degenerate:
        return None
    if pivot is not None and np.any(pivot != body.center_of_mass):
        return None
    return FreeRigidBody.from_body(body)


def check_motion_energy(free: FreeRigidBody, body, omega0) -> float:
    """The energy ``k = ½ ω0·Aω0`` of the motion of ``body`` starting at ``omega0`` (body
    frame), checked against ``free``'s analysis: :class:`ValueError` when its polhodes leave
    the double range (moments near 1e300; see
    :meth:`~poinsot.torquefree.FreeRigidBody.check_energy_range`). A body at rest (k = 0)
    passes."""
    from ..conservation import rotational_energy

    k = float(rotational_energy(body.inertia, omega0))
    if k > 0:
        free.check_energy_range(k)
    return k


def exact_solution_applies(forces) -> bool:
    """Whether the rotation about the centre of mass under ``forces`` is torque-free, so that
    the closed-form solution describes it: no forces, or uniform gravity only (which exerts no
    torque about the centre of mass).

    >>> from poinsot import Gravity, LinearDrag
    >>> exact_solution_applies([]), exact_solution_applies([Gravity()])
    (True, True)
    >>> exact_solution_applies([Gravity(), LinearDrag(0.1)])
    False
    """
    from ..forces import Gravity

    return all(isinstance(f, Gravity) for f in forces)


def flip_reference(body, forces=(), pivot=None) -> FreeRigidBody | None:
    """The free body whose exact flip intervals ``2K(m)/λ`` (:meth:`~poinsot.torquefree.
    FreeRigidBody.flip_interval`) grade measured flips: only for a body with no forces and no
    pivot, not degenerate, with three distinct moments (the only one that flips); else None.
    """
    if forces or pivot is not None or body.is_degenerate:
        return None
    free = FreeRigidBody.from_body(body)
    return free if free.symmetry == "asymmetric" else None
