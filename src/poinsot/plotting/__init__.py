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

__all__ = [
    "animate_tumbling",
    "plot_attitude_frames",
    "plot_energy_ellipsoid",
    "plot_omega",
    "plot_polhode_family",
]
