"""Forward sensitivities of a rigid body's run: ``∂y(tᵢ)/∂p`` at every sample.

A run asks for them through its spec, ``simulate(..., sensitivities=("omega0", "inertia"))``;
the result's :meth:`Trajectory.sensitivity(output, wrt) <poinsot.trajectory.Trajectory.
sensitivity>` returns them. The parameters ``p`` (the *directions*) are named by
:data:`WRT` or by a force: ``"forces[i]"`` (every numeric parameter of the i-th force) or
``"forces[i].name"`` (one of them, :meth:`~poinsot.forces.Force.sensitive_parameters`).

The variational equations ``Ṡ = ∂f/∂y S + ∂f/∂p`` are integrated in the compiled core
alongside the motion, by the same method and steps, on dual numbers: no derivative is
written by hand (``crates/core/src/sensitivity.rs``; ``docs/tutorials/sensitivities.md``).
This module only names the directions and moves the results between frames; it holds no
physics.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable, Mapping, Set
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from . import layout
from ._bindings import inertia as core_inertia
from ._bindings import sensitivity as core_sensitivity
from .integrate.problem import NativeProblem

__all__ = [
    "OUTPUTS",
    "SENSITIVE_METHODS",
    "WRT",
    "Directions",
    "Floquet",
    "SensitiveSystem",
    "Sensitivities",
    "SensitivityMixin",
    "asked_names",
    "check_control",
    "check_directions",
    "check_run",
    "directions",
]

#: The parameters a run differentiates with respect to, with their sizes and meaning.
WRT = {
    "omega0": (3, "the initial angular velocity ω0, in the frame it was given (omega_frame)"),
    "Q0": (3, "the rotation vector δ of the initial attitude, Q0 → exp(δ̂) Q0 (space frame)"),
    "R0": (3, "the initial centre of mass (free body)"),
    "V0": (3, "the initial velocity of the centre of mass (free body)"),
    "inertia": (3, "the principal moments about the reference point, in the order of "
                   "RigidBodySystem.principal_moments (ascending)"),
}  # fmt: skip
#: The outputs a sensitivity is taken of: blocks of the body-frame state.
OUTPUTS = {**layout.STATE_SLICES, "state": slice(0, layout.STATE_SIZE)}
#: The methods whose runs carry sensitivities: the core's kinds for any vector field
#: (classical RK4, explicit tableaux, DOP853), and for a rigid body RKMK4, the splitting
#: method and the exact-flow splittings (the derivatives of their discrete steps).
SENSITIVE_METHODS = frozenset({"rk4", "erk", "dop853"})
RIGID_SENSITIVE_METHODS = SENSITIVE_METHODS | {"rkmk", "splitting", "exact-splitting"}

_START = {"omega0": 1, "Q0": 2, "R0": 3, "V0": 4}
_FORCE = re.compile(r"forces\[(\d+)\](?:\.(\w+))?$")


@dataclass(frozen=True)
class Directions:
    """The directions of a run's sensitivities, in the order of its columns.

    Attributes
    ----------
    names : tuple of str
        The parameters asked for (``wrt``), in order.
    columns : dict
        ``name → slice`` of the columns of each.
    labels : tuple of str
        One label per column (``"omega0[0]"``, ``"forces[1].stiffness"``).
    kinds, components : ndarray (P,)
        Each column's start in the initial state (the core's codes: 0 a parameter).
    moment_seeds : ndarray (P, 3)
    force_seeds : ndarray (P, 10 k)
        Each column's seeds of the principal moments and of the lowered force rows.
    """

    names: tuple
    columns: dict
    labels: tuple
    kinds: np.ndarray
    components: np.ndarray
    moment_seeds: np.ndarray
    force_seeds: np.ndarray

    @property
    def size(self) -> int:
        return len(self.labels)


@dataclass(frozen=True)
class Floquet:
    """The Floquet picture of a periodic motion: its monodromy matrix ``M = ∂x(T)/∂x(0)`` (the
    linearised map over one period ``T``, from the sensitivities of the motion), the
    multipliers (the eigenvalues of ``M``) and the exponents ``ln|μ|/T``.

    A multiplier outside the unit circle is a deviation that grows period after period (at the
    rate of its exponent); a multiplier 1 in a Jordan block is one that drifts linearly (a
    neighbour with another period, a phase). Of a steady motion or an equilibrium, whose
    linearisation ``A`` is constant, the multipliers are ``exp(λ T)`` for the eigenvalues λ of
    ``A``: the run checks the linearisation's verdict on the nonlinear motion itself.

    A multiplier is known to about the monodromy's own accuracy times ``‖M‖``: over a long
    period of an unstable motion, where the largest is ``exp(σ T)``, the small ones drown in
    it (on the intermediate axis of moments 1, 2, 3 over 50 s, the contracting exponent comes
    out −0.17 for −0.58). The largest exponent and the drift stay meaningful; take a shorter
    period to see the rest. A run over a given period that does not return to its start is
    refused (``check_returned``).

    Attributes
    ----------
    period : float
    monodromy : ndarray (d, d)
    multipliers : ndarray (d,) complex
    exponents : ndarray (d,)
        ``ln|μ|/T``, descending.
    drift : float
        ``‖M − I‖₂``: the growth per period of a deviation (0 at a stable fixed point).
    method : str
        ``"closed form"`` (the exact derivatives of the torque-free solution) or
        ``"dop853"`` (the forward sensitivities of an integrated run).
    """

    period: float
    monodromy: np.ndarray
    multipliers: np.ndarray
    exponents: np.ndarray
    drift: float = 0.0
    method: str = "dop853"

    @classmethod
    def of(cls, monodromy, period, method="dop853") -> Floquet:
        """The picture of the monodromy matrix ``monodromy`` over ``period``."""
        M = np.asarray(monodromy, dtype=float)
        mu = np.linalg.eigvals(M)
        with np.errstate(divide="ignore"):
            exponents = np.sort(np.log(np.abs(mu)) / period)[::-1]
        drift = float(np.linalg.norm(M - np.eye(len(M)), 2))
        return cls(float(period), M, mu, exponents, drift, method)


#: How far (relative to the state's scale) a run over a given ``period`` may end from where a
#: periodic motion returns to before its monodromy is refused: the multipliers of a run that
#: does not close are those of no periodic motion.
RETURN_RTOL = 1e-6


def check_returned(end, expected, scale, period, what, hint="") -> None:
    """Refuse a monodromy over ``period`` whose run ended at ``end``, not at ``expected``
    (where a periodic or steady motion is after one period), by more than
    :data:`RETURN_RTOL` of ``scale``: ``period`` is not a period of the motion, or the run
    left an unstable one (round-off grows there as ``exp(σ T)``)."""
    miss = float(np.abs(np.asarray(end, float) - np.asarray(expected, float)).max())
    if not miss <= RETURN_RTOL * scale:
        raise ValueError(f"`period` {period:.9g}: the motion does not return over it ({what} "
                         f"is {miss:.3g} from where it started, {miss / scale:.3g} of its "
                         "scale): the multipliers would be those of no periodic "
                         f"motion{hint}")  # fmt: skip


def check_control(control, solver, asked: bool) -> bool:
    """``control_sensitivities`` checked: a bool (NumPy's included), else refused; ``False``
    refused where it has no effect: without ``sensitivities`` (``asked``) or with a
    fixed-step ``solver``, which controls no error."""
    if not isinstance(control, bool | np.bool_):
        raise TypeError(f"`control_sensitivities` must be True or False, found {control!r}")
    if not control and not asked:
        raise ValueError("`control_sensitivities` has no effect without `sensitivities`")
    if not control and not solver.adaptive:
        raise ValueError(f"`control_sensitivities=False` has no effect with the fixed-step "
                         f"method {solver.name!r}: it leaves the sensitivities out of an "
                         "adaptive method's error control ('dop853')")  # fmt: skip
    return bool(control)


def check_run(system, solver, backend, *, rigid=True) -> None:
    """Refuse a run that cannot carry sensitivities, before it is lowered: a method without
    them (``rigid``: a rigid body's, which adds RKMK4, the splitting method and the exact-flow
    splittings), a force evaluated in Python, the Python backend, a degenerate body (``system``
    a :class:`~poinsot.dynamics.RigidBodySystem`)."""
    lie = {"rkmk": "rkmk4", "splitting": "splitting"} if rigid else {}
    kinds = RIGID_SENSITIVE_METHODS if rigid else SENSITIVE_METHODS
    if solver.kind not in kinds or lie.get(solver.kind, solver.name) != solver.name:
        names = ("'rk4', 'rkmk4', 'splitting', 'exact-splitting*', 'dop853'" if rigid
                 else "'rk4', 'dop853'")  # fmt: skip
        raise ValueError(f"`sensitivities` are computed with {names} or an explicit "
                         f"Runge–Kutta tableau; `method` {solver.name!r} has none")  # fmt: skip
    slow = [f.name for f in system.forces if not f.compiled]
    if slow:
        raise ValueError("`sensitivities` need built-in forces; these are evaluated in Python: "
                         + ", ".join(slow))  # fmt: skip
    if backend == "python":
        raise ValueError("`sensitivities` are computed in the compiled core: omit "
                         "`backend='python'`")  # fmt: skip
    if system.degenerate:
        raise ValueError("`sensitivities` need a body with three non-zero principal moments")


def check_directions(system, solver, dirs: Directions) -> None:
    """Refuse directions a method cannot differentiate. With the splitting method or an
    exact-flow splitting:

    - those that move a spring's damping: the kicks take position-only forces, and a damper
      (of any size, however small) makes the force depend on the velocity;
    - those that move a symmetric body's equal principal moments apart (its free flow is then
      the symmetric closed form, which has no derivative along one of them alone; a body with
      three distinct moments takes another flow)."""
    if solver.kind not in ("splitting", "exact-splitting"):
        return
    force_seeds = np.asarray(dirs.force_seeds, dtype=float).reshape(
        len(dirs.labels), -1, layout.FORCE_PARAMS
    )
    for k, force in enumerate(system.forces):
        if force.kind != "spring":
            continue
        (damping,) = [offset for name, offset, *_ in force.sensitive_parameters()
                      if name == "damping"]  # fmt: skip
        if np.any(force_seeds[:, k, damping] != 0):
            raise ValueError(
                f"`sensitivities` along 'forces[{k}].damping' with {solver.name!r}: its kicks "
                "take position-only forces, and a damper makes the spring's force depend on "
                "the velocity; leave it out, or use 'rkmk4', 'rk4' or 'dop853'"
            )
    moments = np.asarray(system.principal_moments, dtype=float)
    code = core_inertia.symmetry_code(moments, core_inertia.SYMMETRY_RTOL)
    equal = {1: [(1, 2)], 2: [(0, 1)], 3: [(0, 1), (0, 2)]}.get(code, [])
    seeds = np.asarray(dirs.moment_seeds, dtype=float).reshape(-1, 3)
    if any(np.any(seeds[:, a] != seeds[:, b]) for a, b in equal):
        raise ValueError(
            f"`sensitivities` along the principal moments ('inertia') of a symmetric body "
            f"({moments.tolist()}) with {solver.name!r}: its free flow is the symmetric closed "
            "form, which has no derivative along one of its equal moments alone; leave "
            "'inertia' out, or use 'rkmk4', 'rk4' or 'dop853'"
        )


def asked_names(wrt) -> tuple:
    """The names of ``sensitivities`` (a name or a sequence of names; NumPy's strings as
    ``str``), checked: at least one, each a string, none twice."""
    if isinstance(wrt, str):
        names = (wrt,)
    elif isinstance(wrt, Set | Mapping):
        raise TypeError(f"`sensitivities` must be a name or an ordered sequence of names (a "
                        f"tuple or a list: the columns follow its order), found a "
                        f"{type(wrt).__name__}")  # fmt: skip
    elif isinstance(wrt, Iterable):
        names = tuple(str(x) if isinstance(x, str) else x for x in wrt)
    else:
        raise TypeError(f"`sensitivities` must be a name or a sequence of names, found {wrt!r}")
    if not names:
        raise ValueError("`sensitivities` must name at least one parameter")
    for i, name in enumerate(names):
        if not isinstance(name, str):
            raise TypeError(f"`sensitivities[{i}]` must be a name, found {name!r}")
        if name in names[:i]:
            raise ValueError(f"`sensitivities[{i}]`: {name!r} is named twice")
    return names


def refuse_repeated_columns(names, columns: dict, labels) -> None:
    """Refuse names that ask for one column twice under two names (``"forces[0]"`` and
    ``"forces[0].g"``, ``"q0"`` and ``"q0[x]"``): ``columns`` maps each name to its slice of
    the (canonical) ``labels``."""
    first = {}
    for i, name in enumerate(names):
        for label in labels[columns[name]]:
            if label in first:
                j = first[label]
                raise ValueError(f"`sensitivities[{i}]`: {name!r} asks again for the column "
                                 f"{label!r} of `sensitivities[{j}]` {names[j]!r}")  # fmt: skip
            first[label] = i


def directions(system, wrt, starts=None) -> Directions:
    """The :class:`Directions` of ``wrt`` (a name or a sequence of names) for a
    :class:`~poinsot.dynamics.RigidBodySystem`, checked: each name known, once, and with an
    effect on this system. ``starts`` names the initial state's parts (``{"omega0": 1,
    "Q0": 2, "R0": 3, "V0": 4}`` by default; a relative motion's are ``omega_r0``, ``Q_r0``,
    ``r0``, ``v_r0``)."""
    starts = _START if starts is None else starts
    names = asked_names(wrt)
    nf = len(system.force_kind)
    kinds, comps, moments, forces, labels, columns = [], [], [], [], [], {}
    for i, name in enumerate(names):
        start = len(labels)
        for label, kind, comp, dm, df in _columns(system, name, i, nf, starts):
            labels.append(label)
            kinds.append(kind)
            comps.append(comp)
            moments.append(dm)
            forces.append(df)
        columns[name] = slice(start, len(labels))
    refuse_repeated_columns(names, columns, labels)
    seeds = np.array(forces, dtype=float).reshape(len(labels), nf * layout.FORCE_PARAMS)
    return Directions(names, columns, tuple(labels), np.array(kinds, dtype=np.int64),
                      np.array(comps, dtype=np.int64), np.array(moments, dtype=float),
                      seeds)  # fmt: skip


def _columns(system, name, i, nf, starts):
    """The columns of one name: ``(label, start kind, component, moment seeds, force
    seeds)``."""
    zero_f = np.zeros((nf, layout.FORCE_PARAMS))
    if name in starts:
        if system.pivot is not None and starts[name] in (3, 4):
            raise ValueError(f"`sensitivities[{i}]`: {name!r} has no effect about a pivot (the "
                             "pivot sets the centre of mass and its velocity)")  # fmt: skip
        return [(f"{name}[{k}]", starts[name], k, np.zeros(3), zero_f) for k in range(3)]
    if name == "inertia":
        return [(f"inertia[{k}]", 0, 0, np.eye(3)[k], zero_f) for k in range(3)]
    m = _FORCE.match(name)
    if m is None:
        known = ", ".join(repr(n) for n in (*starts, "inertia"))
        raise ValueError(f"`sensitivities[{i}]`: unknown parameter {name!r}; known: {known}, "
                         "'forces[i]' and 'forces[i].<parameter>'")  # fmt: skip
    k, which = int(m.group(1)), m.group(2)
    if k >= len(system.forces):
        raise ValueError(f"`sensitivities[{i}]`: {name!r} names force {k}; the run has "
                         f"{len(system.forces)}")  # fmt: skip
    force = system.forces[k]
    params = force.sensitive_parameters()
    if which is not None:
        params = [p for p in params if p[0] == which]
        if not params:
            names = ", ".join(p[0] for p in force.sensitive_parameters())
            raise ValueError(f"`sensitivities[{i}]`: {force.name} has no parameter {which!r}; "
                             f"its parameters: {names}")  # fmt: skip
    out = []
    for pname, offset, size, frame in params:
        block = np.eye(size) if frame == "space" else system.principal_axes.T
        for c in range(size):
            df = zero_f.copy()
            df[k, offset : offset + size] = block[:, c]
            label = f"forces[{k}].{pname}" + (f"[{c}]" if size > 1 else "")
            out.append((label, 0, 0, np.zeros(3), df))
    return out


class SensitiveSystem:
    """A rigid body's run with its sensitivities, as the run contract takes a system
    (:mod:`poinsot.integrate.problem`): the augmented state ``[y (18), S (18 × P,
    row-major)]`` in the body frame outside the core, in the principal frame inside."""

    #: A rigid body's (RKMK4 steps it on SO(3); the problem lists the methods it offers).
    structure = "rigid"
    #: The state's parts, and the columns after them (a run that stops names what is not
    #: finite).
    state_slices: ClassVar[dict[str, slice]] = {
        **layout.STATE_SLICES,
        "sensitivities": slice(layout.STATE_SIZE, None),
    }
    #: The length of the system's own state.
    size = layout.STATE_SIZE

    def __init__(self, system, dirs: Directions, *, control_all=True, omega_space=False):
        self.system, self.directions = system, dirs
        self.control_all, self.omega_space = bool(control_all), bool(omega_space)
        self.forces = system.forces

    def problem(self, y0) -> NativeProblem:
        body, kinds, params, _, _ = self.system.native(np.asarray(y0, float)[: layout.STATE_SIZE])
        d = self.directions
        data = (body, kinds, params, np.ascontiguousarray(d.moment_seeds),
                np.ascontiguousarray(d.force_seeds), self.control_all)  # fmt: skip
        return NativeProblem(core_sensitivity.integrate_sensitivities, data,
                             RIGID_SENSITIVE_METHODS)  # fmt: skip

    def to_internal(self, y0) -> np.ndarray:
        """The augmented initial state (principal frame) of a body-frame state ``y0`` (18,):
        the directions' initial columns, by the core."""
        y0 = np.asarray(y0, dtype=float)[: layout.STATE_SIZE]
        body = self.system.native(y0)[0]
        d = self.directions
        return core_sensitivity.sensitivity_start(
            body, np.ascontiguousarray(self.system.principal_axes, dtype=float),
            np.ascontiguousarray(self.system.to_internal(y0)), d.kinds, d.components,
            self.omega_space,
        )  # fmt: skip

    def from_internal(self, z) -> np.ndarray:
        """Augmented states (n, 18 (1 + P)) from the principal frame to the body frame: the
        state's map, linear, applied to the state and to each direction's column."""
        z = np.asarray(z, dtype=float)
        n, size, p = z.size // self.width, self.size, self.directions.size
        rows = z.reshape(n, self.width)
        S = rows[:, size:].reshape(n, size, p).transpose(0, 2, 1)  # (n, P, 18)
        out = np.empty_like(rows)
        out[:, :size] = self.system.from_internal(rows[:, :size])
        columns = self.system.from_internal(S.reshape(-1, size)).reshape(n, p, size)
        out[:, size:] = columns.transpose(0, 2, 1).reshape(n, size * p)
        return out.reshape(z.shape)

    @property
    def width(self) -> int:
        """The augmented state's length, ``18 (1 + P)`` (its own state's length for 18)."""
        return self.size * (1 + self.directions.size)


