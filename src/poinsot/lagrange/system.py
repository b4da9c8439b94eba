"""Lagrangian systems with constraints, symbolically (docs/theory.md §3, eqs (6.49)–(6.61)).

Sign convention for the multipliers (fixed here once and for all: SymPy's ``LagrangesMethod``
leaves the sign to the way constraints are entered — sympy issue #30215 — and stores
``lam_coeffs = −G``; with SymPy 1.14 its λ equal ours for holonomic and Pfaffian constraints,
which ``tests/lagrange/test_lagrange.py`` checks)::

    d/dt ∂L/∂q̇_j − ∂L/∂q_j = Σ_k λ_k G_kj + Q_j                                   (6.60)

with ``G`` the constraint Jacobian: ``G_kj = ∂g_k/∂q_j`` for a holonomic constraint
``g_k(q, t) = 0`` (6.52) and ``G_kj = a_kj`` for a Pfaffian constraint
``Σ_j a_kj q̇_j + a_k0 = 0`` (6.53). So ``Σ_k λ_k G_kj`` is the generalized constraint force on
``q_j`` — for Cartesian coordinates of a point, the physical reaction force on it. In matrix form,
with SymPy's ``mass_matrix``/``forcing`` (``M q̈ = f`` before constraint forces)::

    M q̈ = f + Gᵀ λ,      G q̈ = −γ,      γ = Ġ q̇ + ḃ   (b = ∂g/∂t or a_k0)
"""

from __future__ import annotations

from functools import cached_property

from ..display import HTMLDisplay
from .construction import (
    _as_coordinates,
    _as_units,
    _as_zero_form,
    _bodies_kinetic,
    _check_constraints,
    _check_inputs,
    _generalized_forces,
    _pythagorean,
)

__all__ = ["LagrangianSystem", "PointMass"]


def _sympy():
    import sympy

    return sympy


class PointMass:
    """A point mass ``mass`` at ``position`` (a 3-vector of SymPy expressions in q and t)."""

    def __init__(self, mass, position):
        sp = _sympy()
        self.mass = sp.sympify(mass)
        self.position = sp.Matrix(position)
        if self.position.shape != (3, 1):
            raise ValueError(f"`position` must be a 3-vector, found shape {self.position.shape}")


