"""Every array layout (issue 44, item 1): the public functions and the compiled bindings take
an array in any layout and real dtype NumPy converts — slices with steps, a column of a
table, negative strides, Fortran order, big-endian, float32, int64, a list, a misaligned
buffer — and return what they return for the same values as a C-contiguous float64 array,
bit for bit. The bindings convert in one place (crates/python/src/arrays.rs): one copy where
the input is not C-contiguous float64, none where it is; refusals name the argument."""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import poinsot
from poinsot import RigidBody, _core, rotation

# ------------------------------------------------------------------------------- layouts

#: Layouts of the same values; each keeps the values exactly (float32 and int64 only where
#: the values are exact in them, see `layout`).
STRIDED = ("step", "column", "reversed", "fortran", "misaligned")
DTYPES = (">f8", "float32", "int64", "list")
LAYOUTS = ("c", *STRIDED, *DTYPES)

FAST = settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def layout(a, kind: str, step: int = 2):
    """The values of `a` (float64) in the layout `kind`."""
    a = np.array(a, dtype=float)
    if kind == "c":
        return a
    if kind == "step":  # every `step`-th element along the first axis of a larger buffer
        big = np.full((a.shape[0] * step, *a.shape[1:]), np.nan)
        big[::step] = a
        return big[::step]
    if kind == "column":  # a column of a wider table, as `d[:, 1]` of np.loadtxt's array
        big = np.full((*a.shape, 3), np.nan)
        big[..., 1] = a
        return big[..., 1]
    if kind == "reversed":  # negative strides along every axis
        flip = (slice(None, None, -1),) * a.ndim
        return a[flip].copy()[flip]
    if kind == "fortran":  # column-major, a transpose's memory (1-D: the C order, as NumPy's)
        return np.asfortranarray(a)
    if kind == "misaligned":  # float64 at an odd address, as in a pickled buffer
        raw = np.zeros(a.nbytes + 1, dtype=np.uint8)[1:].view(np.float64)
        raw[:] = a.ravel()
        out = raw.reshape(a.shape)
        assert a.size == 0 or not out.flags.aligned
        return out
    if kind == ">f8":
        return a.astype(">f8")
    if kind == "float32":
        assert np.array_equal(a.astype(np.float32), a), "values not exact in float32"
        return a.astype(np.float32)
    if kind == "int64":
        assert np.array_equal(a.astype(np.int64), a), "values not integers"
        return a.astype(np.int64)
    if kind == "list":
        return a.tolist()
    raise AssertionError(kind)


def layouts(*, ints: bool = True, f32: bool = True):
    """A layout, and a step for `step`."""
    kinds = [k for k in LAYOUTS if (ints or k != "int64") and (f32 or k != "float32")]
    return st.tuples(st.sampled_from(kinds), st.integers(2, 3))


