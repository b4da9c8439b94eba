"""Fuzz the scenario loader (issue 26): bundled scenarios with values replaced by odd ones, keys
dropped or added, tables replaced, written back as TOML. Each text is accepted as a scenario
that passes its own check (finite, runnable within the step budget, a body with mass) or
refused with a :class:`ScenarioError` that names the file and the key; nothing else
(:mod:`fuzzing`)."""

from __future__ import annotations

import copy
import json
import math
import re
import tomllib

import numpy as np
import pytest
from fuzzing import FEW, HANG, MANY
from hypothesis import event, given
from hypothesis import strategies as st

from bounded import deadline
from poinsot.app.scenario import (
    LagrangianScenario,
    ScenarioError,
    example_text,
    load_scenario,
)
from poinsot.integrate.base import get_solver
from poinsot.integrate.solve import check_budget

BASES = {name: tomllib.loads(example_text(name))
         for name in ("notebook", "tennis-racket-ensemble", "turntable-spin-up", "heavy-top",
                      "pendulum-cartesian")}  # fmt: skip


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v == math.inf else
                                            "-inf" if v == -math.inf else repr(v))  # fmt: skip
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{json.dumps(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(v)


def dumps(data: dict) -> str:
    """TOML text of ``data``: top-level values, then its tables (``[name]``) and arrays of
    tables (``[[name]]``), with any deeper table written inline."""
    lines, sections = [], []
    for key, v in data.items():
        name = json.dumps(key)
        if isinstance(v, dict) and v:
            sections.append((f"[{name}]", v))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            sections += [(f"[[{name}]]", x) for x in v]
        else:
            lines.append(f"{name} = {_value(v)}")
    for header, table in sections:
        lines += ["", header, *(f"{json.dumps(k)} = {_value(x)}" for k, x in table.items())]
    return "\n".join(lines) + "\n"


def test_the_writer_round_trips_every_base():
    for data in BASES.values():
        assert tomllib.loads(dumps(data)) == data


ODD = st.sampled_from([0, -1, 1e300, -1e300, 1e-300, math.nan, math.inf, -math.inf, 2**70, True,
                       "", "x", "1.0", [], [1.0], [0.0, 0.0], [1.0, 2.0, 3.0, 4.0], [[1.0]],
                       ["a", 1.0, 2.0], {}, {"x": 1.0}, [1e300, 1e300, 1e300],
                       [0.0, 0.0, 0.0], 3, 0.5, 1e9]).map(copy.deepcopy)  # fmt: skip
KEYS = st.sampled_from(["spam", "typ", "mass", "omega", "span", "dt", "members", "seq"])


def _paths(data, prefix=()):
    for k, v in data.items():
        yield (*prefix, k)
        if isinstance(v, dict):
            yield from _paths(v, (*prefix, k))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for i, x in enumerate(v):
                yield from _paths(x, (*prefix, k, i))


@st.composite
def scenario_texts(draw):
    data = copy.deepcopy(BASES[draw(st.sampled_from(sorted(BASES)))])
    for _ in range(draw(st.integers(0, 3))):
        paths = list(_paths(data))
        path = draw(st.sampled_from(paths))
        *parent, last = path
        where = data
        for p in parent:
            where = where[p]
        action = draw(st.sampled_from(["scale", "scale", "replace", "replace", "drop", "add"]))
        if action == "scale":  # a plausible change: numbers scaled, mostly still valid
            factor = draw(st.sampled_from([0.5, 2.0, -1.0, 1e-3, 1e3, 0.0]))
            value = where[last]
            if isinstance(value, int | float) and not isinstance(value, bool):
                where[last] = type(value)(value * factor) if factor else value * 0
            elif isinstance(value, list) and all(isinstance(x, float) for x in value):
                where[last] = [x * factor for x in value]
        elif action == "replace":
            where[last] = draw(ODD)
        elif action == "drop":
            del where[last]
        elif isinstance(where, dict):
            where[draw(KEYS)] = draw(ODD)
    return dumps(data)


#: A refusal names the key path (the file's own names too: a parameter "M", a reaction "rod
#: tension T"), with the value when it is a quantity (``body.mass = '2 kk': …``).
KEY_PATH = re.compile(r"^<built-in>: ([A-Za-z_]+(\[\d+\])?)(\.[^.:=\[]+(\[\d+\])*)*"
                      r"( = '[^']*')?: \S")  # fmt: skip


def _check(scenario):
    """What an accepted scenario promises: a span, samples and a step within the budget; a
    body with a positive, finite mass (or a model with its parameters)."""
    t0, t1 = scenario.t_span
    assert math.isfinite(t0) and math.isfinite(t1) and t1 > t0
    assert scenario.samples >= 2
    check_budget(get_solver(scenario.method), t0, t1, scenario.dt)
    if scenario.dt is not None:
        assert math.isfinite(scenario.dt) and scenario.dt > 0
    if isinstance(scenario, LagrangianScenario):
        assert all(math.isfinite(v) for v in scenario.params.values())
        return
    body = scenario.body
    assert math.isfinite(body.mass) and body.mass > 0
    assert np.isfinite(body.inertia).all() and np.all(np.linalg.eigvalsh(body.inertia) >= 0)


def _load(text):
    with deadline(HANG, "load_scenario"):
        try:
            scenario = load_scenario(text)
        except ScenarioError as exc:
            message = str(exc)
            assert KEY_PATH.match(message) or "TOML syntax error" in message, message
            event("refused")
            return
    event("accepted")
    _check(scenario)


@FEW
@given(scenario_texts())
def test_scenario_loader(text):
    _load(text)


@pytest.mark.slow
@MANY
@given(scenario_texts())
def test_scenario_loader_many(text):
    _load(text)
