# The compiled core, `poinsot._core` (crates/python over crates/core): its names and their
# types, for type checkers. Checked against the built module by `python -m mypy.stubtest
# poinsot._core` (.ci/run) and, name by name, by tests/test_core_stub.py.
#
# Arrays: an array parameter is typed `ArrayLike`: it takes what `numpy.asarray(x, dtype=...)`
# takes for the binding's dtype (float64; int64 for codes, kinds and indices; bool for masks),
# an array of any real dtype in any layout (slices, transposes, Fortran order, big-endian) or
# a list of numbers, and is copied once to C order where it is not C-contiguous float64
# already (crates/python/src/arrays.rs); text and complex numbers are refused. Results, and
# the output buffers the core writes into (`out`, `samples_out`, `finals_out`, the `flips`
# counters), are typed `NDArray[np.float64]` (`_F64`; `_I64`, `_Bool`): those buffers must be
# C-contiguous arrays of exactly that dtype. `_Vec3`, `_Mat3` and `_Numbers` take a sequence
# of numbers as well as an array. Shapes are in the Rust sources' doc comments
# (crates/python/src/*.rs), not in these types.

from collections.abc import Callable, Sequence
from typing import Any, Self, TypeAlias, final, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

_F64: TypeAlias = NDArray[np.float64]
_I64: TypeAlias = NDArray[np.int64]
_Bool: TypeAlias = NDArray[np.bool_]
# a Rust `[f64; 3]` / `[[f64; 3]; 3]` / `Vec<f64>`: any sequence of numbers, or an array
_Vec3: TypeAlias = Sequence[float] | NDArray[np.float64]
_Mat3: TypeAlias = Sequence[Sequence[float]] | NDArray[np.float64]
_Numbers: TypeAlias = Sequence[float] | NDArray[np.float64]
# the user's forces `user(t, y) -> (Fx, Fy, Fz, τx, τy, τz)` of the body-frame state
_Wrench: TypeAlias = Callable[[float, _F64], _Numbers]
# a carrier: piecewise polynomials `(w_breaks, w_coeffs, a_breaks, a_coeffs)`, compiled
# expressions of one input and nine outputs, a C function's address, or `motion(t) -> 9 numbers`
_PPolyCarrier: TypeAlias = tuple[ArrayLike, ArrayLike, ArrayLike, ArrayLike]
_Carrier: TypeAlias = _PPolyCarrier | Expressions | int | Callable[[float], _Numbers]
# an event's zero as `integrate_lagrange` appends it to the log: `(event, t, y)`
_Crossing: TypeAlias = tuple[int, float, _F64]
# `integrate_lagrange`'s events: `(expressions, sources (k, 2), callables g(t, y), terminal
# (k,), direction (k,), spacing, log)`
_Events: TypeAlias = tuple[
    Expressions | None,
    ArrayLike,
    Sequence[Callable[[float, _F64], float]],
    ArrayLike,
    ArrayLike,
    float,
    list[_Crossing],
]