def _equal(a, b) -> bool:
    """Bit for bit (NaN where NaN)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True)


def test_the_layouts_are_what_they_say():
    a = np.arange(12.0).reshape(4, 3)
    for kind in LAYOUTS:
        x = layout(a, kind)
        assert np.array_equal(np.asarray(x, dtype=float), a), kind
        if kind in STRIDED:
            assert not (x.flags.c_contiguous and x.flags.aligned), kind
        if kind in DTYPES:
            assert not isinstance(x, np.ndarray) or x.dtype != np.float64, kind


# --------------------------------------------------------------------------- simulate

BODY = RigidBody.box(2.0, (1.0, 2.0, 3.0))
# a quarter turn about z: a rotation matrix of integers, exact in every dtype
QUARTER = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
# an inertia tensor of integers (principal moments about 3.3, 5 and 6.7)
INERTIA = np.array([[4.0, 1.0, 0.0], [1.0, 5.0, 1.0], [0.0, 1.0, 6.0]])


def _trajectory(tr):
    return tr.t, tr.state


@FAST
@given(layouts(), st.integers(2, 5))
def test_simulate_t_eval(kind, n):
    step = 1.0 if kind[0] == "int64" else 0.25  # exact in the layout's dtype
    t_eval = np.arange(n) * step
    span = (0.0, t_eval[-1])
    x = layout(t_eval, *kind)
    got = poinsot.simulate(BODY, span, omega0=(0.1, 1, 0.2), t_eval=x)
    ref = poinsot.simulate(BODY, span, omega0=(0.1, 1, 0.2), t_eval=t_eval.copy())
    assert all(map(_equal, _trajectory(got), _trajectory(ref)))


def test_simulate_t_eval_of_the_issue():
    te = np.linspace(0, 1, 41)[::2]
    got = poinsot.simulate(BODY, (0, 1), omega0=(0.1, 1, 0.2), t_eval=te)
    ref = poinsot.simulate(BODY, (0, 1), omega0=(0.1, 1, 0.2), t_eval=te.copy())
    assert all(map(_equal, _trajectory(got), _trajectory(ref)))


@FAST
@given(layouts(), layouts())
def test_simulate_omega0_and_Q0(kw, kq):
    w0 = layout([1.0, 2.0, -1.0], *kw)
    q0 = layout(QUARTER, *kq)
    got = poinsot.simulate(BODY, (0, 0.5), omega0=w0, Q0=q0)
    ref = poinsot.simulate(BODY, (0, 0.5), omega0=np.array([1.0, 2.0, -1.0]), Q0=QUARTER.copy())
    assert all(map(_equal, _trajectory(got), _trajectory(ref)))


# --------------------------------------------------------------------------- identify


@pytest.fixture(scope="module")
def throw():
    from poinsot.identify.synthetic import synthetic_throw

    return synthetic_throw(seed=7, duration=0.3)


def _identify(t, omega, rotor_speed, throw):
    from poinsot.identify import identify

    kw = throw.kwargs()
    kw["rotor_speed"] = rotor_speed
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = identify(t, omega, **kw)
    return r.inertia, r.ratios, r.axes


def test_identify_on_the_columns_of_a_table(throw):
    """The issue's call: `identify(d[:, 0], d[:, 1:4], rotor_speed=d[:, 4])` on a table as
    np.loadtxt returns it (was: TypeError, the array is not contiguous)."""
    d = np.column_stack([throw.t, throw.omega, throw.rotor_speed])
    got = _identify(d[:, 0], d[:, 1:4], d[:, 4], throw)
    ref = _identify(throw.t, throw.omega, throw.rotor_speed, throw)
    for a, b in zip(got, ref, strict=True):
        assert np.array_equal(a, b)


FLOATS = [k for k in LAYOUTS if k != "int64"]


def _f32(a, kind):
    """`a`'s values as the layout `kind` holds them (float32 rounds)."""
    return a.astype(np.float32).astype(float) if kind == "float32" else a


@settings(max_examples=6, deadline=None)
@given(st.sampled_from(FLOATS), st.sampled_from(FLOATS), st.sampled_from(FLOATS))
def test_identify_layouts(throw, kt, kw, ks):
    """The time axis, ω and the rotor's speed in every layout: bit for bit against the same
    values as C-contiguous float64 (the smoothing filter works on a C-contiguous copy, so its
    rounding does not depend on the layout)."""
    t, w, s = _f32(throw.t, kt), _f32(throw.omega, kw), _f32(throw.rotor_speed, ks)
    got = _identify(layout(t, kt), layout(w, kw), layout(s, ks), throw)
    ref = _identify(t, w, s, throw)
    assert all(map(_equal, got, ref))


# -------------------------------------------------------------------------- ensembles


