"""Forward sensitivities of a rigid body's run: the augmented initial state of the directions
and the run of the augmented system (``crates/core/src/sensitivity.rs``, ``dual.rs``).
"""

from .._core import (
    integrate_relative_sensitivities,
    integrate_sensitivities,
    relative_sensitivity_start,
    sensitivity_start,
)

__all__ = [
    "integrate_relative_sensitivities",
    "integrate_sensitivities",
    "relative_sensitivity_start",
    "sensitivity_start",
]