@dataclass(frozen=True)
class Sensitivities:
    """The sensitivities of a run: ``S[i, :, j] = ∂y(tᵢ)/∂p_j`` of the body-frame state ``y``
    (18: ``R``, ``V``, ``Q`` row-major, ``ω``), one column per label of its directions."""

    S: np.ndarray
    directions: Directions
    #: The outputs by name: blocks of the state.
    outputs: dict = dataclasses.field(default_factory=lambda: OUTPUTS)
    #: The time of the initial state the derivatives are taken at (the run's start, which
    #: need not be a sample); None: the first sample.
    t0: float | None = None
    #: The frame the ``omega0`` columns' ω0 was given in (``omega_frame`` of the run).
    omega_frame: str = "body"

    def of(self, output, wrt=None) -> np.ndarray:
        """``∂output/∂wrt`` (samples, size of ``output``, size of ``wrt``); ``wrt`` None: every
        column. ``wrt`` is a name the run asked for, or a part of one: a force's parameter
        (``"forces[0].g"`` of ``"forces[0]"``) or one column (``"omega0[1]"``). A name that
        covers more than the run asked (``"params"`` of a run that asked ``"params[m2]"``) is
        refused, naming what was asked: its columns are not all there."""
        if not isinstance(output, str) or output not in self.outputs:
            raise ValueError(f"`output` must be one of {', '.join(map(repr, self.outputs))}, "
                             f"found {output!r}")  # fmt: skip
        if wrt is not None and not isinstance(wrt, str):
            raise TypeError(f"`wrt` must be one name (a string) the run asked for, or None for "
                            f"all of them; found {wrt!r}")  # fmt: skip
        cols = slice(None)
        if wrt is not None:
            cols = self.directions.columns.get(wrt)
            if cols is None:
                cols = self._part(wrt)
        return self.S[:, self.outputs[output], cols]

    def _part(self, wrt: str) -> list:
        """The columns of ``wrt``, a part of a name the run asked for (``"forces[0].g"`` of
        ``"forces[0]"``, ``"omega0[1]"`` of ``"omega0"``); refused otherwise, saying why."""
        names, labels = self.directions.names, self.directions.labels

        def within(name, whole):  # name is a part of whole: "whole[...", "whole.…"
            return name.startswith((whole + "[", whole + "."))

        owner = next((n for n in names if within(wrt, n)), None)
        if owner is None:
            parts = [n for n in names if within(n, wrt)]
            if parts:  # "params" of a run that asked "params[m2]": only some of its columns
                raise ValueError(f"`wrt` {wrt!r}: this run asked only part of it "
                                 f"({', '.join(map(repr, parts))}); name one of those")  # fmt: skip
            asked = ", ".join(map(repr, names))
            raise ValueError(f"`wrt` {wrt!r} was not asked of this run; it has: {asked} "
                             "(simulate(..., sensitivities=...))")  # fmt: skip
        cols = [j for j, x in enumerate(labels) if x == wrt or within(x, wrt)]
        if not cols:  # "omega0[5]": a name asked for, a column it does not have
            own = [labels[j] for j in range(len(labels))[self.directions.columns[owner]]]
            raise ValueError(f"`wrt` {wrt!r}: no such column; those of {owner!r} are "
                             f"{', '.join(map(repr, own))}")  # fmt: skip
        return cols