@FAST
@given(layouts(), st.integers(1, 4))
def test_simulate_ensemble_omega0(kind, n):
    from poinsot.ensemble import simulate_ensemble

    w = np.arange(3.0 * n).reshape(n, 3) % 5 - 2.0  # integers, exact everywhere
    x = layout(w, *kind)
    kw = dict(dt=0.05, threads=1, t_eval=np.linspace(0, 0.5, 6))
    got = simulate_ensemble(BODY, (0, 0.5), omega0=x, **kw)
    ref = simulate_ensemble(BODY, (0, 0.5), omega0=w.copy(), **kw)
    for name in ("state", "final_state", "energy_error", "flip_count"):
        assert _equal(getattr(got, name), getattr(ref, name)), name


@FAST
@given(layouts(), layouts())
def test_simulate_ensemble_Q0_and_t_eval(kq, kt):
    from poinsot.ensemble import simulate_ensemble

    q = np.stack([QUARTER, QUARTER.T, np.eye(3)])
    t_eval = np.arange(5.0) / 8 if kt[0] != "int64" else np.arange(2.0)
    w = np.array([[1.0, 2.0, 0.5], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]])
    kw = dict(dt=0.0625, threads=1, omega0=w)
    span = (0, float(t_eval[-1]))
    got = simulate_ensemble(BODY, span, Q0=layout(q, *kq), t_eval=layout(t_eval, *kt), **kw)
    ref = simulate_ensemble(BODY, span, Q0=q.copy(), t_eval=t_eval.copy(), **kw)
    assert _equal(got.state, ref.state) and _equal(got.t, ref.t)


# ------------------------------------------------------------------ bodies and rotation


@FAST
@given(layouts(), layouts(), st.integers(1, 6))
def test_from_particles(km, kp, n):
    rng = np.random.default_rng(n)
    masses = rng.integers(1, 5, n).astype(float)
    positions = rng.integers(-3, 4, (n, 3)).astype(float)
    got = RigidBody.from_particles(layout(masses, *km), layout(positions, *kp))
    ref = RigidBody.from_particles(masses, positions)
    assert _equal(got.inertia, ref.inertia) and _equal(got.center_of_mass, ref.center_of_mass)
    assert _equal(got.principal_moments, ref.principal_moments)


@FAST
@given(layouts(), layouts(), layouts())
def test_body_inertia_layouts(ki, kp, ka):
    inertia = INERTIA.copy()
    body = RigidBody(2.0, layout(inertia, *ki))
    ref = RigidBody(2.0, inertia)
    assert _equal(body.inertia, ref.inertia)
    assert _equal(body.principal_axes, ref.principal_axes)
    point = np.array([1.0, -2.0, 3.0])
    assert _equal(body.inertia_about(layout(point, *kp)), ref.inertia_about(point))
    axis = np.array([0.0, 1.0, 1.0])
    assert _equal(body.moment_of_inertia(layout(axis, *ka)), ref.moment_of_inertia(axis))
    placed = ref.placed(orientation=layout(QUARTER, *ka))
    assert _equal(placed.inertia, ref.placed(orientation=QUARTER.copy()).inertia)


@FAST
@given(layouts(), st.integers(1, 5))
def test_rotation_functions(kind, n):
    rng = np.random.default_rng(n)
    v = rng.integers(-4, 5, (n, 3)) / 4
    q = rng.integers(-4, 5, (n, 4)) / 4 + np.array([2.0, 0, 0, 0])
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q32 = q.astype(np.float32).astype(float)  # exact in float32
    R = rotation.matrix_from_quat(q32)
    if kind[0] in ("int64", "float32"):  # values exact in the dtype
        v, R = np.round(v), np.stack([QUARTER] * n)
    angles = v.copy()
    angles[:, 1] = 1.0 + np.abs(v[:, 1]) / 4  # θ away from 0 and π (gimbal lock)
    if kind[0] == "int64":
        angles[:, 1] = 1.0
    for f, x in (
        (rotation.matrix_from_rotvec, v),
        (rotation.quat_from_matrix, R),
        (rotation.rotvec_from_matrix, R),
        (lambda a: rotation.euler_rates_from_body(a, v), angles),
        (lambda a: rotation.euler_rates_from_body(angles, a), v),
        (lambda a: rotation.body_rates_from_euler(a, v), angles),
    ):
        assert _equal(f(layout(x, *kind)), f(x.copy()))
    if kind[0] != "int64":
        assert _equal(rotation.matrix_from_quat(layout(q32, *kind)), rotation.matrix_from_quat(q32))