class LagrangianSystem(HTMLDisplay):
    """A mechanical system in generalized coordinates, with constraints and applied forces.

    Parameters
    ----------
    coordinates : sequence of SymPy functions of t
        Generalized coordinates ``q_j(t)`` (e.g. ``sympy.physics.mechanics.dynamicsymbols``).
    lagrangian : SymPy expression, optional
        ``L(q, q̇, t)``. Or give ``kinetic`` and ``potential`` (L = T − U), or ``bodies``.
    kinetic, potential : SymPy expressions, optional
    bodies : sequence, optional
        :class:`PointMass` objects, and ``(rigid_body, position, orientation)`` triples: a
        :class:`~poinsot.bodies.RigidBody`, the position of its centre of mass (3-vector) and its
        attitude matrix (3×3), both functions of q and t. Their kinetic energy
        ``½ M |Ṙ|² + ½ ωᵀ A ω`` (``hat(ω) = Qᵀ Q̇``) is added to ``kinetic``.
    holonomic : sequence of expressions
        ``g_k(q, t)`` with ``g_k = 0`` (6.52).
    nonholonomic : sequence of expressions
        Pfaffian velocity constraints ``Σ_j a_kj q̇_j + a_k0`` (= 0), linear in q̇ (6.53).
    forces : sequence
        Applied forces not in the potential: ``(point, force)`` pairs of 3-vectors (converted by
        ``Q_j = F · ∂r/∂q_j``, (6.61)), or mappings ``{coordinate: generalized force}``.
    units : dict, optional
        ``{coordinate: unit}``, e.g. ``{x: "m", theta: "rad"}``, for labels, tables and the
        units of the conjugate momenta. Coordinates not given are shown without a unit.
    frame : sympy.physics.vector.ReferenceFrame, optional
        The inertial frame, when ``bodies`` holds SymPy ``Particle``/``RigidBody`` objects or
        ``forces`` holds SymPy loads: ``(Point, Vector)`` forces and ``(ReferenceFrame,
        Vector)`` torques, turned into generalized forces by their partial velocities
        (``Q_j = F · ∂v_P/∂q̇_j``, ``T · ∂ω_B/∂q̇_j``; (6.61)). See also :meth:`from_sympy`.
    unilateral : sequence of expressions
        One-sided holonomic constraints ``g(q, t) ≥ 0`` (a wall, a floor): enforced as
        ``g = 0`` while their multiplier λ ≥ 0 (the reaction ``λ ∇g`` pushes into ``g > 0``),
        released for the rest of the run when λ falls through zero (``simulate`` locates
        that instant). Listed after the holonomic constraints; no impacts on re-contact.
    hidden : sequence of :class:`~poinsot.lagrange.reactions.HiddenConstraint`
        Constraints that the coordinates satisfy by construction, declared so that their
        forces can be had (:meth:`reaction_forces`): the expressions above may use each
        one's auxiliary coordinate ρ(t) (a rod's length, a pivot's position) where the
        constraint holds it at its ``value``. The system itself is the minimal one (ρ held,
        substituted after the Lagrangian is formed); :attr:`augmented` is the system in the
        coordinates and the ρ with the constraints ``ρ − value = 0``.

    Examples
    --------
    A pendulum in Cartesian coordinates, the rod as a constraint:

    >>> import sympy as sp
    >>> from sympy.physics.mechanics import dynamicsymbols
    >>> x, y = dynamicsymbols("x y")
    >>> m, g, l = sp.symbols("m g l", positive=True)
    >>> sys = LagrangianSystem([x, y], kinetic=m * (x.diff() ** 2 + y.diff() ** 2) / 2,
    ...                        potential=m * g * y, holonomic=[x**2 + y**2 - l**2])
    >>> sys.mass_matrix
    Matrix([
    [m, 0],
    [0, m]])
    >>> sys.constraint_jacobian
    Matrix([[2*x(t), 2*y(t)]])
    """

    def __init__(
        self,
        coordinates,
        lagrangian=None,
        *,
        kinetic=None,
        potential=None,
        bodies=(),
        holonomic=(),
        nonholonomic=(),
        forces=(),
        units=None,
        unilateral=(),
        frame=None,
        hidden=(),
    ):
        sp = _sympy()
        self.frame = frame
        self.t = sp.Symbol("t")
        self.hidden = ()
        if hidden:  # the minimal system: each auxiliary coordinate held at its value
            coordinates, lagrangian, holonomic, unilateral, nonholonomic, forces = (
                self._hold_hidden(coordinates, hidden, lagrangian, kinetic, potential, bodies,
                                  holonomic, nonholonomic, forces, units, unilateral))  # fmt: skip
            kinetic = potential = None
            bodies = ()
        self.coordinates = _as_coordinates(coordinates, self.t)
        self.speeds = [q.diff(self.t) for q in self.coordinates]
        if lagrangian is not None and (kinetic is not None or potential is not None):
            raise ValueError("give `lagrangian`, or `kinetic`/`potential`, not both")
        T = sp.sympify(0 if kinetic is None else kinetic) + _bodies_kinetic(bodies, self.t, frame)
        self.potential = sp.sympify(0 if potential is None else potential)
        #: ``[(mass, position)]`` when the kinetic energy is that of point masses alone (the
        #: equations then follow from the positions' Jacobians, :attr:`_point_mass_route`)
        self._point_masses = (
            [(b.mass, b.position) for b in bodies]
            if lagrangian is None and kinetic is None and bodies
            and all(isinstance(b, PointMass) for b in bodies)
            else None
        )  # fmt: skip
        if lagrangian is None:
            if T == 0 and lagrangian is None:
                raise ValueError("give `lagrangian`, `kinetic` (with `potential`) or `bodies`")
            lagrangian = T - self.potential
        self.lagrangian = sp.sympify(lagrangian)
        self.holonomic = [_as_zero_form(g, f"holonomic[{i}]") for i, g in enumerate(holonomic)]
        one_sided = [_as_zero_form(g, f"unilateral[{i}]") for i, g in enumerate(unilateral)]
        #: indices (in ``holonomic``) of the one-sided constraints
        self.unilateral = tuple(range(len(self.holonomic), len(self.holonomic) + len(one_sided)))
        self.holonomic += one_sided
        self.nonholonomic = [
            _as_zero_form(a, f"nonholonomic[{i}]") for i, a in enumerate(nonholonomic)
        ]
        _check_constraints(self)
        self.generalized_forces = _generalized_forces(forces, self.coordinates, self.speeds, frame)
        self.units = _as_units(units, self.coordinates)
        _check_inputs(self)

    def _hold_hidden(self, coordinates, hidden, lagrangian, kinetic, potential, bodies,
                     holonomic, nonholonomic, forces, units, unilateral):  # fmt: skip
        """Form the augmented system (the coordinates and the auxiliary ones of ``hidden``),
        then hold every auxiliary coordinate at its value: the minimal system's coordinates,
        Lagrangian, holonomic, one-sided and non-holonomic constraints, and forces."""
        from .reactions import _check, _held

        if isinstance(coordinates, str | bytes) or not hasattr(coordinates, "__iter__"):
            raise TypeError("`coordinates` must be a sequence of functions of time")
        coordinates = list(coordinates)
        hidden = _check(hidden, coordinates, self.t)
        holonomic, unilateral = list(holonomic), list(unilateral)
        # the augmented system: the coordinates and the auxiliary ones, each held by its
        # constraint ρ − value = 0 (after the user's holonomic ones, before one-sided ones)
        augmented = LagrangianSystem(
            coordinates + [h.coordinate for h in hidden], lagrangian, kinetic=kinetic,
            potential=potential, bodies=bodies,
            holonomic=holonomic + [h.coordinate - h.value for h in hidden],
            nonholonomic=nonholonomic, forces=forces, units=units, unilateral=unilateral,
            frame=self.frame)  # fmt: skip
        # this system: the augmented one with every ρ held at its value, after the
        # Lagrangian and the generalized forces are formed
        n, nh = len(coordinates), len(holonomic)
        # sin² + cos² = 1 collapsed (exact): the freed positions leave such sums behind
        lagrangian = _pythagorean(_held(augmented.lagrangian, hidden))
        holonomic = [_held(g, hidden) for g in augmented.holonomic[:nh]]
        unilateral = [_held(g, hidden) for g in augmented.holonomic[nh + len(hidden) :]]
        nonholonomic = [_held(a, hidden) for a in augmented.nonholonomic]
        forces = [{q: _held(Q, hidden)} for q, Q in
                  zip(coordinates, augmented.generalized_forces[:n], strict=True)
                  if Q != 0]  # fmt: skip
        self.hidden = hidden
        self._augmented = augmented
        return coordinates, lagrangian, holonomic, unilateral, nonholonomic, forces

    @cached_property
    def inputs(self) -> list:
        """Specified inputs: functions of t in the equations that are neither coordinates nor
        parameters (SymPy ``dynamicsymbols`` such as a driving force ``F(t)``), sorted by name.
        ``simulate(..., inputs={F: ...})`` gives each a number, a function of t, or a function
        of ``(t, q, q̇)`` (feedback); ``linearize`` returns their matrix B.

        Examples
        --------
        >>> import sympy as sp
        >>> from sympy.physics.mechanics import dynamicsymbols
        >>> x, F = dynamicsymbols("x F")
        >>> cart = LagrangianSystem([x], kinetic=x.diff() ** 2 / 2, forces=[{x: F}])
        >>> cart.inputs
        [F(t)]
        """
        sp = _sympy()
        exprs = [self.lagrangian, *self.holonomic, *self.nonholonomic, *self.generalized_forces]
        found = set()
        for e in exprs:
            for f in sp.sympify(e).atoms(sp.core.function.AppliedUndef):
                if f.args == (self.t,) and f not in self.coordinates:
                    found.add(f)
        return sorted(found, key=str)

    @property
    def augmented(self) -> LagrangianSystem:
        """The system in the coordinates and the auxiliary ones of :attr:`hidden`, with the
        constraints ``ρ − value = 0`` whose multipliers are the hidden forces (itself when
        nothing is hidden)."""
        return getattr(self, "_augmented", self)

    def reaction_forces(self, at, *, names=None, params=None, qd=None, t=0.0, inputs=None):
        """The forces of the constraints the coordinates hide (:attr:`hidden`), by name:
        along a run (``at`` a :class:`~poinsot.lagrange.LagrangianSolution` of this system:
        arrays (n_samples,)) or at a state (``at`` = ``{coordinate: value}``, e.g. an
        equilibrium, with ``params``, optional speeds ``qd`` (default at rest), ``t`` and
        ``inputs``: floats). The multipliers of :attr:`augmented` at the very states given,
        times each constraint's ``sign``; see :mod:`poinsot.lagrange.reactions`.

        Examples
        --------
        The double pendulum hanging at rest: the rods carry the weights below them.

        >>> from poinsot.models import double_pendulum
        >>> model = double_pendulum()
        >>> t1, t2 = model.system.coordinates
        >>> forces = model.system.reaction_forces({t1: 0.0, t2: 0.0}, params=model.params)
        >>> {k: round(v, 9) for k, v in forces.items()}
        {'rod 1 tension T1': 19.62, 'rod 2 tension T2': 9.81}
        """
        from .reactions import reaction_forces

        return reaction_forces(self, at, names=names, params=params, qd=qd, t=t, inputs=inputs)

    def released(self, index: int) -> LagrangianSystem:
        """This system without its holonomic constraint ``index`` (a one-sided constraint
        that has let go): same Lagrangian, forces, units and other constraints."""
        keep = [g for i, g in enumerate(self.holonomic) if i != index]
        forces = [{q: Q} for q, Q in zip(self.coordinates, self.generalized_forces, strict=True)
                  if Q != 0]  # fmt: skip
        out = LagrangianSystem(
            self.coordinates,
            self.lagrangian,
            holonomic=[g for i, g in enumerate(keep) if i + (i >= index) not in self.unilateral],
            unilateral=[g for i, g in enumerate(keep) if i + (i >= index) in self.unilateral],
            nonholonomic=self.nonholonomic,
            forces=forces,
            units=self.units,
            frame=self.frame,
        )
        return out

    @cached_property
    def plain(self):
        """Plain SymPy symbols for the numeric side: ``q`` (q0…), ``v`` (v0…, the speeds),
        ``u`` (u0…, the inputs) and ``lam`` (lam0…, the multipliers), and ``of(expr)``,
        the expression in them (speeds replaced first: ``q̇`` contains ``q``). One place
        for the substitution that lambdify, the generated engine and ``evaluate`` share."""
        from types import SimpleNamespace

        sp = _sympy()
        n, m = self.n_coordinates, self.n_constraints
        q, v = sp.symbols(f"q0:{n}"), sp.symbols(f"v0:{n}")
        u, lam = sp.symbols(f"u0:{len(self.inputs)}"), sp.symbols(f"lam0:{m}")
        to = {
            **dict(zip(self.speeds, v, strict=True)),
            **dict(zip(self.coordinates, q, strict=True)),
            **dict(zip(self.inputs, u, strict=True)),
            **dict(zip(list(self.lam_vec), lam, strict=True)),
        }

        def of(expr):
            # one simultaneous, structural replacement, top-down (q̇ is matched before the q
            # inside it); ``subs`` would take 100× longer on large equations of motion
            return sp.sympify(expr).xreplace(to)

        return SimpleNamespace(q=q, v=v, u=u, lam=lam, of=of)

    def unit_of(self, coordinate) -> str:
        """The unit of a coordinate ("" when not given)."""
        return self.units.get(coordinate, "")

    @classmethod
    def from_sympy(cls, model, *, units=None):
        """A :class:`LagrangianSystem` from a SymPy mechanics model: a ``LagrangesMethod``
        (its Lagrangian, coordinates, constraints and loads) or a ``System`` (its bodies,
        loads, coordinates and constraints; potential energies set on its bodies).

        Examples
        --------
        >>> import sympy as sp
        >>> from sympy.physics.mechanics import (LagrangesMethod, Lagrangian, Particle, Point,
        ...                                      ReferenceFrame, dynamicsymbols)
        >>> q = dynamicsymbols("q")
        >>> m, k = sp.symbols("m k", positive=True)
        >>> N = ReferenceFrame("N"); O = Point("O"); P = O.locatenew("P", q * N.x)
        >>> O.set_vel(N, 0); P.set_vel(N, q.diff() * N.x)
        >>> bob = Particle("bob", P, m); bob.potential_energy = k * q**2 / 2
        >>> lm = LagrangesMethod(Lagrangian(N, bob), [q], frame=N)
        >>> LagrangianSystem.from_sympy(lm).mass_matrix
        Matrix([[m]])
        """
        from sympy.physics.mechanics import LagrangesMethod

        sp = _sympy()
        if isinstance(model, LagrangesMethod):
            hol = list(model._hol_coneqs)
            nonhol = list(model.coneqs[len(hol) :])
            return cls(list(model.q), model._L[0], holonomic=hol, nonholonomic=nonhol,
                       forces=list(model._forcelist or ()), frame=model.inertial,
                       units=units)  # fmt: skip
        try:
            from sympy.physics.mechanics import System
        except ImportError:  # pragma: no cover - SymPy < 1.13
            System = ()
        if isinstance(model, System):
            coords = list(model.q)
            potential = sum((getattr(b, "potential_energy", 0) for b in model.bodies),
                            sp.Integer(0))  # fmt: skip
            return cls(coords, bodies=list(model.bodies), potential=potential,
                       holonomic=list(model.holonomic_constraints),
                       nonholonomic=list(model.nonholonomic_constraints),
                       forces=list(model.loads), frame=model.frame, units=units)  # fmt: skip
        raise TypeError(
            "`model` must be a sympy.physics.mechanics LagrangesMethod or System, found "
            f"{type(model).__name__}"
        )

    # ----------------------------------------------------------------- sizes
    @property
    def n_coordinates(self) -> int:
        return len(self.coordinates)

    @property
    def n_holonomic(self) -> int:
        return len(self.holonomic)

    @property
    def n_constraints(self) -> int:
        return len(self.holonomic) + len(self.nonholonomic)

    # ----------------------------------------------------------------- symbolic outputs
    @cached_property
    def _point_mass_route(self):
        """For point masses at positions ``r_b(q)`` (no explicit time) under a potential
        ``U(q)``: ``(M, f0, h)`` from the positions' Jacobians ``J_b = ∂r_b/∂q`` instead of
        differentiating L twice — ``M = Σ m_b J_bᵀ J_b``, ``f0 = −Σ m_b J_bᵀ (J̇_b q̇) − ∂U/∂q``
        (Lagrange's equations of ``T = ½ Σ m_b |J_b q̇|²``: ``Σ m_b r̈_b · ∂r_b/∂q_j``
        with ``r̈_b = J_b q̈ + J̇_b q̇``), ``h = T + U``; ``J̇_b q̇`` as the derivative of
        ``J_b q̇`` along ``q̇`` (d/dε at q + ε q̇). The same equations as the route through L
        (tested to agree); small expressions in, small expressions out. ``None`` where it does
        not apply (a Lagrangian or kinetic energy given, a rigid body, explicit time)."""
        if self._point_masses is None:
            return None
        sp = _sympy()
        n = self.n_coordinates
        q = [sp.Dummy(f"q{i}", real=True) for i in range(n)]
        v = [sp.Dummy(f"v{i}", real=True) for i in range(n)]
        to = dict(zip(self.coordinates, q, strict=True))
        back = {**dict(zip(v, self.speeds, strict=True)), **dict(zip(q, self.coordinates,
                                                                      strict=True))}  # fmt: skip
        bodies = [(sp.sympify(m), sp.Matrix(r).xreplace(to)) for m, r in self._point_masses]
        U = self.potential.xreplace(to)
        plain = [U, *(m for m, _ in bodies), *(e for _, r in bodies for e in r)]
        if any(self.t in e.free_symbols or e.atoms(sp.Derivative) or
               e.atoms(sp.core.function.AppliedUndef) for e in plain):  # fmt: skip
            return None  # explicit time, speeds or inputs: the route through L
        eps = sp.Dummy("eps")
        along = {qk: qk + eps * vk for qk, vk in zip(q, v, strict=True)}
        M = [[sp.Integer(0)] * n for _ in range(n)]
        f = [-U.diff(qj) for qj in q]
        T = sp.Integer(0)
        for m, r in bodies:
            J = [[r[a].diff(qk) for qk in q] for a in range(3)]
            rd = [sum((J[a][k] * v[k] for k in range(n) if J[a][k] != 0), sp.Integer(0))
                  for a in range(3)]  # fmt: skip
            acc = [e.xreplace(along).diff(eps).xreplace({eps: 0}) for e in rd]  # J̇ q̇
            T += m * sum(e**2 for e in rd) / 2
            for i in range(n):
                for j in range(i, n):
                    M[i][j] += m * sum(J[a][i] * J[a][j] for a in range(3))
                f[i] -= m * sum(J[a][i] * acc[a] for a in range(3))
        Mat = sp.Matrix(n, n, lambda i, j: M[min(i, j)][max(i, j)].xreplace(back))
        return Mat, [fj.xreplace(back) for fj in f], (T + U).xreplace(back)

    @cached_property
    def mass_matrix(self):
        """``M = ∂²L/∂q̇∂q̇`` (n × n), SymPy."""
        sp = _sympy()
        if self._point_mass_route is not None:
            return self._point_mass_route[0]
        _, v, _, p, back = self._derivation
        n = self.n_coordinates
        # symmetric (∂²L/∂q̇_i∂q̇_j = ∂²L/∂q̇_j∂q̇_i): the upper triangle is derived, the lower
        # one mirrors it
        upper = {(i, j): p[i].diff(v[j]).xreplace(back) for i in range(n) for j in range(i, n)}
        return sp.Matrix(n, n, lambda i, j: upper[(min(i, j), max(i, j))])

    @cached_property
    def _derivation(self):
        """``(q, v, L, p, back)``: the Lagrangian in plain symbols (``Dummy`` coordinates q
        and speeds v, so that no user symbol can collide; real, as they are, which spares SymPy
        assumption queries: 20 % of the derivation), its momenta ``p_j = ∂L/∂v_j`` and
        the map ``back`` to the time functions. SymPy differentiates plain symbols about 10×
        faster than functions of t and their derivatives: every derivative of the equations
        of motion is taken here, and the results are mapped back."""
        sp = _sympy()
        n = self.n_coordinates
        q = [sp.Dummy(f"q{i}", real=True) for i in range(n)]
        v = [sp.Dummy(f"v{i}", real=True) for i in range(n)]
        # one simultaneous replacement, top-down: q̇ (which contains q) is matched first
        to = {**dict(zip(self.speeds, v, strict=True)), **dict(zip(self.coordinates, q,
                                                                    strict=True))}  # fmt: skip
        L = sp.sympify(self.lagrangian).xreplace(to)
        back = {**dict(zip(v, self.speeds, strict=True)), **dict(zip(q, self.coordinates,
                                                                      strict=True))}  # fmt: skip
        return q, v, L, [L.diff(vj) for vj in v], back

    @cached_property
    def _momenta(self):
        """``p_j = ∂L/∂q̇_j``, computed once for the mass matrix, the forcing and the
        constants of the motion."""
        _, _, _, p, back = self._derivation
        return [pj.xreplace(back) for pj in p]

    @cached_property
    def _explicitly_timed(self) -> bool:
        """Whether L depends on t other than through q and q̇: with q and q̇ replaced by plain
        symbols (:attr:`_derivation`), whether t is left."""
        return self.t in self._derivation[2].free_symbols

    @cached_property
    def forcing(self):
        """``f`` (n × 1) with ``M q̈ = f`` before constraint forces (SymPy's convention):
        ``f_j = ∂L/∂q_j − Σ_k ∂²L/∂q̇_j∂q_k q̇_k − ∂²L/∂q̇_j∂t + Q_j``."""
        sp = _sympy()
        if self._point_mass_route is not None:
            f0 = self._point_mass_route[1]
            return sp.Matrix([f0[j] + self.generalized_forces[j] for j in range(len(f0))])
        t = self.t
        q, v, L, p, back = self._derivation
        # Σ_k ∂p_j/∂q_k q̇_k is the derivative of p_j along q̇: d/dε p_j(q + ε q̇)|ε=0, one
        # differentiation instead of n (40 % of the derivation of a 10-link chain)
        eps = sp.Dummy("eps")
        along = {qk: qk + eps * vk for qk, vk in zip(q, v, strict=True)}
        rows = []
        for j, pj in enumerate(p):
            expr = L.diff(q[j]) - pj.xreplace(along).diff(eps).xreplace({eps: 0})
            expr = expr.xreplace(back)
            if self._explicitly_timed:  # explicit time dependence of ∂L/∂q̇_j
                expr -= _explicit_time_derivative(self._momenta[j], self.coordinates,
                                                  self.speeds, t)  # fmt: skip
            rows.append(expr + self.generalized_forces[j])
        return sp.Matrix(rows)

    @cached_property
    def constraint_jacobian(self):
        """``G`` (m × n): ``∂g_k/∂q_j`` (holonomic rows first), then ``a_kj`` (Pfaffian)."""
        sp = _sympy()
        rows = [[g.diff(q) for q in self.coordinates] for g in self.holonomic]
        rows += [[a.diff(v) for v in self.speeds] for a in self.nonholonomic]
        return sp.Matrix(rows) if rows else sp.zeros(0, self.n_coordinates)

    @cached_property
    def constraint_rhs(self):
        """``b`` (m × 1) with the velocity-level constraints ``G q̇ + b = 0``:
        ``∂g_k/∂t`` for holonomic rows, ``a_k0`` for Pfaffian ones."""
        sp = _sympy()
        b = [
            _explicit_time_derivative(g, self.coordinates, self.speeds, self.t)
            for g in self.holonomic
        ]
        zero = {v: 0 for v in self.speeds}
        b += [a.subs(zero) for a in self.nonholonomic]
        return sp.Matrix(b) if b else sp.zeros(0, 1)

    @cached_property
    def constraint_gamma(self):
        """``γ = d/dt(G) q̇ + d/dt(b)`` (m × 1): the velocity-product terms of the
        differentiated constraints, so that ``G q̈ = −γ``."""
        sp = _sympy()
        if not self.n_constraints:
            return sp.zeros(0, 1)
        v = sp.Matrix(self.speeds)
        expr = self.constraint_jacobian.diff(self.t) * v + self.constraint_rhs.diff(self.t)
        acc = {s.diff(self.t): 0 for s in self.speeds}
        return expr.subs(acc)

    @cached_property
    def lam_vec(self):
        """The multipliers ``λ_k(t)`` (m × 1), holonomic first (SymPy's name)."""
        sp = _sympy()
        from sympy.physics.mechanics import dynamicsymbols

        return (
            sp.Matrix(dynamicsymbols(f"lambda1:{self.n_constraints + 1}"))
            if self.n_constraints
            else sp.zeros(0, 1)
        )

    def equations(self):
        """Euler–Lagrange equations with multipliers, (6.50)/(6.60), as SymPy ``Eq`` objects:
        ``d/dt ∂L/∂q̇_j − ∂L/∂q_j = Σ_k λ_k G_kj + Q_j``, one per coordinate."""
        sp = _sympy()
        out = []
        lam_force = (
            self.constraint_jacobian.T * self.lam_vec
            if self.n_constraints
            else sp.zeros(self.n_coordinates, 1)
        )
        for j, (q, v) in enumerate(zip(self.coordinates, self.speeds, strict=True)):
            lhs = self.lagrangian.diff(v).diff(self.t) - self.lagrangian.diff(q)
            out.append(sp.Eq(lhs, lam_force[j] + self.generalized_forces[j]))
        return out

    @cached_property
    def augmented_matrix(self):
        """The multiplier-augmented (index-1) matrix ``[[M, −Gᵀ], [G, 0]]``, (n+m) × (n+m),
        acting on ``[q̈; λ]``."""
        sp = _sympy()
        n, m = self.n_coordinates, self.n_constraints
        K = sp.zeros(n + m, n + m)
        K[:n, :n] = self.mass_matrix
        if m:
            K[:n, n:] = -self.constraint_jacobian.T
            K[n:, :n] = self.constraint_jacobian
        return K

    @cached_property
    def augmented_forcing(self):
        """Right-hand side ``[f; −γ]`` ((n+m) × 1) of the augmented system
        ``augmented_matrix · [q̈; λ] = augmented_forcing``."""
        sp = _sympy()
        return (
            sp.Matrix.vstack(self.forcing, -self.constraint_gamma)
            if self.n_constraints
            else self.forcing
        )

    @cached_property
    def generalized_constraint_forces(self):
        """``Σ_k λ_k G_kj`` (n × 1) in terms of :attr:`lam_vec` (SymPy)."""
        return self.constraint_jacobian.T * self.lam_vec

    @cached_property
    def energy_function(self):
        """The Jacobi integral ``h = Σ q̇_j ∂L/∂q̇_j − L`` (= T + U for natural systems)."""
        if self._point_mass_route is not None:
            return self._point_mass_route[2]
        _, v, L, p, back = self._derivation  # the momenta, once
        return (sum(vj * pj for vj, pj in zip(v, p, strict=True)) - L).xreplace(back)

    def constants_of_motion(self):
        """The first integrals this system has by its form, with the reason for each:
        ``[(name, symbol, unit, expression, reason)]`` (SymPy expressions in q, q̇, t).

        * the Jacobi integral ``h = Σ q̇ ∂L/∂q̇ − L`` when ``L`` has no explicit t, no applied
          force acts and every constraint is scleronomic (no explicit t, ``b = 0``), so the
          reactions do no work (``Σ λ_k G_kj q̇_j = −λ·b = 0``);
        * the conjugate momentum ``p_j = ∂L/∂q̇_j`` of a cyclic coordinate (``∂L/∂q_j = 0``)
          on which neither an applied force nor a constraint reaction acts (column j of G and
          ``Q_j`` zero): ``ṗ_j = ∂L/∂q_j + Σ λ_k G_kj + Q_j = 0``.

        Examples
        --------
        >>> from poinsot.models import pendulum_on_cart
        >>> [c[1] for c in pendulum_on_cart().system.constants_of_motion()]
        ['h', 'p_x']
        """
        sp = _sympy()
        out = []
        L = self.lagrangian
        t = self.t
        explicit = self._explicitly_timed
        forced = any(sp.simplify(Q) != 0 for Q in self.generalized_forces)
        rheonomic = any(sp.simplify(b) != 0 for b in self.constraint_rhs) or any(
            _explicit_time_derivative(e, self.coordinates, self.speeds, t) != 0
            for e in self.constraint_jacobian
        )
        if not (explicit or forced or rheonomic):
            out.append(("energy (Jacobi integral h = Σ q̇ ∂L/∂q̇ − L)", "h", "J",
                        self.energy_function, "L has no explicit t, no applied force, and the "
                        "constraints are fixed in time"))  # fmt: skip
        G = self.constraint_jacobian
        for j, (q, v) in enumerate(zip(self.coordinates, self.speeds, strict=True)):
            cyclic = _holding_speeds(L, self.coordinates, self.speeds, q) == 0
            free = all(sp.simplify(G[k, j]) == 0 for k in range(G.rows))
            if cyclic and free and sp.simplify(self.generalized_forces[j]) == 0:
                name = str(q).replace("(t)", "")
                unit = {"m": "kg·m/s", "rad": "kg·m²/s"}.get(self.unit_of(q), "")
                out.append((f"momentum conjugate to {name}, ∂L/∂{name}̇", f"p_{name}", unit,
                            sp.simplify(L.diff(v)), f"{name} is cyclic and no force or "
                            "constraint acts along it"))  # fmt: skip
        return out

    @cached_property
    def parameters(self):
        """Free symbols other than t (to be given numbers at ``simulate`` time), sorted."""
        sp = _sympy()
        exprs = [
            self.lagrangian,
            *self.holonomic,
            *self.nonholonomic,
            *list(self.generalized_forces),
        ]
        out = set()
        for e in exprs:
            out |= sp.sympify(e).free_symbols
        return sorted(out - {self.t}, key=str)

    def __repr__(self):
        return (
            f"LagrangianSystem(coordinates={self.coordinates}, holonomic={self.n_holonomic}, "
            f"nonholonomic={len(self.nonholonomic)})"
        )

    def _repr_latex_(self) -> str:
        r"""The equations of motion (6.60), one per coordinate, and the constraints, as LaTeX by
        SymPy's printing (``q̇`` as a dot): the display of a system in a notebook.

        Examples
        --------
        >>> from poinsot.models import pendulum_cartesian
        >>> latex = pendulum_cartesian().system._repr_latex_()
        >>> r"\ddot{x}" in latex and r"\lambda_{1}" in latex and latex.startswith("$")
        True
        """
        from sympy.physics.vector.printing import vlatex

        lines = [f"{vlatex(e.lhs)} &= {vlatex(e.rhs)}" for e in self.equations()]
        for k, g in enumerate(self.holonomic):
            relation = r"\geq" if k in self.unilateral else "="
            lines.append(f"{vlatex(g)} &{relation} 0")
        lines += [f"{vlatex(a)} &= 0" for a in self.nonholonomic]
        return r"$\displaystyle \begin{aligned}" + r" \\ ".join(lines) + r"\end{aligned}$"

    # numeric side: poinsot.lagrange.numeric
    def simulate(self, t_span, *, q0, qd0=None, params=None, **kwargs):
        """Integrate the equations of motion; see :func:`poinsot.lagrange.numeric.simulate`."""
        from .numeric import simulate

        return simulate(self, t_span, q0=q0, qd0=qd0, params=params, **kwargs)

    def prepare(self, t_span, *, params=None, **kwargs):
        """Check a run and lower it once, for any initial state; see
        :func:`poinsot.lagrange.numeric.prepare`."""
        from .numeric import prepare

        return prepare(self, t_span, params=params, **kwargs)

    def simulate_ensemble(self, t_span, *, q0, qd0=None, params=None, **kwargs):
        """Integrate N members (parameter sets × initial states) in compiled calls; see
        :func:`poinsot.lagrange.ensemble.simulate_ensemble`."""
        from .ensemble import simulate_ensemble

        return simulate_ensemble(self, t_span, q0=q0, qd0=qd0, params=params, **kwargs)

    def prepare_ensemble(self, t_span, **kwargs):
        """Check an ensemble's run and lower it once, for any members; see
        :func:`poinsot.lagrange.ensemble.prepare_ensemble`."""
        from .ensemble import prepare_ensemble

        return prepare_ensemble(self, t_span, **kwargs)

    def equilibria(self, params=None, **kwargs):
        """Equilibria ``{coordinate: value}``; see :func:`poinsot.lagrange.linear.equilibria`."""
        from .linear import equilibria

        return equilibria(self, params=params, **kwargs)

    def linearize(self, equilibrium, params=None, **kwargs):
        """Linearisation about an equilibrium or a steady motion (``speeds=``), with the input
        matrix B; see :func:`poinsot.lagrange.linear.linearize`."""
        from .linear import linearize

        return linearize(self, equilibrium, params=params, **kwargs)


def _holding_speeds(expr, coordinates, speeds, q):
    """``∂expr/∂q`` holding the speeds fixed (``q̇`` contains ``q`` in SymPy)."""
    sp = _sympy()
    vs = sp.symbols(f"_v0:{len(speeds)}")
    forward = dict(zip(speeds, vs, strict=True))
    d = sp.simplify(expr.subs(forward).diff(q))
    return d.subs(dict(zip(vs, speeds, strict=True)))


def _explicit_time_derivative(expr, coordinates, speeds, t):
    """``∂expr/∂t`` holding q and q̇ fixed."""
    sp = _sympy()
    qs = sp.symbols(f"_q0:{len(coordinates)}")
    vs = sp.symbols(f"_v0:{len(speeds)}")
    forward = dict(zip(speeds, vs, strict=True))
    e = expr.subs(forward).subs(dict(zip(coordinates, qs, strict=True)))
    back = {**dict(zip(qs, coordinates, strict=True)), **dict(zip(vs, speeds, strict=True))}
    return e.diff(t).subs(back)
