"""The result of a rigid-body simulation: samples, derived quantities, diagnostics, export."""

from __future__ import annotations

import json
from functools import cached_property

import numpy as np

from ._bindings import invariants as core_invariants
from ._bindings import rigid as core_rigid
from ._bindings.rotations import matrix_to_quat
from ._io import atomic_path, atomic_savez
from .display import Displayable
from .layout import STATE_SIZE, STATE_SLICES
from .sensitivity import SensitivityMixin

__all__ = ["Exportable", "Trajectory"]


def _readonly(a):
    a = np.asarray(a)
    a.flags.writeable = False
    return a


_VEC = ("time", "axis")
_MAT = ("time", "row", "col")
_MOMENTUM = {"units": "kg m2/s", "frame": "space"}
#: The exported fields of the motion, in order (:meth:`Trajectory.variables`):
#: ``(name, the attribute holding the values, dims, attrs)``.
_MOTION_VARIABLES = (
    ("R", "R", _VEC, {"units": "m", "frame": "space",
                      "long_name": "position of the centre of mass from the space origin"}),
    ("V", "V", _VEC, {"units": "m/s", "frame": "space",
                      "long_name": "velocity of the centre of mass"}),
    ("Q", "Q", _MAT, {"units": "1", "long_name": "attitude, body → space"}),
    ("omega", "omega", _VEC, {"units": "rad/s", "frame": "body",
                              "long_name": "angular velocity"}),
    ("omega_space", "omega_space", _VEC, {"units": "rad/s", "frame": "space",
                                          "long_name": "angular velocity"}),
    ("quaternion", "quaternion", ("time", "component"),
     {"units": "1", "long_name": "attitude, body → space, scalar first"}),
    ("angular_momentum_com", "angular_momentum_com", _VEC,
     {**_MOMENTUM, "about": "centre of mass", "symbol": "L_G",
      "long_name": "angular momentum about the centre of mass"}),
    ("angular_momentum_origin", "angular_momentum", _VEC,
     {**_MOMENTUM, "about": "space origin", "symbol": "L_O",
      "long_name": "angular momentum about the space origin"}),
)  # fmt: skip
#: The exported scalar fields and the time, after the momentum about a pivot.
_SCALAR_VARIABLES = (
    ("kinetic_energy", "kinetic_energy", ("time",), {"units": "J"}),
    ("potential_energy", "potential_energy", ("time",), {"units": "J"}),
    ("total_energy", "total_energy", ("time",), {"units": "J"}),
    ("orthogonality_error", "orthogonality_error", ("time",),
     {"units": "1", "long_name": "max |Qᵀ Q − I|"}),
    ("time", "t", ("time",), {"units": "s"}),
)  # fmt: skip