# ---------------------------------------------------------------- the bindings, directly


@FAST
@given(layouts(), layouts())
def test_core_rotational_energies_and_momenta(ki, kw):
    inertia = INERTIA.copy()
    w = np.arange(12.0).reshape(4, 3) - 5.0
    i_x, w_x = layout(inertia, *ki), layout(w, *kw)
    assert _equal(_core.rotational_energies(i_x, w_x), _core.rotational_energies(inertia, w))
    assert _equal(_core.angular_momenta(i_x, w_x), _core.angular_momenta(inertia, w))
    assert _equal(
        _core.rotational_energies_and_momenta(i_x, w_x),
        _core.rotational_energies_and_momenta(inertia, w),
    )


@FAST
@given(layouts(ints=False), layouts(), layouts(ints=False))
def test_core_gyrostat_omegas(kt, km, ks):
    """The binding behind `identify` that refused a column of a table (`t`, `rotor_speed`)."""
    t = np.arange(0.0, 0.25, 1 / 64)
    speed = 100.0 + 16 * t
    moments = np.array([[2.0, 3.0, 4.0]])
    axes = np.eye(3)[None]
    args = (np.array([0.01]), np.array([[1.0, 0.5, 0.25]]))
    from poinsot.identify.output_error import gyrostat_run

    axis = np.array([0.0, 0.0, 1.0])
    got = _core.gyrostat_omegas(
        layout(moments, *km), layout(axes, *km), *args, gyrostat_run(layout(t, *kt), 1 / 128),
        layout(t, *kt), layout(speed, *ks), axis,
    )  # fmt: skip
    ref = _core.gyrostat_omegas(moments, axes, *args, gyrostat_run(t, 1 / 128), t, speed, axis)
    assert _equal(got, ref)


@FAST
@given(layouts(), layouts(ints=False))
def test_core_exact_and_geometry(kind, kf):
    u = np.arange(-4.0, 5.0) / 4
    ref = _core.jacobi_sn_cn_dn_am(u, 0.25, 0.75)
    got = _core.jacobi_sn_cn_dn_am(layout(u, *kf), 0.25, 0.75)
    assert all(map(_equal, got, ref))
    inertia = INERTIA.copy()
    got = _core.principal_decomposition(layout(inertia, *kind))
    assert all(map(_equal, got, _core.principal_decomposition(inertia)))
    # a tetrahedron: vertices (float) and faces (int64, here in the layout too)
    verts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=float)
    got = _core.polyhedron_mass_properties(layout(verts, *kind), layout(faces, *kind))
    ref = _core.polyhedron_mass_properties(verts, faces.astype(np.int64))
    assert all(map(_equal, got, ref))


@functools.cache
def _falling_box():
    """The engine's arguments for a box under gravity: body parameters, force kinds and
    parameters, sample times and engine states (C-contiguous, of the bindings' dtypes)."""
    tr = poinsot.simulate(
        BODY, (0, 0.5), omega0=(0.5, 1, 0.25), V0=(1, 0, 2), forces=[poinsot.Gravity()],
        t_eval=np.arange(5.0) / 8,
    )  # fmt: skip
    system = tr.system
    kinds = np.asarray(system.force_kind, dtype=np.int64)
    params = np.asarray(system.force_params, dtype=float).reshape(len(kinds), -1)
    states = np.ascontiguousarray(system.to_internal(tr.state))
    return system.body_parameters(), kinds, params, np.ascontiguousarray(tr.t), states


