"""How a :class:`~poinsot.lagrange.LagrangianSystem` reads and checks its arguments.

The coordinates (distinct functions of time), the constraints as expressions ``e = 0`` (each
one constraining something, the Pfaffian ones linear in the velocities, their Jacobian of full
row rank), the kinetic energy of the bodies (point masses, rigid bodies by their position and
attitude, SymPy ``Particle``/``RigidBody``), the generalized forces of the applied loads
(``Q_j = F · ∂r/∂q_j``, (6.61), or by partial velocities for SymPy loads), the coordinates'
units and the inputs: every refusal names the argument it is about.
"""

from __future__ import annotations

from collections.abc import Mapping

__all__: list[str] = []


def _as_coordinates(coordinates, t) -> list:
    """The generalized coordinates, checked: a non-empty sequence of distinct functions of
    ``t`` (dynamicsymbols)."""
    import sympy as sp

    if isinstance(coordinates, str | bytes) or not hasattr(coordinates, "__iter__"):
        raise TypeError(
            "`coordinates` must be a sequence of functions of time (dynamicsymbols), found "
            f"{type(coordinates).__name__}"
        )
    coordinates = list(coordinates)
    if not coordinates:
        raise ValueError("`coordinates` must hold at least one generalized coordinate")
    for i, q in enumerate(coordinates):
        if not (isinstance(q, sp.Function | sp.core.function.AppliedUndef) and q.args == (t,)):
            raise ValueError(
                f"`coordinates[{i}]` = {q} is not a function of time: use "
                "sympy.physics.mechanics.dynamicsymbols (e.g. dynamicsymbols('x'))"
            )
    if len(set(coordinates)) != len(coordinates):
        raise ValueError("`coordinates` must be distinct")
    return coordinates


def _as_zero_form(expr, name):
    """A constraint as one expression ``e`` meaning ``e = 0``: an equation ``Eq(lhs, rhs)``
    becomes ``lhs − rhs``; anything SymPy cannot read is refused, named."""
    import sympy as sp

    if isinstance(expr, sp.Equality):
        return expr.lhs - expr.rhs
    try:
        e = sp.sympify(expr)
    except (sp.SympifyError, TypeError, ValueError):
        raise TypeError(f"`{name}` must be a SymPy expression, found {expr!r}") from None
    if isinstance(e, sp.logic.boolalg.Boolean) or not isinstance(e, sp.Expr):
        raise TypeError(f"`{name}` must be an expression (= 0) or an Eq, found {e}")
    return e


def _bodies_kinetic(bodies, t, frame):
    """The kinetic energy of ``bodies``: point masses, SymPy bodies (velocities in ``frame``)
    and ``(rigid_body, position, orientation)`` triples, ``½ M |Ṙ|² + ½ ωᵀ A ω``."""
    import sympy as sp

    from .system import PointMass

    T = sp.Integer(0)
    for i, item in enumerate(bodies):
        if isinstance(item, PointMass):
            v = item.position.diff(t)
            T += item.mass * (v.T * v)[0] / 2
            continue
        if _is_sympy_body(item):  # a sympy.physics.mechanics Particle or RigidBody
            if frame is None:
                raise ValueError(
                    f"`bodies[{i}]` is a SymPy {type(item).__name__}: give the inertial "
                    "`frame` (a ReferenceFrame) its velocities are taken in"
                )
            T += item.kinetic_energy(frame)
            continue
        try:
            body, position, orientation = item
        except (TypeError, ValueError):
            raise TypeError(
                f"`bodies[{i}]` must be a PointMass or a (RigidBody, position, orientation) triple"
            ) from None
        R = sp.Matrix(position)
        Q = sp.Matrix(orientation)
        if R.shape != (3, 1) or Q.shape != (3, 3):
            raise ValueError(f"`bodies[{i}]`: position must be 3×1 and orientation 3×3")
        v = R.diff(t)
        # ω (body frame) = vee(Qᵀ Q̇): only its three entries, reduced by sin² = 1 − cos²
        # and expanded (exact, and milliseconds where simplify() took seconds for Euler
        # angles)
        W = Q.T * Q.diff(t)
        w = sp.Matrix([_pythagorean(W[i, j]) for i, j in ((2, 1), (0, 2), (1, 0))])
        A = sp.Matrix(body.inertia.tolist())
        T += body.mass * (v.T * v)[0] / 2 + (w.T * A * w)[0] / 2
    return T


def _check_constraints(system):
    """Refuse a constraint of ``system`` that constrains nothing, a Pfaffian one not linear in
    the velocities (or with accelerations), a holonomic one with velocities, and redundant
    ones."""
    import sympy as sp

    speeds = system.speeds
    for kind, exprs in (("holonomic", system.holonomic), ("nonholonomic", system.nonholonomic)):
        for k, g in enumerate(exprs):
            wrt = system.coordinates if kind == "holonomic" else speeds
            if all(sp.simplify(g.diff(s)) == 0 for s in wrt):
                what = "coordinates" if kind == "holonomic" else "velocities"
                raise ValueError(
                    f"`{kind}[{k}]` = {g} does not depend on the {what}: it constrains nothing"
                )
            if kind == "nonholonomic":
                for s in speeds:
                    if sp.simplify(g.diff(s).diff(s)) != 0:
                        raise ValueError(
                            f"`nonholonomic[{k}]` = {g} is not linear in the "
                            "velocities (Pfaffian form Σ a_kj q̇_j + a_k0)"
                        )
                if any(g.has(s.diff(system.t)) for s in speeds):
                    raise ValueError(f"`nonholonomic[{k}]` must not contain accelerations")
            elif any(g.has(s) for s in speeds):
                raise ValueError(
                    f"`holonomic[{k}]` = {g} contains velocities: give it as a "
                    "nonholonomic (Pfaffian) constraint"
                )
    if system.n_constraints:
        _check_rank(system)


