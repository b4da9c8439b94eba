"""The torque-free rigid body solved exactly (``docs/theory.md`` §1, "Torque-free body",
eqs (19)–(33); ``docs/torque_free.md``).

:class:`FreeRigidBody` holds the principal moments and answers everything Euler's equation
``A ω̇ + ω × Aω = 0`` (20) allows in closed form. One concept per module:

* :mod:`~poinsot.torquefree.body` — the body, its frames, the invariants (30)–(31), the cone
  (32) and the feasibility condition (33);
* :mod:`~poinsot.torquefree.stability` — fixed points and their stability;
* :mod:`~poinsot.torquefree.solution` — ω(t) by Jacobi elliptic functions, the attitude Q(t)
  by Euler angles about the angular momentum with the third-kind integral, periods, flip
  intervals and the polhode family; every one takes one initial condition (3,) or many
  (N, 3), evaluated in the compiled core (``poinsot._core``: the Rust crate ``poinsot-core``,
  modules ``torque_free``, ``elliptic`` and ``freebody``);
* :mod:`~poinsot.torquefree.polhodes` — polhodes, separatrix arcs and herpolhodes.

Frames. ``FreeRigidBody(moments)`` takes the moments along the body's x, y, z axes (any order):
the body frame *is* the principal frame. :meth:`FreeRigidBody.from_body` takes a
:class:`~poinsot.bodies.RigidBody` and works in its principal frame, mapping every input and
result to and from the body frame. Internally the moments are sorted, ``I1 ≤ I2 ≤ I3``, in a
right-handed frame ``S`` (columns: the sorted axes in body coordinates).
"""

from .body import FreeRigidBody, energy_ellipsoid_semi_axes, momentum_ellipsoid_semi_axes
from .polhodes import Polhode
from .stability import FixedPointSet, Floquet, Stability

__all__ = [
    "FixedPointSet",
    "Floquet",
    "FreeRigidBody",
    "Polhode",
    "Stability",
    "energy_ellipsoid_semi_axes",
    "momentum_ellipsoid_semi_axes",
]