class Exportable:
    """The writers of a sampled motion: :meth:`to_npz`, :meth:`to_csv`, :meth:`to_netcdf` and
    :meth:`to_xarray`, all of the one list :meth:`variables` (``name → (dims, values,
    attrs)``) that the class defines, with its ``t``, ``method`` and :meth:`summary`."""

    t: np.ndarray
    method: str
    backend: str
    success: bool
    message: str
    nfev: int
    nsteps: int
    wall_time: float
    body: object

    def variables(self) -> dict:  # pragma: no cover - each result defines its own
        raise NotImplementedError

    def summary(self) -> dict:  # pragma: no cover - each result defines its own
        raise NotImplementedError

    def _run_summary(self) -> dict:
        """The part of :meth:`summary` every run has: how it ran, its span, its body."""
        return {
            "method": self.method,
            "backend": self.backend,
            "success": self.success,
            "message": self.message,
            "samples": len(self.t),
            "t_start": float(self.t[0]) if len(self.t) else None,
            "t_end": float(self.t[-1]) if len(self.t) else None,
            "nfev": int(self.nfev),
            "nsteps": int(self.nsteps),
            "wall_time_s": float(self.wall_time),
            "mass": self.body.mass,
            "principal_moments": self.body.principal_moments.tolist(),
        }

    def _table_fields(self, table) -> dict:
        """The fields ``name → (dims, values, attrs)`` of one table of exported fields
        (:data:`_MOTION_VARIABLES`, :data:`_SCALAR_VARIABLES`), each with its own attrs."""
        return {name: (dims, getattr(self, attr), dict(attrs)) for name, attr, dims, attrs in table}

    def _fields(self, table=False):
        """The exported fields, ``t`` first, without the labels of the time, axis and
        component dimensions (implied by the field names); with the sensitivities' labels,
        ``state_component`` and ``parameter`` (which row and column is which), as the NetCDF
        export has them. A ``table`` has no sensitivities, nor their labels."""
        fields = {"t": ((), self.t, {"units": "s"})}
        for name, value in self.variables().items():
            if name in ("time", "axis", "component"):
                continue
            if not (table and any(d in _SENSITIVITY_COORDS for d in value[0])):
                fields[name] = value
        return fields

    def to_npz(self, path) -> None:
        """Write every field of :meth:`variables` to a compressed ``.npz`` file (atomically),
        with ``attributes`` (JSON: each field's units, frame and reference point) and
        ``summary`` (JSON). With sensitivities, ``sensitivity (time, state_component,
        parameter)`` comes with its labels ``state_component`` and ``parameter`` (NumPy
        unicode arrays, as the NetCDF coordinates: ``numpy.load`` reads them without
        pickle)."""
        fields = self._fields()
        atomic_savez(
            path,
            **{name: value for name, (_, value, _) in fields.items()},
            attributes=np.array(json.dumps({n: a for n, (_, _, a) in fields.items()})),
            summary=np.array(json.dumps(self.summary())),
        )

    def csv_columns(self) -> list[str]:
        """The CSV header: each column's name and SI unit (``omega_x [rad/s]``; ``[1]``
        dimensionless); a moment's name carries its reference point
        (``angular_momentum_com_x``), frames are those of :meth:`variables`."""
        cols = []
        for name, (dims, value, attrs) in self._fields(table=True).items():
            unit = f" [{attrs.get('units', '1')}]"
            if name == "t" or value.ndim == 1:
                cols.append(name + unit)
            elif dims[-1] == "col":
                cols += [f"{name}_{i}{j}{unit}" for i in range(1, 4) for j in range(1, 4)]
            else:
                cols += [f"{name}_{c}{unit}" for c in ("xyz" if dims[-1] == "axis" else "wxyz")]
        return cols

    def to_csv(self, path) -> None:
        """Write one row per sample with every field of :meth:`variables` to CSV, atomically;
        the header is :meth:`csv_columns`. The sensitivities (three axes) are not a table's:
        the other formats carry them."""
        table = np.column_stack([v.reshape(len(self.t), -1)
                                 for _, v, _ in self._fields(table=True).values()])  # fmt: skip
        with atomic_path(path) as tmp:
            np.savetxt(tmp, table, delimiter=",", header=",".join(self.csv_columns()),
                       comments="", fmt="%.17g")  # fmt: skip

    def to_xarray(self):
        """An ``xarray.Dataset`` of :meth:`variables` (needs the ``xarray`` extra)."""
        from ._io import xarray_dataset

        attrs = {"method": self.method, "summary": json.dumps(self.summary())}
        return xarray_dataset(self.variables(), attrs)

    def to_netcdf(self, path) -> None:
        """Write :meth:`variables` to a NetCDF-3 file (atomically, with SciPy's writer: no
        xarray needed)."""
        from ._io import write_netcdf

        write_netcdf(path, self.variables(), {"method": self.method,
                                              "summary": json.dumps(self.summary())})  # fmt: skip