def _check_rank(system):
    """Refuse redundant or inconsistent constraints: G must have full row rank at a generic
    point (random coordinates, velocities and parameters)."""
    import numpy as np

    rng = np.random.default_rng(12345)
    G = system.constraint_jacobian
    syms = sorted(G.free_symbols - {system.t}, key=str)
    subs = {s: float(rng.uniform(0.7, 1.9)) for s in syms}
    subs.update({q: float(rng.uniform(-1.3, 1.3)) for q in system.coordinates})
    subs[system.t] = 0.37
    for _ in range(3):
        value = np.array(G.subs(subs).evalf(), dtype=float)
        rank = np.linalg.matrix_rank(value, tol=1e-9 * max(1.0, np.abs(value).max()))
        if rank == system.n_constraints:
            return
        subs.update({q: float(rng.uniform(-1.3, 1.3)) for q in system.coordinates})
    raise ValueError(
        f"the constraints are redundant or inconsistent: the constraint Jacobian has rank "
        f"{rank} < {system.n_constraints} constraints (rank-deficient Jacobian)"
    )


def _generalized_forces(forces, coordinates, speeds, frame):
    """The generalized forces (n × 1) of ``forces``: ``{coordinate: force}`` mappings,
    ``(point, force)`` pairs (``Q_j = F · ∂r/∂q_j``, (6.61)) and SymPy loads."""
    import sympy as sp

    Q = sp.zeros(len(coordinates), 1)
    for i, item in enumerate(forces):
        if isinstance(item, Mapping):
            for q, value in item.items():
                if q not in coordinates:
                    raise ValueError(f"`forces[{i}]`: {q} is not one of the coordinates")
                Q[coordinates.index(q)] += sp.sympify(value)
            continue
        if _is_sympy_load(item):
            Q += _sympy_load(item, i, speeds, frame)
            continue
        try:
            point, force = item
        except (TypeError, ValueError):
            raise TypeError(
                f"`forces[{i}]` must be a (point, force) pair of 3-vectors or "
                "a {coordinate: generalized force} mapping"
            ) from None
        r = sp.Matrix(point)
        F = sp.Matrix(force)
        if r.shape != (3, 1) or F.shape != (3, 1):
            raise ValueError(f"`forces[{i}]`: point and force must be 3-vectors")
        for j, q in enumerate(coordinates):  # Q_j = F · ∂r/∂q_j  (6.61)
            Q[j] += (F.T * r.diff(q))[0]
    return Q


def _sympy_load(item, i, speeds, frame):
    """Generalized force (n × 1) of a SymPy load: a force at a Point, a torque on a
    ReferenceFrame (or a sympy.physics.mechanics Force/Torque), by partial velocities."""
    import sympy as sp
    from sympy.physics.vector import Point, ReferenceFrame

    if frame is None:
        raise ValueError(f"`forces[{i}]` is a SymPy load: give the inertial `frame`")
    where, vector = (item.location, item.vector) if hasattr(item, "location") else item
    if isinstance(where, Point):
        velocity = where.vel(frame)
    elif isinstance(where, ReferenceFrame):
        velocity = where.ang_vel_in(frame)
    else:  # pragma: no cover - guarded by _is_sympy_load
        raise TypeError(f"`forces[{i}]`: expected a Point or a ReferenceFrame")
    return sp.Matrix([vector.dot(velocity.diff(v, frame)) for v in speeds])


def _as_units(units, coordinates) -> dict:
    """``{coordinate: unit}``, checked: coordinates of the system, units as strings."""
    if units is None:
        return {}
    if not isinstance(units, Mapping):
        raise TypeError(f"`units` must be a dict {{coordinate: unit}}, found {units!r}")
    for q, u in units.items():
        if q not in coordinates:
            raise ValueError(f"`units`: {q} is not one of the coordinates")
        if not isinstance(u, str):
            raise TypeError(f"`units[{q}]` must be a string such as 'm' or 'rad'")
    return dict(units)


def _check_inputs(system):
    """Refuse an input of ``system`` that its expressions differentiate."""
    import sympy as sp

    exprs = [system.lagrangian, *system.holonomic, *system.nonholonomic]
    exprs += list(system.generalized_forces)
    for e in exprs:
        for d in sp.sympify(e).atoms(sp.Derivative):
            if d.expr in system.inputs:
                raise ValueError(
                    f"the input {d.expr} appears differentiated ({d}): give its derivative "
                    "as an input of its own"
                )


def _pythagorean(expr):
    """``expr`` expanded with every ``sin(a)²`` replaced by ``1 − cos(a)²``: the identity
    that collapses the products of elementary rotations (exact)."""
    import sympy as sp

    e = sp.expand(expr)
    squares = {s**2: 1 - sp.cos(s.args[0]) ** 2 for s in e.atoms(sp.sin)}
    return sp.expand(e.subs(squares)) if squares else e


def _is_sympy_body(item) -> bool:
    from sympy.physics.mechanics import Particle, RigidBody

    return isinstance(item, Particle | RigidBody)


def _is_sympy_load(item) -> bool:
    from sympy.physics.vector import Point, ReferenceFrame, Vector

    if hasattr(item, "location") and hasattr(item, "vector"):  # mechanics Force / Torque
        return True
    if not (isinstance(item, tuple | list) and len(item) == 2):
        return False
    return isinstance(item[0], Point | ReferenceFrame) and isinstance(item[1], Vector)
