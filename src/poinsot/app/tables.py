"""Reading a scenario file's tables: each value converted to the kind a key expects, every
error naming the key path, what was expected and what was found, and an unknown key refused
with the nearest valid key suggested (:class:`ScenarioError`)."""

from __future__ import annotations

import difflib
import math
import warnings

import numpy as np

__all__ = ["ScenarioError"]

_MISSING = object()


class ScenarioError(ValueError):
    """A scenario that cannot run; ``str()`` starts with the file and the key path."""


#: While not None, every key the validator reads is appended here as
#: ``(table path, variant, key, kind, default, choices, unit)``: the scenario schema, recorded
#: from the validator itself (:mod:`poinsot.app.scenario_reference` renders it).
_SCHEMA_RECORDER: list | None = None

#: While not None, every value given as a quantity with a unit is recorded here as
#: ``key path → {"given": text, "value": SI value, "unit": SI unit}``: the scenario echoes
#: them in ``summary.json``.
_QUANTITY_RECORDER: dict | None = None

#: The SI unit of an angle: a bare number beyond 2π of it is most likely in degrees.
ANGLE = "rad"


class _Table:
    """A TOML table being read: typed getters, key paths in errors, unknown keys refused."""

    def __init__(self, data, path: str):
        if not isinstance(data, dict):
            raise ScenarioError(f"{path or 'scenario'}: expected a table, found {_show(data)}")
        self.data = data
        self.path = path
        self.used: set[str] = set()
        self.variant = None  # the value of its "type" key, once read

    def _record(self, key, kind, default=_MISSING, choices=None, unit=None):
        if _SCHEMA_RECORDER is not None:
            _SCHEMA_RECORDER.append((self.path, self.variant, key, kind, default, choices, unit))

    def where(self, key):
        return f"{self.path}.{key}" if self.path else key

    def has(self, key):
        return key in self.data

    def get(self, key, kind, default=_MISSING, **kw):
        """The value of ``key`` as a ``kind``; ``unit=`` (an SI unit such as ``"rad/s"``) lets
        a number be written as a quantity with a unit (``"100 rpm"``), converted to it."""
        self.used.add(key)
        self._record(key, kind, default, kw.get("choices"), kw.get("unit"))
        if key not in self.data:
            if default is _MISSING:
                self._typo_of(key)
                raise ScenarioError(f"{self.where(key)}: required key is missing")
            return default
        value = _convert(self.data[key], kind, self.where(key), **kw)
        if key == "type":
            self.variant = value
        return value

    def _typo_of(self, key):
        """A required ``key`` is missing: if an unknown key in the table looks like it, the typo
        is the error to report (``initial.omgea: unknown key; did you mean 'omega'?``)."""
        unknown = [k for k in self.data if k not in self.used and k != key]
        near = difflib.get_close_matches(key, unknown, n=1, cutoff=0.6)
        if near:
            raise ScenarioError(f"{self.where(near[0])}: unknown key; did you mean {key!r}?")

    def table(self, key, default=_MISSING):
        self.used.add(key)
        self._record(key, "table", default)
        if key not in self.data:
            if default is _MISSING:
                self._typo_of(key)
                raise ScenarioError(f"{self.where(key)}: required table is missing")
            return _Table({}, self.where(key)) if default is None else default
        return _Table(self.data[key], self.where(key))

    def tables(self, key):
        self.used.add(key)
        self._record(key, "tables", ())
        items = self.data.get(key, [])
        if not isinstance(items, list):
            raise ScenarioError(
                f"{self.where(key)}: expected an array of tables, found {_show(items)}"
            )
        return [_Table(item, f"{self.where(key)}[{i}]") for i, item in enumerate(items)]

    def finish(self, valid=None):
        valid = set(valid or ()) | self.used
        for key in self.data:
            if key not in valid:
                near = difflib.get_close_matches(key, sorted(valid), n=1, cutoff=0.5)
                hint = (
                    f"; did you mean {near[0]!r}?"
                    if near
                    else (f"; valid keys: {', '.join(sorted(valid))}" if valid else "")
                )
                raise ScenarioError(f"{self.where(key)}: unknown key{hint}")


