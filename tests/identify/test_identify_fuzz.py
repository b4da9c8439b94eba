"""Fuzzing ``identify``: every call either returns a result that passes its own checks or
raises ValueError/TypeError naming the argument (never another exception, never NaN)."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from poinsot.identify import identify

ARGUMENTS = ("t", "omega", "rotor_speed", "rotor_axis", "rotor_inertia", "window", "accel",
             "saturation", "loss", "segment", "max_nfev")  # fmt: skip
_NAMED = re.compile(r"`(" + "|".join(ARGUMENTS) + r")[`\[]")


@st.composite
def logs(draw):
    """Logs from plausible throws to garbage: lengths, rates, spins, noise, NaNs, repeats,
    rotors with or without their axis, windows inside or outside."""
    n = draw(st.integers(2, 600))
    rate = draw(st.sampled_from([100.0, 1000.0, 4000.0]))
    t = np.arange(n) / rate + draw(st.floats(-10, 10))
    kind = draw(st.sampled_from(["tumble", "random", "constant"]))
    if kind == "tumble":
        from poinsot.identify.synthetic import logger_block
        from poinsot.torquefree import FreeRigidBody

        body, _ = logger_block()
        w0 = draw(hnp.arrays(float, 3, elements=st.floats(-30, 30, allow_subnormal=False)))
        w = FreeRigidBody.from_body(body).exact_omega(w0, t - t[0])
        w = w + draw(st.floats(0, 0.1)) * np.random.default_rng(n).standard_normal(w.shape)
    elif kind == "random":
        w = draw(hnp.arrays(float, (n, 3), elements=st.floats(-50, 50)))
    else:
        w = np.tile(draw(hnp.arrays(float, 3, elements=st.floats(-5, 5))), (n, 1))

    def sometimes():  # each corruption or option in about one log of five
        return draw(st.integers(0, 4)) == 4  # hypothesis prefers small draws

    if sometimes() and n > 3:
        w[draw(st.integers(0, n - 1)), draw(st.integers(0, 2))] = np.nan
    if sometimes() and n > 3:
        k = draw(st.integers(1, n - 1))
        t[k] = t[k - 1]
    kw = {}
    if sometimes():
        kw["rotor_speed"] = draw(hnp.arrays(float, n, elements=st.floats(0, 1500)))
        if not sometimes():
            kw["rotor_axis"] = draw(hnp.arrays(float, 3, elements=st.floats(-1, 1)))
    elif sometimes():
        kw["rotor_axis"] = draw(hnp.arrays(float, 3, elements=st.floats(-1, 1)))
    if sometimes():
        kw["rotor_inertia"] = draw(st.floats(-1e-5, 1e-5))
    if sometimes():
        a = draw(st.floats(t[0] - 1, t[-1] + 1))
        kw["window"] = (a, a + draw(st.floats(-0.1, 2.0)))
    if sometimes():
        kw["saturation"] = draw(st.floats(-1, 60))
    return t, w, kw


@settings(max_examples=25, deadline=60_000, suppress_health_check=[HealthCheck.too_slow])
@given(logs())
def test_identify_returns_a_checked_result_or_names_the_argument(log):
    _assert_named_or_checked(*log)


def _assert_named_or_checked(t, w, kw):
    """``identify`` either refuses the log naming the argument and the rule, or returns a
    result that passes its own checks, with finite numbers and its window inside the log."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # flagged results are fine: they say so
            res = identify(t, w, **kw)
    except (ValueError, TypeError) as exc:
        assert _NAMED.search(str(exc)), str(exc)
        return
    res.check()
    assert np.all(np.isfinite(res.inertia)) and np.isfinite(res.residual_ratio)
    assert t[0] <= res.window[0] < res.window[1] <= t[-1]


def test_logs_the_fuzz_found_are_refused_by_name():
    # constant ω (a steady spin: the linear fits are singular, LAPACK's eigensolver failed or
    # the output-error fit started from I3 = 0), with and without a rotor; nearly constant ω
    t = np.arange(68) * 0.01
    w = np.ones((68, 3))
    w[1, 0] = 0.0
    _assert_named_or_checked(t, w, {})
    _assert_named_or_checked(4 + np.arange(61) * 0.01, np.full((61, 3), 5.0), {})
    rotor = {"rotor_speed": np.zeros(30), "rotor_axis": np.ones(3), "rotor_inertia": 1e-13}
    _assert_named_or_checked(np.arange(30) * 0.01, np.full((30, 3), 2.0), rotor)
    with pytest.raises(ValueError, match="`omega`: ω is constant"):
        identify(np.arange(30) * 0.01, np.full((30, 3), 2.0), **rotor)
