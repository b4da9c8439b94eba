"""poinsot's integrators: one contract (:class:`Solver`), one registry (:data:`METHODS`).

================= ===== ======== ===================================================
name              order adaptive conserves
================= ===== ======== ===================================================
rk4               4     no       nothing (the notebook's method; its drift is reported)
dop853            8     yes      nothing exactly (errors at the tolerance)
rkmk4             4     no       Q on SO(3) (Lie-group method)
splitting         2     no       Q on SO(3), ``|L|``, spatial L (torque-free), symplectic
exact-splitting   2     no       the same; torque-free it is the exact flow at any step
exact-splitting4  4     no       the same (Blanes & Moan's SRKN6b composition)
exact-splitting6  6     no       the same (SRKN14a, FRB's example 1)
================= ===== ======== ===================================================

The ``exact-splitting`` methods compose the exact torque-free flow (the closed form) with
kicks of the forces: their error under a torque of size ε is O(ε hᵖ) (``docs/theory.md`` §5).

The steps themselves are the compiled core's (``crates/core/src/steppers.rs``), shared by every
driver; :func:`~poinsot.integrate.driver.integrate` runs a whole integration in one call.
"""

from .base import INVARIANTS, METHODS, Solver, get_solver, register, register_core_methods
from .control import ConstantStepSize, StepSizeController
from .dop853 import DOP853
from .lie import RKMK4, MuntheKaas
from .rk import RK4, ExplicitRungeKutta
from .saveat import SaveAt
from .splitting import Splitting

register_core_methods()  # the core's methods without a class here

__all__ = [
    "DOP853",
    "INVARIANTS",
    "METHODS",
    "RK4",
    "RKMK4",
    "ConstantStepSize",
    "ExplicitRungeKutta",
    "MuntheKaas",
    "SaveAt",
    "Solver",
    "Splitting",
    "StepSizeController",
    "get_solver",
    "register",
]