def _show(value):
    text = repr(value)
    return text if len(text) < 60 else text[:57] + "..."


def _number(value, where, unit=None):
    if isinstance(value, str) and unit is not None:
        return _quantity(value, unit, where)
    if isinstance(value, bool) or not isinstance(value, int | float):
        hint = f' or a quantity such as "1.5 {unit}"' if unit not in (None, "1") else ""
        raise ScenarioError(f"{where}: expected a number{hint}, found {_show(value)}")
    if not math.isfinite(value):
        raise ScenarioError(f"{where}: expected a finite number, found {value}")
    if unit == ANGLE and abs(value) > 2 * math.pi:
        from .._io import PoinsotWarning

        warnings.warn(f"{where} = {value:g}: an angle beyond 2π rad; bare numbers are radians — "
                      f'if it is in degrees, write "{value:g} deg"', PoinsotWarning,
                      stacklevel=2)  # fmt: skip
    return float(value)


def _registry():
    """pint's unit registry, made once (its first use costs about 0.5 s)."""
    global _UREG
    if _UREG is None:
        import pint

        _UREG = pint.UnitRegistry()
    return _UREG


_UREG = None


def _quantity(text: str, unit: str, where: str) -> float:
    """A quantity written with a unit (``"100 rpm"``, ``"1.5 g/cm^3"``), parsed by pint's own
    expression parser (never ``eval``) and converted to the SI ``unit``; a bare number in the
    string is SI. Refused, naming the key, when pint is missing, the unit is unknown, or the
    dimension is not that of ``unit``."""
    if not any(c.isdigit() for c in text):
        raise ScenarioError(f"{where}: expected a number or a quantity such as \"1.5 {unit}\", "
                            f"found {text!r}")  # fmt: skip
    try:
        ureg = _registry()
    except ImportError:
        raise ScenarioError(f"{where} = {text!r}: quantities with units need pint: "
                            "pip install 'poinsot[units]' (or give the number in SI units, "
                            f"{unit})") from None  # fmt: skip
    import pint

    try:
        q = ureg.parse_expression(text)
    except pint.UndefinedUnitError as exc:
        names = [str(n) for n in getattr(exc, "unit_names", ())] or [str(exc)]
        near = difflib.get_close_matches(names[0], _units_like(ureg, unit), n=3, cutoff=0.6)
        hint = f"; did you mean {' or '.join(map(repr, near))}?" if near else ""
        raise ScenarioError(f"{where} = {text!r}: unknown unit {names[0]!r}{hint}") from None
    except Exception:  # pint's tokenizer refuses anything that is not a quantity
        raise ScenarioError(f"{where} = {text!r}: not a number with a unit "
                            f'(such as "1.5 {unit}")') from None  # fmt: skip
    if not isinstance(q, ureg.Quantity):  # a bare number in a string: SI, as a bare number
        value = float(q)
        if not math.isfinite(value):
            raise ScenarioError(f"{where} = {text!r}: expected a finite quantity")
        return value
    target = ureg.Quantity(1.0, "dimensionless" if unit == "1" else unit)
    if q.dimensionality != target.dimensionality:
        given = f"{q.units:~P}" or "no unit"
        raise ScenarioError(f"{where} = {text!r}: {given} is {_dimension(q)}, not {unit} "
                            f"({_dimension(target)})")  # fmt: skip
    value = float(q.to(target.units).magnitude)
    if not math.isfinite(value):
        raise ScenarioError(f"{where} = {text!r}: expected a finite quantity")
    if _QUANTITY_RECORDER is not None:
        _QUANTITY_RECORDER[where] = {"given": text, "value": value, "unit": unit}
    return value


_UNITS_LIKE: dict = {}