# the module's `__all__` (pyo3 lists every name it adds)
__all__ = [
    "BODY_SIZE",
    "CALLBACK_FAILED",
    "COMPILED_ISAS",
    "COM_OFFSET",
    "DEGENERATE_RTOL",
    "ELLIPTIC_NEAR_ONE",
    "ELLIPTIC_TINY_M1",
    "FIELD_KINDS",
    "FINISHED",
    "FORCE_KINDS",
    "FORCE_PARAMS",
    "HAS_PIVOT",
    "INERTIA_COM",
    "INV_MASS",
    "INV_MOMENTS",
    "ISA",
    "MASS",
    "METHODS",
    "METHOD_KINDS",
    "MOMENTS",
    "MOTION_SIZE",
    "NEAR_UNSTABLE_AXIS",
    "NONFINITE",
    "OMEGA_AT",
    "OUTPUT_FULL",
    "PIVOT",
    "Q_AT",
    "REGIME_OFFSETS",
    "RELATIVE_STATE_SIZE",
    "ROTOR",
    "RUNNING",
    "R_AT",
    "STATE_SIZE",
    "STEP_TOO_SMALL",
    "SYMMETRY_CLASSES",
    "SYMMETRY_RTOL",
    "TERMINATED",
    "TORQUE_FREE_CASE_NAMES",
    "V_AT",
    "Expressions",
    "LagrangianModel",
    "LagrangianTangent",
    "RunSpec",
    "RunState",
    "RunStats",
    "__version__",
    "absolute_states",
    "angular_momenta",
    "axis_rotation",
    "body_vector",
    "box_inertia",
    "carlson_rf",
    "carlson_rj",
    "carrier_motions",
    "center_of_mass",
    "check_inertia",
    "composition",
    "cone_coefficients",
    "cone_inertia",
    "coriolis_moments",
    "coriolis_moments_particles",
    "coriolis_moments_three_term",
    "cylinder_inertia",
    "dexpinv",
    "ellipf",
    "ellipk_m1",
    "ellippi",
    "ellippi_complete",
    "ellipsoid_inertia",
    "energy_ellipsoid_semi_axes",
    "equivalent_box_half_extents",
    "euler_jacobian",
    "euler_omega_dot_free",
    "exp_so3",
    "first_kind_from_sn_cn",
    "fixed_point_attitudes",
    "force_wrench_potential",
    "gyroscopic_precession_rate",
    "gyrostat_omega_dot",
    "gyrostat_omegas",
    "gyrostat_regressor",
    "gyrostat_sensitivities",
    "hat",
    "heavy_top_derivatives",
    "heavy_top_motions",
    "initial_states",
    "integrate_lagrange",
    "integrate_lagrange_sensitivities",
    "integrate_python",
    "integrate_relative",
    "integrate_relative_sensitivities",
    "integrate_rigid",
    "integrate_sensitivities",
    "is_degenerate",
    "jacobi_reduced",
    "jacobi_sn_cn_dn_am",
    "kinetic_energies",
    "lagrange_sensitivity_start",
    "log_so3",
    "matrix_to_quat",
    "member_bodies",
    "momentum_ellipsoid_semi_axes",
    "omega_space",
    "orthogonality_errors",
    "parallel_axis",
    "particle_inertia",
    "particle_motion",
    "pivot_point",
    "planar_inertia",
    "planar_inertia_particles",
    "point_acceleration_matrices",
    "polyhedron_mass_properties",
    "potential_energies",
    "principal_decomposition",
    "principal_invariants",
    "project_onto_pivot",
    "quat_conjugate",
    "quat_multiply",
    "quat_normalize",
    "quat_rotate",
    "quat_to_matrix",
    "quat_to_rotvec",
    "relative_rhs",
    "relative_sensitivity_start",
    "rigid_body_parameters",
    "rigid_motion_from_particles",
    "rigid_rates",
    "rod_inertia",
    "rotate_inertia",
    "rotational_energies",
    "rotational_energies_and_momenta",
    "rotvec_to_quat",
    "run_ensemble",
    "sensitivity_start",
    "sphere_inertia",
    "spherical_shell_inertia",
    "states_principal",
    "steady_precession_rates",
    "symmetric_top_axis",
    "symmetry_code",
    "tableau",
    "third_kind_u",
    "torque_free_attitudes",
    "torque_free_derivatives",
    "torque_free_families",
    "torque_free_omegas",
    "torque_free_regimes",
    "transport_moments",
    "vee",
    "zxz_angle_rates",
    "zxz_body_rates",
    "zxz_matrix",
]

__version__: str

# ------------------------------------------------------------------------------- lib.rs

COMPILED_ISAS: list[str]
ISA: str

# the run's status codes (`poinsot_core::drivers::Status`)
RUNNING: int
FINISHED: int
NONFINITE: int
STEP_TOO_SMALL: int
OUTPUT_FULL: int
CALLBACK_FAILED: int
TERMINATED: int

# ------------------------------------------------------------------------------- spec.rs

