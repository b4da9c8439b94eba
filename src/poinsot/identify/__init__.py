"""Inertia from a gyroscope log: identify a tumbling body's principal moments and axes,
torque-free or carrying a spinning rotor (a gyrostat; ``docs/identify.md``,
``docs/theory.md`` §4).

:func:`identify` takes the times and gyro readings of a throw (and optionally the rotor's speed,
axis and inertia, the accelerometer, a window) and returns an :class:`IdentifyResult`: the
inertia tensor in the sensor frame (up to scale unless the rotor's inertia is known), the
principal moments, the ratios ``I1/I3, I2/I3`` and the principal axes, each with its standard
error, the free-flight window, the residuals and the identifiability. One concept per module:

* :mod:`~poinsot.identify.log` — reading a CSV log through a column map with scale factors
  (a small TOML file or keyword arguments);
* :mod:`~poinsot.identify.flight` — finding the free flight with the accelerometer's lever-arm
  model, and saturated gyro samples;
* :mod:`~poinsot.identify.signals` — Savitzky–Golay smoothing and derivatives, noise level;
* :mod:`~poinsot.identify.equation_error` — the linear least-squares estimate;
* :mod:`~poinsot.identify.output_error` — the nonlinear least-squares fit of the integrated
  gyrostat (compiled core) to the raw readings, with standard errors;
* :mod:`~poinsot.identify.estimate` — :func:`identify` itself, with its refusals;
* :mod:`~poinsot.identify.result` — :class:`IdentifyResult`;
* :mod:`~poinsot.identify.combine` — several throws of one body as one estimate;
* :mod:`~poinsot.identify.synthetic` — synthetic throws made by poinsot, for tests and docs.
"""

from .combine import CombinedResult, combine
from .estimate import identify
from .log import GyroLog, LogMap, LogMapError, load_map, read_log
from .result import IdentifyResult, ModelMismatchWarning, NotIdentifiableError
from .synthetic import SyntheticThrow, logger_block, synthetic_throw

__all__ = [
    "CombinedResult",
    "GyroLog",
    "IdentifyResult",
    "LogMap",
    "LogMapError",
    "ModelMismatchWarning",
    "NotIdentifiableError",
    "SyntheticThrow",
    "combine",
    "identify",
    "load_map",
    "logger_block",
    "read_log",
    "synthetic_throw",
]
