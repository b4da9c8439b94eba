"""Honest refusals: bad input is refused naming the argument, and a motion that does not
determine a ratio or an axis is refused saying which (never a confident wrong number)."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import RigidBody
from poinsot.identify import NotIdentifiableError, identify, synthetic_throw
from poinsot.identify.estimate import MAX_RATIO_STDERR, MAX_SAMPLES, MIN_SAMPLES


@pytest.fixture(scope="module")
def log():
    th = synthetic_throw(seed=31, accel=True)
    return th.t, th.omega, th.kwargs()


def _bad(t, w, kw, **change):
    return t, w, {**kw, **change}


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (
            lambda t, w, kw: (np.r_[t[:5], t[4], t[6:]], w, kw),
            r"`t` must increase strictly: "
            r"t\[5\].*repeats",
        ),
        (lambda t, w, kw: (np.r_[t[:5], t[3], t[6:]], w, kw), r"`t`.*goes back"),
        (
            lambda t, w, kw: (t, np.where(np.arange(len(t))[:, None] == 7, np.nan, w), kw),
            r"`omega` has a NaN or infinite sample at row 7",
        ),
        (lambda t, w, kw: (t, w[:-1], kw), r"`omega` must have shape \(2001, 3\)"),
        (lambda t, w, kw: (t, w[:, :2], kw), r"`omega` must have shape"),
        (
            lambda t, w, kw: (t, w, {k: v for k, v in kw.items() if k != "rotor_axis"}),
            r"`rotor_speed` was given without `rotor_axis`",
        ),
        (
            lambda t, w, kw: (t, w, {"rotor_axis": (0, 0, 1)}),
            r"`rotor_axis` was given without "
            r"`rotor_speed`",
        ),
        (lambda t, w, kw: (t, w, {"rotor_inertia": 1e-6}), r"`rotor_inertia` was given without"),
        (lambda t, w, kw: _bad(t, w, kw, rotor_axis=(0, 0, 0)), r"`rotor_axis` must be a nonzero"),
        (
            lambda t, w, kw: _bad(t, w, kw, rotor_inertia=-1.0),
            r"`rotor_inertia` must be a "
            r"positive",
        ),
        (
            lambda t, w, kw: _bad(t, w, kw, rotor_speed=np.r_[np.nan, kw["rotor_speed"][1:]]),
            r"`rotor_speed` has a NaN",
        ),
        (
            lambda t, w, kw: _bad(t, w, kw, rotor_speed=kw["rotor_speed"][:10]),
            r"`rotor_speed` must have shape \(2001,\)",
        ),
        (lambda t, w, kw: _bad(t, w, kw, accel=kw["accel"] * np.nan), r"`accel` has a NaN"),
        (
            lambda t, w, kw: _bad(t, w, kw, window=(0.1, 0.9)),
            r"`window` \(0.1, 0.9\) s reaches "
            r"outside the log.*shorter than",
        ),
        (lambda t, w, kw: _bad(t, w, kw, window=(-1.0, 0.2)), r"`window`.*outside the log"),
        (lambda t, w, kw: _bad(t, w, kw, window=(0.3, 0.2)), r"`window` must be \(start, end\)"),
        (lambda t, w, kw: _bad(t, w, kw, window=(0.3,)), r"`window` must have shape \(2,\)"),
        (lambda t, w, kw: _bad(t, w, kw, loss="l1"), r"`loss` must be one of"),
        (lambda t, w, kw: _bad(t, w, kw, segment=0.0), r"`segment` must be a positive"),
        (lambda t, w, kw: _bad(t, w, kw, segment=1e-3), r"`segment` = 0.001 s splits"),
        (lambda t, w, kw: _bad(t, w, kw, max_nfev=0), r"`max_nfev` must be a positive integer"),
        (lambda t, w, kw: _bad(t, w, kw, saturation=-3.0), r"`saturation` must be a positive"),
        (lambda t, w, kw: ([0.0], w[:1], {}), r"`t` must hold at least 2 samples"),
    ],
)
def test_bad_input_is_refused_by_name(log, edit, match):
    t, w, kw = edit(*log)
    with pytest.raises(ValueError, match=match):
        identify(t, w, **kw)


@pytest.mark.parametrize(
    ("t", "omega", "name"),
    [("abc", np.zeros((3, 3)), "`t`"), (np.arange(3.0), {"x": 1}, "`omega`"),
     (np.arange(3.0), np.ones((3, 3)) * 1j, "`omega`")],
)  # fmt: skip
def test_wrong_types_are_refused_by_name(t, omega, name):
    with pytest.raises(TypeError, match=name):
        identify(t, omega)


def test_every_gyro_sample_saturated_is_refused():
    t = np.arange(100) / 100
    with pytest.raises(ValueError, match=r"`omega`: every gyro sample is saturated"):
        identify(t, np.full((100, 3), 35.0), saturation=35.0)


def test_a_window_too_long_is_refused_up_front():
    n = MAX_SAMPLES + 10
    t = np.arange(n) / 4000.0
    w = np.column_stack([np.sin(t), np.cos(t), np.sin(2 * t)]) * 5
    with pytest.raises(ValueError, match=rf"`window`.*more than {MAX_SAMPLES} samples"):
        identify(t, w)


# ---------------------------------------------------------------------- identifiability
def test_a_spin_about_one_principal_axis_is_not_identifiable():
    th0 = synthetic_throw(seed=3, rotor=False)
    for k in range(3):
        w0 = 25 * th0.axes[:, k] + 0.02 * th0.axes[:, (k + 1) % 3]
        th = synthetic_throw(seed=3, rotor=False, omega0=w0)
        with pytest.raises(NotIdentifiableError, match="spin about one principal axis") as err:
            identify(th.t, th.omega)
        assert {"I1/I3", "I2/I3"} & set(err.value.unidentifiable)
        assert "`omega`" in str(err.value) and "I1/I3 (standard error" in str(err.value)
        assert err.value.result is not None


def test_the_rotor_makes_a_spin_about_one_axis_identifiable():
    """The flywheel's spin-up turns the body off its axis: the same spin with the rotor is
    identified (the point of the logger's flywheel)."""
    th0 = synthetic_throw(seed=3)
    th = synthetic_throw(seed=3, omega0=25 * th0.axes[:, 2] + 0.02 * th0.axes[:, 0])
    res = identify(th.t, th.omega, **th.kwargs())
    assert np.all(np.abs(res.ratios / th.ratios - 1) < 0.005)


def test_too_short_a_window_is_not_identifiable():
    th = synthetic_throw(seed=3, rotor=False)
    with pytest.raises(NotIdentifiableError, match=r"`window`.*too short.*at least "
                                                   rf"{MIN_SAMPLES} samples") as err:  # fmt: skip
        identify(th.t, th.omega, window=(0.1, 0.1 + 20 / 4000))
    assert set(err.value.unidentifiable) == {"I1/I3", "I2/I3", "e1", "e2", "e3"}
    # 60 ms (240 samples) turn the body 1.5 rad: too little to separate the moments
    th = synthetic_throw(seed=3, rotor=False, duration=0.06)
    with pytest.raises(NotIdentifiableError, match=r"does not identify I1/I3") as err:
        identify(th.t, th.omega)
    assert err.value.result.ratios_stderr[0] > MAX_RATIO_STDERR


def test_too_little_rotation_is_not_identifiable():
    th = synthetic_throw(seed=3, rotor=False, spin=1.0)
    with pytest.raises(NotIdentifiableError, match=r"too little rotation.*turned 0.5 rad"):
        identify(th.t, th.omega)


def test_a_symmetric_body_names_the_axes_that_turn_freely():
    body = RigidBody.box(0.2, (0.05, 0.05, 0.12))  # I2 = I3: e2, e3 free in their plane
    th = synthetic_throw(seed=3, rotor=False, body=body)
    with pytest.raises(NotIdentifiableError, match="I2 and I3 are nearly equal") as err:
        identify(th.t, th.omega)
    assert {"e2", "e3"} <= set(err.value.unidentifiable) and "e1" not in err.value.unidentifiable
    # 2 % away from symmetric is identified
    body = RigidBody.box(0.2, (0.05, 0.051, 0.12))
    th = synthetic_throw(seed=3, rotor=False, body=body)
    res = identify(th.t, th.omega)
    assert np.all(np.abs(res.ratios / th.ratios - 1) < 0.005)