# the method registry (`poinsot_core::spec::REGISTRY`): one dict per method users name, with
# the keys `name` (str), `kind` (str, one of `METHOD_KINDS`), `order` (int), `tableau` (str, a
# name of `tableau`, of `composition` for the kind "exact-splitting", or ""), `conserves`
# (tuple of str), `kicks` (bool), `adaptive` (bool) and `summary` (str). (Not a TypedDict:
# stubtest sees the runtime dicts as `dict[Any, Any]`, which no TypedDict accepts.)
METHODS: tuple[dict[str, Any], ...]
METHOD_KINDS: list[str]
# the kinds that run on any vector field (the others need a rigid body's structure)
FIELD_KINDS: list[str]

@final
class RunSpec:
    def __new__(
        cls,
        method: str,
        *,
        t_end: float,
        dt: float = 0.0,
        tableau: tuple[ArrayLike, ArrayLike, ArrayLike] | None = None,
        composition: tuple[ArrayLike, ArrayLike, bool] | None = None,
        rtol: float = 1e-10,
        atol: float = 1e-12,
        safety: float = 0.9,
        min_factor: float = 0.2,
        max_factor: float = 10.0,
        max_step: float = ...,
        first_step: float = 0.0,
        t_eval: ArrayLike | None = None,
        save_every: int = 1,
        max_steps: int = ...,
    ) -> Self: ...
    @property
    def method(self) -> str: ...
    @property
    def dt(self) -> float: ...
    @property
    def t_end(self) -> float: ...
    @property
    def t_eval(self) -> _F64: ...
    @property
    def save_every(self) -> int: ...
    @property
    def max_steps(self) -> int: ...

@final
class RunStats:
    @property
    def samples(self) -> int: ...
    @property
    def steps(self) -> int: ...
    @property
    def evaluations(self) -> int: ...
    @property
    def rejected(self) -> int: ...

@final
class RunState:
    def __new__(cls, t0: float, y0: ArrayLike, capacity: int) -> Self: ...
    @property
    def t(self) -> float: ...
    @property
    def state(self) -> _F64: ...
    @property
    def status(self) -> int: ...
    @property
    def stats(self) -> RunStats: ...
    @property
    def capacity(self) -> int: ...
    def grow(self) -> None: ...
    def samples(self) -> tuple[_F64, _F64]: ...

# ----------------------------------------------------------------------------- engine.rs

def tableau(name: str) -> tuple[_F64, _F64, _F64]: ...
def composition(name: str) -> tuple[_F64, _F64, bool]: ...
def integrate_rigid(
    body: ArrayLike,
    force_kind: ArrayLike,
    force_params: ArrayLike,
    axes: ArrayLike,
    user: _Wrench | int | None,
    spec: RunSpec,
    state: RunState,
    steps: int,
    flips: tuple[_F64, _F64, _F64] | None = None,
) -> int: ...
def integrate_sensitivities(
    body: ArrayLike,
    force_kind: ArrayLike,
    force_params: ArrayLike,
    moment_seeds: ArrayLike,
    force_seeds: ArrayLike,
    control_all: bool,
    spec: RunSpec,
    state: RunState,
    steps: int,
) -> int: ...
def integrate_relative_sensitivities(
    body: ArrayLike,
    force_kind: ArrayLike,
    force_params: ArrayLike,
    carrier: object,
    balance_transport: bool,
    hold_com: bool,
    moment_seeds: ArrayLike,
    force_seeds: ArrayLike,
    control_all: bool,
    spec: RunSpec,
    state: RunState,
    steps: int,
) -> int: ...
def relative_sensitivity_start(
    body: ArrayLike,
    axes: ArrayLike,
    z0: ArrayLike,
    kinds: ArrayLike,
    components: ArrayLike,
) -> _F64: ...
def sensitivity_start(
    body: ArrayLike,
    axes: ArrayLike,
    z0: ArrayLike,
    kinds: ArrayLike,
    components: ArrayLike,
    omega_space: bool = False,
) -> _F64: ...
def integrate_python(
    rhs: Callable[[float, _F64], _Numbers],
    project: Callable[[_F64, float], _Numbers] | None,
    spec: RunSpec,
    state: RunState,
    steps: int,
) -> int: ...

