"""Argument checking at poinsot's boundary.

Every public function turns user input into arrays here, so that a bad value is refused with
a message that names the argument, the offending index and the rule it breaks, e.g.
``"`masses[3]` must be a positive finite number, found -1.0"``. Nothing is broadcast silently:
a wrong shape is an error, never a reshaped array.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

__all__ = [
    "as_array",
    "as_gains",
    "as_positive_scalar",
    "as_rotation_matrices",
    "as_rotation_matrix",
    "as_sample_times",
    "as_scalar",
    "as_times",
    "as_vector3",
    "as_vectors",
]

#: Tolerance for accepting a user-given rotation matrix or quaternion (typed-in values such as
#: 0.7071 are common); accepted input is then projected exactly onto SO(3).
ROTATION_TOLERANCE = 1e-6
#: The largest phase (rad) at which a closed form is evaluated: 2⁵², where the spacing of
#: doubles reaches 1 (:data:`poinsot.torquefree.solution.MAX_PHASE`, ``docs/reliability.md``).
MAX_PHASE = 2.0**52


def _fmt_index(idx: tuple[int, ...]) -> str:
    return "".join(f"[{i}]" for i in idx)


def as_array(value, name: str, shape: tuple[int | None, ...], *, finite: bool = True) -> np.ndarray:
    """Convert ``value`` to a float array of ``shape`` (``None`` = any length).

    Raises
    ------
    TypeError
        If ``value`` is not numeric.
    ValueError
        If the shape differs or (with ``finite``) an entry is NaN or infinite; the message
        names ``name`` and the first offending index.
    """
    arr = _real_array(value, name)
    if arr.ndim != len(shape) or any(
        s is not None and n != s for s, n in zip(shape, arr.shape, strict=True)
    ):
        dims = ["N" if s is None else str(s) for s in shape]
        expected = "(" + ", ".join(dims) + ("," if len(dims) == 1 else "") + ")"
        raise ValueError(f"`{name}` must have shape {expected}, found shape {arr.shape}")
    if finite and not np.isfinite(arr).all():
        bad = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        raise ValueError(
            f"`{name}{_fmt_index(bad)}` must be finite, found {arr[bad] if bad else arr.item()}"
        )
    return arr


def _real_array(value, name: str) -> np.ndarray:
    """``value`` as a float array, or a TypeError naming ``name``: complex numbers (whose
    imaginary part NumPy would drop with only a warning), ragged lists, strings, dicts and
    other objects are refused."""
    if isinstance(value, str | bytes | dict | set):
        raise TypeError(f"`{name}` must be numeric, found {type(value).__name__}")
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):  # a ragged list
        raise ValueError(f"`{name}` must be a regular array of numbers, found a ragged "
                         "list (rows of different lengths)") from None  # fmt: skip
    if np.iscomplexobj(raw) or (
        raw.dtype == object and any(isinstance(v, complex) for v in raw.flat)
    ):
        raise TypeError(f"`{name}` must be real, found complex values")
    if raw.dtype.kind == "b":
        raise TypeError(f"`{name}` must be numeric, found booleans")
    if raw.dtype.kind in "US" or (
        raw.dtype == object and any(isinstance(v, str | bytes) for v in raw.flat)
    ):  # NumPy would read "1" as 1.0
        raise TypeError(f"`{name}` must be numeric, found text")
    if raw.dtype.kind in "iuf":
        return raw.astype(float, copy=False)
    try:
        return np.asarray(raw, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"`{name}` must be numeric, found {type(value).__name__}") from None


def as_vector3(value, name: str) -> np.ndarray:
    """A finite 3-vector, shape (3,)."""
    return as_array(value, name, (3,))


def as_frame(value, name: str = "omega_frame") -> str:
    """``value`` checked as the name of a frame a vector is given in: ``'body'`` or
    ``'space'``."""
    if not isinstance(value, str) or value not in ("body", "space"):
        raise ValueError(f"`{name}` must be 'body' or 'space', found {value!r}")
    return value


def as_scalar(value, name: str) -> float:
    """A finite real number (bools refused)."""
    if type(value) is float or type(value) is int:  # the common case, without NumPy
        x = float(value)
        if not math.isfinite(x):
            raise ValueError(f"`{name}` must be finite, found {x}")
        return x
    if isinstance(value, bool) or not isinstance(value, numbers.Real | np.ndarray):
        raise TypeError(f"`{name}` must be a real number, found {type(value).__name__}")
    arr = _real_array(value, name)
    if arr.ndim != 0:
        raise ValueError(f"`{name}` must be a scalar, found shape {arr.shape}")
    x = float(arr)
    if not np.isfinite(x):
        raise ValueError(f"`{name}` must be finite, found {x}")
    return x


def as_count(value, name: str, low: int = 1, high: int | None = None) -> int:
    """An integer from ``low`` to ``high`` (a float with an integer value is taken; a bool, a
    fraction, NaN or text is refused, named). The message says "a positive integer" when
    ``low`` is 1 and there is no ``high``."""
    ok = not isinstance(value, bool) and isinstance(value, int | np.integer)
    if not ok and isinstance(value, float | np.floating) and float(value).is_integer():
        value, ok = int(value), True
    if ok and value >= low and (high is None or value <= high):
        return int(value)
    if high is not None:
        rule = (
            f"an integer from {low} to {high:.0e}"
            if high >= 10**5
            else f"an integer from {low} to {high}"
        )
    else:
        rule = "a positive integer" if low == 1 else f"an integer ≥ {low}"
    found = f"{float(value):.3g}" if ok and abs(value) >= 10**15 else repr(value)
    raise ValueError(f"`{name}` must be {rule}, found {found}")


def as_positive_scalar(value, name: str) -> float:
    """A finite number > 0."""
    x = as_scalar(value, name)
    if x <= 0:
        raise ValueError(f"`{name}` must be a positive number, found {x}")
    return x


def as_gains(value, name: str, n: int = 2, what: str = "(alpha, beta)") -> tuple[float, ...]:
    """``n`` non-negative finite real numbers given as a sequence, e.g. Baumgarte's gains
    ``(alpha, beta)``; anything else (None, one number, a string, complex numbers, a
    negative, NaN or infinite gain) is refused, named.

    Examples
    --------
    >>> as_gains((10, 0.0), "baumgarte")
    (10.0, 0.0)
    >>> as_gains(5.0, "baumgarte")
    Traceback (most recent call last):
    ...
    TypeError: `baumgarte` must be a pair (alpha, beta) of non-negative numbers, found float
    """
    rule = f"a {'pair' if n == 2 else f'sequence of {n}'} {what} of non-negative numbers"
    if (
        value is None
        or isinstance(value, str | bytes | dict | set | numbers.Number)
        or (isinstance(value, np.ndarray) and value.ndim == 0)
    ):
        raise TypeError(f"`{name}` must be {rule}, found {type(value).__name__}")
    if not hasattr(value, "__len__") or len(value) != n:
        found = f"{len(value)} values" if hasattr(value, "__len__") else type(value).__name__
        raise ValueError(f"`{name}` must be {rule}, found {found}")
    out = []
    for i, x in enumerate(value):
        g = as_scalar(x, f"{name}[{i}]")
        if g < 0:
            raise ValueError(f"`{name}[{i}]` must be non-negative, found {g}")
        out.append(g)
    return tuple(out)


def as_positive_array(value, name: str, shape: tuple[int | None, ...]) -> np.ndarray:
    """A finite array with every entry > 0; the message names the first bad index."""
    arr = as_array(value, name, shape)
    if np.any(arr <= 0):
        bad = tuple(int(i) for i in np.argwhere(arr <= 0)[0])
        raise ValueError(f"`{name}{_fmt_index(bad)}` must be a positive number, found {arr[bad]}")
    return arr


_QUAT_ORDER = {True: "(w, x, y, z), scalar first", False: "(x, y, z, w), scalar last"}


def _rotation_input(value, name: str, scalar_first: bool = True) -> np.ndarray:
    """An array from a rotation input: a ``scipy.spatial.transform.Rotation`` (one or many,
    as matrices), or numbers; quaternions come back scalar-first."""
    if type(value).__name__ == "Rotation" and hasattr(value, "as_matrix"):
        if not scalar_first:
            raise ValueError(f"`scalar_first` applies to a quaternion `{name}`; this one is a "
                             "scipy Rotation: omit it")  # fmt: skip
        return np.asarray(value.as_matrix(), dtype=float)
    arr = _real_array(value, name)
    if not scalar_first:
        if not (arr.ndim in (1, 2) and arr.shape[-1] == 4):
            raise ValueError(f"`scalar_first` applies to a quaternion `{name}` (4 numbers); "
                             f"this one has shape {arr.shape}: omit it")  # fmt: skip
        arr = np.roll(arr, 1, axis=-1)  # (x, y, z, w) → (w, x, y, z)
    return arr


def as_rotation_matrix(value, name: str) -> np.ndarray:
    """A rotation given as a 3×3 matrix, a ``scipy.spatial.transform.Rotation``, or a
    scalar-first unit quaternion (w, x, y, z) (:func:`_rotation_input` reads SciPy's order).

    Input within :data:`ROTATION_TOLERANCE` of a rotation is accepted and projected exactly onto
    SO(3) (quaternion normalised; matrix replaced by its orthogonal polar factor). Anything else
    (a reflection, a shear, a quaternion of the wrong norm) is refused.
    """
    arr = _rotation_input(value, name)
    if arr.shape not in ((3, 3), (4,)):
        raise ValueError(
            f"`{name}` must be a 3×3 rotation matrix or a unit quaternion {_QUAT_ORDER[True]}, "
            f"found shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"`{name}` must be finite, found {arr.tolist()}")
    if arr.shape == (4,):
        with np.errstate(over="ignore"):  # a huge quaternion's norm is inf: refused below
            norm = float(np.linalg.norm(arr))
        if abs(norm - 1.0) > ROTATION_TOLERANCE:
            raise ValueError(
                f"`{name}` is not a rotation: the quaternion {_QUAT_ORDER[True]} has norm "
                f"{norm:.9g}, not 1"
            )
        from ._bindings.rotations import quat_to_matrix

        return quat_to_matrix(arr / norm)
    orth = float(np.max(np.abs(arr.T @ arr - np.eye(3))))
    det = float(np.linalg.det(arr))
    if orth > ROTATION_TOLERANCE or det <= 0:
        raise ValueError(
            f"`{name}` is not a rotation: needs RᵀR = I and det R = +1, "
            f"found max|RᵀR − I| = {orth:.3g} and det R = {det:.6g}"
        )
    u, _, vt = np.linalg.svd(arr)
    return u @ vt


def as_vectors(value, name: str, n: int | None = None, *, single_ok: bool = True) -> np.ndarray:
    """Finite 3-vectors: ``(3,)`` (one, shared; returned as (1, 3) when ``single_ok``) or
    ``(n, 3)`` (one per member). ``n = None`` accepts any number of rows. The message of a bad
    entry names the member: ``"`omega0[7, 1]` must be finite"``."""
    arr = _real_array(value, name)
    if arr.ndim == 1 and single_ok:
        return as_array(arr, name, (3,))[None, :]
    if arr.ndim != 2 or arr.shape[1] != 3 or (n is not None and arr.shape[0] != n):
        rows = "N" if n is None else str(n)
        one = "(3,) or " if single_ok else ""
        raise ValueError(
            f"`{name}` must have shape {one}({rows}, 3) (one row per member), found shape "
            f"{arr.shape}"
        )
    return as_array(arr, name, (None, 3))


def as_rotation_matrices(value, name: str, n: int | None = None) -> np.ndarray:
    """Rotations as matrices (M, 3, 3), ``M = 1`` (one shared) or ``n``: from one matrix (3, 3)
    or quaternion (4,), or one per member, (n, 3, 3) or (n, 4). Each is checked as in
    :func:`as_rotation_matrix` and projected onto SO(3); a bad one is named by its member index
    (``"`Q0[12]` is not a rotation: ..."``)."""
    arr = _rotation_input(value, name)
    if arr.shape in ((3, 3), (4,)):
        return as_rotation_matrix(arr, name)[None]
    if (
        arr.ndim not in (2, 3)
        or arr.shape[1:] not in ((3, 3), (4,))
        or (n is not None and arr.shape[0] != n)
    ):
        rows = "N" if n is None else str(n)
        raise ValueError(
            f"`{name}` must be one rotation ((3, 3) matrix or (4,) quaternion "
            f"{_QUAT_ORDER[True]}) or one per member (({rows}, 3, 3) or ({rows}, 4)), "
            f"found shape {arr.shape}"
        )
    if not np.isfinite(arr).all():
        bad = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        raise ValueError(f"`{name}{_fmt_index(bad)}` must be finite, found {arr[bad]}")
    if arr.ndim == 2:  # quaternions
        with np.errstate(over="ignore"):  # a huge quaternion's norm is inf: refused below
            norms = np.linalg.norm(arr, axis=1)
        bad = np.flatnonzero(np.abs(norms - 1.0) > ROTATION_TOLERANCE)
        if len(bad):
            i = int(bad[0])
            raise ValueError(
                f"`{name}[{i}]` is not a rotation: the quaternion {_QUAT_ORDER[True]} has norm "
                f"{norms[i]:.9g}, not 1"
            )
        from ._bindings.rotations import quat_to_matrix

        return quat_to_matrix(arr / norms[:, None])
    orth = np.abs(np.einsum("nki,nkj->nij", arr, arr) - np.eye(3)).max(axis=(1, 2))
    det = np.linalg.det(arr)
    bad = np.flatnonzero((orth > ROTATION_TOLERANCE) | (det <= 0))
    if len(bad):
        i = int(bad[0])
        raise ValueError(
            f"`{name}[{i}]` is not a rotation: needs RᵀR = I and det R = +1, found "
            f"max|RᵀR − I| = {orth[i]:.3g} and det R = {det[i]:.6g}"
        )
    u, _, vt = np.linalg.svd(arr)
    return u @ vt


def as_times(t, name: str = "t") -> np.ndarray:
    """Times at which something is evaluated: one finite real number or a 1-D array of them,
    as a float array (n,) (a number gives n = 1). An empty array is allowed and gives empty
    results wherever times are taken (``docs/reliability.md``); NaN and ±inf are refused,
    named with their index.

    Examples
    --------
    >>> as_times(2), as_times([]).shape
    (array([2.]), (0,))
    >>> as_times([0.0, float("inf")])
    Traceback (most recent call last):
    ...
    ValueError: `t[1]` must be finite, found inf
    """
    arr = _real_array(t, name)
    if arr.ndim == 0:
        return np.array([as_scalar(arr, name)])
    return as_array(arr, name, (None,))


def as_sample_times(t_eval, t0: float, t1: float, name: str = "t_eval") -> np.ndarray:
    """Sample times (n,): finite, strictly increasing, within ``[t0, t1]``; an empty array
    asks for no samples (the run is still integrated to ``t1``)."""
    t = as_array(t_eval, name, (None,))
    if not len(t):
        return t
    if (t[1:] <= t[:-1]).any():
        k = int(np.argmax(t[1:] <= t[:-1])) + 1
        raise ValueError(
            f"`{name}` must be strictly increasing, found {name}[{k}] = {t[k]} after {t[k - 1]}"
        )
    if t[0] < t0 or t[-1] > t1:
        raise ValueError(f"`{name}` must lie within t_span = ({t0}, {t1})")
    return t
