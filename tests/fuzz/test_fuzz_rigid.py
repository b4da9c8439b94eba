"""Fuzz ``simulate``, ``simulate_ensemble`` and ``simulate_relative`` (issue 26): each call is
accepted with a result that passes its own check, refused naming the argument, or fails as a
documented :class:`~poinsot.SimulationError` (:mod:`fuzzing`)."""

from __future__ import annotations

import numpy as np
import pytest
from fuzzing import FEW, MANY, finite, number, odd_objects, outcome, sometimes, vector3
from hypothesis import event, given
from hypothesis import strategies as st

from poinsot import FreeRigidBody, RigidBody, simulate
from poinsot.ensemble import simulate_ensemble
from poinsot.relative import Carrier, simulate_relative

METHODS = sometimes(
    st.sampled_from(["dop853", "rk4", "rkmk4", "splitting"]), st.sampled_from(["euler", 3, None])
)


@st.composite
def runs(draw):
    """Keyword arguments of a torque-free run of a box: mostly sensible, sometimes not."""
    sizes = draw(st.tuples(*[st.floats(0.2, 3.0)] * 3))
    body = RigidBody.box(draw(st.floats(0.1, 10.0)), sizes)
    T = draw(st.floats(0.05, 30.0))
    t_span = draw(sometimes(st.sampled_from([(0.0, T), (-T, T), (T, 2 * T)]),
                            st.tuples(number(finite), number(finite)), odd_objects))  # fmt: skip
    omega0 = draw(vector3(st.floats(-5, 5)))
    method = draw(METHODS)
    kw = {"omega0": omega0, "method": method}
    if draw(st.booleans()) or method in ("rk4", "rkmk4", "splitting"):
        kw["dt"] = draw(sometimes(st.floats(1e-3, 0.5), number(st.floats(1e-3, 0.5)), st.none()))
    if draw(st.booleans()):
        kw["rtol"] = draw(number(st.floats(1e-13, 1e-2)))
    if draw(st.booleans()):
        kw["atol"] = draw(number(st.floats(1e-14, 1e-3)))
    if draw(st.booleans()):
        n = draw(st.integers(0, 6))
        grid = sorted(draw(st.lists(st.floats(0.0, T), min_size=n, max_size=n, unique=True)))
        kw["t_eval"] = draw(
            sometimes(
                st.just(grid),
                st.just(grid[::-1]),
                st.just([]),
                st.just([0.0, np.nan]),
                odd_objects,
                share=0.2,
            )
        )
    if draw(st.booleans()):
        kw["max_steps"] = draw(sometimes(st.integers(1, 10**5), number(st.integers(1, 10))))
    if draw(st.booleans()):
        rotations = [(1.0, 0.0, 0.0, 0.0), np.eye(3), (0.5, 0.5, 0.5, 0.5)]
        kw["Q0"] = draw(sometimes(st.sampled_from(rotations), vector3(), odd_objects))
    return body, t_span, kw


RUN_ARGS = ["body", "t_span", "omega0", "method", "dt", "rtol", "atol", "t_eval", "max_steps",
            "Q0"]  # fmt: skip


def _accuracy_ok(kw, speed):
    """Whether the run is accurate enough for its invariants to be checked (tolerances or a
    step that resolve the motion)."""
    method = kw["method"]
    if method == "dop853":
        rtol, atol = kw.get("rtol") or 1e-10, kw.get("atol") or 1e-12
        return rtol <= 1e-7 and atol <= 1e-9 * max(speed, 1e-300)
    return kw.get("dt") is not None and kw["dt"] * speed <= 0.05


def _check_rigid(body, t_span, kw):
    def check(traj):
        t0, t1 = float(t_span[0]), float(t_span[1])
        t_eval = kw.get("t_eval")
        assert traj.success
        if t_eval is not None:
            np.testing.assert_array_equal(traj.t, np.asarray(t_eval, dtype=float))
        else:
            assert traj.t[0] == t0 and traj.t[-1] == pytest.approx(t1, rel=1e-12, abs=1e-12)
        assert np.isfinite(traj.state).all()
        if not len(traj.t):
            return
        w0 = np.asarray(kw["omega0"], dtype=float)
        if traj.t[0] == t0:  # the first sample is the initial state, exactly
            speed0 = float(np.linalg.norm(w0))
            np.testing.assert_allclose(traj.omega[0], w0, rtol=0, atol=1e-14 * speed0 + 1e-300)
        if kw["method"] in ("rkmk4", "splitting"):  # steps on SO(3): Q stays a rotation
            assert traj.orthogonality_error.max() < 1e-9
        free = FreeRigidBody.from_body(body)
        k, a = free.invariants(traj.omega)  # body frame: 2k = ω·Aω, a = |Aω|
        speed = float(np.linalg.norm(traj.omega, axis=1).max())
        if speed > 0 and _accuracy_ok(kw, speed):
            event("invariants checked")
            k0, a0 = free.invariants(w0)
            np.testing.assert_allclose(k, k0, rtol=1e-2, atol=1e-12 * speed**2)
            np.testing.assert_allclose(a, a0, rtol=1e-2, atol=1e-12 * speed)

    return check