def _units_like(ureg, unit: str) -> list[str]:
    """The registry's unit names of the dimension of ``unit`` (the suggestions for a misspelt
    one: "rmp" → "rpm", never a teaspoon for a time), computed once per dimension."""
    target = ureg.Quantity(1.0, "dimensionless" if unit == "1" else unit).dimensionality
    key = str(target)
    if key not in _UNITS_LIKE:
        names = []
        for name in dir(ureg):
            if name.startswith("_"):
                continue
            try:
                if ureg.get_dimensionality(name) == target:
                    names.append(name)
            except Exception:  # not a unit (a registry method, a prefix)
                continue
        _UNITS_LIKE[key] = names
    return _UNITS_LIKE[key]


def _dimension(q) -> str:
    """``"[mass]"``, ``"1 / [time]"``, ``"dimensionless"``: the dimension in pint's words."""
    d = str(q.dimensionality)
    return d if d != "dimensionless" else "dimensionless"


def _convert(value, kind, where, choices=None, unit=None):
    if kind == "number":
        return _number(value, where, unit)
    if kind == "positive":
        x = _number(value, where, unit)
        if not x > 0:
            raise ScenarioError(f"{where}: expected a positive number, found {_show(value)}")
        return x
    if kind == "nonnegative":
        x = _number(value, where, unit)
        if x < 0:
            raise ScenarioError(f"{where}: expected a number ≥ 0, found {_show(value)}")
        return x
    if kind == "int":
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ScenarioError(f"{where}: expected a positive integer, found {_show(value)}")
        return value
    if kind == "bool":
        if not isinstance(value, bool):
            raise ScenarioError(f"{where}: expected true or false, found {_show(value)}")
        return value
    if kind == "string":
        if not isinstance(value, str):
            raise ScenarioError(f"{where}: expected a string, found {_show(value)}")
        if choices and value not in choices:
            near = difflib.get_close_matches(value, choices, n=1, cutoff=0.5)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            raise ScenarioError(
                f"{where}: expected one of {', '.join(map(repr, choices))}, found {value!r}{hint}"
            )
        return value
    if kind == "expression":  # text read by poinsot.expressions.parse, or a number
        if isinstance(value, bool) or not isinstance(value, str | int | float):
            raise ScenarioError(
                f"{where}: expected an expression as text (such as "
                f'"m*g*l*cos(theta)") or a number, found {_show(value)}'
            )
        return value
    if kind == "any_list":
        if not isinstance(value, list):
            raise ScenarioError(f"{where}: expected an array, found {_show(value)}")
        return value
    if kind in ("vector3", "vector4", "vector2", "vector"):
        n = {"vector3": 3, "vector4": 4, "vector2": 2, "vector": None}[kind]
        if not isinstance(value, list) or (n is not None and len(value) != n):
            what = f"an array of {n} numbers" if n else "an array of numbers"
            raise ScenarioError(f"{where}: expected {what}, found {_show(value)}")
        return np.array([_number(v, f"{where}[{i}]", unit) for i, v in enumerate(value)])
    if kind == "expressions3":  # numbers, or expressions in t as strings
        if not isinstance(value, list) or len(value) != 3:
            raise ScenarioError(f"{where}: expected an array of 3 numbers or expressions in t, "
                                f"found {_show(value)}")  # fmt: skip
        out = []
        for i, v in enumerate(value):
            if isinstance(v, str):
                out.append(v)
            else:
                out.append(_number(v, f"{where}[{i}]"))
        return out
    if kind == "matrix3":
        if not isinstance(value, list) or len(value) != 3:
            raise ScenarioError(f"{where}: expected a 3×3 array, found {_show(value)}")
        return np.array([_convert(row, "vector3", f"{where}[{i}]", unit=unit)
                         for i, row in enumerate(value)])  # fmt: skip
    if kind == "vectors3":
        if not isinstance(value, list) or not value:
            raise ScenarioError(
                f"{where}: expected a non-empty array of 3-vectors, found {_show(value)}"
            )
        return np.array([_convert(row, "vector3", f"{where}[{i}]", unit=unit)
                         for i, row in enumerate(value)])  # fmt: skip
    raise AssertionError(kind)  # pragma: no cover


# --------------------------------------------------------------------------- bodies