# ------------------------------------------------------------------------------ rigid.rs

STATE_SIZE: int
R_AT: int
V_AT: int
Q_AT: int
OMEGA_AT: int
MASS: int
INV_MASS: int
MOMENTS: int
INV_MOMENTS: int
COM_OFFSET: int
INERTIA_COM: int
PIVOT: int
HAS_PIVOT: int
ROTOR: int
BODY_SIZE: int
FORCE_PARAMS: int
FORCE_KINDS: dict[str, int]

def states_principal(axes: ArrayLike, states: ArrayLike, inverse: bool = False) -> _F64: ...
@overload
def initial_states(
    q: ArrayLike,
    omega: ArrayLike,
    r: ArrayLike,
    v: ArrayLike,
    com: _Vec3,
    c: _Vec3,
    pivot: _Vec3,
    has_pivot: bool,
    line: _Vec3,
    out: None = None,
) -> _F64: ...
@overload
def initial_states(
    q: ArrayLike,
    omega: ArrayLike,
    r: ArrayLike,
    v: ArrayLike,
    com: _Vec3,
    c: _Vec3,
    pivot: _Vec3,
    has_pivot: bool,
    line: _Vec3,
    out: _F64,
) -> None: ...
def pivot_point(body: ArrayLike, state: ArrayLike) -> list[float]: ...
def project_onto_pivot(body: ArrayLike, states: ArrayLike) -> _F64: ...
def rigid_rates(
    body: ArrayLike,
    force_kind: ArrayLike,
    force_params: ArrayLike,
    axes: ArrayLike,
    user: _Wrench | None,
    t: float,
    state: ArrayLike,
) -> tuple[_F64, _F64]: ...
def force_wrench_potential(
    kind: int, params: ArrayLike, body: ArrayLike, t: float, state: ArrayLike
) -> tuple[tuple[list[float], list[float]], float]: ...
def rigid_body_parameters(
    mass: float,
    moments: _Vec3,
    axes: ArrayLike,
    com_offset: _Vec3,
    inertia_com: ArrayLike,
    has_pivot: bool,
) -> tuple[_F64, bool]: ...
def body_vector(
    mass: float,
    moments: _Vec3,
    com_offset: _Vec3,
    inertia_com: ArrayLike,
    pivot: _Vec3,
    has_pivot: bool,
    rotor: int,
) -> _F64: ...
def potential_energies(
    body: ArrayLike, force_kind: ArrayLike, force_params: ArrayLike, t: ArrayLike, states: ArrayLike
) -> _F64: ...
def kinetic_energies(inertia: ArrayLike, mass: float, omega: ArrayLike, v: ArrayLike) -> _F64: ...
def rotational_energies(inertia: ArrayLike, omega: ArrayLike) -> _F64: ...
def angular_momenta(
    inertia: ArrayLike,
    omega: ArrayLike,
    q: ArrayLike | None = None,
    mass: float = 0.0,
    r: ArrayLike | None = None,
    v: ArrayLike | None = None,
) -> _F64: ...
def omega_space(q: ArrayLike, omega: ArrayLike) -> _F64: ...
def orthogonality_errors(q: ArrayLike) -> _F64: ...
def particle_motion(
    r: ArrayLike, q: ArrayLike, u: ArrayLike, omega: ArrayLike | None = None
) -> _F64: ...
def rigid_motion_from_particles(
    masses: ArrayLike,
    positions: ArrayLike,
    velocities: ArrayLike,
    center: _Vec3,
    inertia_inv: ArrayLike,
) -> tuple[list[float], list[float], _F64]: ...

# --------------------------------------------------------------------------- relative.rs

RELATIVE_STATE_SIZE: int
MOTION_SIZE: int

