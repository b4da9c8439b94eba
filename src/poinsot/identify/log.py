"""Reading a gyro log from a CSV file through a column map with scale factors.

Nothing device-specific is built in: a :class:`LogMap` says which columns hold the time, the
gyro's x, y, z (and optionally the accelerometer and a rotor's speed) and what one unit of each
is worth in SI units. It comes from a small TOML file (:func:`load_map`) or from keyword
arguments (the command line's options)::

    [columns]                 # header names, or 0-based column numbers
    time = "time (us)"
    gyro = ["gyroADC[0]", "gyroADC[1]", "gyroADC[2]"]
    accel = ["accSmooth[0]", "accSmooth[1]", "accSmooth[2]"]     # optional
    rotor_speed = "rpm"                                          # optional
    attitude = ["qw", "qx", "qy", "qz"]    # optional (poinsot grade): a quaternion w, x, y, z
                                           # or nine matrix columns, body → space
    [scale]                   # one unit of the file in SI: a number, or "FACTOR UNIT"
    time = "1 us"
    gyro = "1/16.384 deg/s"
    accel = "1/2048 g"
    rotor_speed = "1 rpm"

    [rotor]                   # optional
    axis = [0, 0, 1]          # sensor frame
    inertia = 1.7e-6          # kg m²

    [identify]                # optional
    window = [12.3, 12.9]     # s, on the file's time axis after scaling
    saturation = "2000 deg/s"

    [csv]                     # optional
    delimiter = ","           # default: guessed from the header line
    decimal = "."             # "," for decimal commas
    skip_rows = 0             # lines before the header

Without a map the columns are recognised by their header names (``time``/``t``/``timestamp``,
and ``gyro``/``omega`` with ``x``/``y``/``z`` or ``[0]``/``[1]``/``[2]``), and units written in
parentheses in a header, as a phone app writes them (``Time (s)``, ``Gyroscope x (rad/s)``),
are read; a column with neither a scale nor a unit is taken as SI and the log says so in its
``notes``.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field, fields, replace
from fractions import Fraction
from pathlib import Path

import numpy as np

__all__ = ["UNITS", "GyroLog", "LogMap", "LogMapError", "load_map", "parse_scale", "read_log"]


class LogMapError(ValueError):
    """A column map or a log that cannot be read; the message names the file, the key or the
    column, and the line."""


_DEG = math.pi / 180.0
#: The units a scale may name, per quantity: SI value of one unit.
UNITS = {
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "μs": 1e-6, "ns": 1e-9,
             "min": 60.0},
    "rate": {"rad/s": 1.0, "mrad/s": 1e-3, "deg/s": _DEG, "°/s": _DEG, "dps": _DEG,
             "rpm": 2 * math.pi / 60, "rev/s": 2 * math.pi, "hz": 2 * math.pi},
    "accel": {"m/s²": 1.0, "m/s^2": 1.0, "m/s2": 1.0, "g": 9.80665, "mg": 9.80665e-3},
}  # fmt: skip
_KIND = {"time": "time", "gyro": "rate", "accel": "accel", "rotor_speed": "rate",
         "saturation": "rate"}  # fmt: skip
_SECTIONS = {
    "columns": ("time", "gyro", "accel", "rotor_speed", "attitude"),
    "scale": ("time", "gyro", "accel", "rotor_speed"),
    "rotor": ("axis", "inertia"),
    "identify": ("window", "saturation"),
    "csv": ("delimiter", "decimal", "skip_rows"),
}


def parse_scale(value, kind: str, name: str = "scale") -> float:
    """One unit of a log's column in SI units.

    ``value`` is a positive number (the SI factor itself) or a string ``"FACTOR UNIT"``,
    ``"UNIT"`` or ``"FACTOR"``, with FACTOR a number or a fraction ``a/b`` and UNIT one of
    :data:`UNITS` for the ``kind`` (``"time"``, ``"rate"`` or ``"accel"``).

    Examples
    --------
    >>> round(parse_scale("1/16.384 deg/s", "rate"), 12)
    0.001065264436
    >>> parse_scale("1 us", "time"), parse_scale(0.5, "time"), parse_scale("rad/s", "rate")
    (1e-06, 0.5, 1.0)
    """
    units = UNITS[kind]
    if isinstance(value, bool):
        raise LogMapError(f"`{name}` must be a number or a string such as "
                          f"\"1/16.384 deg/s\", found {value!r}")  # fmt: skip
    if isinstance(value, int | float):
        x = float(value)
    elif isinstance(value, str):
        text = value.strip()
        m = re.fullmatch(r"([-+0-9.eE]+(?:\s*/\s*[-+0-9.eE]+)?)?\s*(.*)", text)
        factor, unit = (m.group(1), m.group(2).strip()) if m else (None, text)
        try:
            x = _fraction(factor) if factor else 1.0
        except (ValueError, ZeroDivisionError):
            raise LogMapError(f"`{name}` = {value!r}: {factor!r} is not a number or a "
                              "fraction a/b") from None  # fmt: skip
        if unit:
            key = unit if unit in units else unit.lower()
            if key not in units:
                raise LogMapError(
                    f"`{name}` = {value!r}: unknown unit {unit!r} (one of {', '.join(units)})"
                )
            x *= units[key]
    else:
        raise LogMapError(f"`{name}` must be a number or a string such as "
                          f"\"1/16.384 deg/s\", found {type(value).__name__}")  # fmt: skip
    if not (math.isfinite(x) and x > 0):
        raise LogMapError(f"`{name}` must be positive and finite, found {value!r}")
    return x


def _fraction(text: str) -> float:
    if "/" in text:
        a, b = text.split("/")
        return float(Fraction(float(a.strip())) / Fraction(float(b.strip())))
    return float(text)


Column = str | int


@dataclass(frozen=True)
class LogMap:
    """Which columns of a CSV log hold what, and their scales (see the module's docstring).

    Columns are header names or 0-based numbers; ``None`` means: recognise it by its header.
    Scales are SI per unit of the file (``parse_scale`` turns ``"1/16.384 deg/s"`` into one);
    ``None`` means: from the header's unit, else SI.
    """

    time: Column | None = None
    gyro: tuple | None = None
    accel: tuple | None = None
    rotor_speed: Column | None = None
    attitude: tuple | None = None
    time_scale: float | None = None
    gyro_scale: float | None = None
    accel_scale: float | None = None
    rotor_speed_scale: float | None = None
    rotor_axis: tuple | None = None
    rotor_inertia: float | None = None
    window: tuple | None = None
    saturation: float | None = None
    delimiter: str | None = None
    decimal: str = "."
    skip_rows: int = 0
    source: str = field(default="", compare=False)

    def updated(self, **changes) -> LogMap:
        """A copy with the keys given (not None) replaced: options over a map file."""
        names = {f.name for f in fields(self)}
        for key in changes:
            if key not in names:
                raise LogMapError(f"unknown map key `{key}`")
        changes = {k: v for k, v in changes.items() if v is not None}
        for key, check in _COLUMN_CHECKS.items():  # as a map file's columns are checked
            if key in changes:
                changes[key] = check(changes[key], key)
        return replace(self, **changes)


def _column(value, name: str) -> Column:
    if isinstance(value, bool) or not isinstance(value, str | int):
        raise LogMapError(f"`{name}` must be a column name or a 0-based column number, "
                          f"found {value!r}")  # fmt: skip
    if isinstance(value, int) and value < 0:
        raise LogMapError(f"`{name}` must be a column number ≥ 0, found {value}")
    return value


def _three(value, name: str) -> tuple:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise LogMapError(f"`{name}` must list three columns (x, y, z), found {value!r}")
    return tuple(_column(v, f"{name}[{i}]") for i, v in enumerate(value))


def _attitude_columns(value, name: str) -> tuple:
    """Four columns (a quaternion w, x, y, z) or nine (a matrix, row by row), body → space."""
    if not isinstance(value, list | tuple) or len(value) not in (4, 9):
        raise LogMapError(f"`{name}` must list four quaternion columns (w, x, y, z) or nine "
                          f"matrix columns (row by row), found {value!r}")  # fmt: skip
    return tuple(_column(v, f"{name}[{i}]") for i, v in enumerate(value))


#: The checks of the column keys, the same for a map file's ``[columns]`` and for options.
_COLUMN_CHECKS = {"time": _column, "gyro": _three, "accel": _three, "rotor_speed": _column,
                  "attitude": _attitude_columns}  # fmt: skip


def load_map(path) -> LogMap:
    """Read a column map from a TOML file (format in the module's docstring); every key is
    checked and an unknown or malformed one is refused by name.

    Raises
    ------
    LogMapError
        Naming the file and the key.
    """
    from .._io import TOMLError, read_toml

    path = Path(path)
    try:
        data = read_toml(path.read_text(encoding="utf-8"), str(path))
    except FileNotFoundError:
        raise LogMapError(f"{path}: no such file") from None
    except TOMLError as exc:
        raise LogMapError(str(exc)) from None
    except UnicodeDecodeError:
        raise LogMapError(f"{path}: not a UTF-8 text file") from None
    try:
        return _map_from_dict(data, str(path))
    except LogMapError as exc:
        raise LogMapError(f"{path}: {exc}") from None


def _map_from_dict(data: dict, source: str = "") -> LogMap:
    for section, value in data.items():
        if section not in _SECTIONS:
            raise LogMapError(f"unknown section [{section}] (expected "
                              f"{', '.join(f'[{s}]' for s in _SECTIONS)})")  # fmt: skip
        if not isinstance(value, dict):
            raise LogMapError(f"`{section}` must be a table [{section}]")
        for key in value:
            if key not in _SECTIONS[section]:
                raise LogMapError(f"unknown key `{section}.{key}` (expected one of "
                                  f"{', '.join(_SECTIONS[section])})")  # fmt: skip
    cols = data.get("columns", {})
    scale = data.get("scale", {})
    rotor = data.get("rotor", {})
    ident = data.get("identify", {})
    csvt = data.get("csv", {})
    kw: dict = {"source": source}
    if "time" in cols:
        kw["time"] = _column(cols["time"], "columns.time")
    if "gyro" in cols:
        kw["gyro"] = _three(cols["gyro"], "columns.gyro")
    if "accel" in cols:
        kw["accel"] = _three(cols["accel"], "columns.accel")
    if "rotor_speed" in cols:
        kw["rotor_speed"] = _column(cols["rotor_speed"], "columns.rotor_speed")
    if "attitude" in cols:
        kw["attitude"] = _attitude_columns(cols["attitude"], "columns.attitude")
    for key in _SECTIONS["scale"]:
        if key in scale:
            kw[f"{key}_scale"] = parse_scale(scale[key], _KIND[key], f"scale.{key}")
    if "axis" in rotor:
        a = rotor["axis"]
        if (
            not isinstance(a, list)
            or len(a) != 3
            or not all(isinstance(x, int | float) and not isinstance(x, bool) for x in a)
        ):
            raise LogMapError(f"`rotor.axis` must be three numbers, found {a!r}")  # fmt: skip
        kw["rotor_axis"] = tuple(float(x) for x in a)
    if "inertia" in rotor:
        J = rotor["inertia"]
        if isinstance(J, bool) or not isinstance(J, int | float) or not J > 0:
            raise LogMapError(f"`rotor.inertia` must be a positive number (kg m²), found {J!r}")
        kw["rotor_inertia"] = float(J)
    if "window" in ident:
        w = ident["window"]
        if (
            not isinstance(w, list)
            or len(w) != 2
            or not all(isinstance(x, int | float) and not isinstance(x, bool) for x in w)
        ):
            raise LogMapError(f"`identify.window` must be two times [start, end] (s), "
                              f"found {w!r}")  # fmt: skip
        kw["window"] = (float(w[0]), float(w[1]))
    if "saturation" in ident:
        kw["saturation"] = parse_scale(ident["saturation"], "rate", "identify.saturation")
    if "delimiter" in csvt:
        d = csvt["delimiter"]
        if not isinstance(d, str) or len(d) != 1:
            raise LogMapError(f"`csv.delimiter` must be one character, found {d!r}")
        kw["delimiter"] = d
    if "decimal" in csvt:
        d = csvt["decimal"]
        if d not in (".", ","):
            raise LogMapError(f'`csv.decimal` must be "." or ",", found {d!r}')
        kw["decimal"] = d
    if "skip_rows" in csvt:
        s = csvt["skip_rows"]
        if isinstance(s, bool) or not isinstance(s, int) or s < 0:
            raise LogMapError(f"`csv.skip_rows` must be an integer ≥ 0, found {s!r}")
        kw["skip_rows"] = s
    return LogMap(**kw)


@dataclass(frozen=True, eq=False)
class GyroLog:
    """A log read from a file, in SI units.

    Attributes
    ----------
    t : ndarray (n,)
        Times [s].
    omega : ndarray (n, 3)
        Gyro readings [rad/s].
    accel : ndarray (n, 3) or None
        Specific force [m/s²].
    rotor_speed : ndarray (n,) or None
        [rad/s].
    attitude : ndarray (n, 3, 3) or None
        With ``columns.attitude``: the attitude, body → space (a quaternion's matrix after
        normalising it; nine columns as they are).
    rotor_axis, rotor_inertia, window, saturation
        From the map.
    columns : dict
        The header name of each quantity read (``"time"``, ``"gyro.x"``, …).
    notes : tuple of str
        Assumptions made (a unit taken as SI, a unit read from a header).
    path : str
    """

    t: np.ndarray
    omega: np.ndarray
    accel: np.ndarray | None
    rotor_speed: np.ndarray | None
    rotor_axis: tuple | None
    rotor_inertia: float | None
    window: tuple | None
    saturation: float | None
    columns: dict
    notes: tuple
    path: str
    attitude: np.ndarray | None = None

    def identify_kwargs(self) -> dict:
        """The keyword arguments of :func:`poinsot.identify.identify` for this log."""
        kw = {}
        for key in ("rotor_speed", "rotor_axis", "rotor_inertia", "window", "accel",
                    "saturation"):  # fmt: skip
            value = getattr(self, key)
            if value is not None:
                kw[key] = value
        return kw

    def identify(self, **options):
        """:func:`poinsot.identify.identify` on this log (``options`` override the map's)."""
        from .estimate import identify

        return identify(self.t, self.omega, **{**self.identify_kwargs(), **options})


_UNIT_IN_HEADER = re.compile(r"[\(\[]\s*([^\)\]]+?)\s*[\)\]]\s*$")


def _header_unit(name: str, kind: str) -> float | None:
    m = _UNIT_IN_HEADER.search(name)
    if not m:
        return None
    unit = m.group(1).strip()
    units = UNITS[kind]
    key = unit if unit in units else unit.lower()
    return units.get(key)


def _norm(name: str) -> str:
    return re.sub(r"\s+", " ", name.strip().lower())


def _find_time(names) -> int | None:
    for i, name in enumerate(names):
        n = _norm(name)
        if re.match(r"^(time|t|timestamp|times)\b", n) or n.startswith("time_"):
            return i
    return None


def _find_gyro(names) -> tuple | None:
    found = {}
    for i, name in enumerate(names):
        n = _norm(name)
        if not re.search(r"gyro|omega|angular|rotation rate|^w[ _]?[xyz]\b", n):
            continue
        m = re.search(r"(?:^|[\s_\-\[\(])([xyz012])(?:$|[\s_\-\]\)])", n.split("(")[0] + " ")
        if m is None:
            m = re.search(r"\[([012])\]", n)
        if m is None:
            continue
        k = "xyz".find(m.group(1)) if m.group(1) in "xyz" else int(m.group(1))
        found.setdefault(k, i)
    if all(k in found for k in range(3)):
        return (found[0], found[1], found[2])
    return None


def _resolve(col: Column, names, what: str, source: str) -> int:
    if isinstance(col, str):
        stripped = [x.strip() for x in names]
        if col.strip() in stripped:
            return stripped.index(col.strip())
        if col.strip().isdigit() and int(col) < len(names):
            return int(col)
        shown = ", ".join(repr(x.strip()) for x in names[:40])
        raise LogMapError(f"{source}: the column {col!r} ({what}) is not in the header; its "
                          f"columns are {shown}")  # fmt: skip
    if col >= len(names):
        raise LogMapError(f"{source}: column number {col} ({what}) is beyond the "
                          f"{len(names)} columns")  # fmt: skip
    return col


def _lines(path, skip_rows: int, src: str) -> list:
    """The header and sample lines of the file ``(line number, text)``: after ``skip_rows``,
    neither blank nor a ``#`` comment; refused when there is no header and sample."""
    try:
        with open(path, encoding="utf-8-sig", newline="") as fh:
            lines = fh.read().splitlines()
    except FileNotFoundError:
        raise LogMapError(f"{src}: no such file") from None
    except IsADirectoryError:
        raise LogMapError(f"{src}: is a folder, not a CSV file") from None
    except UnicodeDecodeError:
        raise LogMapError(f"{src}: not a UTF-8 text file (a CSV export is expected)") from None
    body = [(i + 1, ln) for i, ln in enumerate(lines) if i >= skip_rows and ln.strip()
            and not ln.lstrip().startswith("#")]  # fmt: skip
    if len(body) < 2:
        raise LogMapError(f"{src}: expected a header line and samples, found "
                          f"{len(body)} non-empty line(s)")  # fmt: skip
    return body


def _wanted_columns(m: LogMap, names, src: str) -> dict:
    """The column number of each quantity read (``"time"``, ``"gyro.x"``, …): the map's, or
    the time and gyro recognised by their header names."""
    t_col = m.time if m.time is not None else _find_time(names)
    if t_col is None:
        raise LogMapError(f"{src}: no time column recognised in the header (give "
                          "`columns.time` in a map file or --time)")  # fmt: skip
    g_cols = m.gyro if m.gyro is not None else _find_gyro(names)
    if g_cols is None:
        raise LogMapError(f"{src}: no gyro x, y, z columns recognised in the header (give "
                          "`columns.gyro` in a map file or --gyro X Y Z)")  # fmt: skip
    wanted = {"time": _resolve(t_col, names, "time", src)}
    for k, c in zip("xyz", g_cols, strict=True):
        wanted[f"gyro.{k}"] = _resolve(c, names, f"gyro {k}", src)
    if m.accel is not None:
        for k, c in zip("xyz", m.accel, strict=True):
            wanted[f"accel.{k}"] = _resolve(c, names, f"accel {k}", src)
    if m.rotor_speed is not None:
        wanted["rotor_speed"] = _resolve(m.rotor_speed, names, "rotor speed", src)
    for k, c in enumerate(m.attitude or ()):
        wanted[f"attitude[{k}]"] = _resolve(c, names, f"attitude[{k}]", src)
    return wanted


def _numbers(body, wanted: dict, columns: dict, delim: str, decimal: str, src: str):
    """The samples (n, len(wanted)) of the wanted columns; a missing, empty, non-numeric or
    non-finite cell is refused with its line and column."""
    data = np.empty((len(body) - 1, len(wanted)))
    reader = csv.reader((ln for _, ln in body[1:]), delimiter=delim)
    idx = list(wanted.values())
    keys = list(wanted)
    for r, row in enumerate(reader):
        line = body[1 + r][0]
        for j, i in enumerate(idx):
            if i >= len(row):
                raise LogMapError(f"{src} line {line}: the row has {len(row)} fields, so no "
                                  f"column {columns[keys[j]]!r}")  # fmt: skip
            cell = row[i].strip()
            if decimal == ",":
                cell = cell.replace(",", ".")
            try:
                data[r, j] = float(cell)
            except ValueError:
                what = "is empty" if not cell else f"{cell!r} is not a number"
                raise LogMapError(f"{src} line {line}, column {columns[keys[j]]!r}: "
                                  f"{what}") from None  # fmt: skip
            if not math.isfinite(data[r, j]):
                raise LogMapError(f"{src} line {line}, column {columns[keys[j]]!r}: "
                                  f"{cell!r} is not a finite number (NaN sample)")  # fmt: skip
    return data


def _scale(key: str, given, kind: str, header: str, notes: list) -> float:
    """One unit of a column in SI: the map's ``given`` scale, else the header's unit, else 1
    (SI); the last two add a line to ``notes``."""
    if given is not None:
        return given
    unit = _header_unit(header, kind)
    if unit is not None:
        notes.append(f"{key}: unit read from the header {header!r}")
        return unit
    si = {"time": "s", "rate": "rad/s", "accel": "m/s²"}[kind]
    notes.append(f"{key}: no scale and no unit in the header {header!r}: taken as {si}")
    return 1.0


def _check_increasing(t, data, body, columns: dict, src: str) -> None:
    """Refuse times ``t`` that do not increase strictly, naming the two lines."""
    d = np.diff(t)
    if np.any(d <= 0):
        k = int(np.flatnonzero(d <= 0)[0])
        what = "repeats the time of" if d[k] == 0 else "goes back in time from"
        raise LogMapError(
            f"{src}: column {columns['time']!r} must increase strictly: line "
            f"{body[k + 2][0]} ({float(data[k + 1, 0])!r}) {what} line {body[k + 1][0]} "
            f"({float(data[k, 0])!r})"
        )


def _attitude(raw, body, src: str):
    """The attitude matrices (n, 3, 3) of four quaternion columns (normalised; a zero one is
    refused) or of nine matrix columns."""
    from ..rotation import matrix_from_quat

    if raw.shape[1] == 4:
        norms = np.linalg.norm(raw, axis=1)
        if np.any(norms == 0):
            k = int(np.argmax(norms == 0))
            raise LogMapError(f"{src} line {body[k + 1][0]}: the attitude quaternion is "
                              "zero")  # fmt: skip
        return matrix_from_quat(raw)
    return raw.reshape(-1, 3, 3)


def read_log(path, log_map: LogMap | None = None, **options) -> GyroLog:
    """Read a gyro log from a CSV file.

    Parameters
    ----------
    path : str or Path
        The CSV file: one header line (after ``skip_rows`` lines), then one sample per line.
    log_map : LogMap, optional
        The columns and scales; ``options`` (the same names) replace its entries.

    Returns
    -------
    GyroLog

    Raises
    ------
    LogMapError
        Naming the file, the column and the line: a missing column, a cell that is not a
        number, an empty cell, times that do not increase, a map entry that makes no sense.

    Examples
    --------
    >>> import tempfile, os
    >>> text = "Time (s),Gyroscope x (rad/s),Gyroscope y (rad/s),Gyroscope z (rad/s)\\n"
    >>> text += "".join(f"{k / 100},{k},0,1\\n" for k in range(5))
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "phone.csv")
    ...     _ = open(p, "w").write(text)
    ...     log = read_log(p)
    >>> log.t.tolist(), log.omega[:, 0].tolist(), log.columns["gyro.y"]
    ([0.0, 0.01, 0.02, 0.03, 0.04], [0.0, 1.0, 2.0, 3.0, 4.0], 'Gyroscope y (rad/s)')
    """
    m = (log_map or LogMap()).updated(**options)
    path = Path(path)
    src = str(path)
    body = _lines(path, m.skip_rows, src)
    _header_line, header = body[0]
    delim = m.delimiter or _sniff(header, m.decimal)
    if delim == "," and m.decimal == ",":
        raise LogMapError(f'{src}: `csv.decimal` "," needs another `csv.delimiter` than ","')
    names = next(csv.reader([header], delimiter=delim))
    notes = []
    wanted = _wanted_columns(m, names, src)
    columns = {key: names[i].strip() for key, i in wanted.items()}
    data = _numbers(body, wanted, columns, delim, m.decimal, src)
    ts = _scale("time", m.time_scale, "time", columns["time"], notes)
    t = data[:, 0] * ts
    _check_increasing(t, data, body, columns, src)
    gs = _scale("gyro", m.gyro_scale, "rate", columns["gyro.x"], notes)
    omega = data[:, 1:4] * gs
    col = 4
    accel = None
    if m.accel is not None:
        acs = _scale("accel", m.accel_scale, "accel", columns["accel.x"], notes)
        accel = data[:, col : col + 3] * acs
        col += 3
    rotor = None
    if m.rotor_speed is not None:
        rs = _scale("rotor_speed", m.rotor_speed_scale, "rate", columns["rotor_speed"], notes)
        rotor = data[:, col] * rs
        col += 1
    attitude = None
    if m.attitude is not None:
        attitude = _attitude(data[:, col : col + len(m.attitude)], body, src)
    return GyroLog(
        t=t,
        omega=omega,
        accel=accel,
        rotor_speed=rotor,
        rotor_axis=m.rotor_axis,
        rotor_inertia=m.rotor_inertia,
        window=m.window,
        saturation=m.saturation,
        columns=columns,
        notes=tuple(notes),
        path=src,
        attitude=attitude,
    )


def _sniff(header: str, decimal: str) -> str:
    candidates = ["\t", ";", ","] if decimal == "," else [",", "\t", ";"]
    counts = {d: header.count(d) for d in candidates}
    best = max(candidates, key=lambda d: counts[d])
    return best if counts[best] > 0 else ","
