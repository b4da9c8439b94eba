"""The presentation: figures, the HTML report and the numbers of a run as a reader sees them.

One module per concept, drawing what the library module of the same name computes:
:mod:`~poinsot.viz.torquefree` (energy ellipsoid, polhodes, the tumbling body),
:mod:`~poinsot.viz.trajectory` (time series, conservation, method comparison),
:mod:`~poinsot.viz.lagrange`, :mod:`~poinsot.viz.ensemble`, :mod:`~poinsot.viz.relative` and
:mod:`~poinsot.viz.identify` (an inertia identified from a gyro log) with matplotlib
(PNG/SVG); :mod:`~poinsot.viz.interactive` (plotly figures),
:mod:`~poinsot.viz.report` (the self-contained HTML report) and :mod:`~poinsot.viz.numbers`
(names, groups and units of a summary's numbers); :mod:`~poinsot.viz.display` (the notebook
displays, ``.plot()`` and ``.show()`` of the library's results, registered with
:mod:`poinsot.display`).

The figure functions below return the figure they drew on and accept ``ax=`` to draw into an
existing axes. matplotlib is imported only when a function is called. The presentation
imports the library, never the application (:mod:`poinsot.app`).
"""

from . import display as display  # registers the notebook displays of the library's classes
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
