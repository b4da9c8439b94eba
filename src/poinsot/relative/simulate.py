"""``simulate_relative``: integrate a body's motion relative to a moving carrier frame, and the
samples it returns (``docs/relative.md``; paper eqs (11)–(18))."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .._bindings import invariants as core_invariants
from .._bindings import relative as core_relative
from .._validation import as_array, as_rotation_matrix, as_vector3
from ..display import Displayable
from ..integrate.solve import check_run, solve
from ..rotation import body_rates_from_euler, euler_from_matrix, euler_rates_from_body
from ..sensitivity import SensitivityMixin
from ..trajectory import _MAT, _VEC, Exportable, Trajectory, _sensitivity_variables
from .carrier import Carrier
from .moments import coriolis_moment, transport_moment
from .system import RELATIVE_SLICES, RelativeMotionSystem

__all__ = ["PreparedRelativeRun", "RelativeTrajectory", "prepare_relative", "simulate_relative"]

#: |sin θ| below this, z-x-z Euler angle rates are refused (gimbal lock at θ = 0, π).
EULER_SINGULAR = 1e-6


def _readonly(a):
    a = np.asarray(a)
    a.flags.writeable = False
    return a


def simulate_relative(
    body,
    t_span,
    *,
    omega_r0=None,
    Q_r0=None,
    carrier,
    forces=(),
    balance_transport=False,
    hold_com=False,
    euler_angles0=None,
    euler_rates0=None,
    r0=None,
    v_r0=None,
    Q_carrier0=None,
    origin0=None,
    origin_velocity0=None,
    method="dop853",
    dt=None,
    rtol=None,
    atol=None,
    t_eval=None,
    save_every=1,
    progress=None,
    backend=None,
    max_steps=None,
    sensitivities=None,
    control_sensitivities=True,
) -> RelativeTrajectory:
    """Integrate a body's motion relative to a carrier frame: the compact relative Euler
    equation (11) in principal components (12),

    ``J ω̇_r = Jω_r × ω_r − J ε_e + Jω_e × ω_e + 2 ω_r × (J'ω_e) + M(F)``,

    with ``Q̇_r = Q_r Ω_r``, the carrier's own kinematics and, unless ``hold_com``, the centre
    of mass under the physical and the inertia forces relative to the carrier.

    Parameters
    ----------
    body : RigidBody
    t_span : (float, float)
    omega_r0 : array_like (3,)
        Angular velocity relative to the carrier, body components (or give ``euler_rates0``).
    Q_r0 : (3, 3) matrix or (4,) quaternion, optional
        Attitude relative to the carrier (body → carrier); identity by default (or give
        ``euler_angles0``).
    carrier : Carrier
        The carrier's prescribed motion.
    forces : sequence of Force
        Physical forces (inertial frame), as for :func:`poinsot.simulate`.
    balance_transport : bool
        Add the physical moment ``M(F) = J ε_e − Jω_e × ω_e`` that cancels the transport
        moment (case (16)): the relative rotational energy is then conserved (17).
    hold_com : bool
        Hold the centre of mass at its place in the carrier (a body mounted at its centre of
        mass).
    euler_angles0, euler_rates0 : array_like (3,), optional
        The initial relative attitude and angular velocity as z-x-z Euler angles (ψ, θ, φ) and
        their rates, eq. (13), instead of ``Q_r0`` and ``omega_r0``.
    r0, v_r0 : array_like (3,), optional
        The centre of mass relative to the carrier's origin and its velocity relative to the
        carrier, carrier components; default: the body's own centre of mass, at rest.
    Q_carrier0 : (3, 3) matrix or (4,) quaternion, optional
        The carrier's initial attitude (identity by default; taken from the carrier when it
        is given by Euler angles or an attitude).
    origin0, origin_velocity0 : array_like (3,), optional
        The carrier origin's initial position and velocity, inertial (default zero).
    method, dt, rtol, atol, t_eval, save_every, progress, backend, max_steps
        As for :func:`poinsot.simulate`; the methods that need the rigid-body structure
        (``"splitting"``, ``"rkmk4"``) are refused.
    sensitivities, control_sensitivities
        Forward sensitivities, as for :func:`poinsot.simulate`, with respect to
        ``"omega_r0"``, ``"Q_r0"`` (a rotation vector, ``Q_r0 → exp(δ̂) Q_r0`` in the carrier
        frame), ``"r0"``, ``"v_r0"``, ``"inertia"`` and the forces' parameters; then
        ``sol.sensitivity(output, wrt)`` with ``output`` one of ``"r"``, ``"v_r"``, ``"Q_r"``,
        ``"omega_r"`` or ``"state"`` (all 33: the carrier's part does not move).

    Returns
    -------
    RelativeTrajectory

    Examples
    --------
    A body on a turntable that turns at 1 rad/s about its z axis, the body held still
    relative to it: its absolute angular velocity is the turntable's.

    >>> from poinsot import RigidBody
    >>> from poinsot.relative import Carrier, simulate_relative
    >>> body = RigidBody.box(1.0, (1.0, 2.0, 3.0))
    >>> sol = simulate_relative(body, (0, 1), omega_r0=(0, 0, 0),
    ...                         carrier=Carrier(omega_e=(0, 0, 1)), hold_com=True)
    >>> sol.omega_absolute[-1].round(9).tolist()
    [0.0, 0.0, 1.0]
    """
    prepared = prepare_relative(body, t_span, carrier=carrier, forces=forces,
                                balance_transport=balance_transport, hold_com=hold_com,
                                method=method, dt=dt, rtol=rtol, atol=atol, t_eval=t_eval,
                                save_every=save_every, backend=backend,
                                max_steps=max_steps, sensitivities=sensitivities,
                                control_sensitivities=control_sensitivities)  # fmt: skip
    return prepared.run(omega_r0=omega_r0, Q_r0=Q_r0, euler_angles0=euler_angles0,
                        euler_rates0=euler_rates0, r0=r0, v_r0=v_r0, Q_carrier0=Q_carrier0,
                        origin0=origin0, origin_velocity0=origin_velocity0,
                        progress=progress)  # fmt: skip


def prepare_relative(body, t_span, *, carrier, forces=(), balance_transport=False,
                     hold_com=False, method="dop853", dt=None, rtol=None, atol=None,
                     t_eval=None, save_every=1, backend=None, max_steps=None,
                     sensitivities=None,
                     control_sensitivities=True) -> PreparedRelativeRun:  # fmt: skip
    """Check a relative run and lower its body, forces and carrier once: the
    :class:`PreparedRelativeRun` that :func:`simulate_relative` runs. The arguments are
    :func:`simulate_relative`'s less the initial state and ``progress``, checked here with
    the same errors.

    Examples
    --------
    >>> from poinsot import RigidBody
    >>> from poinsot.relative import Carrier, prepare_relative
    >>> run = prepare_relative(RigidBody.box(1.0, (1, 2, 3)), (0, 1),
    ...                        carrier=Carrier(omega_e=(0, 0, 1)), hold_com=True)
    >>> [run.run(omega_r0=(0, 0, w)).omega_absolute[-1, 2].round(9) for w in (0, 1)]
    [np.float64(1.0), np.float64(2.0)]
    """
    run = check_run(t_span, method, dt=dt, rtol=rtol, atol=atol, t_eval=t_eval,
                    save_every=save_every, max_steps=max_steps)  # fmt: skip
    if not isinstance(carrier, Carrier):
        raise TypeError(
            f"`carrier` must be a poinsot.relative.Carrier, found {type(carrier).__name__}"
        )
    solver = run.solver
    if solver.requires == "rigid":
        raise ValueError(
            f"`method` {solver.name!r} needs the rigid-body structure; relative motion runs with "
            "'dop853' or an explicit Runge–Kutta method such as 'rk4'"
        )
    if isinstance(forces, str) or not hasattr(forces, "__iter__"):
        raise TypeError(f"`forces` must be a sequence of Force objects, found {forces!r}")
    system = RelativeMotionSystem(body, carrier, forces, balance_transport=bool(balance_transport),
                                  hold_com=bool(hold_com))  # fmt: skip
    carrier.check(run.t0, run.t1)
    from ..sensitivity import check_control

    dirs = None
    control = check_control(control_sensitivities, solver, sensitivities is not None)
    if sensitivities is not None:
        dirs = _check_sensitivities(system, solver, sensitivities, backend)
    return PreparedRelativeRun(system, run, backend, dirs, control)


#: The initial state's parts a relative run differentiates with respect to.
RELATIVE_STARTS = {"omega_r0": 1, "Q_r0": 2, "r0": 3, "v_r0": 4}


def _check_sensitivities(system, solver, wrt, backend):
    """The directions of a relative run's ``sensitivities``, refused where it cannot carry
    them."""
    from ..sensitivity import check_run as check_sensitive
    from ..sensitivity import directions

    check_sensitive(system.rigid, solver, backend, rigid=False)
    dirs = directions(system.rigid, wrt, RELATIVE_STARTS)
    if system.hold_com and "v_r0" in dirs.names:
        raise ValueError("`sensitivities`: 'v_r0' has no effect with `hold_com` (the centre of "
                         "mass is held)")  # fmt: skip
    return dirs


@dataclass(frozen=True)
class PreparedRelativeRun:
    """A relative run, checked and lowered (:func:`prepare_relative`): :meth:`run` integrates
    it from an initial state.

    Attributes
    ----------
    system : RelativeMotionSystem
        The body, its forces lowered for the core, the carrier and the options.
    settings : RunSettings
        The checked span, method, sampling, step or tolerances and step budget.
    backend : str or None
    """

    system: RelativeMotionSystem
    settings: object
    backend: str | None = None
    sensitivities: object = None
    control_sensitivities: bool = True

    def initial_state(self, *, omega_r0=None, Q_r0=None, euler_angles0=None,
                      euler_rates0=None, r0=None, v_r0=None, Q_carrier0=None, origin0=None,
                      origin_velocity0=None) -> np.ndarray:  # fmt: skip
        """The run's state at its start (33,), from :func:`simulate_relative`'s arguments,
        checked (the right-hand side there included)."""
        system, t0 = self.system, self.settings.t0
        body, carrier = system.body, system.carrier
        if euler_angles0 is not None:
            if Q_r0 is not None:
                raise ValueError("give `Q_r0` or `euler_angles0`, not both")
            from ..rotation import matrix_from_euler

            angles = as_vector3(euler_angles0, "euler_angles0")
            Q = matrix_from_euler(angles, "ZXZ")
        else:
            angles = None
            Q = np.eye(3) if Q_r0 is None else as_rotation_matrix(Q_r0, "Q_r0")
        if euler_rates0 is not None:
            if omega_r0 is not None:
                raise ValueError("give `omega_r0` or `euler_rates0`, not both")
            if angles is None:
                raise ValueError("`euler_rates0` needs `euler_angles0`")
            w = body_rates_from_euler(angles, as_vector3(euler_rates0, "euler_rates0"))  # (13)
        elif omega_r0 is None:
            raise ValueError("`omega_r0` must be given (or `euler_angles0` and `euler_rates0`)")
        else:
            w = as_vector3(omega_r0, "omega_r0")
        Qc = carrier.initial_attitude(t0, Q_carrier0)
        r = np.array(body.center_of_mass, dtype=float) if r0 is None else as_vector3(r0, "r0")
        v = np.zeros(3) if v_r0 is None else as_vector3(v_r0, "v_r0")
        if system.hold_com and v_r0 is not None and np.any(v != 0):
            raise ValueError("`v_r0` must be zero (or omitted) with `hold_com`")
        X = np.zeros(3) if origin0 is None else as_vector3(origin0, "origin0")
        VO = (
            np.zeros(3)
            if origin_velocity0 is None
            else as_vector3(origin_velocity0, "origin_velocity0")
        )
        y0 = np.concatenate([r, v, Q.ravel(), w, Qc.ravel(), X, VO])
        _check_start(system, t0, y0)
        return y0

    def run(self, *, y0=None, progress=None, **initial) -> RelativeTrajectory:
        """Integrate from the initial state given as :func:`simulate_relative` takes it
        (``omega_r0``, ``Q_r0``, ``euler_angles0``, ...), or from ``y0``, the whole state (33,)
        as :meth:`initial_state` returns it, checked as a start (:meth:`_given_state`)."""
        if y0 is None:
            y0 = self.initial_state(**initial)
        elif initial:
            raise TypeError(f"give `y0` or the initial state's parts, not both: {sorted(initial)}")
        else:
            y0 = self._given_state(y0)
        system = self.system
        if self.sensitivities is not None:
            return self._run_sensitive(y0, progress)
        return solve(system, y0, self.settings,
                     trajectory=lambda r: RelativeTrajectory(r, system), progress=progress,
                     backend=self.backend)  # fmt: skip

    def _given_state(self, y0) -> np.ndarray:
        """``run(y0=...)``: the relative state (33,) checked whole: finite, ``Q_r`` and
        ``Q_carrier`` rotations (within the tolerance ``Q_r0`` has, then projected onto SO(3)
        as it is), ``Q_carrier`` the carrier's own attitude at the start where the carrier
        gives one, ``v_r`` zero under ``hold_com``, and the rates finite there."""
        s, system, t0 = RELATIVE_SLICES, self.system, self.settings.t0
        y = as_array(y0, "y0", (RELATIVE_SIZE,)).copy()
        for part, start in (("Q_r", 6), ("Q_carrier", 18)):
            name = f"y0[{start}:{start + 9}] ({part}, row by row)"
            y[s[part]] = as_rotation_matrix(y[s[part]].reshape(3, 3), name).ravel()
        carrier = system.carrier
        if carrier.has_attitude:
            Qc = carrier.initial_attitude(t0)
            off = float(np.abs(y[s["Q_carrier"]] - Qc.ravel()).max())
            if off > 1e-9:
                raise ValueError(f"`y0[18:27]` (Q_carrier) must be the carrier's attitude at "
                                 f"t0 = {t0:g}, given by its `{carrier.given}` (off by "
                                 f"{off:.3g}); give the state `initial_state` returns")  # fmt: skip
            y[s["Q_carrier"]] = Qc.ravel()
        if system.hold_com and np.any(y[s["v_r"]] != 0):
            raise ValueError("`y0[3:6]` (v_r) must be zero with `hold_com`")
        _check_start(system, t0, y)
        return y

    def _run_sensitive(self, y0, progress) -> RelativeTrajectory:
        """The run with its sensitivities: the augmented system through the same driver."""
        from dataclasses import replace

        from ..sensitivity import split
        from .system import RelativeSensitiveSystem

        dirs = self.sensitivities
        aug = RelativeSensitiveSystem(self.system, dirs, control_all=self.control_sensitivities)

        def trajectory(result):
            y, sens = split(result.y, dirs, RELATIVE_SIZE, RELATIVE_OUTPUTS, t0=self.settings.t0)
            sol = RelativeTrajectory(replace(result, y=y), self.system)
            sol.sensitivities = sens
            return sol

        return solve(aug, y0, self.settings, trajectory=trajectory, progress=progress)


def _check_start(system, t0, y0):
    """The right-hand side at the start must be finite (a force undefined there, a carrier that
    returns NaN), named before any step."""
    with np.errstate(all="ignore"):
        f = system.rhs(t0, y0)
    for name, sl in RELATIVE_SLICES.items():
        if not np.all(np.isfinite(f[sl])):
            raise ValueError(
                f"the relative motion is undefined at the initial state (`omega_r0`, `forces`, "
                f"`carrier`): non-finite rate of {name} (a force or the carrier's motion is not "
                f"finite at t = {t0:g}, or the state is beyond the double range)"
            )


#: The length of the relative state, and the outputs of its sensitivities.
RELATIVE_SIZE = 33
RELATIVE_OUTPUTS = {**{k: v for k, v in RELATIVE_SLICES.items()
                       if k in ("r", "v_r", "Q_r", "omega_r")},
                    "state": slice(0, RELATIVE_SIZE)}  # fmt: skip


#: The exported fields of a relative motion, in order (:meth:`RelativeTrajectory.variables`):
#: ``(name, the attribute holding the values, dims, attrs)``.
_RELATIVE_VARIABLES = (
    ("r", "r", _VEC, {"units": "m", "frame": "carrier",
                      "long_name": "position of the centre of mass from the carrier's origin"}),
    ("v_r", "v_r", _VEC, {"units": "m/s", "frame": "carrier",
                          "long_name": "velocity of the centre of mass relative to the carrier"}),
    ("Q_r", "Q_r", _MAT, {"units": "1", "long_name": "attitude relative to the carrier, "
                                                     "body → carrier"}),
    ("omega_r", "omega_r", _VEC, {"units": "rad/s", "frame": "body",
                                  "long_name": "angular velocity relative to the carrier"}),
    ("Q_carrier", "Q_carrier", _MAT, {"units": "1",
                                      "long_name": "the carrier's attitude, carrier → space"}),
    ("origin", "origin", _VEC, {"units": "m", "frame": "space",
                                "long_name": "the carrier's origin"}),
    ("origin_velocity", "origin_velocity", _VEC,
     {"units": "m/s", "frame": "space", "long_name": "velocity of the carrier's origin"}),
    ("omega_e", "omega_e", _VEC, {"units": "rad/s", "frame": "body",
                                  "long_name": "the carrier's angular velocity ω_e"}),
    ("epsilon_e", "epsilon_e", _VEC, {"units": "rad/s2", "frame": "body",
                                      "long_name": "the carrier's angular acceleration ε_e"}),
    ("transport_moment", "transport_moment", _VEC,
     {"units": "N m", "frame": "body", "about": "centre of mass", "symbol": "M_e",
      "long_name": "transport moment −J ε_e + Jω_e × ω_e (eq. 11)"}),
    ("coriolis_moment", "coriolis_moment", _VEC,
     {"units": "N m", "frame": "body", "about": "centre of mass", "symbol": "M_c",
      "long_name": "Coriolis moment 2 ω_r × (J'ω_e) (eq. 11)"}),
    ("relative_energy", "relative_energy", ("time",),
     {"units": "J", "long_name": "relative rotational energy ½ ω_r·Jω_r (eq. 17)"}),
    ("R_absolute", "R_absolute", _VEC, {"units": "m", "frame": "space",
                                        "long_name": "position of the centre of mass"}),
    ("V_absolute", "V_absolute", _VEC, {"units": "m/s", "frame": "space",
                                        "long_name": "velocity of the centre of mass"}),
    ("Q_absolute", "Q_absolute", _MAT, {"units": "1", "long_name": "attitude, body → space"}),
    ("omega_absolute", "omega_absolute", _VEC, {"units": "rad/s", "frame": "body",
                                                "long_name": "absolute angular velocity"}),
    ("time", "t", ("time",), {"units": "s"}),
)  # fmt: skip


class RelativeTrajectory(Exportable, SensitivityMixin, Displayable):
    """Samples of a motion relative to a carrier frame, and the absolute motion they map to.

    Attributes
    ----------
    t : ndarray (n,)
    omega_r : ndarray (n, 3)
        Angular velocity relative to the carrier, body components.
    Q_r : ndarray (n, 3, 3)
        Attitude relative to the carrier (body → carrier).
    Q_carrier : ndarray (n, 3, 3)
        The carrier's attitude (carrier → inertial).
    r, v_r : ndarray (n, 3)
        The centre of mass relative to the carrier's origin and its relative velocity
        (carrier components).
    origin, origin_velocity : ndarray (n, 3)
        The carrier origin's position and velocity (inertial).
    """

    _growth = ("omega_r", "omega_r0")

    def __init__(self, result, system: RelativeMotionSystem):
        self.t = _readonly(np.asarray(result.t, dtype=float))
        self._y = _readonly(np.asarray(result.y, dtype=float).reshape(len(self.t), 33))
        self.system = system
        self.body = system.body
        self.carrier = system.carrier
        self.method = result.method
        self.nfev = result.nfev
        self.nsteps = result.nsteps
        self.wall_time = result.wall_time
        self.message = result.message
        self.success = result.success
        self.backend = result.backend
        s = RELATIVE_SLICES
        n = len(self.t)
        self.r = self._y[:, s["r"]]
        self.v_r = self._y[:, s["v_r"]]
        self.Q_r = self._y[:, s["Q_r"]].reshape(n, 3, 3)
        self.omega_r = self._y[:, s["omega_r"]]
        self.Q_carrier = self._y[:, s["Q_carrier"]].reshape(n, 3, 3)
        self.origin = self._y[:, s["origin"]]
        self.origin_velocity = self._y[:, s["origin_velocity"]]

    def __len__(self):
        return len(self.t)

    @property
    def y(self) -> np.ndarray:
        """The relative states (n, 33), body frame (layout: :data:`RELATIVE_SLICES`)."""
        return self._y

    # ----------------------------------------------------------------- the carrier
    @cached_property
    def carrier_motion(self) -> np.ndarray:
        """``(ω_e, ε_e, a_O)`` at the samples (n, 9), carrier components."""
        return _readonly(self.carrier.motions(self.t))

    @cached_property
    def omega_e(self) -> np.ndarray:
        """ω_e projected on the body axes, ``Q_rᵀ ω_e`` (n, 3) (eq. (15))."""
        return _readonly(np.einsum("nji,nj->ni", self.Q_r, self.carrier_motion[:, 0:3]))

    @cached_property
    def epsilon_e(self) -> np.ndarray:
        """ε_e projected on the body axes (n, 3)."""
        return _readonly(np.einsum("nji,nj->ni", self.Q_r, self.carrier_motion[:, 3:6]))

    # ----------------------------------------------------------------- the absolute motion
    @cached_property
    def absolute_states(self) -> np.ndarray:
        """The absolute body-frame states ``[R, V, Q, ω]`` (n, 18)."""
        motions = np.ascontiguousarray(self.carrier_motion)
        return _readonly(core_relative.absolute_states(np.ascontiguousarray(self._y), motions))

    @property
    def Q_absolute(self) -> np.ndarray:
        """``Q_carrier @ Q_r`` (n, 3, 3): body → inertial."""
        return self.absolute_states[:, 6:15].reshape(-1, 3, 3)

    @property
    def omega_absolute(self) -> np.ndarray:
        """The absolute angular velocity in body components, ``ω_r + Q_rᵀ ω_e`` (n, 3)."""
        return self.absolute_states[:, 15:18]

    @property
    def R_absolute(self) -> np.ndarray:
        """The centre of mass in the inertial frame, ``X_O + Q_c r`` (n, 3)."""
        return self.absolute_states[:, 0:3]

    @property
    def V_absolute(self) -> np.ndarray:
        """Its inertial velocity, ``V_O + Q_c (v_r + ω_e × r)`` (n, 3)."""
        return self.absolute_states[:, 3:6]

    def to_trajectory(self) -> Trajectory:
        """The absolute motion as a :class:`~poinsot.trajectory.Trajectory` (energies, momenta,
        particles, figures, export), under the same physical forces."""
        return Trajectory(
            self.t,
            self.absolute_states,
            self.system.rigid,
            method=self.method,
            nfev=self.nfev,
            nsteps=self.nsteps,
            wall_time=self.wall_time,
            message=self.message,
            success=self.success,
            backend=self.backend,
        )

    # ----------------------------------------------------------------- the inertia moments
    @cached_property
    def relative_energy(self) -> np.ndarray:
        """The relative rotational energy ``½ ω_r·Jω_r`` (n,) (eq. (17): constant under the
        balancing moment (16))."""
        J = np.ascontiguousarray(self.body.inertia, dtype=float)
        return _readonly(core_invariants.rotational_energies(J, np.ascontiguousarray(self.omega_r)))

    @cached_property
    def transport_moment(self) -> np.ndarray:
        """``M_e = −J ε_e + Jω_e × ω_e`` along the motion (n, 3), body components."""
        return _readonly(transport_moment(self.body.inertia, self.omega_e, self.epsilon_e))

    @cached_property
    def coriolis_moment(self) -> np.ndarray:
        """``M_c = 2 ω_r × (J'ω_e)`` along the motion (n, 3), body components."""
        return _readonly(coriolis_moment(self.body.inertia, self.omega_r, self.omega_e))

    def hodograph_ratio(self) -> float:
        """``max |ω_r| / min |ω_r|`` over the samples; under the balancing moment it never
        exceeds :meth:`hodograph_bound` (18)."""
        n = np.linalg.norm(self.omega_r, axis=1)
        if not len(n):  # no samples (an empty t_eval)
            return float("nan")
        return float(n.max() / n.min()) if n.min() > 0 else float("inf")

    def hodograph_bound(self) -> float:
        """``√(C/A)``, C and A the largest and smallest principal moments: the ratio of the
        extreme semi-axes of the energy ellipsoid (17) on which ω_r moves under the balancing
        moment, hence a bound on :meth:`hodograph_ratio` (eq. (18); the paper states an
        equality, but a given motion need not reach the extreme semi-axes)."""
        m = np.asarray(self.body.principal_moments)
        return float(np.sqrt(m[2] / m[0])) if m[0] > 0 else float("inf")

    # ----------------------------------------------------------------- Euler angles
    def euler_angles(self) -> np.ndarray:
        """The relative attitude as z-x-z Euler angles (ψ, θ, φ) (n, 3), radians."""
        return euler_from_matrix(self.Q_r, "ZXZ")

    def euler_rates(self) -> np.ndarray:
        """``(ψ̇, θ̇, φ̇)`` (n, 3) from ω_r by inverting eq. (13).

        Raises
        ------
        ValueError
            When a sample lies at the gimbal lock (θ = 0 or π), where the rates are undefined;
            the message names the first such time (use ``Q_r`` or ``omega_r`` there).
        """
        angles = self.euler_angles()
        s = np.abs(np.sin(angles[:, 1]))
        if np.any(s < EULER_SINGULAR):
            i = int(np.argmax(s < EULER_SINGULAR))
            raise ValueError(
                f"z-x-z Euler angle rates are singular at θ = 0 or π (gimbal lock): θ = "
                f"{angles[i, 1]:.3g} rad at t = {self.t[i]:.6g}; use `Q_r` and `omega_r` there"
            )
        return euler_rates_from_body(angles, self.omega_r)

    # ----------------------------------------------------------------- export
    def summary(self) -> dict:
        """A JSON-ready summary: the run, the body and the carrier."""
        ratio = self.hodograph_ratio() if self.system.balance_transport else None
        return {
            **self._run_summary(),
            "carrier": repr(self.carrier),
            "balance_transport": self.system.balance_transport,
            "hold_com": self.system.hold_com,
            # the bound (18) holds only under the balancing moment (16)
            **({"hodograph_ratio": ratio if np.isfinite(ratio) else None,
                "hodograph_bound": self.hodograph_bound()}
               if self.system.balance_transport else {}),
        }  # fmt: skip

    def variables(self) -> dict:
        """Every exported field as ``name → (dims, values, attrs)``: the relative state
        (``r``, ``v_r``, ``Q_r``, ``omega_r``) and the carrier's (``Q_carrier``, ``origin``,
        ``origin_velocity``), ω_e and ε_e on the body axes, the transport and Coriolis
        moments, the relative energy, and the absolute motion they map to; each vector's
        attributes name its frame (``carrier``: the carrier's axes). The one list that
        :meth:`to_npz`, :meth:`to_csv`, :meth:`to_netcdf` and :meth:`to_xarray` write; with
        sensitivities, ``sensitivity (time, state_component, parameter)`` of the 33-number
        relative state and its labels."""
        out = self._table_fields(_RELATIVE_VARIABLES)
        if self.sensitivities is not None:
            out |= _sensitivity_variables(
                self.sensitivities,
                _state_labels(),
                "r, v_r carrier frame; Q_r body to carrier; omega_r body frame; Q_carrier "
                "carrier to space; origin, origin_velocity space frame",
            )
        out["axis"] = (("axis",), np.array(list("xyz")), {})
        return out

    def __repr__(self):
        span = f"t = [{self.t[0]:g}, {self.t[-1]:g}], " if len(self.t) else ""
        return f"RelativeTrajectory({len(self.t)} samples, {span}{self.method}, {self.carrier!r})"


def _state_labels() -> list[str]:
    """The names of the relative state's 33 components (:data:`RELATIVE_SLICES`)."""
    names = []
    for part, sl in RELATIVE_SLICES.items():
        if sl.stop - sl.start == 9:
            names += [f"{part}_{i}{j}" for i in range(1, 4) for j in range(1, 4)]
        else:
            names += [f"{part}_{c}" for c in "xyz"]
    return names