class Trajectory(Exportable, SensitivityMixin, Displayable):
    """Samples of a rigid-body motion and everything computed from them.

    Attributes
    ----------
    t : ndarray, shape (n,)
    R, V : ndarray, shape (n, 3)
        Centre of mass and its velocity, space frame.
    Q : ndarray, shape (n, 3, 3)
        Attitude: body frame → space frame.
    omega : ndarray, shape (n, 3)
        Angular velocity in the body frame.
    method, nfev, nsteps, wall_time
        How it was computed (``wall_time``: seconds of the integration itself, in the
        compiled core; nothing is compiled at run time).
    t_events, y_events : list of ndarray
        With ``simulate(..., events=)``: per event, the times and states of its zeros.
    sensitivities : poinsot.sensitivity.Sensitivities or None
        With ``simulate(..., sensitivities=)``: ``∂y(tᵢ)/∂p`` (:meth:`sensitivity`).
    """

    t_events: tuple = ()
    y_events: tuple = ()

    def __init__(
        self,
        t,
        y,
        system,
        *,
        method="",
        nfev=0,
        nsteps=0,
        wall_time=0.0,
        message="",
        success=True,
        backend="",
    ):
        self.t = _readonly(np.asarray(t, dtype=float))
        self._y = _readonly(np.asarray(y, dtype=float).reshape(len(self.t), STATE_SIZE))
        self.system = system
        self.body = system.body
        self.method = method
        self.nfev = nfev
        self.nsteps = nsteps
        self.wall_time = wall_time
        self.message = message
        self.success = bool(success)
        self.backend = backend

    def __len__(self):
        return len(self.t)

    def __repr__(self):
        return (
            f"Trajectory(n={len(self.t)}, "
            + (f"t=[{self.t[0]:.6g}, {self.t[-1]:.6g}], " if len(self.t) else "")
            + f"method={self.method!r}, nfev={self.nfev})"
        )

    # ----------------------------------------------------------------- state
    @property
    def R(self):
        return self._y[:, STATE_SLICES["R"]]

    @property
    def V(self):
        return self._y[:, STATE_SLICES["V"]]

    @property
    def Q(self):
        return self._y[:, STATE_SLICES["Q"]].reshape(-1, 3, 3)

    @property
    def omega(self):
        return self._y[:, STATE_SLICES["omega"]]

    @property
    def state(self):
        """The flat 18-component states (n, 18): ``[R, V, Q (row-major), ω]``."""
        return self._y

    @cached_property
    def quaternion(self):
        """Attitude as scalar-first unit quaternions (n, 4), sign chosen continuous in time."""
        q = matrix_to_quat(self.Q)
        # remove the ±q ambiguity: keep each sample on the side of the previous one
        for i in range(1, len(q)):
            if q[i] @ q[i - 1] < 0:
                q[i] = -q[i]
        return _readonly(q)

    def _c(self, a):
        return np.ascontiguousarray(a, dtype=float)

    @cached_property
    def omega_space(self):
        """Angular velocity in the space frame, ``Q ω`` (n, 3)."""
        return _readonly(core_invariants.omega_space(self._c(self.Q), self._c(self.omega)))

    @cached_property
    def angular_momentum_com(self):
        """Angular momentum about the centre of mass, space frame: ``Q A ω`` (n, 3)."""
        A = self._c(self.body.inertia)
        return _readonly(core_invariants.angular_momenta(A, self._c(self.omega), self._c(self.Q)))

    @cached_property
    def angular_momentum(self):
        """Angular momentum about the space origin, eq. (03): ``L = Q A ω + M R × Ṙ`` (n, 3)."""
        A = self._c(self.body.inertia)
        return _readonly(
            core_invariants.angular_momenta(
                A,
                self._c(self.omega),
                self._c(self.Q),
                float(self.body.mass),
                self._c(self.R),
                self._c(self.V),
            )
        )

    @cached_property
    def pivot_position(self):
        """The pivot's fixed position in space (3,), or None for a free body."""
        if self.system.pivot is None or not len(self.t):
            return None
        return _readonly(self.system.pivot_point(self.state[0]))

    @cached_property
    def angular_momentum_pivot(self):
        """Angular momentum about the pivot, space frame, eq. (03) about the fixed point P:
        ``L_P = Q A ω + M (R − P) × Ṙ`` (n, 3); None for a free body."""
        if self.pivot_position is None:
            return None
        A = self._c(self.body.inertia)
        return _readonly(core_invariants.angular_momenta(A, self._c(self.omega), self._c(self.Q),
                                                         float(self.body.mass),
                                                         self._c(self.R - self.pivot_position),
                                                         self._c(self.V)))  # fmt: skip

    @cached_property
    def kinetic_energy(self):
        """Kinetic energy, eq. (12): ``½ Aω·ω + ½ M |Ṙ|²`` (n,)."""
        A = self._c(self.body.inertia)
        return _readonly(
            core_invariants.kinetic_energies(
                A, float(self.body.mass), self._c(self.omega), self._c(self.V)
            )
        )

    @property
    def is_conservative(self) -> bool:
        """True when every force is conservative (total energy is a constant of the motion):
        each has a potential and none dissipates (a damped spring, drag)."""
        return self.system.conservative

    @cached_property
    def potential_energy(self):
        """Sum of the potentials of the forces that have one (n,); zero with no such force."""
        return _readonly(self.system.potential_energies(self.t, self._y))

    @cached_property
    def total_energy(self):
        """``kinetic_energy + potential_energy`` (n,); conserved when :attr:`is_conservative`."""
        return _readonly(self.kinetic_energy + self.potential_energy)

    def positions(self):
        """Particle trajectories ``r_i = Q u_i + R``, shape (n, N, 3); needs a particle body."""
        return core_rigid.particle_motion(self._c(self.R), self._c(self.Q), self._c(self.body.u))

    # ----------------------------------------------------------------- attitude
    def _frame(self, frame):
        """``(Q F, ω F)``: attitudes and body rates in the body axes given by the columns of
        ``F`` (body components): ``"body"`` (the identity), ``"principal"`` (e1, e2, e3) or a
        rotation matrix (3, 3)."""
        if isinstance(frame, str):
            if frame == "body":
                return self.Q, self.omega
            if frame == "principal":
                F = self.body.principal_axes
            else:
                raise ValueError(
                    f"`frame` must be 'body', 'principal' or a rotation matrix (3, 3) whose "
                    f"columns are body axes, found {frame!r}"
                )
        else:
            from ._validation import as_rotation_matrix

            F = as_rotation_matrix(frame, "frame")
        return self.Q @ F, self.omega @ F

    def _euler(self, frame):
        from .rotation import euler_series

        key = frame if isinstance(frame, str) else np.asarray(frame, float).tobytes()
        cache = self.__dict__.setdefault("_euler_cache", {})
        if key not in cache:
            Q, w = self._frame(frame)
            series = euler_series(Q, w, self.t)
            cache[key] = type(series)(*(_readonly(a) for a in series))
        return cache[key]

    def euler_angles(self, frame="body") -> np.ndarray:
        """z-x-z Euler angles ``(ψ, θ, φ)`` of the attitude (n, 3), radians: ``Q = Rz(ψ) Rx(θ)
        Rz(φ)`` (the paper's precession, nutation and proper rotation, eq. (13)).

        θ ∈ [0, π] is the tilt of the body's z axis from the space z axis; ψ and φ are
        unwrapped (continuous in time; :func:`poinsot.rotation.euler_series`), so ``ψ(t)``
        shows the accumulated precession. Near θ = 0 or π (:meth:`euler_singular`) ψ and φ
        are not separately defined.

        Parameters
        ----------
        frame : {"body", "principal"} or array_like (3, 3)
            The body axes the angles describe: the body's own, its principal axes e1, e2, e3,
            or the columns of a rotation matrix (body components; its third column is the
            axis whose tilt θ is).

        Examples
        --------
        >>> import numpy as np
        >>> from poinsot import RigidBody, simulate
        >>> top = RigidBody.cylinder(1.0, 0.3, 0.2)
        >>> traj = simulate(top, (0, 0.5), omega0=(0, 0, 50), Q0=[[1, 0, 0], [0, np.cos(0.6),
        ...                 -np.sin(0.6)], [0, np.sin(0.6), np.cos(0.6)]], t_eval=[0, 0.5])
        >>> traj.euler_angles()[:, 1].round(12).tolist()  # torque-free: the axis keeps its tilt
        [0.6, 0.6]
        """
        return self._euler(frame).angles

    def euler_rates(self, frame="body") -> np.ndarray:
        """``(ψ̇, θ̇, φ̇)`` (n, 3) in rad/s, from the body rates by the inverse of eq. (13)
        (the core's ``zxz_angle_rates``); NaN at the singular samples (:meth:`euler_singular`).
        ``frame`` as for :meth:`euler_angles`."""
        return self._euler(frame).rates

    def euler_singular(self, frame="body") -> np.ndarray:
        """Samples (n,) of bool where θ is within ``1e-6`` of 0 or π (gimbal lock): ψ and φ are
        not separately defined there and their rates are NaN."""
        return self._euler(frame).singular

    def _body_axis(self, axis):
        names = {"x": 0, "y": 1, "z": 2}
        if isinstance(axis, str):
            if axis in names:
                return np.eye(3)[names[axis]]
            if axis in ("e1", "e2", "e3"):
                return self.body.principal_axes[:, int(axis[1]) - 1]
            raise ValueError(
                f"`axis` must be 'x', 'y', 'z', 'e1', 'e2', 'e3' or a 3-vector (body "
                f"components), found {axis!r}"
            )
        from ._validation import as_vector3

        a = as_vector3(axis, "axis")
        norm = float(np.linalg.norm(a))
        if not norm > 0:
            raise ValueError("`axis` must be a nonzero 3-vector (body components)")
        return a / norm

    def symmetry_axis(self) -> np.ndarray:
        """The body's symmetry axis (body components, unit): the principal axis whose moment
        differs from the two equal others (e3 of an oblate body, e1 of a prolate one).

        Raises ``ValueError`` for an asymmetric body (no symmetry axis) and a spherical one
        (every axis is one)."""
        kind = self.body.symmetry
        if kind not in ("oblate", "prolate"):
            raise ValueError(
                f"the body is {kind}: it has no single symmetry axis; give `axis` explicitly"
            )
        return self.body.principal_axes[:, 2 if kind == "oblate" else 0].copy()

    def axis_trace(self, axis=None) -> np.ndarray:
        """The direction in space of a body axis along the motion, ``Q a`` (n, 3): unit vectors,
        its trace on the unit sphere. ``axis``: a body-frame 3-vector or ``"x"``, ``"y"``,
        ``"z"``, ``"e1"``, ``"e2"``, ``"e3"``; default :meth:`symmetry_axis`.

        Examples
        --------
        >>> import numpy as np
        >>> from poinsot import RigidBody, simulate
        >>> traj = simulate(RigidBody.cylinder(1.0, 0.3, 0.2), (0, 1), omega0=(0, 0, 5))
        >>> bool(np.abs(traj.axis_trace() - [0, 0, 1]).max() < 1e-12)  # spinning about its axis
        True
        """
        a = self.symmetry_axis() if axis is None else self._body_axis(axis)
        return np.einsum("nij,j->ni", self.Q, a)

    def axis_tilt(self, axis=None, vertical=(0.0, 0.0, 1.0)) -> np.ndarray:
        """The angle (n,) in radians, in [0, π], between a body axis (as for :meth:`axis_trace`)
        and the space direction ``vertical`` (default +z): ``atan2(|a × v|, a · v)``. The tilt of
        the body's z axis is the Euler angle θ of :meth:`euler_angles`."""
        from ._validation import as_vector3

        v = as_vector3(vertical, "vertical")
        if not np.linalg.norm(v) > 0:
            raise ValueError("`vertical` must be a nonzero 3-vector")
        v = v / np.linalg.norm(v)
        a = self.axis_trace(axis)
        return np.arctan2(np.linalg.norm(np.cross(a, v), axis=1), a @ v)

    # ----------------------------------------------------------------- diagnostics
    @cached_property
    def orthogonality_error(self):
        """``max |QᵀQ − I|`` per sample (n,)."""
        return _readonly(core_invariants.orthogonality_errors(self._c(self.Q)))

    @cached_property
    def rigidity_error(self):
        """Largest change of a distance between two body points, per sample (n,).

        Exact over all particle pairs for particle bodies of up to 200 particles; otherwise
        the bound ``max_k |σ_k(Q) − 1| · d`` with ``d`` the body's diameter (the farthest pair
        of particles, or of the 6 points ``±√(5 I_k / M)`` along the principal axes of a body
        given by its mass properties).
        """
        body = self.body
        if body.has_particles and body.n_particles <= 200:
            u = body.u
            i, j = np.triu_indices(len(u), 1)
            if len(i) == 0:
                return _readonly(np.zeros(len(self.t)))
            d_ref = np.linalg.norm(u[i] - u[j], axis=1)
            d = np.linalg.norm(np.einsum("nab,pb->npa", self.Q, u[i] - u[j]), axis=2)
            return _readonly(np.abs(d - d_ref).max(axis=1))
        if body.has_particles:
            span = np.ptp(body.u, axis=0)
            diameter = float(np.linalg.norm(span))
        else:
            radius = np.sqrt(5 * np.maximum(body.principal_moments, 0) / body.mass)
            diameter = 2 * float(radius.max())
        sigma = np.linalg.svd(self.Q, compute_uv=False)
        return _readonly(np.abs(sigma - 1).max(axis=1) * diameter)

    @cached_property
    def invariants(self):
        """The quantities this problem conserves (and the notable ones it does not), as
        :class:`~poinsot.conservation.Invariant` objects: total energy, then the momenta its
        forces and constraint leave constant (:func:`poinsot.conservation.invariants_of`)."""
        from .conservation import invariants_of

        return tuple(invariants_of(self)) if len(self.t) else ()

    @cached_property
    def energy_drift(self):
        """Relative change of total energy ``(E(t) − E(0))/|E(0)|`` (n,) (absolute if E(0)=0)."""
        E = self.total_energy
        if not len(E):  # no samples (an empty t_eval): no drift either
            return _readonly(E)
        if not np.isfinite(E).all():  # overflowed (V ≈ 1e217): E / s², s the largest rate
            w, V = self.omega, self.V
            s = float(max(np.abs(w).max(), np.abs(V).max()))
            if np.isfinite(s) and s > 0:
                A, M = self._c(self.body.inertia), float(self.body.mass)
                with np.errstate(over="ignore"):
                    U = self.potential_energy / (s * s)
                E = core_invariants.kinetic_energies(A, M, self._c(w / s), self._c(V / s)) + U
        return _readonly((E - E[0]) / (abs(E[0]) or 1.0))

    @cached_property
    def momentum_drift(self):
        """Relative change of the spatial angular momentum about the centre of mass,
        ``|L(t) − L(0)| / |L(0)|`` (n,): zero for a torque-free body, and physics, not error,
        when a force has a torque about the centre of mass (see :attr:`invariants` for what
        the problem conserves)."""
        L = self.angular_momentum_com
        if not len(L):
            return _readonly(np.zeros(0))
        scale = float(np.abs(L[0]).max()) or 1.0  # so that |L|² cannot overflow near 1e300
        dL = np.linalg.norm((L - L[0]) / scale, axis=1)
        return _readonly(dL / (np.linalg.norm(L[0] / scale) or 1.0))

    def diagnostics(self) -> dict:
        """Largest orthogonality, rigidity, energy and momentum errors over the run (NaN for
        a trajectory without samples: nothing was measured)."""

        def largest(a):
            return float(np.max(a)) if len(a) else float("nan")

        return {
            "orthogonality_error": largest(self.orthogonality_error),
            "rigidity_error": largest(self.rigidity_error),
            "energy_drift": largest(np.abs(self.energy_drift)),
            "momentum_drift": largest(self.momentum_drift),
            "energy_conserved_by_model": self.is_conservative,
            "invariants": {i.name: i.describe() for i in self.invariants},
        }

    def summary(self) -> dict:
        """A JSON-ready summary: the run, the body and the diagnostics."""
        return {**self._run_summary(), "diagnostics": self.diagnostics()}

    # ----------------------------------------------------------------- export
    def variables(self) -> dict:
        """Every exported field as ``name → (dims, values, attrs)``, coordinates included:
        the one list that :meth:`to_npz`, :meth:`to_csv`, :meth:`to_netcdf` and
        :meth:`to_xarray` write, so that every format carries the same fields. Each vector's
        attributes name its frame and, for a moment, its reference point (``about``): the
        angular momentum about the centre of mass (``L_G``), about the space origin (``L_O``)
        and, for a body on a pivot, about the pivot (``L_P``)."""
        out = self._table_fields(_MOTION_VARIABLES)
        if self.angular_momentum_pivot is not None:
            out["angular_momentum_pivot"] = (
                _VEC,
                self.angular_momentum_pivot,
                {**_MOMENTUM, "about": "pivot", "symbol": "L_P",
                 "pivot_position": self.pivot_position.tolist(),
                 "long_name": "angular momentum about the pivot"},
            )  # fmt: skip
        out |= self._table_fields(_SCALAR_VARIABLES)
        if self.sensitivities is not None:
            out |= _sensitivity_variables(self.sensitivities)
        out["axis"] = (("axis",), np.array(list("xyz")), {})
        out["component"] = (("component",), np.array(list("wxyz")), {})
        return out