@final
class Expressions:
    def __new__(
        cls, codes: ArrayLike, values: ArrayLike, n_inputs: int, n_outputs: int
    ) -> Self: ...
    def __call__(self, inputs: ArrayLike) -> _F64: ...
    @property
    def machine_code(self) -> bool: ...

def transport_moments(j: ArrayLike, omega_e: ArrayLike, epsilon_e: ArrayLike) -> _F64: ...
def coriolis_moments(j: ArrayLike, omega_r: ArrayLike, omega_e: ArrayLike) -> _F64: ...
def coriolis_moments_three_term(j: ArrayLike, omega_r: ArrayLike, omega_e: ArrayLike) -> _F64: ...
def coriolis_moments_particles(
    masses: ArrayLike, rho: ArrayLike, omega_r: ArrayLike, omega_e: ArrayLike
) -> _F64: ...
def planar_inertia_particles(masses: ArrayLike, rho: ArrayLike) -> list[list[float]]: ...
def carrier_motions(carrier: _PPolyCarrier | Expressions, t: ArrayLike) -> _F64: ...
def absolute_states(states: ArrayLike, motions: ArrayLike) -> _F64: ...
def relative_rhs(
    body: ArrayLike,
    force_kind: ArrayLike,
    force_params: ArrayLike,
    axes: ArrayLike,
    user: _Wrench | int | None,
    carrier: _Carrier,
    balance_transport: bool,
    hold_com: bool,
    t: float,
    y: ArrayLike,
) -> _F64: ...
def integrate_relative(
    body: ArrayLike,
    force_kind: ArrayLike,
    force_params: ArrayLike,
    axes: ArrayLike,
    user: _Wrench | int | None,
    carrier: _Carrier,
    balance_transport: bool,
    hold_com: bool,
    spec: RunSpec,
    state: RunState,
    steps: int,
) -> int: ...

# --------------------------------------------------------------------------- geometry.rs

def hat(w: ArrayLike) -> _F64: ...
def vee(b: ArrayLike) -> _F64: ...
def exp_so3(w: ArrayLike) -> _F64: ...
def log_so3(r: ArrayLike) -> _F64: ...
def dexpinv(u: ArrayLike, v: ArrayLike) -> _F64: ...
def axis_rotation(axis: int, angle: float) -> _F64: ...
def quat_multiply(p: ArrayLike, q: ArrayLike) -> _F64: ...
def quat_conjugate(q: ArrayLike) -> _F64: ...
def quat_normalize(q: ArrayLike) -> _F64: ...
def quat_to_matrix(q: ArrayLike) -> _F64: ...
def quat_rotate(q: ArrayLike, v: ArrayLike) -> _F64: ...
def matrix_to_quat(r: ArrayLike) -> _F64: ...
def rotvec_to_quat(w: ArrayLike) -> _F64: ...
def quat_to_rotvec(q: ArrayLike) -> _F64: ...
def zxz_matrix(angles: ArrayLike) -> _F64: ...
def zxz_body_rates(angles: ArrayLike, rates: ArrayLike) -> _F64: ...
def zxz_angle_rates(angles: ArrayLike, omega: ArrayLike) -> _F64: ...
def center_of_mass(masses: ArrayLike, positions: ArrayLike) -> _F64: ...
def particle_inertia(masses: ArrayLike, offsets: ArrayLike) -> _F64: ...
def parallel_axis(inertia_com: ArrayLike, mass: float, d: ArrayLike) -> _F64: ...
def planar_inertia(inertia: ArrayLike) -> _F64: ...
def rotate_inertia(inertia: ArrayLike, r: ArrayLike) -> _F64: ...
def principal_decomposition(inertia: ArrayLike) -> tuple[_F64, _F64]: ...
def check_inertia(inertia: ArrayLike, rtol: float) -> tuple[_F64, _F64, _F64, _F64]: ...
def is_degenerate(moments: ArrayLike, rtol: float) -> bool: ...
def polyhedron_mass_properties(
    vertices: ArrayLike, faces: ArrayLike
) -> tuple[float, _F64, _F64]: ...
def box_inertia(m: float, size: ArrayLike) -> _F64: ...
def sphere_inertia(m: float, r: float) -> _F64: ...
def spherical_shell_inertia(m: float, r: float) -> _F64: ...
def cylinder_inertia(m: float, r: float, h: float) -> _F64: ...
def ellipsoid_inertia(m: float, semi_axes: ArrayLike) -> _F64: ...
def rod_inertia(m: float, length: float) -> _F64: ...
def cone_inertia(m: float, r: float, h: float) -> _F64: ...
def equivalent_box_half_extents(moments: ArrayLike, mass: float) -> _F64: ...

