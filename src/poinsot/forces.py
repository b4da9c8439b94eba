"""Forces and torques on a rigid body, as immutable descriptions (``docs/theory.md`` §1, eqs
(07)–(08)).

A force is data: a kind and its parameters. It never changes once built, and preparing it for a
body — :meth:`Force.lower` — returns a *new* row of numbers, the lowered force that the compiled
engine reads (``crates/core/src/forces.rs`` holds every formula). The same force can therefore
act on several bodies, in several systems, at once.

At a state ``(t, R, V, Q, ω)`` a force has a **wrench**: the total force ``F`` in the space frame
and its torque ``τ`` about the **centre of mass** in the **body frame**. The simulator adds the
wrenches, shifts torques to the pivot when there is one, and solves ``M R̈ = F`` (07) and
``A ω̇ + ω × Aω = τ`` (08), ``τ = Σ u_i × Qᵀ F_i``.

Flags:

* ``position_only``: the wrench depends on ``(t, R, Q)`` alone, so the force can act as a kick
  in the symplectic splitting integrator;
* ``has_potential``: there is a potential ``U`` (:meth:`Force.potential`), and ``K + U`` is
  reported; ``dissipative``: the force also removes energy (a damper, drag);
  ``conservative = has_potential and not dissipative``: total energy is then conserved.
* ``compiled``: a built-in kind the compiled engine evaluates. Forces given by Python callables
  (:class:`ParticleForce`, :class:`CustomForce`, a :class:`PointForce` or :class:`Torque` with a
  callable) run on the Python path, the slow one: each right-hand side then calls Python.

Body points are given in the body's reference configuration (the frame in which the
:class:`~poinsot.bodies.RigidBody` was built); at attitude ``Q`` the point ``p`` sits at
``R + Q (p − c)`` with ``c`` the reference centre of mass.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

import numpy as np

from ._bindings import rigid as core_rigid
from ._validation import as_positive_scalar, as_scalar, as_vector3
from .layout import FORCE_KINDS, FORCE_PARAMS, pack_state

__all__ = [
    "BodyFrame",
    "CentralGravity",
    "CustomForce",
    "Force",
    "ForceContext",
    "ForceError",
    "Gravity",
    "LinearDrag",
    "ParticleForce",
    "PointForce",
    "QuadraticDrag",
    "Spring",
    "Torque",
]


class ForceError(ValueError):
    """A force (usually a user callable) returned something unusable, or raised: the message
    names the force and the time, the original exception is the cause."""


def _call_user(force, method, ctx, what="force"):
    """``method(ctx)`` of the Python ``force``, with an exception from the user's code re-raised
    as :class:`ForceError` naming the force and the time ``t`` (the original as its
    ``__cause__``); an interrupt passes through untouched."""
    try:
        return method(ctx)
    except ForceError:
        raise
    except Exception as exc:
        raise ForceError(f"{what} {force.name} raised {type(exc).__name__} at t = "
                         f"{float(ctx.t):.17g}: {exc}") from exc  # fmt: skip


class BodyFrame:
    """Where a body's points and body-fixed vectors go when a force is lowered: relative to the
    centre of mass ``center_of_mass`` (3,), in the frame whose axes are the columns of ``axes``
    (3, 3) in body coordinates (the principal axes inside the engine; the identity for the
    body's own frame)."""

    __slots__ = ("axes", "center_of_mass")

    def __init__(self, center_of_mass, axes=None):
        self.center_of_mass = np.asarray(center_of_mass, dtype=float)
        self.axes = np.eye(3) if axes is None else np.asarray(axes, dtype=float)

    def point(self, p) -> np.ndarray:
        """Coordinates of the body point ``p`` (reference configuration) from the centre of
        mass, in this frame."""
        return self.axes.T @ (np.asarray(p, dtype=float) - self.center_of_mass)

    def vector(self, v) -> np.ndarray:
        """Components of the body-fixed vector ``v`` in this frame."""
        return self.axes.T @ np.asarray(v, dtype=float)


def _particles(R, Q, u, omega=None):
    """Positions ``Q u + R`` of body points ``u`` (N, 3) of one state, or with ``omega`` their
    velocities ``Q(ω × u) + R`` (``R`` then the velocity ``V``): (N, 3), by the core."""
    c = np.ascontiguousarray
    R = c(R, dtype=float).reshape(1, 3)
    Q = c(Q, dtype=float).reshape(1, 3, 3)
    u = c(u, dtype=float).reshape(-1, 3)
    if omega is None:
        return core_rigid.particle_motion(R, Q, u)[0]
    return core_rigid.particle_motion(R, Q, u, c(omega, dtype=float).reshape(1, 3))[0]


class ForceContext:
    """The state a Python force sees: time, centre of mass ``R``, its velocity ``V`` (space
    frame), attitude ``Q`` and body angular velocity ``omega``, plus the body. Particle
    positions and velocities are computed on first use."""

    __slots__ = ("Q", "R", "V", "_r", "_v", "body", "omega", "t")

    def __init__(self, body, t, R, V, Q, omega):
        self.body, self.t, self.R, self.V, self.Q, self.omega = body, t, R, V, Q, omega
        self._r = self._v = None

    def point_position(self, offset_body):
        """Space position ``R + Q b`` of the body point at offset ``b`` (3,) from the centre of
        mass."""
        return _particles(self.R, self.Q, np.atleast_2d(offset_body))[0]

    def point_velocity(self, offset_body):
        """Space velocity ``V + Q(ω × b)`` of the body point at offset ``b``."""
        return _particles(self.V, self.Q, np.atleast_2d(offset_body), self.omega)[0]

    @property
    def particle_positions(self):
        """``r_i = Q u_i + R``, shape (N, 3)."""
        if self._r is None:
            self._r = _particles(self.R, self.Q, self.body.u)
        return self._r

    @property
    def particle_velocities(self):
        """``ṙ_i = Q(ω × u_i) + Ṙ``, shape (N, 3)."""
        if self._v is None:
            self._v = _particles(self.V, self.Q, self.body.u, self.omega)
        return self._v

    def state(self) -> np.ndarray:
        """The flat 18-state ``[R, V, Q, ω]`` (body frame)."""
        return pack_state(self.R, self.V, self.Q, self.omega)


def _readonly(a) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


class Force:
    """Base class of forces: an immutable description.

    Built-in kinds set :attr:`kind` (a key of :data:`~poinsot.layout.FORCE_KINDS`)
    and implement :meth:`lower`; forces given by Python callables implement
    :meth:`python_wrench` (and :meth:`python_potential`) instead.
    """

    kind: ClassVar[str | None] = None
    position_only: bool = False
    has_potential: bool = False
    dissipative: bool = False

    def _freeze(self, **values):
        for name, value in values.items():
            object.__setattr__(self, name, value)

    def __setattr__(self, name, value):
        raise AttributeError(
            f"{type(self).__name__} is immutable: build a new force instead of setting {name!r}"
        )

    @property
    def name(self) -> str:
        return type(self).__name__

    @property
    def compiled(self) -> bool:
        """True when the compiled engine evaluates this force (a built-in kind)."""
        return self.kind is not None

    @property
    def conservative(self) -> bool:
        """True when the force has a potential and dissipates nothing (``K + U`` is kept)."""
        return self.has_potential and not self.dissipative

    def check(self, body) -> None:
        """Refuse a body this force cannot act on (raises ``ValueError``)."""

    def sensitive_parameters(self) -> tuple:
        """The numeric parameters a run may differentiate with respect to
        (``simulate(..., sensitivities=("forces[i].name",))``): ``(name, offset in the
        lowered row, size, frame)``, ``frame`` ``"body"`` where :meth:`lower` turns the
        parameter into the principal frame, else ``"space"`` (it is copied as given). A force
        evaluated in Python has none."""
        raise ValueError(f"{self.name} is evaluated in Python: a run cannot differentiate "
                         "with respect to its parameters")  # fmt: skip

    def lower(self, frame: BodyFrame) -> np.ndarray:
        """The force's parameters for the compiled engine, a new array (FORCE_PARAMS,), with body
        points and body-fixed vectors expressed in ``frame``. The force itself is unchanged."""
        raise NotImplementedError(f"{self.name} is evaluated in Python, it has no lowered form")

    def wrench(self, ctx: ForceContext) -> tuple[np.ndarray, np.ndarray]:
        """``(F (3,) space frame, τ (3,) body frame about the centre of mass)`` at ``ctx``."""
        if not self.compiled:
            return self.python_wrench(ctx)
        return _core_wrench(ctx, self.kind, self.lower)

    def potential(self, ctx: ForceContext) -> float:
        """Potential energy ``U``, defined up to a constant."""
        if not self.has_potential:
            raise NotImplementedError(f"{self.name} has no potential")
        if not self.compiled:
            return self.python_potential(ctx)
        body_params, frame = _body_frame_parameters(ctx.body)
        _, U = core_rigid.force_wrench_potential(
            FORCE_KINDS[self.kind], self.lower(frame), body_params, float(ctx.t), ctx.state()
        )
        return float(U)

    def python_wrench(self, ctx):  # pragma: no cover - abstract
        raise NotImplementedError

    def python_potential(self, ctx):  # pragma: no cover - abstract
        raise NotImplementedError

    def __repr__(self) -> str:
        return self.name


def _core_wrench(ctx, kind, lower):
    """The core's wrench of the built-in force ``kind`` whose parameter row is
    ``lower(frame)``, at ``ctx``: ``(F (3,) space frame, τ (3,) body frame about the centre of
    mass)``. Forces given by Python callables whose output is a built-in kind's data (a
    point force's vector, a torque) go through it, so the formula lives in the core only."""
    body_params, frame = _body_frame_parameters(ctx.body)
    (F, tau), _ = core_rigid.force_wrench_potential(
        FORCE_KINDS[kind], lower(frame), body_params, float(ctx.t), ctx.state()
    )
    return np.array(F), np.array(tau)


def _body_frame_parameters(body):
    """The parameter vector of a free body in its own frame (identity axes), for evaluating one
    force outside the engine."""
    inertia = np.ascontiguousarray(body.inertia, dtype=float)
    params = core_rigid.body_vector(
        float(body.mass), [float(x) for x in np.diag(inertia)], [0.0] * 3, inertia, [0.0] * 3,
        False, -1,
    )  # fmt: skip
    return params, BodyFrame(body.center_of_mass)


def _row(*values) -> np.ndarray:
    row = np.zeros(FORCE_PARAMS)
    flat = np.concatenate([np.atleast_1d(np.asarray(v, dtype=float)) for v in values])
    row[: flat.size] = flat
    return row


def _check_output(value, shape, force: Force, what: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != shape:
        raise ForceError(
            f"force {force.name} returned {what} of shape {arr.shape}, expected {shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise ForceError(f"force {force.name} returned a non-finite {what}: {arr.tolist()}")
    return arr


def _frame_name(frame: str) -> str:
    if frame not in ("space", "body"):
        raise ValueError(f"`frame` must be 'space' or 'body', found {frame!r}")
    return frame


# --------------------------------------------------------------------------- built-in kinds
class Gravity(Force):
    """Uniform gravity ``g`` (3,): ``F = M g`` at the centre of mass, no torque about it.

    ``U = −M g·R``. For a particle body this equals ``F_i = m_i g`` on every particle.

    Examples
    --------
    >>> Gravity((0, 0, -9.8)).g.tolist()
    [0.0, 0.0, -9.8]
    """

    kind = "gravity"
    position_only = True
    has_potential = True

    def __init__(self, g=(0.0, 0.0, -9.81)):
        self._freeze(g=_readonly(as_vector3(g, "g")))

    def sensitive_parameters(self):
        return (("g", 0, 3, "space"),)

    def lower(self, frame):
        return _row(self.g)

    def __repr__(self):
        return f"Gravity(g={self.g.tolist()})"


class CentralGravity(Force):
    """Gravity of a point mass ``mu = G M_central`` at ``center``, with the gravity-gradient
    terms of MacCullagh's formula when ``gradient=True``.

    ``U = −μM/r − μ/(2r³) (tr A − 3 n̂·A n̂)``, ``n̂`` the unit vector from the centre to the
    body, in body axes. The torque about the centre of mass is ``τ = 3μ/r³ n̂ × (A n̂)`` (the
    gravity-gradient torque); the force is ``−∇U`` of the same expression, so total energy is
    conserved exactly by the model. See ``central_gravity`` in ``crates/core/src/forces.rs``.
    """

    kind = "central_gravity"
    position_only = True
    has_potential = True

    def __init__(self, mu, center=(0.0, 0.0, 0.0), *, gradient: bool = True):
        self._freeze(
            mu=as_positive_scalar(mu, "mu"),
            center=_readonly(as_vector3(center, "center")),
            gradient=bool(gradient),
        )

    def sensitive_parameters(self):
        return (("mu", 0, 1, "space"), ("center", 1, 3, "space"))

    def lower(self, frame):
        return _row(self.mu, self.center, float(self.gradient))

    def __repr__(self):
        return f"CentralGravity(mu={self.mu:g}, center={self.center.tolist()})"


class Spring(Force):
    """A linear spring (or elastic tether) from a body point to a fixed anchor in space.

    Tension ``T = k (ℓ − ℓ₀) + c ℓ̇`` along the spring, ``ℓ`` its length; a ``tether`` goes
    slack (no force) when ``ℓ < ℓ₀``. ``U = ½ k (ℓ − ℓ₀)²`` (zero while a tether is slack).
    Damping ``c > 0`` makes the force velocity-dependent and dissipative: the potential is still
    that of the elastic part, but the spring is no longer conservative.
    """

    kind = "spring"
    has_potential = True

    def __init__(
        self, point, anchor, stiffness, rest_length=0.0, *, damping=0.0, tether: bool = False
    ):
        rest = as_scalar(rest_length, "rest_length")
        if rest < 0:
            raise ValueError(f"`rest_length` must be ≥ 0, found {rest}")
        damping = as_scalar(damping, "damping")
        if damping < 0:
            raise ValueError(f"`damping` must be ≥ 0, found {damping}")
        self._freeze(
            point=_readonly(as_vector3(point, "point")),
            anchor=_readonly(as_vector3(anchor, "anchor")),
            stiffness=as_positive_scalar(stiffness, "stiffness"),
            rest_length=rest,
            damping=damping,
            tether=bool(tether),
            position_only=damping == 0,
            dissipative=damping > 0,
        )

    def sensitive_parameters(self):
        return (("point", 0, 3, "body"), ("anchor", 3, 3, "space"), ("stiffness", 6, 1, "space"),
                ("rest_length", 7, 1, "space"), ("damping", 8, 1, "space"))  # fmt: skip

    def lower(self, frame):
        return _row(
            frame.point(self.point),
            self.anchor,
            self.stiffness,
            self.rest_length,
            self.damping,
            float(self.tether),
        )


class _Drag(Force):
    """Drag with a translational ``coefficient`` (on the centre of mass) and a ``rotational``
    one (a torque against ω), both ≥ 0."""

    dissipative = True

    def __init__(self, coefficient, rotational=0.0):
        c = as_scalar(coefficient, "coefficient")
        r = as_scalar(rotational, "rotational")
        if c < 0 or r < 0:
            raise ValueError("drag coefficients `coefficient` and `rotational` must be ≥ 0")
        self._freeze(coefficient=c, rotational=r)

    def sensitive_parameters(self):
        return (("coefficient", 0, 1, "space"), ("rotational", 1, 1, "space"))

    def lower(self, frame):
        return _row(self.coefficient, self.rotational)


class LinearDrag(_Drag):
    """Linear (Stokes) drag: ``F = −c V`` on the centre of mass, ``τ = −c_rot ω``."""

    kind = "linear_drag"


class QuadraticDrag(_Drag):
    """Quadratic drag: ``F = −c |V| V`` on the centre of mass, ``τ = −c_rot |ω| ω``."""

    kind = "quadratic_drag"


class PointForce(Force):
    """A force applied at a body point.

    Parameters
    ----------
    point : array_like, shape (3,)
        The point of application, in the body's reference configuration.
    force : array_like (3,) or callable ``f(t) → (3,)``
        Constant (built-in, compiled) or time-dependent (a Python callable: the slow path).
    frame : {"space", "body"}
        ``"space"``: ``force`` is given in the space frame; ``"body"``: it is body-fixed and
        turns with the body (``F = Q f``).
    """

    position_only = True

    def __init__(self, point, force, *, frame: str = "space"):
        constant = not callable(force)
        self._freeze(
            point=_readonly(as_vector3(point, "point")),
            force=_readonly(as_vector3(force, "force")) if constant else force,
            frame=_frame_name(frame),
            kind="point_force" if constant else None,
        )

    def sensitive_parameters(self):
        return (("point", 0, 3, "body"), ("force", 3, 3, self.frame))

    def lower(self, frame, force=None):
        f = self.force if force is None else force
        f = frame.vector(f) if self.frame == "body" else f
        return _row(frame.point(self.point), f, float(self.frame == "body"))

    def python_wrench(self, ctx):
        """The callable's force at ``ctx.t``, applied by the core's point force."""
        f = _check_output(self.force(ctx.t), (3,), self, "force")
        return _core_wrench(ctx, "point_force", lambda frame: self.lower(frame, f))


class Torque(Force):
    """A pure torque (couple), constant (built-in) or ``f(t) → (3,)`` (a Python callable), in
    the body or the space frame."""

    position_only = True

    def __init__(self, torque, *, frame: str = "body"):
        constant = not callable(torque)
        self._freeze(
            torque=_readonly(as_vector3(torque, "torque")) if constant else torque,
            frame=_frame_name(frame),
            kind="torque" if constant else None,
        )

    def sensitive_parameters(self):
        return (("torque", 0, 3, self.frame),)

    def lower(self, frame, torque=None):
        tau = self.torque if torque is None else torque
        tau = frame.vector(tau) if self.frame == "body" else tau
        return _row(tau, float(self.frame == "body"))

    def python_wrench(self, ctx):
        """The callable's torque at ``ctx.t``, applied by the core's torque."""
        tau = _check_output(self.torque(ctx.t), (3,), self, "torque")
        return _core_wrench(ctx, "torque", lambda frame: self.lower(frame, tau))


# --------------------------------------------------------------------------- Python forces
class ParticleForce(Force):
    """Forces on every particle from one callable ``func(t, r, v) → F``, arrays (N, 3).

    The total force is ``Σ F_i`` and the torque ``Σ u_i × Qᵀ F_i`` (eq. (08)). Needs a body
    built from particles. ``position_only=True`` declares that ``func`` ignores ``v`` (enables
    the splitting integrator). A Python callable: the slow path.

    Examples
    --------
    The notebook's gravity, particle by particle:

    >>> import numpy as np
    >>> f = ParticleForce(lambda t, r, v: np.outer([1.0, 2.0], [0, 0, -9.8]), name="weight")
    >>> f.name
    'weight'
    """

    def __init__(self, func: Callable, *, name: str | None = None, position_only: bool = False):
        if not callable(func):
            raise TypeError(f"`func` must be callable, found {type(func).__name__}")
        self._freeze(
            func=func,
            _name=name or getattr(func, "__name__", "ParticleForce"),
            position_only=bool(position_only),
        )

    @property
    def name(self):
        return self._name

    def check(self, body):
        if not body.has_particles:
            raise ValueError(f"force {self.name}: ParticleForce needs a body built from particles")

    def python_wrench(self, ctx):
        u = ctx.body.u
        F_i = _check_output(
            self.func(ctx.t, ctx.particle_positions, ctx.particle_velocities),
            u.shape,
            self,
            "particle forces",
        )
        return F_i.sum(axis=0), np.cross(u, F_i @ ctx.Q).sum(axis=0)


def _is_jitted(func) -> bool:
    """True for a numba-compiled function (a dispatcher), without importing numba."""
    return type(func).__name__ == "CPUDispatcher" and hasattr(func, "py_func")


def _c_function(func, returns, label):
    """``(address, ctypes function)`` of a C function given as a numba ``cfunc`` or a ctypes
    function pointer, with its signature checked (``returns`` the ctypes return type; the
    arguments ``(double t, const double *y[, double *out])``); None for anything else."""
    import ctypes

    cf = getattr(func, "ctypes", None) if hasattr(func, "address") else None  # numba cfunc
    if cf is None and isinstance(func, ctypes._CFuncPtr):
        cf = func
    if cf is None:
        return None
    double_p = ctypes.POINTER(ctypes.c_double)
    args = (ctypes.c_double, double_p, double_p) if returns is ctypes.c_int else (
        ctypes.c_double, double_p)  # fmt: skip
    ok_ret = cf.restype in ((ctypes.c_int, ctypes.c_int32) if returns is ctypes.c_int else
                            (ctypes.c_double,))  # fmt: skip
    if tuple(cf.argtypes or ()) != args or not ok_ret:
        want = ("int f(double t, const double *y, double *wrench)" if returns is ctypes.c_int
                else "double u(double t, const double *y)")  # fmt: skip
        raise TypeError(f"`{label}`: a C function must have the signature {want}")
    return ctypes.cast(cf, ctypes.c_void_p).value, cf


class CustomForce(Force):
    """Any wrench, from your own function.

    * A Python callable ``func(ctx) → (F_space (3,), τ_body (3,))`` about the centre of mass,
      ``ctx`` a :class:`ForceContext`, optionally with ``potential(ctx) → float``: the slow
      path (the core calls Python at every evaluation of the right-hand side).
    * A C function ``int func(double t, const double *y, double *wrench)`` — a numba
      ``cfunc``, a ctypes function pointer, any function with a C ABI — of the time and the
      body-frame state ``y`` (18,) = ``[R, V, Q (row-major), ω]``
      (:data:`poinsot.layout.STATE_SLICES`), writing ``(Fx, Fy, Fz, τx, τy, τz)`` (the force
      in space, the torque about the centre of mass in the body frame) and returning 0 (any
      other value stops the run), optionally with ``double potential(double t, const double
      *y)``: the core calls it by address, with no Python in between (one such force per body;
      several are summed through Python).
    * A numba-compiled function ``func(t, y) → (Fx, Fy, Fz, τx, τy, τz)`` (``njit``), with
      an optional ``potential(t, y)``: called from Python (give a ``cfunc`` for speed).

    Examples
    --------
    A C function from ctypes (a numba ``cfunc`` of the same signature works alike):

    >>> import ctypes
    >>> proto = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double,
    ...                          ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double))
    >>> def lift(t, y, out):
    ...     out[0], out[1], out[2], out[3], out[4], out[5] = 0.0, 0.0, 2.0, 0.0, 0.0, 0.0
    ...     return 0
    >>> c_lift = proto(lift)
    >>> force = CustomForce(c_lift, position_only=True)
    >>> force.address is not None
    True
    """

    def __init__(self, func, *, potential=None, position_only=False, name=None):
        import ctypes

        if not callable(func):
            raise TypeError(f"`func` must be callable, found {type(func).__name__}")
        if potential is not None and not callable(potential):
            raise TypeError(f"`potential` must be callable, found {type(potential).__name__}")
        c = _c_function(func, ctypes.c_int, "func")
        c_potential = None
        if c is not None and potential is not None:
            c_potential = _c_function(potential, ctypes.c_double, "potential")
            if c_potential is None:
                raise TypeError("`potential` of a C force must be a C function "
                                "double u(double t, const double *y)")  # fmt: skip
        jitted = c is None and _is_jitted(func)
        if c is None and potential is not None and _is_jitted(potential) != jitted:
            raise TypeError(
                "`func` and `potential` must both be numba-compiled functions of (t, y), or both "
                "Python callables of the force context"
            )
        self._freeze(
            func=func,
            _potential=potential,
            has_potential=potential is not None,
            position_only=bool(position_only),
            jitted=jitted,
            address=None if c is None else c[0],
            _c=c,
            _c_potential=c_potential,
            _name=name or getattr(func, "__name__", "CustomForce"),
        )

    @property
    def name(self):
        return self._name

    def python_wrench(self, ctx):
        if self._c is not None:  # the C function, called from Python (forces summed there)
            import ctypes

            y = np.ascontiguousarray(ctx.state(), dtype=float)
            out = np.zeros(6)
            p = ctypes.POINTER(ctypes.c_double)
            status = self._c[1](float(ctx.t), y.ctypes.data_as(p), out.ctypes.data_as(p))
            if status != 0:
                raise ForceError(f"force {self.name} returned {status} at t = {ctx.t:g}")
            return out[:3].copy(), out[3:].copy()
        if self.jitted:
            out = self.func(float(ctx.t), ctx.state())
            if not isinstance(out, tuple) or len(out) != 6:
                raise ForceError(f"force {self.name} must return (Fx, Fy, Fz, τx, τy, τz)")
            out = (np.array(out[:3], dtype=float), np.array(out[3:], dtype=float))
        else:
            out = self.func(ctx)
            if not isinstance(out, tuple | list) or len(out) != 2:
                raise ForceError(f"force {self.name} must return a pair (force, torque)")
        return (
            _check_output(out[0], (3,), self, "force"),
            _check_output(out[1], (3,), self, "torque"),
        )

    def python_potential(self, ctx):
        if self._c_potential is not None:
            import ctypes

            y = np.ascontiguousarray(ctx.state(), dtype=float)
            p = ctypes.POINTER(ctypes.c_double)
            return float(self._c_potential[1](float(ctx.t), y.ctypes.data_as(p)))
        if self.jitted:
            return float(self._potential(float(ctx.t), ctx.state()))
        return float(self._potential(ctx))