#: The coordinates of the exported sensitivities.
_SENSITIVITY_COORDS = ("state_component", "parameter")


def _sensitivity_variables(sens, names=None, frames=None, **attrs) -> dict:
    """The exported sensitivities: ``sensitivity (time, state_component, parameter)`` with
    its two label coordinates; ``names`` label the state's components and ``frames`` says
    theirs (default: a rigid body's state, ``[R, V, Q, ω]``), ``attrs`` are added."""
    if names is None:
        names = [f"{b}_{c}" for b in ("R", "V") for c in "xyz"]
        names += [f"Q_{i}{j}" for i in range(1, 4) for j in range(1, 4)]
        names += [f"omega_{c}" for c in "xyz"]
        frames = "R, V space frame; Q body to space; omega body frame"
        attrs = {"omega0_frame": sens.omega_frame, **attrs}
    return {
        "sensitivity": (("time", "state_component", "parameter"), sens.S,
                        {"long_name": "forward sensitivity d state / d parameter",
                         "frames": frames,
                         "units": "the state component's over the parameter's (SI)",
                         **attrs,
                         **({} if sens.t0 is None else
                            {"t0": sens.t0,
                             "t0_long_name": "time of the initial state the derivatives "
                                             "are taken at"})}),
        "state_component": (("state_component",), np.array(names), {}),
        "parameter": (("parameter",), np.array(sens.directions.labels), {}),
    }  # fmt: skip
