"""Reading a scenario file's tables: each value converted to the kind a key expects, every
error naming the key path, what was expected and what was found, and an unknown key refused
with the nearest valid key suggested (:class:`ScenarioError`)."""

from __future__ import annotations

import difflib
import math

import numpy as np

__all__ = ["ScenarioError"]

_MISSING = object()


class ScenarioError(ValueError):
    """A scenario that cannot run; ``str()`` starts with the file and the key path."""


#: While not None, every key the validator reads is appended here as
#: ``(table path, variant, key, kind, default, choices)``: the scenario schema, recorded from
#: the validator itself (:mod:`poinsot.app.scenario_reference` renders it).
_SCHEMA_RECORDER: list | None = None


class _Table:
    """A TOML table being read: typed getters, key paths in errors, unknown keys refused."""

    def __init__(self, data, path: str):
        if not isinstance(data, dict):
            raise ScenarioError(f"{path or 'scenario'}: expected a table, found {_show(data)}")
        self.data = data
        self.path = path
        self.used: set[str] = set()
        self.variant = None  # the value of its "type" key, once read

    def _record(self, key, kind, default=_MISSING, choices=None):
        if _SCHEMA_RECORDER is not None:
            _SCHEMA_RECORDER.append((self.path, self.variant, key, kind, default, choices))

    def where(self, key):
        return f"{self.path}.{key}" if self.path else key

    def has(self, key):
        return key in self.data

    def get(self, key, kind, default=_MISSING, **kw):
        self.used.add(key)
        self._record(key, kind, default, kw.get("choices"))
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


def _number(value, where):
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ScenarioError(f"{where}: expected a number, found {_show(value)}")
    if not math.isfinite(value):
        raise ScenarioError(f"{where}: expected a finite number, found {value}")
    return float(value)


def _convert(value, kind, where, choices=None):
    if kind == "number":
        return _number(value, where)
    if kind == "positive":
        if isinstance(value, int | float) and not isinstance(value, bool) and not value > 0:
            raise ScenarioError(f"{where}: expected a positive number, found {value}")
        x = _number(value, where)
        return x
    if kind == "nonnegative":
        x = _number(value, where)
        if x < 0:
            raise ScenarioError(f"{where}: expected a number ≥ 0, found {value}")
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
    if kind in ("vector3", "vector4", "vector2", "vector"):
        n = {"vector3": 3, "vector4": 4, "vector2": 2, "vector": None}[kind]
        if not isinstance(value, list) or (n is not None and len(value) != n):
            what = f"an array of {n} numbers" if n else "an array of numbers"
            raise ScenarioError(f"{where}: expected {what}, found {_show(value)}")
        return np.array([_number(v, f"{where}[{i}]") for i, v in enumerate(value)])
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
        return np.array([_convert(row, "vector3", f"{where}[{i}]") for i, row in enumerate(value)])
    if kind == "vectors3":
        if not isinstance(value, list) or not value:
            raise ScenarioError(
                f"{where}: expected a non-empty array of 3-vectors, found {_show(value)}"
            )
        return np.array([_convert(row, "vector3", f"{where}[{i}]") for i, row in enumerate(value)])
    raise AssertionError(kind)  # pragma: no cover


# --------------------------------------------------------------------------- bodies
