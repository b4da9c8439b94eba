"""Fuzz :class:`~poinsot.FreeRigidBody` and its methods (issue 26): each call is accepted with a
result that passes its own check (the invariants along the exact solution, Euler's equation,
the period, a second formula), or refused naming the argument (:mod:`fuzzing`)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fuzzing import FEW, MANY, number, odd_objects, outcome, sometimes, vector3
from hypothesis import event, given
from hypothesis import strategies as st

from poinsot import FreeRigidBody
from poinsot.torquefree.solution import MAX_PHASE

SHAPES = st.sampled_from([(1.0, 2.0, 3.0), (1.0, 1.0, 2.0), (2.0, 2.0, 1.0), (1.0, 1.0, 1.0),
                          (1.3, 1.7, 2.9), (3.0, 2.0, 1.0)])  # fmt: skip
scales = st.integers(-60, 60).map(lambda e: 10.0**e)
directions = st.tuples(*[st.sampled_from([0.0, 1e-3, 0.3, 1.0, -0.6])] * 3).filter(any)


@st.composite
def bodies(draw):
    moments = np.array(draw(SHAPES)) * draw(scales)
    return draw(sometimes(st.just(moments), vector3(number(st.floats(0.1, 5.0)))))


@st.composite
def spins(draw):
    return draw(sometimes(st.tuples(directions, scales).map(lambda d: np.array(d[0]) * d[1]),
                          vector3()))  # fmt: skip


def times(scale=1.0):
    grid = st.lists(st.floats(-50, 50), min_size=0, max_size=5).map(lambda v: np.array(v) / scale)
    return sometimes(grid, st.floats(-50, 50).map(lambda x: x / scale),
                     st.just([]), st.just([0.0, np.inf]), st.just(np.nan), odd_objects)  # fmt: skip


def _rel(a, b, rtol):
    scale = max(np.abs(a).max(initial=0.0), np.abs(b).max(initial=0.0), 1e-300)
    assert np.abs(np.asarray(a) - np.asarray(b)).max(initial=0.0) <= rtol * scale, (a, b)


def _same_invariants(free, w, w0):
    k, a = free.invariants(np.atleast_2d(w))
    k0, a0 = free.invariants(w0)
    _rel(k, np.full_like(k, k0), 1e-8)
    _rel(a, np.full_like(a, a0), 1e-8)


METHODS = ["exact_omega", "exact_attitude", "period", "flip_interval", "classify", "invariants",
           "herpolhode", "fixed_point_attitude", "check_feasible", "polhode", "describe",
           "stability", "euler_rhs"]  # fmt: skip


@st.composite
def calls(draw):
    moments = draw(bodies())
    name = draw(st.sampled_from(METHODS))
    w0 = draw(spins())
    ok = isinstance(w0, np.ndarray) and w0.shape == (3,) and np.isfinite(w0).all()
    speed = float(np.linalg.norm(w0)) if ok else 1.0
    t = draw(times(max(speed, 1e-300) if math.isfinite(speed) else 1.0))
    if name == "fixed_point_attitude":  # a principal axis, or anything
        axis = np.eye(3)[draw(st.integers(0, 2))] * draw(scales)
        w0 = draw(sometimes(st.just(axis), st.just(w0)))
    extra = {}
    if name == "check_feasible":
        extra = {"energy": draw(number(st.floats(1e-3, 1e3))),
                 "momentum": draw(number(st.floats(1e-3, 1e3)))}  # fmt: skip
    return moments, name, w0, t, extra


def _call(case):
    moments, name, w0, t, extra = case

    def run():
        free = FreeRigidBody(moments)
        method = getattr(free, name)
        if name in ("exact_omega", "exact_attitude", "herpolhode", "fixed_point_attitude"):
            return free, method(w0, t)
        if name == "check_feasible":
            return free, method(extra["energy"], extra["momentum"])
        return free, method(w0)

    def check(result):
        free, out = result
        I = free.principal_moments
        event(name)
        if name == "exact_omega":  # the invariants along the exact ω(t), ω(0) = ω0
            if len(out):
                _same_invariants(free, out, w0)
            _rel(free.exact_omega(w0, 0.0)[0], w0, 1e-12)
        elif name == "exact_attitude":  # a rotation; L = Q A ω constant in space
            if len(out):
                np.testing.assert_allclose(
                    np.einsum("nki,nkj->nij", out, out),
                    np.broadcast_to(np.eye(3), out.shape),
                    atol=1e-9,
                )
                w = free.exact_omega(w0, t)
                L = np.einsum("nij,jk,nk->ni", out, free.inertia, w)
                _rel(L, np.broadcast_to(free.inertia @ w0, L.shape), 1e-7)
        elif name == "period":  # ω(t + T) = ω(t), where double precision resolves t + T
            if math.isfinite(out) and 4 * np.abs(w0).max() * out < MAX_PHASE:
                assert out > 0
                s = np.array([0.0, 0.37 * out])
                _rel(free.exact_omega(w0, s + out), free.exact_omega(w0, s), 1e-6)
        elif name == "flip_interval":  # half a period of the intermediate-axis motion
            if math.isfinite(out):
                assert out == pytest.approx(free.period(w0) / 2, rel=1e-9)
        elif name == "classify":
            assert out in ("around e1", "around e3", "separatrix", "fixed point", "symmetric",
                           "spherical")  # fmt: skip
        elif name == "invariants":  # 2k = ω·Aω, a = |Aω|, by NumPy
            w = np.asarray(w0, dtype=float)
            with np.errstate(over="ignore"):
                Aw = free.inertia @ w
                k, a = 0.5 * w @ Aw, np.linalg.norm(Aw)
            if math.isfinite(k) and math.isfinite(a):
                assert out[0] == pytest.approx(k, rel=1e-12) and out[1] == pytest.approx(
                    a, rel=1e-12
                )
        elif name == "herpolhode":  # on the invariable plane z = 2k/a
            k, a = free.invariants(w0)
            if len(out) and a > 0 and math.isfinite(2 * k / a):
                np.testing.assert_allclose(out[:, 2], 2 * k / a, rtol=1e-8)
        elif name == "fixed_point_attitude":  # Rodrigues against the real Jordan form
            jordan = free.fixed_point_attitude(w0, t, method="jordan")
            np.testing.assert_allclose(out, jordan, atol=1e-9)
        elif name == "check_feasible":
            assert I[0] <= out <= I[2]
        elif name == "polhode":  # on the energy ellipsoid and the momentum sphere
            k, a = free.invariants(w0)
            _same_invariants(free, out.points, w0)
            assert out.energy == pytest.approx(k, rel=1e-12)
        elif name == "describe":
            k, a = free.invariants(w0)
            assert out["energy"] == k and out["momentum"] == a
        elif name == "stability":
            J = free.jacobian(w0)
            np.testing.assert_allclose(
                np.sort_complex(out.eigenvalues), np.sort_complex(np.linalg.eigvals(J)), atol=1e-12
            )
        elif name == "euler_rhs":  # A ω̇ = Aω × ω (Euler's equation (20))
            w = np.asarray(w0, dtype=float)
            with np.errstate(over="ignore", invalid="ignore"):
                rhs = np.cross(free.inertia @ w, w)
            scale = np.abs(free.inertia).max() * float(w @ w)  # |A| |ω|²
            if np.isfinite(rhs).all() and math.isfinite(scale):
                assert np.abs(free.inertia @ out - rhs).max() <= 1e-12 * scale

    outcome(run, check, ["moments", "omega0", "omega", "t", "energy", "momentum", "Q0"],
            what=f"FreeRigidBody({moments!r}).{name}({w0!r}, t={t!r}, {extra!r})")  # fmt: skip


@FEW
@given(calls())
def test_free_rigid_body(case):
    _call(case)


@pytest.mark.slow
@MANY
@given(calls())
def test_free_rigid_body_many(case):
    _call(case)