SYMMETRY_RTOL: float
DEGENERATE_RTOL: float
SYMMETRY_CLASSES: tuple[str, ...]

# ------------------------------------------------------------------------------ exact.rs

# `jacobi_reduced`: the list `[sn, cn, dn, p, v]`; `jacobi_sn_cn_dn_am`: `[sn, cn, dn, am]`,
# each of the shape of `u`
def jacobi_reduced(u: ArrayLike, m: float, m1: float, k: float) -> list[_F64]: ...
def jacobi_sn_cn_dn_am(u: ArrayLike, m: float, m1: float) -> list[_F64]: ...
def ellipk_m1(m1: float) -> float: ...
def ellipf(phi: ArrayLike, m: float, m1: float) -> _F64: ...
def ellippi_complete(n: float, m: float, m1: float) -> float: ...
def ellippi(n: float, phi: ArrayLike, m: float, m1: float) -> _F64: ...
def first_kind_from_sn_cn(s: float, c: float, m: float, m1: float) -> float: ...
def third_kind_u(n: float, u: ArrayLike, m: float, m1: float) -> _F64: ...
def carlson_rf(x: float, y: float, z: float) -> float: ...
def carlson_rj(x: float, y: float, z: float, p: float) -> float: ...
def torque_free_regimes(
    moments: ArrayLike, axes: ArrayLike, symmetry: int, w: ArrayLike
) -> _F64: ...
def torque_free_families(
    moments: ArrayLike, axes: ArrayLike, symmetry: int, w: ArrayLike
) -> _F64: ...
def torque_free_derivatives(
    moments: ArrayLike, w: ArrayLike, q0: ArrayLike, t: ArrayLike
) -> tuple[_F64, _F64, _F64, _F64, _F64, _F64]: ...
def torque_free_omegas(
    moments: ArrayLike, axes: ArrayLike, symmetry: int, w: ArrayLike, t: ArrayLike
) -> _F64: ...
def torque_free_attitudes(
    moments: ArrayLike, axes: ArrayLike, symmetry: int, w: ArrayLike, q0: ArrayLike, t: ArrayLike
) -> _F64: ...
def fixed_point_attitudes(w: ArrayLike, q0: ArrayLike, t: ArrayLike) -> _F64: ...
def principal_invariants(moments: ArrayLike, w: ArrayLike) -> tuple[_F64, _F64]: ...
def rotational_energies_and_momenta(inertia: ArrayLike, w: ArrayLike) -> tuple[_F64, _F64]: ...
def energy_ellipsoid_semi_axes(moments: ArrayLike, energy: float) -> _F64: ...
def momentum_ellipsoid_semi_axes(moments: ArrayLike, momentum: float) -> _F64: ...
def cone_coefficients(moments: ArrayLike, energy: float, momentum: float) -> _F64: ...
def euler_jacobian(inertia: ArrayLike, w: ArrayLike) -> _F64: ...
def euler_omega_dot_free(moments: ArrayLike, w: ArrayLike) -> _F64: ...

# exact.rs registers `symmetry_code` after geometry.rs: this one (a float64 array) is the
# module's
def symmetry_code(moments: ArrayLike, rtol: float) -> int: ...

