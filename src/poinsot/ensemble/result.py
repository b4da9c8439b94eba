"""The result of an ensemble run: samples, per-member statistics, summaries and exports."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..display import Displayable
from ..layout import STATE_SIZE, STATE_SLICES

__all__ = ["EnsembleResult"]

#: Status codes of the compiled drivers, as words.
STATUS_NAMES = {1: "finished", 2: "non-finite state", 3: "step size too small", 0: "not run"}
#: A member with status 0 that took steps: its step budget was spent before its end.
STOPPED_AT_BUDGET = "stopped at `max_steps`"
#: Per-member statistics that :meth:`EnsembleResult.summary` describes, with their meaning.
STATISTICS = {
    "energy_error": "max |E(t) − E(0)| / |E(0)| over the samples (E = K + U)",
    "momentum_error": "max |L(t) − L(0)| / |L(0)|, L about the centre of mass, space frame",
    "orthogonality_error": "max |QᵀQ − I| over the samples",
    "first_flip": "time of the first sign change of ω on the intermediate principal axis [s]",
    "flip_count": "number of sign changes of ω on the intermediate principal axis",
    "flip_interval": "mean time between flips, (last − first)/(count − 1) [s]",
}


def _readonly(a):
    a.flags.writeable = False
    return a


@dataclass
class EnsembleResult(Displayable):
    """N motions sampled at the same times.

    Attributes
    ----------
    t : (n,) sample times (only the end time when no ``t_eval`` was given).
    state : (N, n, 18) body-frame states ``[R, V, Q, ω]`` (with ``keep_states=False`` only the
        final ones are kept: ``final_state`` (N, 18)).
    omega, Q, R, V, quaternion : views of ``state`` per quantity.
    energy_error, momentum_error, orthogonality_error : (N,) per member, over the samples.
    first_flip, last_flip : (N,) times of the first and last flips (NaN: none); flip_count (N,).
    status : (N,) driver status codes (1: finished); success (N,) bool; nsteps, nfev (N,).
    reductions : dict of the user reductions' results, name → (N, ...).
    """

    t: np.ndarray
    method: str
    final_state: np.ndarray
    energy_error: np.ndarray
    momentum_error: np.ndarray
    orthogonality_error: np.ndarray
    first_flip: np.ndarray
    last_flip: np.ndarray
    flip_count: np.ndarray
    status: np.ndarray
    nsteps: np.ndarray
    nfev: np.ndarray
    reductions: dict
    body: object = None
    member_moments: np.ndarray | None = None
    flips_recorded: bool = True
    _states: np.ndarray | None = None
    wall_time: float = math.nan
    options: dict = field(default_factory=dict)

    # ----------------------------------------------------------------- assembly
    @classmethod
    def allocate(cls, spec, N, keep_states, body, members):
        n = len(spec.t_eval)
        states = np.empty((N, n, STATE_SIZE)) if keep_states else None
        res = cls(
            t=_readonly(spec.t_eval.copy()),
            method=spec.method_name,
            final_state=np.empty((N, STATE_SIZE)),
            energy_error=np.empty(N),
            momentum_error=np.empty(N),
            orthogonality_error=np.empty(N),
            first_flip=np.empty(N),
            last_flip=np.empty(N),
            flip_count=np.empty(N, dtype=np.int64),
            status=np.zeros(N, dtype=np.int64),
            nsteps=np.zeros(N, dtype=np.int64),
            nfev=np.zeros(N, dtype=np.int64),
            reductions={},
            body=body,
            member_moments=None if members.inertia is None else members.inertia,
            flips_recorded=spec.flips,
            _states=states,
            options={
                "dt": spec.dt,
                "t_span": (spec.t0, spec.t1),
                "kind": spec.kind,
                "top": spec.top,
            },
        )
        res._N = N
        res._spec, res._members = spec, members  # the initial states, computed on demand
        return res

    def views(self, start, stop):
        """Where the chunk of members ``start … stop − 1`` run in this process writes its
        states (:class:`~poinsot.ensemble.tasks.ChunkViews`)."""
        from .tasks import ChunkViews

        s = slice(start, stop)
        Y = None if self._states is None else self._states[s]
        return ChunkViews(Y, self.final_state[s])

    def absorb(self, out) -> None:
        """Copy one chunk's output into place (called as chunks finish, in any order); its
        states are there already when it ran :meth:`in place <views>`."""
        s = slice(out.start, out.stop)
        if not out.in_place:
            if self._states is not None:
                self._states[s] = out.Y
            self.final_state[s] = out.final
        for name in ("energy", "momentum", "orthogonality"):
            getattr(self, f"{name}_error")[s] = getattr(out, name)
        self.first_flip[s] = out.first_flip
        self.last_flip[s] = out.last_flip
        self.flip_count[s] = out.flip_count
        self.status[s] = out.status
        self.nsteps[s] = out.nsteps
        self.nfev[s] = out.nfev
        for name, value in out.reductions.items():
            if name not in self.reductions:
                self.reductions[name] = np.empty((self._N, *value.shape[1:]), dtype=value.dtype)
            self.reductions[name][s] = value

    def drop_samples(self) -> None:
        """Keep none of the samples (an empty ``t_eval``): ``t`` (0,) and ``state``
        (N, 0, 18); the final states and the per-member statistics of the run remain."""
        self.t = _readonly(self.t[:0].copy())
        if self._states is not None:
            self._states = self._states[:, :0]

    # ----------------------------------------------------------------- samples
    def __len__(self):
        return len(self.final_state)

    def __repr__(self):
        ok = int(self.success.sum())
        return (
            f"EnsembleResult(N={len(self)}, samples={len(self.t)}, method={self.method!r}, "
            f"succeeded={ok}/{len(self)})"
        )

    #: Members whose initial states are computed at once by :meth:`initial_block`.
    INITIAL_CHUNK = 65_536

    @property
    def initial_state(self) -> np.ndarray:
        """Body-frame initial states (N, 18), computed from the members' inputs when asked
        for (the run does not keep them: 144 bytes a member); :meth:`initial_block` gives one
        quantity in less memory."""
        return self._initial("state")

    @property
    def initial_omega(self) -> np.ndarray:
        """Body-frame initial angular velocities (N, 3)."""
        return self._initial("omega")

    def initial_block(self, name: str) -> np.ndarray:
        """One quantity of the initial states (``"omega"``, ``"Q"``, ``"R"``, ``"V"``): (N, 3)
        or (N, 3, 3), computed a chunk of members at a time."""
        if name not in STATE_SLICES:
            raise ValueError(f"`name` must be one of {', '.join(STATE_SLICES)}, found {name!r}")
        return self._initial(name)

    def _initial(self, name):
        from .tasks import initial_states

        N, step = len(self), self.INITIAL_CHUNK
        width = STATE_SIZE if name == "state" else STATE_SLICES[name].stop - STATE_SLICES[
            name].start  # fmt: skip
        out = np.empty((N, width))
        for i0 in range(0, N, step):
            Y0 = initial_states(self._spec, self._members.task(i0, min(i0 + step, N)))
            out[i0 : i0 + len(Y0)] = Y0 if name == "state" else Y0[:, STATE_SLICES[name]]
        return out.reshape(N, 3, 3) if name == "Q" else out

    @property
    def state(self) -> np.ndarray:
        """Body-frame states (N, n, 18)."""
        if self._states is None:
            raise AttributeError(
                "this run kept only the final states (keep_states=False): use `final_state`, "
                "`final_omega`, `final_Q` and the per-member statistics"
            )
        return self._states

    def _block(self, name, states):
        out = states[..., STATE_SLICES[name]]
        return out.reshape(*states.shape[:-1], 3, 3) if name == "Q" else out

    @property
    def omega(self) -> np.ndarray:
        """Body-frame angular velocity (N, n, 3)."""
        return self._block("omega", self.state)

    @property
    def Q(self) -> np.ndarray:
        """Attitude, body → space (N, n, 3, 3)."""
        return self._block("Q", self.state)

    @property
    def R(self) -> np.ndarray:
        """Centre of mass (N, n, 3)."""
        return self._block("R", self.state)

    @property
    def V(self) -> np.ndarray:
        """Its velocity (N, n, 3)."""
        return self._block("V", self.state)

    @property
    def quaternion(self) -> np.ndarray:
        """Attitude as unit quaternions (w, x, y, z), w ≥ 0 (N, n, 4)."""
        from .._bindings.rotations import matrix_to_quat

        return matrix_to_quat(np.ascontiguousarray(self.Q))

    @property
    def final_omega(self) -> np.ndarray:
        """ω at the last sample (N, 3)."""
        return self._block("omega", self.final_state)

    @property
    def final_Q(self) -> np.ndarray:
        """Q at the last sample (N, 3, 3)."""
        return self._block("Q", self.final_state)

    # ----------------------------------------------------------------- per member
    @property
    def success(self) -> np.ndarray:
        """True for members whose run finished (N,)."""
        return self.status == 1

    @property
    def messages(self) -> np.ndarray:
        """Each member's status in words (N,)."""
        return np.array([_status_name(s, k) for s, k in zip(self.status, self.nsteps, strict=True)])

    def _failures(self, failed) -> dict:
        """``{status in words: members}`` of the members where ``failed`` (N,) is true (only
        those are named: a message per member of a large run would take 100 bytes each)."""
        names = [_status_name(s, k) for s, k in zip(self.status[failed], self.nsteps[failed],
                                                      strict=True)]  # fmt: skip
        return {str(n): int(c) for n, c in zip(*np.unique(names, return_counts=True), strict=True)}

    @property
    def flip_interval(self) -> np.ndarray:
        """Mean time between successive flips, ``(last − first)/(count − 1)`` (NaN with fewer
        than two flips) (N,)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            out = (self.last_flip - self.first_flip) / (self.flip_count - 1)
        return np.where(self.flip_count >= 2, out, np.nan)

    def statistic(self, name) -> np.ndarray:
        """A per-member statistic by name (see :data:`STATISTICS`) or a user reduction."""
        if name in STATISTICS:
            return np.asarray(getattr(self, name), dtype=float)
        if name in self.reductions:
            return self.reductions[name]
        raise ValueError(
            f"`name` must be one of {sorted(STATISTICS) + sorted(self.reductions)}, found {name!r}"
        )

    # ----------------------------------------------------------------- final attitudes
    def final_attitude_statistics(self) -> dict:
        """The spread of the final attitudes: their chordal mean rotation (SciPy's
        ``Rotation.mean``) and each member's angle from it, summarised."""
        from scipy.spatial.transform import Rotation

        ok = np.flatnonzero(self.success)
        if not len(ok):
            return {}
        step = self.INITIAL_CHUNK  # matrices to quaternions a chunk at a time: 32 B a member
        quats = np.empty((len(ok), 4))
        for i in range(0, len(ok), step):
            quats[i : i + step] = Rotation.from_matrix(self.final_Q[ok[i : i + step]]).as_quat()
        mean = Rotation.from_quat(quats).mean()
        angles = np.empty(len(ok))
        for i in range(0, len(ok), step):
            angles[i : i + step] = (
                mean.inv() * Rotation.from_quat(quats[i : i + step])
            ).magnitude()
        return {
            "mean_rotation_vector": mean.as_rotvec().tolist(),
            "angle_from_mean": _describe(angles),
        }

    # ----------------------------------------------------------------- grading
    def exact_errors(self) -> dict:
        """Errors of every member against the exact solution from its initial state:
        ``{"omega": (N,), "attitude": (N,)}``, the largest ``|Δω|`` and ``|ΔQ|`` over the
        samples. The exact solution is the torque-free one
        (:class:`~poinsot.torquefree.FreeRigidBody`, vectorised) for a run without forces or
        pivot, and Lagrange's top in closed form (:func:`poinsot.tops.exact_motion`) for a
        heavy symmetric top whose members share the body. Needs the states kept."""
        from ..torquefree import FreeRigidBody

        t = self.t - self.options["t_span"][0]
        W0, Q0 = self.initial_omega, self.initial_block("Q")
        omega, Q = self.omega, self.Q
        top = self.options.get("top")
        if top is not None and self.member_moments is None:
            from ..tops import exact_motion

            exact = exact_motion(top, W0, Q0, t)
            return {
                "omega": np.array([np.abs(omega[i] - e.omega).max() for i, e in enumerate(exact)]),
                "attitude": np.array([np.abs(Q[i] - e.Q).max() for i, e in enumerate(exact)]),
            }
        if self.options.get("kind") not in ("free", "free_varied"):
            raise ValueError("exact errors need a torque-free ensemble (no forces, no pivot) "
                             "or a heavy symmetric top whose members share the body")  # fmt: skip
        d_omega = np.empty(len(self))
        d_Q = np.empty(len(self))
        if self.member_moments is None:
            groups = [(FreeRigidBody.from_body(self.body), np.arange(len(self)))]
        else:
            groups = [(_free_body(J), np.array([i])) for i, J in enumerate(self.member_moments)]
        for free, idx in groups:
            w = free.exact_omega(W0[idx], t)
            q = free.exact_attitude(W0[idx], t, Q0[idx])
            d_omega[idx] = np.abs(omega[idx] - w).max(axis=(1, 2))
            d_Q[idx] = np.abs(Q[idx] - q).max(axis=(1, 2, 3))
        return {"omega": d_omega, "attitude": d_Q}

    # ----------------------------------------------------------------- summaries
    def summary(self) -> dict:
        """A JSON-ready summary: the run, and for each statistic its distribution over the
        members that finished (min, 5 %, median, 95 %, max, mean)."""
        ok = self.success
        out = {
            "members": len(self),
            "succeeded": int(ok.sum()),
            "failed": self._failures(~ok),
            "method": self.method,
            "samples": len(self.t),
            "t_span": list(self.options["t_span"]),
            "dt": self.options["dt"] or None,
            "wall_time_s": self.wall_time,
            "steps_per_member": _describe(self.nsteps[ok].astype(float)),
            "statistics": {},
        }
        for name, meaning in STATISTICS.items():
            if name.startswith(("first_flip", "flip")) and not self.flips_recorded:
                continue
            values = self.statistic(name)[ok]
            entry = {"meaning": meaning, **_describe(values)}
            if name == "first_flip":
                entry["members_with_a_flip"] = int(np.isfinite(values).sum())
            out["statistics"][name] = entry
        for name, value in self.reductions.items():
            if value.ndim == 1 and np.issubdtype(value.dtype, np.number):
                out["statistics"][name] = {"meaning": "user reduction", **_describe(value[ok])}
        if ok.any():
            out["final_attitude"] = self.final_attitude_statistics()
        return out

    # ----------------------------------------------------------------- exports
    def variables(self) -> dict:
        """The data as ``name → (dims, values, attrs)`` with dims ``member``, ``time``,
        ``component`` (and ``row``, ``col`` for Q), coordinates included (variables named like
        their dimension); per-member statistics on ``member``. What :meth:`to_xarray` and
        :meth:`to_netcdf` write."""
        data = {}
        if self._states is not None:
            dims = ("member", "time", "component")
            data["omega"] = (
                dims,
                self.omega,
                {"units": "rad/s", "frame": "body", "long_name": "angular velocity"},
            )
            data["R"] = (
                dims,
                self.R,
                {
                    "units": "m",
                    "frame": "space",
                    "long_name": "position of the centre of mass from the space origin",
                },
            )
            data["V"] = (
                dims,
                self.V,
                {"units": "m/s", "frame": "space", "long_name": "velocity of the centre of mass"},
            )
            data["Q"] = (
                ("member", "time", "row", "col"),
                self.Q,
                {"units": "1", "long_name": "attitude, body → space"},
            )
        else:
            data["final_omega"] = (
                ("member", "component"),
                self.final_omega,
                {"units": "rad/s", "frame": "body", "long_name": "angular velocity at the end"},
            )
            data["final_Q"] = (
                ("member", "row", "col"),
                self.final_Q,
                {"units": "1", "long_name": "attitude at the end, body → space"},
            )
        units = {"first_flip": "s", "flip_interval": "s"}
        for name, meaning in STATISTICS.items():
            attrs = {"long_name": meaning, "units": units.get(name, "1")}
            data[name] = (("member",), self.statistic(name), attrs)
        data["status"] = (("member",), self.status, {"long_name": "1: finished"})
        data["nsteps"] = (("member",), self.nsteps, {"units": "1"})
        for name, value in self.reductions.items():
            extra = tuple(f"{name}_dim{k}" for k in range(1, value.ndim))
            if value.ndim >= 2 and value.shape[1] == len(self.t):
                extra = ("time", *extra[1:])
            data[name] = (("member", *extra), value, {})
        coords = {
            "member": (("member",), np.arange(len(self)), {}),
            "time": (("time",), self.t, {"units": "s"}),
            "component": (("component",), np.array(["x", "y", "z"]), {}),
            "row": (("row",), np.arange(3), {}),
            "col": (("col",), np.arange(3), {}),
        }
        return {**data, **coords}

    def to_xarray(self):
        """An ``xarray.Dataset`` of :meth:`variables` (needs the ``xarray`` extra)."""
        from .._io import xarray_dataset

        return xarray_dataset(self.variables(), {"method": self.method})

    def to_netcdf(self, path, extra=None) -> None:
        """Write :meth:`variables` (and ``extra``, more ``name → (dims, values, attrs)``) to a
        NetCDF-3 file, atomically, with SciPy's writer: no xarray needed."""
        from .._io import write_netcdf

        write_netcdf(path, {**self.variables(), **(extra or {})}, {"method": self.method})


def _describe(values) -> dict:
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]
    if not len(finite):
        return {"count": 0}
    q = np.quantile(finite, [0.0, 0.05, 0.5, 0.95, 1.0])
    return {
        "count": len(finite),
        "min": float(q[0]),
        "p05": float(q[1]),
        "median": float(q[2]),
        "p95": float(q[3]),
        "max": float(q[4]),
        "mean": float(finite.mean()),
    }


def _free_body(inertia):
    from ..torquefree import FreeRigidBody

    moments, axes = np.linalg.eigh(inertia)
    free = FreeRigidBody.__new__(FreeRigidBody)
    free._setup(moments, axes)
    return free


def _status_name(status, nsteps) -> str:
    """A member's status in words: status 0 is "not run", or, after some steps, a member
    stopped by its step budget."""
    if int(status) == 0 and int(nsteps) > 0:
        return STOPPED_AT_BUDGET
    return STATUS_NAMES.get(int(status), str(status))