@FAST
@given(layouts(ints=False, f32=False), layouts(), layouts(ints=False, f32=False))
def test_core_potential_energies(kb, kk, ks):
    """`body` and `t` (1-D), `force_kind` (int64, 1-D), `force_params` and `states` (2-D)."""
    body, kinds, params, t, states = _falling_box()
    ref = _core.potential_energies(body, kinds, params, t, states)
    got = _core.potential_energies(
        layout(body, *kb), layout(kinds, *kk), layout(params, *kb), layout(t, *kb),
        layout(states, *ks),
    )  # fmt: skip
    assert _equal(got, ref)


def test_core_carrier_tuple_and_run_spec():
    """Arrays inside tuples (a carrier's piecewise polynomials; a tableau) and optional ones
    (`t_eval`) go through the same conversion."""
    breaks = np.array([0.0, 0.5, 1.0])
    coeffs = np.arange(18.0).reshape(3, 2, 3) / 8
    t = np.arange(9.0) / 8
    ref = _core.carrier_motions((breaks, coeffs, breaks, coeffs), t)
    for kind in (k for k in LAYOUTS if k != "int64"):
        b, c = layout(breaks, kind), layout(coeffs, kind)
        got = _core.carrier_motions((b, c, b, c), layout(t, kind))
        assert _equal(got, ref), kind
    a, bw, cn = _core.tableau("rk4")
    for kind in (*STRIDED, ">f8", "list"):
        spec = _core.RunSpec(
            "rk4", t_end=1.0, dt=0.1, tableau=(layout(a, kind), layout(bw, kind),
            layout(cn, kind)), t_eval=layout(t, kind),
        )  # fmt: skip
        assert _equal(spec.t_eval, t), kind


# ------------------------------------------------------------ no copy, and the refusals


def _initial_states(n, r, out):
    q = np.tile(np.eye(3), (n, 1, 1))
    w = np.ones((n, 3))
    zero = (0.0, 0.0, 0.0)
    return _core.initial_states(q, w, r, np.zeros((0, 3)), zero, zero, zero, False, zero,
                                out=out)  # fmt: skip


def test_a_contiguous_float64_array_is_not_copied():
    """A C-contiguous float64 view of the output buffer reaches the core as it is (the borrow
    checker then refuses to write `out` while it is read); a strided one is copied first."""
    out = np.zeros((1, 18))
    with pytest.raises(TypeError, match="already borrowed"):
        _initial_states(1, out[:, :3], out)
    out = np.zeros((2, 18))
    r = out[:, 3:6]  # strided: copied, so no conflict
    r[:] = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
    _initial_states(2, r, out)
    ref = np.zeros((2, 18))
    _initial_states(2, np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]), ref)
    assert _equal(out, ref)


@pytest.mark.parametrize(
    ("value", "found"),
    [
        ("abc", "found str"),
        (None, "found NoneType"),
        ({"a": 1}, "found dict"),
        (np.ones(3), r"found an array of shape \(3,\)"),
        ([1.0, 2.0, 3.0], r"found list of shape \(3,\)"),
        ([[1.0, 2.0, 3.0], [1.0, 2.0]], "found list"),
        (np.ones((2, 3)) * 1j, "found complex numbers"),
        ([["1", "2", "3"]], "found text"),
    ],
)
def test_refusals_name_the_argument_and_what_was_expected(value, found):
    with pytest.raises(TypeError, match="expected a 2-dimensional array of float64") as e:
        _core.rotational_energies(np.eye(3), value)
    assert e.match(found)
    assert "while processing 'omega'" in getattr(e.value, "__notes__", [])


def test_a_strided_int_array_and_a_float_array_for_ints():
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    verts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    ref = _core.polyhedron_mass_properties(verts, faces)
    for f in (faces.T.copy().T, faces[::-1].copy()[::-1], faces.astype(np.int32),
              faces.astype(">i8"), faces.astype(float), faces.tolist()):  # fmt: skip
        assert all(map(_equal, _core.polyhedron_mass_properties(verts, f), ref))