REGIME_OFFSETS: dict[str, int]
TORQUE_FREE_CASE_NAMES: list[str]
NEAR_UNSTABLE_AXIS: float
ELLIPTIC_NEAR_ONE: float
ELLIPTIC_TINY_M1: float

# --------------------------------------------------------------------------- ensemble.rs

def member_bodies(
    mass: float, inertia: ArrayLike, c: _Vec3, has_pivot: bool
) -> tuple[_F64, _F64, _Bool]: ...

# samples (or None), final states (or None), the drifts (energy, momentum, orthogonality),
# the flips (first, last, count), and status, steps and evaluations per member
def run_ensemble(
    spec: RunSpec,
    t0: float,
    inertia: ArrayLike,
    bodies: ArrayLike,
    axes: ArrayLike,
    force_kind: ArrayLike,
    force_params: ArrayLike,
    y0: ArrayLike,
    flips: bool = True,
    keep_samples: bool = True,
    threads: int = 1,
    samples_out: _F64 | None = None,
    finals_out: _F64 | None = None,
) -> tuple[
    _F64 | None,
    _F64 | None,
    _F64,
    _F64,
    _F64,
    _F64,
    _F64,
    _I64,
    _I64,
    _I64,
    _I64,
]: ...

# --------------------------------------------------------------------------- lagrange.rs

@final
class LagrangianTangent:
    def __new__(
        cls, codes: ArrayLike, values: ArrayLike, n: int, m: int, nh: int, np: int, nu: int
    ) -> Self: ...
    @property
    def sizes(self) -> tuple[int, int, int, int, int]: ...
    # `[M, f, G, b, γ, g, h, ∂[M, f, G, b, γ, g]/∂[q, q̇, p, u]]`
    def evaluate(
        self, t: float, q: ArrayLike, qd: ArrayLike, p: ArrayLike, u: ArrayLike
    ) -> _F64: ...
    # `(∂ẏ/∂y (2n, 2n), ∂ẏ/∂p (2n, np), ∂ẏ/∂u (2n, nu))`
    def rates_jacobian(
        self, t: float, y: ArrayLike, p: ArrayLike, u: ArrayLike
    ) -> tuple[_F64, _F64, _F64]: ...

def lagrange_sensitivity_start(
    tangent: LagrangianTangent,
    t0: float,
    y0: ArrayLike,
    p: ArrayLike,
    u: ArrayLike,
    kinds: ArrayLike,
    components: ArrayLike,
    seeds: ArrayLike,
    free_q: ArrayLike,
    free_v: ArrayLike,
) -> _F64: ...
def integrate_lagrange_sensitivities(
    tangent: LagrangianTangent,
    p: ArrayLike,
    u: ArrayLike,
    alpha: float,
    beta: float,
    projection: bool,
    seeds: ArrayLike,
    control_all: bool,
    spec: RunSpec,
    state: RunState,
    steps: int,
) -> int: ...