def split(y_aug, dirs: Directions, size=layout.STATE_SIZE,
          outputs=None, t0=None) -> tuple[np.ndarray, Sensitivities]:  # fmt: skip
    """The states (n, ``size``) and :class:`Sensitivities` of augmented states, taken at the
    initial state of time ``t0``."""
    n = len(y_aug)
    rows = np.asarray(y_aug, dtype=float).reshape(n, size * (1 + dirs.size))
    S = rows[:, size:].reshape(n, size, dirs.size).copy()
    S.flags.writeable = False
    return rows[:, :size], Sensitivities(S, dirs, OUTPUTS if outputs is None else outputs,
                                         None if t0 is None else float(t0))  # fmt: skip


class SensitivityMixin:
    """:meth:`sensitivity` and :meth:`lyapunov_exponents` of a result that may carry
    sensitivities (``sensitivities``: :class:`Sensitivities` or None)."""

    sensitivities = None
    #: The default output and parameter of :meth:`lyapunov_exponents`.
    _growth = ("omega", "omega0")

    def sensitivity(self, output, wrt=None) -> np.ndarray:
        """``∂output(tᵢ)/∂wrt`` at every sample, shape (samples, size of ``output``, size of
        ``wrt``), of a run that asked for them (``sensitivities=(...)`` of its front-end).

        Parameters
        ----------
        output : str
            A block of the state: ``"R"``, ``"V"``, ``"Q"`` (row-major, 9), ``"omega"``,
            ``"state"`` for a rigid body; ``"r"``, ``"v_r"``, ``"Q_r"``, ``"omega_r"``,
            ``"state"`` relative to a carrier; in the frames of the result's own fields.
        wrt : str, optional
            One of the names the run asked for, or a part of one (``"forces[0].g"`` of
            ``"forces[0]"``, ``"omega0[1]"``); None: all of them, in order.

        Examples
        --------
        >>> from poinsot import RigidBody, simulate
        >>> traj = simulate(RigidBody.box(1.0, (1, 2, 3)), (0, 1), omega0=(0, 1, 0),
        ...                 method="rk4", dt=1e-2, sensitivities="omega0")
        >>> traj.sensitivity("omega", "omega0").shape
        (101, 3, 3)
        """
        if self.sensitivities is None:
            raise ValueError("this run carries no sensitivities: ask for them with "
                             "sensitivities=(...) when it is run")  # fmt: skip
        return self.sensitivities.of(output, wrt)

    def lyapunov_exponents(self, output=None, wrt=None) -> np.ndarray:
        """Finite-time Lyapunov exponents ``λ_k(t) = ln σ_k(∂output(t)/∂wrt)/(t − t0)``, the
        singular values ``σ_k`` of the sensitivity descending, at every sample (NaN at
        ``t0``, the run's start, whether or not it is a sample): shape (samples, min(size of
        output, size of wrt)). By default the angular velocity against its initial value
        (``"omega"``, ``"omega0"``; relative to a carrier ``"omega_r"``, ``"omega_r0"``).

        The largest exponent is as accurate as the sensitivity itself. A smaller one is
        resolved only while ``σ_k/σ_1`` stays well above the sensitivity's relative accuracy
        (its round-off, 1e-16, or the run's tolerance, whichever is larger): the sensitivity's
        error is relative to ``σ_1``. Past that, ``σ_k`` is noise. About the intermediate axis
        the smallest exponent of ω is off by 1e-7 once ``σ_1/σ_3 = e^{24}`` (t = 20 with a
        growth rate of 0.6), and by a few per cent at t = 30. The exponents of a
        volume-preserving flow (the torque-free ω) sum to zero, and that sum is a check.

        Examples
        --------
        >>> from poinsot import RigidBody, simulate
        >>> traj = simulate(RigidBody.box(1.0, (1, 2, 3)), (0, 20), omega0=(0, 1, 0),
        ...                 method="dop853", sensitivities="omega0")
        >>> round(float(traj.lyapunov_exponents()[-1, 0]), 2)   # growth about the middle axis
        0.48
        """
        S = self.sensitivity(output or self._growth[0], wrt or self._growth[1])
        sigma = np.linalg.svd(S, compute_uv=False)
        t0 = self.sensitivities.t0
        elapsed = (self.t - (self.t[0] if t0 is None else t0))[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            out = np.log(sigma) / elapsed
        out[elapsed[:, 0] == 0] = np.nan
        return out
