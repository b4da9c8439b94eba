"""Figures. matplotlib (PNG/SVG) here; interactive plotly versions in :mod:`poinsot.report`.

Every function returns the figure it drew on and accepts ``ax=`` to draw into an existing
axes. matplotlib is imported only when a function is called.
"""

from .torquefree import (
    animate_tumbling,
    plot_attitude_frames,
    plot_energy_ellipsoid,
    plot_omega,
    plot_polhode_family,
)
from .trajectory import (
    plot_center_of_mass_path,
    plot_conservation,
    plot_method_comparison,
    plot_omega_series,
)

__all__ = [
    "animate_tumbling",
    "plot_attitude_frames",
    "plot_center_of_mass_path",
    "plot_conservation",
    "plot_energy_ellipsoid",
    "plot_method_comparison",
    "plot_omega",
    "plot_omega_series",
    "plot_polhode_family",
]