def _simulate(case):
    body, t_span, kw = case
    if kw.get("max_steps") is None and kw["method"] == "dop853":
        kw["max_steps"] = 10**5  # a bounded run, quick enough for a fuzz test
    outcome(lambda: simulate(body, t_span, **kw), _check_rigid(body, t_span, kw), RUN_ARGS,
            what=f"simulate(t_span={t_span!r}, {kw!r})")  # fmt: skip


@FEW
@given(runs())
def test_simulate(case):
    _simulate(case)


@pytest.mark.slow
@MANY
@given(runs())
def test_simulate_many(case):
    _simulate(case)


# ----------------------------------------------------------------- ensembles
@st.composite
def ensembles(draw):
    body, t_span, kw = draw(runs())
    kw.pop("Q0", None)
    kw.pop("max_steps", None)
    m = draw(st.integers(0, 4))
    rows = draw(st.lists(st.tuples(*[st.floats(-3, 3)] * 3), min_size=m, max_size=m))
    kw["omega0"] = draw(sometimes(st.just(np.array(rows).reshape(m, 3)), vector3(),
                                  st.just([[0.0, 1.0]]), odd_objects))  # fmt: skip
    kw["keep_states"] = draw(st.booleans())
    kw["progress"] = False
    return body, t_span, kw


def _ensemble(case):
    body, t_span, kw = case

    def check(res):
        """Every member is the single-body run of its initial spin (the core runs each member
        as that run: bit for bit)."""
        W = np.asarray(kw["omega0"], dtype=float)
        assert res.final_state.shape == (len(W), 18)
        i = len(W) // 2
        if not res.success[i] or (kw["method"] == "dop853" and kw.get("dt") is not None):
            return
        single = {k: v for k, v in kw.items() if k not in ("keep_states", "progress")}
        # runs end at their last sample (t1 without samples, or with an empty t_eval)
        last = kw.get("t_eval")
        last = [float(t_span[1])] if last is None or not len(last) else last
        single.update(omega0=W[i], t_eval=last, max_steps=10**8)
        traj = simulate(body, t_span, **single)
        event("member = single run checked")
        np.testing.assert_allclose(res.final_omega[i], traj.omega[-1], rtol=1e-12, atol=1e-12)

    outcome(lambda: simulate_ensemble(body, t_span, **kw), check,
            [*RUN_ARGS, "keep_states", "progress", "reductions"],
            what=f"simulate_ensemble(t_span={t_span!r}, {kw!r})")  # fmt: skip


@FEW
@given(ensembles())
def test_simulate_ensemble(case):
    _ensemble(case)


@pytest.mark.slow
@MANY
@given(ensembles())
def test_simulate_ensemble_many(case):
    _ensemble(case)


# ----------------------------------------------------------------- relative motion
CARRIERS = st.sampled_from([
    {"omega_e": (0.0, 0.0, 1.0)},
    {"omega_e": ("0", "0", "0.2*t")},
    {"omega_e": ("0", "0", "sin(t)"), "origin_acceleration": (0.0, 0.0, 0.0)},
    {"euler_angles": ("t", "0.3", "0")},
])  # fmt: skip


@st.composite
def relative_runs(draw):
    body, t_span, kw = draw(runs())
    kw["omega_r0"] = kw.pop("omega0")
    if "Q0" in kw:
        kw["Q_r0"] = kw.pop("Q0")
    if kw["method"] in ("rkmk4", "splitting"):
        kw["method"] = draw(st.sampled_from(["rkmk4", "dop853"]))
    carrier = draw(sometimes(CARRIERS, odd_objects))
    return body, t_span, kw, carrier


def _relative(case):
    body, t_span, kw, carrier = case
    if kw.get("max_steps") is None and kw["method"] == "dop853":
        kw["max_steps"] = 10**5

    def make():
        c = Carrier(**carrier) if isinstance(carrier, dict) else carrier
        return simulate_relative(body, t_span, carrier=c, **kw)

    def check(rel):
        """Seen from the inertial frame the body is torque-free (no forces, the carrier only a
        moving frame, its origin held): the spatial angular momentum about the centre of mass
        is constant."""
        assert rel.success and np.isfinite(rel.y).all()
        if len(rel.t) < 2:
            return
        traj = rel.to_trajectory()
        L = traj.angular_momentum_com
        speed = float(np.linalg.norm(traj.omega, axis=1).max())
        if speed > 0 and _accuracy_ok(kw, speed):
            event("L conserved checked")
            scale = float(np.linalg.norm(L[0])) or 1.0
            assert np.abs(L - L[0]).max() <= 1e-2 * scale + 1e-12 * speed

    outcome(make, check, [*RUN_ARGS, "omega_r0", "Q_r0", "carrier", "omega_e", "euler_angles"],
            what=f"simulate_relative(t_span={t_span!r}, {kw!r}, carrier={carrier!r})")  # fmt: skip


@FEW
@given(relative_runs())
def test_simulate_relative(case):
    _relative(case)


@pytest.mark.slow
@MANY
@given(relative_runs())
def test_simulate_relative_many(case):
    _relative(case)
