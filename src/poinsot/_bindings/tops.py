"""The heavy symmetric top: its closed form (Lagrange's top) and its steady precession
(``crates/core/src/heavy_top.rs``, ``tops.rs``).
"""

from .._core import (
    gyroscopic_precession_rate,
    heavy_top_derivatives,
    heavy_top_motions,
    steady_precession_rates,
)

__all__ = [
    "gyroscopic_precession_rate",
    "heavy_top_derivatives",
    "heavy_top_motions",
    "steady_precession_rates",
]