@final
class LagrangianModel:
    def __new__(
        cls, codes: ArrayLike, values: ArrayLike, n: int, m: int, nh: int, np: int, nu: int
    ) -> Self: ...
    @property
    def machine_code(self) -> bool: ...
    @property
    def sizes(self) -> tuple[int, int, int, int, int]: ...
    # `(M, f, G, b, γ, g, h)`
    def parts(
        self, t: float, q: ArrayLike, qd: ArrayLike, p: ArrayLike, u: ArrayLike
    ) -> tuple[_F64, _F64, _F64, _F64, _F64, _F64, float]: ...
    def rhs(
        self,
        t: float,
        y: ArrayLike,
        p: ArrayLike,
        u: ArrayLike,
        alpha: float = 0.0,
        beta: float = 0.0,
        active: ArrayLike | None = None,
    ) -> _F64: ...
    def accelerations(
        self,
        t: float,
        q: ArrayLike,
        qd: ArrayLike,
        p: ArrayLike,
        u: ArrayLike,
        active: ArrayLike | None = None,
    ) -> tuple[_F64, _F64]: ...
    # `(q̈, λ, Gᵀλ, g, G q̇ + b, h)` per sample
    def samples(
        self,
        t: ArrayLike,
        y: ArrayLike,
        p: ArrayLike,
        u: ArrayLike,
        active: ArrayLike | None = None,
    ) -> tuple[_F64, _F64, _F64, _F64, _F64, _F64]: ...
    def project(
        self,
        t: float,
        q: ArrayLike,
        qd: ArrayLike,
        p: ArrayLike,
        u: ArrayLike,
        active: ArrayLike | None = None,
        tol: float = 1e-13,
        max_iter: int = 20,
    ) -> tuple[_F64, _F64, bool]: ...
    def starts(
        self, t: float, z: ArrayLike, params: ArrayLike, inputs: ArrayLike
    ) -> tuple[_F64, _F64, _Bool]: ...
    # `(samples, status, steps, evaluations, releases)`
    def run_ensemble(
        self,
        params: ArrayLike,
        inputs: ArrayLike,
        y0: ArrayLike,
        alpha: float,
        beta: float,
        projection: bool,
        spec: RunSpec,
        t0: float,
        threads: int,
        unilateral: Sequence[int] = ...,
        resolution: int = 2001,
    ) -> tuple[_F64, _I64, _I64, _I64, _F64]: ...

def integrate_lagrange(
    model: LagrangianModel,
    p: ArrayLike,
    inputs: ArrayLike | Expressions | Callable[[float, _F64, _F64], _Numbers],
    alpha: float,
    beta: float,
    projection: bool,
    active: ArrayLike | None,
    run_spec: RunSpec,
    state: RunState,
    steps: int,
    events: _Events | None = None,
) -> int: ...

# --------------------------------------------------------------------------- gyrostat.rs

def point_acceleration_matrices(omega: ArrayLike, omega_dot: ArrayLike) -> _F64: ...
def gyrostat_omega_dot(
    moments: ArrayLike, axes: ArrayLike, omega: ArrayLike, h: ArrayLike, h_dot: ArrayLike
) -> _F64: ...
def gyrostat_regressor(
    omega: ArrayLike,
    omega_dot: ArrayLike,
    rotor_speed: ArrayLike,
    rotor_accel: ArrayLike,
    rotor_axis: ArrayLike,
) -> _F64: ...
def gyrostat_omegas(
    moments: ArrayLike,
    axes: ArrayLike,
    rotor_inertia: ArrayLike,
    omega0: ArrayLike,
    spec: RunSpec,
    rotor_t: ArrayLike,
    rotor_speed: ArrayLike,
    rotor_axis: ArrayLike,
) -> _F64: ...
def gyrostat_sensitivities(
    moments: ArrayLike,
    moment_seeds: ArrayLike,
    axes0: ArrayLike,
    delta: ArrayLike,
    delta_seeds: ArrayLike,
    rotor_inertia: float,
    inertia_seeds: ArrayLike,
    omega0: ArrayLike,
    omega_seeds: ArrayLike,
    specs: Sequence[RunSpec],
    rotor_t: ArrayLike,
    rotor_speed: ArrayLike,
    rotor_axis: ArrayLike,
) -> list[tuple[_F64, _F64]]: ...

# ------------------------------------------------------------------------------- tops.rs

def symmetric_top_axis(
    moments: _Vec3, axes: _Mat3, c: _Vec3, rtol: float
) -> list[float] | None: ...
def steady_precession_rates(
    a: float, c: float, mgl: float, theta: float, spin: float
) -> tuple[float, float]: ...
def gyroscopic_precession_rate(c: float, mgl: float, spin: float) -> float: ...
def heavy_top_motions(
    a: float, c: float, mgl: float, angles: ArrayLike, rates: ArrayLike, t: ArrayLike
) -> tuple[_F64, _F64]: ...
def heavy_top_derivatives(
    a: float, c: float, mgl: float, angles: _Vec3, rates: _Vec3, t: ArrayLike
) -> tuple[_F64, _F64, _F64, _F64, _F64, _F64, _F64, _F64]: ...
