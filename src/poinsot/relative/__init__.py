"""Motion of a body relative to a moving carrier frame (``docs/relative.md``; the second source,
paper eqs (1)–(18)).

* The inertia moments as named quantities: :func:`transport_moment` ``M_e``,
  :func:`coriolis_moment` ``M_c = 2 ω_r × (J'ω_e)`` (with its three-term form and its
  particle-sum definition), the planar inertia tensor :func:`planar_inertia` ``J'``,
  :func:`planar_principal_moments` ``A' = (B + C − A)/2`` and the planar inertia ellipsoid,
  the balancing moment of case (16).
* :class:`Carrier`: the carrier's prescribed motion (a constant or time-varying ω_e, its Euler
  angles (14), its attitude, the acceleration of its origin).
* :func:`simulate_relative`: the compact relative Euler equation (11)–(12) on poinsot's
  compiled steppers, and :class:`RelativeTrajectory` with the absolute motion it maps to;
  :func:`prepare_relative` checks and lowers a run once for any initial state.
* :func:`relative_equations`: the same equations in Euler angles (12)–(15) as SymPy
  expressions, with a LaTeX export.
"""

from .carrier import Carrier
from .moments import (
    balancing_moment,
    coriolis_moment,
    coriolis_moment_particles,
    coriolis_moment_three_term,
    planar_inertia,
    planar_inertia_ellipsoid,
    planar_principal_moments,
    transport_moment,
)
from .simulate import (
    PreparedRelativeRun,
    RelativeTrajectory,
    prepare_relative,
    simulate_relative,
)
from .symbolic import RelativeEquations, relative_equations
from .system import RelativeMotionSystem

__all__ = [
    "Carrier",
    "PreparedRelativeRun",
    "RelativeEquations",
    "RelativeMotionSystem",
    "RelativeTrajectory",
    "balancing_moment",
    "coriolis_moment",
    "coriolis_moment_particles",
    "coriolis_moment_three_term",
    "planar_inertia",
    "planar_inertia_ellipsoid",
    "planar_principal_moments",
    "prepare_relative",
    "relative_equations",
    "simulate_relative",
    "transport_moment",
]
