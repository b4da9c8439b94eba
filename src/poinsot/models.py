"""Canonical mechanical systems, shared by the tests, the docs and the command line.

Each function returns a :class:`Model`: the :class:`~poinsot.lagrange.LagrangianSystem`, its
symbols, default parameter values and default initial conditions, so that
``model.simulate((0, 10))`` runs it as is. Parameters stay symbolic in ``model.system``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .display import HTMLDisplay

__all__ = [
    "MODELS",
    "Model",
    "atwood_machine",
    "bead_on_rotating_hoop",
    "double_pendulum",
    "heavy_symmetric_top",
    "knife_edge",
    "notebook_body",
    "pendulum_cartesian",
    "pendulum_on_cart",
    "pendulum_polar",
    "rolling_coin",
    "rolling_coin_kane",
    "rolling_disk",
    "sliding_ladder",
    "spherical_pendulum",
]


@dataclass
class Model(HTMLDisplay):
    """A canonical system with defaults and the geometry to draw it.

    Attributes
    ----------
    system : LagrangianSystem
        With its coordinates' units (``system.units``).
    symbols : dict
        Name → SymPy symbol or coordinate.
    params, q0, qd0 : dict
        ``{symbol: value}``, ``{coordinate: value}``.
    reactions : dict
        The multipliers as the physical forces they are: ``name → (expression, unit,
        meaning)``, the expression in ``system.lam_vec``, the coordinates and the parameters
        (e.g. the rod tension ``T = −2 λ l``).
    points : dict
        ``name → (x, y, z)`` SymPy expressions in the coordinates, t and the parameters [m]:
        the mechanism's moving points (bobs, the cart, a disk's rim).
        Points named with a ``#`` (a rim's vertices, a string's end) are drawn without a
        marker or label.
    links : tuple
        ``(a, b)`` pairs of point names drawn as rods, strings or rims.
    trail : str or None
        A point whose whole path is drawn (the contact point of a rolling disk).
    outline : dict
        ``name → [(x, y, z), …]`` fixed polylines in the parameters (a rail, the hoop, the
        ground) [m].
    view : str
        ``"xy"`` (a planar mechanism, y up) or ``"3d"``.
    param_units : dict
        ``{symbol: unit}`` of every parameter (SI: ``"kg"``, ``"m"``, ``"m/s²"``, ``"rad"``…),
        for tables and reports.
    """

    name: str
    description: str
    system: object
    symbols: dict
    params: dict
    q0: dict
    qd0: dict = field(default_factory=dict)
    guess: dict = field(default_factory=dict)
    reactions: dict = field(default_factory=dict)
    points: dict = field(default_factory=dict)
    links: tuple = ()
    outline: dict = field(default_factory=dict)
    view: str = "xy"
    trail: str | None = None
    param_units: dict = field(default_factory=dict)

    def unit_of_parameter(self, symbol) -> str:
        """The unit of a parameter, by symbol or name ("" when not declared)."""
        by_name = {str(k): u for k, u in self.param_units.items()}
        return by_name.get(str(symbol), "")

    def positions(self, sol):
        """The mechanism's :attr:`points` along a solution: ``(names, array (n_samples,
        n_points, 3))`` [m], evaluated at the solution's parameters."""
        names = list(self.points)
        exprs = [c for p in self.points.values() for c in p]
        return names, sol.evaluate(exprs).reshape(len(sol.t), len(names), 3)

    def outlines(self, params=None) -> dict:
        """:attr:`outline` as numbers: ``name → array (k, 3)`` [m]."""
        import numpy as np
        import sympy as sp

        values = {**self.params, **(params or {})}
        return {
            name: np.array([[float(sp.sympify(c).subs(values)) for c in p] for p in pts])
            for name, pts in self.outline.items()
        }

    def reaction_values(self, sol) -> dict:
        """:attr:`reactions` along a solution, then the forces of the constraints the
        coordinates hide (``system.hidden``, :meth:`~poinsot.lagrange.LagrangianSystem.
        reaction_forces`): ``name → (values (n_samples,), unit, meaning)``."""
        out = {
            name: (sol.evaluate(expr), unit, meaning)
            for name, (expr, unit, meaning) in self.reactions.items()
        }
        hidden = self.system.hidden
        if hidden and not sol.releases:
            forces = self.system.reaction_forces(sol)
            out.update({h.name: (forces[h.name], h.unit, h.meaning) for h in hidden})
        return out

    def simulate(self, t_span, **kwargs):
        """``system.simulate`` with the model's defaults (any of them overridable)."""
        kwargs.setdefault("q0", self.q0)
        kwargs.setdefault("qd0", self.qd0)
        kwargs.setdefault("params", self.params)
        if self.guess and "guess" not in kwargs:  # only for the coordinates q0 leaves out
            from .lagrange.arguments import key_index

            index = key_index(self.system.coordinates)
            given = {index(k) for k in kwargs["q0"]}
            guess = {k: v for k, v in self.guess.items() if index(k) not in given}
            if guess:
                kwargs["guess"] = guess
        sol = self.system.simulate(t_span, **kwargs)
        sol.model = self  # its reactions named, its mechanism drawn (sol.plot(), sol.show())
        return sol


def notebook_body():
    """The source notebook's reference body (docs/theory.md §1): 27 equal particles at
    ``(a i, b j, c k)``, ``i, j, k ∈ {0, ½, 1}``, ``(a, b, c) = (1, 2, 3)``, total mass 10.
    Principal moments 25/3, 50/3, 65/3.

    Examples
    --------
    >>> (notebook_body().principal_moments * 3).round(9).tolist()
    [25.0, 50.0, 65.0]
    """
    import numpy as np

    from .bodies import RigidBody

    grid = [(i, 2 * j, 3 * k) for i in (0, 0.5, 1) for j in (0, 0.5, 1) for k in (0, 0.5, 1)]
    return RigidBody.from_particles(np.full(27, 10 / 27), grid)


def _sp():
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols

    return sp, dynamicsymbols


def _ring(name, center, u, v, radius, k=24):
    """Points and links of a circle (a rim, a hoop) drawn as a ``k``-gon: ``center + radius
    (cos s u + sin s v)``. The vertices are named ``{name}#0``, ``{name}#1``, … (a ``#`` marks
    a vertex drawn without a marker); ``{name}#0`` is at ``s = 0``, so a spoke drawn to it
    shows the turning."""
    sp, _ = _sp()
    points = {}
    for i in range(k):
        s = 2 * sp.pi * i / k
        points[f"{name}#{i}"] = tuple(
            center[j] + radius * (sp.cos(s) * u[j] + sp.sin(s) * v[j]) for j in range(3)
        )
    links = tuple((f"{name}#{i}", f"{name}#{(i + 1) % k}") for i in range(k))
    return points, links


def pendulum_polar(theta0=1.0471975511965976) -> Model:
    """Simple pendulum in its angle θ from the downward vertical (a minimal coordinate):
    ``L = ½ m l² θ̇² + m g l cos θ``."""
    sp, ds = _sp()
    theta = ds("theta")
    m, g, l = sp.symbols("m g l", positive=True)
    L = m * l**2 * theta.diff() ** 2 / 2 + m * g * l * sp.cos(theta)
    from .lagrange import LagrangianSystem

    return Model(
        "pendulum-polar",
        "Simple pendulum in its angle (minimal coordinate)",
        LagrangianSystem([theta], L, units={theta: "rad"}),
        {"theta": theta, "m": m, "g": g, "l": l},
        {m: 1.0, g: 9.81, l: 1.0},
        {theta: theta0},
        {theta: 0.0},
        points={"pivot": (0, 0, 0), "bob": (l * sp.sin(theta), -l * sp.cos(theta), 0)},
        links=(("pivot", "bob"),),
        param_units={m: "kg", g: "m/s²", l: "m"},
    )


def pendulum_cartesian(theta0=1.0471975511965976) -> Model:
    """Pendulum bob at (x, y) (y up, pivot at the origin) with the rod as a holonomic
    constraint ``x² + y² − l² = 0``; the multiplier gives the rod tension
    ``T = −2 λ l`` (the force on the bob is ``2λ (x, y)``)."""
    sp, ds = _sp()
    x, y = ds("x y")
    m, g, l = sp.symbols("m g l", positive=True)
    from .lagrange import LagrangianSystem

    system = LagrangianSystem(
        [x, y],
        kinetic=m * (x.diff() ** 2 + y.diff() ** 2) / 2,
        potential=m * g * y,
        holonomic=[x**2 + y**2 - l**2],
        units={x: "m", y: "m"},
    )
    import math

    return Model(
        "pendulum-cartesian",
        "Pendulum in Cartesian coordinates; the rod is a "
        "constraint whose multiplier is the rod tension",
        system,
        {"x": x, "y": y, "m": m, "g": g, "l": l},
        {m: 1.0, g: 9.81, l: 1.0},
        {x: math.sin(theta0), y: -math.cos(theta0)},
        {x: 0.0, y: 0.0},
        reactions={
            "rod tension T": (
                -2 * system.lam_vec[0] * l,
                "N",
                "T = −2λl: the rod pulls the bob toward the pivot when T > 0",
            )
        },
        points={"pivot": (0, 0, 0), "bob": (x, y, 0)},
        links=(("pivot", "bob"),),
        param_units={m: "kg", g: "m/s²", l: "m"},
    )


def double_pendulum() -> Model:
    """Planar double pendulum in the two absolute angles from the downward vertical.

    The rods' lengths are hidden constraints (:class:`~poinsot.lagrange.HiddenConstraint`):
    written with the lengths ρ1, ρ2 as auxiliary coordinates held at l1, l2, the model reports
    both rod tensions (``system.reaction_forces``), though its coordinates are the angles."""
    sp, ds = _sp()
    t1, t2 = ds("theta1 theta2")
    r1, r2 = ds("rho1 rho2")  # the rods' lengths, held at l1, l2 by the rods
    m1, m2, l1, l2, g = sp.symbols("m1 m2 l1 l2 g", positive=True)
    X1, Y1 = r1 * sp.sin(t1), -r1 * sp.cos(t1)
    X2, Y2 = X1 + r2 * sp.sin(t2), Y1 - r2 * sp.cos(t2)
    x1, y1 = l1 * sp.sin(t1), -l1 * sp.cos(t1)
    x2, y2 = x1 + l2 * sp.sin(t2), y1 - l2 * sp.cos(t2)
    from .lagrange import HiddenConstraint, LagrangianSystem, PointMass

    system = LagrangianSystem(
        [t1, t2],
        bodies=[PointMass(m1, [X1, Y1, 0]), PointMass(m2, [X2, Y2, 0])],
        potential=m1 * g * Y1 + m2 * g * Y2,
        units={t1: "rad", t2: "rad"},
        hidden=[
            HiddenConstraint(
                r1, l1, "rod 1 tension T1", "N", -1, "the pull of rod 1 on bob 1, toward the pivot"
            ),
            HiddenConstraint(
                r2, l2, "rod 2 tension T2", "N", -1, "the pull of rod 2 on bob 2, toward bob 1"
            ),
        ],
    )
    return Model(
        "double-pendulum",
        "Planar double pendulum (chaotic at large amplitude)",
        system,
        {"theta1": t1, "theta2": t2, "m1": m1, "m2": m2, "l1": l1, "l2": l2, "g": g},
        {m1: 1.0, m2: 1.0, l1: 1.0, l2: 1.0, g: 9.81},
        {t1: 2.0, t2: 1.0},
        {t1: 0.0, t2: 0.0},
        points={"pivot": (0, 0, 0), "bob 1": (x1, y1, 0), "bob 2": (x2, y2, 0)},
        links=(("pivot", "bob 1"), ("bob 1", "bob 2")),
        trail="bob 2",
        param_units={m1: "kg", m2: "kg", l1: "m", l2: "m", g: "m/s²"},
    )


def spherical_pendulum() -> Model:
    """Spherical pendulum in polar angle θ (from the downward vertical) and azimuth φ."""
    sp, ds = _sp()
    th, ph = ds("theta phi")
    m, g, l = sp.symbols("m g l", positive=True)
    L = m * l**2 * (th.diff() ** 2 + sp.sin(th) ** 2 * ph.diff() ** 2) / 2 + m * g * l * sp.cos(th)
    from .lagrange import LagrangianSystem

    return Model(
        "spherical-pendulum",
        "Spherical pendulum (conical motions, precessing orbits)",
        LagrangianSystem([th, ph], L, units={th: "rad", ph: "rad"}),
        {"theta": th, "phi": ph, "m": m, "g": g, "l": l},
        {m: 1.0, g: 9.81, l: 1.0},
        {th: 0.8, ph: 0.0},
        {th: 0.0, ph: 2.0},
        points={
            "pivot": (0, 0, 0),
            "bob": (l * sp.sin(th) * sp.cos(ph), l * sp.sin(th) * sp.sin(ph), -l * sp.cos(th)),
        },
        links=(("pivot", "bob"),),
        view="3d",
        trail="bob",
        param_units={m: "kg", g: "m/s²", l: "m"},
    )


def bead_on_rotating_hoop() -> Model:
    """Bead on a hoop of radius R spinning at ω about its vertical diameter; θ from the bottom:
    ``L = ½ m R² (θ̇² + ω² sin² θ) + m g R cos θ``. For ω² > g/R the bottom is unstable and
    ``cos θ* = g/(ω² R)`` is stable with frequency ``ω sin θ*``."""
    sp, ds = _sp()
    th = ds("theta")
    m, R, w, g = sp.symbols("m R omega g", positive=True)
    t = sp.Symbol("t")
    turn = (sp.cos(w * t), sp.sin(w * t), 0)  # the hoop's plane turns about z at ω
    hoop, hoop_links = _ring("hoop", (0, 0, 0), turn, (0, 0, 1), R)
    L = m * R**2 * (th.diff() ** 2 + w**2 * sp.sin(th) ** 2) / 2 + m * g * R * sp.cos(th)
    from .lagrange import LagrangianSystem

    return Model(
        "bead-on-hoop",
        "Bead on a rotating hoop: a pitchfork bifurcation at ω² = g/R",
        LagrangianSystem([th], L, units={th: "rad"}),
        {"theta": th, "m": m, "R": R, "omega": w, "g": g},
        {m: 1.0, R: 1.0, w: 5.0, g: 9.81},
        {th: 0.3},
        {th: 0.0},
        points={
            "bead": (
                R * sp.sin(th) * sp.cos(w * t),
                R * sp.sin(th) * sp.sin(w * t),
                -R * sp.cos(th),
            ),
            **hoop,
        },
        links=hoop_links,
        outline={"axis of rotation": [(0, 0, -1.3 * R), (0, 0, 1.3 * R)]},
        view="3d",
        trail="bead",
        param_units={m: "kg", R: "m", w: "rad/s", g: "m/s²"},
    )


def atwood_machine() -> Model:
    """Atwood machine with a pulley of inertia I and radius r: heights y1, y2 (up) and pulley
    angle φ, with constraints ``y1 + y2 = const`` (inextensible string) and ``r φ + y1 = const``
    (no slip). The multipliers give the tensions: ``T2 = λ1`` on mass 2 and ``T1 = λ1 + λ2`` on
    mass 1; the acceleration is ``(m1 − m2) g / (m1 + m2 + I/r²)``."""
    sp, ds = _sp()
    y1, y2, ph = ds("y1 y2 phi")
    m1, m2, I, r, g = sp.symbols("m1 m2 I r g", positive=True)
    c = sp.Symbol("c", real=True)  # the rope's constant: zero when y1, y2 are displacements
    T = (m1 * y1.diff() ** 2 + m2 * y2.diff() ** 2 + I * ph.diff() ** 2) / 2
    U = m1 * g * y1 + m2 * g * y2
    from .lagrange import LagrangianSystem

    system = LagrangianSystem(
        [y1, y2, ph],
        kinetic=T,
        potential=U,
        holonomic=[y1 + y2 - c, r * ph + y1],
        units={y1: "m", y2: "m", ph: "rad"},
    )
    lam1, lam2 = system.lam_vec
    drop = 2.5  # drawn: the masses hang this far below the pulley's centre at y = 0
    rim, rim_links = _ring("rim", (0, 0, 0), (1, 0, 0), (0, 1, 0), r, k=16)
    return Model(
        "atwood",
        "Atwood machine with pulley inertia; tensions from the multipliers",
        system,
        {"y1": y1, "y2": y2, "phi": ph, "m1": m1, "m2": m2, "I": I, "r": r, "g": g, "c": c},
        {m1: 3.0, m2: 2.0, I: 0.05, r: 0.1, g: 9.81, c: 0.0},
        {y1: 0.0},
        {y1: 0.0},
        reactions={
            "tension T1 (string on mass 1)": (lam1 + lam2, "N", "T1 = λ1 + λ2"),
            "tension T2 (string on mass 2)": (lam1, "N", "T2 = λ1"),
        },
        points={
            "mass 1": (-r, y1 - drop, 0),
            "mass 2": (r, y2 - drop, 0),
            "pulley": (0, 0, 0),
            "#left": (-r, 0, 0),
            "#right": (r, 0, 0),
            "#spoke": (r * sp.cos(ph), r * sp.sin(ph), 0),
            **rim,
        },
        links=(("#left", "mass 1"), ("#right", "mass 2"), ("pulley", "#spoke"), *rim_links),
        param_units={m1: "kg", m2: "kg", I: "kg·m²", r: "m", g: "m/s²", c: "m"},
    )


def pendulum_on_cart() -> Model:
    """Cart of mass M on a horizontal rail (x) carrying a pendulum (m, l) at angle θ."""
    sp, ds = _sp()
    x, th = ds("x theta")
    M, m, l, g = sp.symbols("M m l g", positive=True)
    from .lagrange import LagrangianSystem, PointMass

    bob = PointMass(m, [x + l * sp.sin(th), -l * sp.cos(th), 0])
    cart = PointMass(M, [x, 0, 0])
    system = LagrangianSystem(
        [x, th],
        bodies=[cart, bob],
        potential=-m * g * l * sp.cos(th),
        units={x: "m", th: "rad"},
    )
    return Model(
        "pendulum-on-cart",
        "Pendulum on a free cart (momentum along the rail conserved)",
        system,
        {"x": x, "theta": th, "M": M, "m": m, "l": l, "g": g},
        {M: 2.0, m: 1.0, l: 1.0, g: 9.81},
        {x: 0.0, th: 1.0},
        {x: 0.0, th: 0.0},
        points={"cart": (x, 0, 0), "bob": (x + l * sp.sin(th), -l * sp.cos(th), 0)},
        links=(("cart", "bob"),),
        outline={"rail": [(-2 * l, 0, 0), (2 * l, 0, 0)]},
        param_units={M: "kg", m: "kg", l: "m", g: "m/s²"},
    )


def rolling_disk() -> Model:
    """A vertical disk of radius R rolling without slipping on a plane (non-holonomic):
    contact point (x, y), heading φ, rolling angle θ, with the Pfaffian constraints
    ``ẋ − R θ̇ cos φ = 0`` and ``ẏ − R θ̇ sin φ = 0`` (not integrable)."""
    sp, ds = _sp()
    x, y, ph, th = ds("x y phi theta")
    m, R = sp.symbols("m R", positive=True)
    I_spin, I_turn = m * R**2 / 2, m * R**2 / 4  # uniform disk
    T = (
        m * (x.diff() ** 2 + y.diff() ** 2) + I_spin * th.diff() ** 2 + I_turn * ph.diff() ** 2
    ) / 2
    from .lagrange import LagrangianSystem

    system = LagrangianSystem(
        [x, y, ph, th],
        kinetic=T,
        nonholonomic=[x.diff() - R * th.diff() * sp.cos(ph), y.diff() - R * th.diff() * sp.sin(ph)],
        units={x: "m", y: "m", ph: "rad", th: "rad"},
    )
    lam1, lam2 = system.lam_vec
    heading = (sp.cos(ph), sp.sin(ph), 0)
    centre = (x, y, R)
    rim, rim_links = _ring("rim", centre, heading, (0, 0, 1), R)
    mark = tuple(centre[j] - R * (sp.sin(th) * heading[j] + sp.cos(th) * int(j == 2))
                 for j in range(3))  # fmt: skip
    return Model(
        "rolling-disk",
        "Vertical disk rolling without slipping (non-holonomic)",
        system,
        {"x": x, "y": y, "phi": ph, "theta": th, "m": m, "R": R},
        {m: 1.0, R: 0.5},
        {x: 0.0, y: 0.0, ph: 0.0, th: 0.0},
        {ph: 0.8, th: 4.0},
        reactions={
            "friction F_x": (lam1, "N", "horizontal contact force along x"),
            "friction F_y": (lam2, "N", "horizontal contact force along y"),
        },
        points={"contact": (x, y, 0), "centre": centre, "#mark": mark, **rim},
        links=(("centre", "#mark"), ("centre", "contact"), *rim_links),
        view="3d",
        trail="contact",
        param_units={m: "kg", R: "m"},
    )


def knife_edge() -> Model:
    """A knife edge (a skate) on a plane inclined at α: contact point (x, y) with x down the
    slope, heading φ of the blade, and the non-holonomic constraint that the contact point
    moves along the blade, ``ẋ sin φ − ẏ cos φ = 0`` (Bloch, *Nonholonomic Mechanics and
    Control*, §1.6). Turning at a constant rate ω it never slides down: ``x = g sin α sin² ωt
    / (2ω²)`` stays bounded while y drifts across the slope. Across the slope (φ = ±π/2) it
    rests: the constraint's reaction ``λ = ∓ m g sin α`` balances gravity."""
    sp, ds = _sp()
    x, y, ph = ds("x y phi")
    m, g, alpha, I = sp.symbols("m g alpha I", positive=True)
    from .lagrange import LagrangianSystem

    system = LagrangianSystem(
        [x, y, ph],
        kinetic=m * (x.diff() ** 2 + y.diff() ** 2) / 2 + I * ph.diff() ** 2 / 2,
        potential=-m * g * sp.sin(alpha) * x,
        nonholonomic=[x.diff() * sp.sin(ph) - y.diff() * sp.cos(ph)],
        units={x: "m", y: "m", ph: "rad"},
    )
    (lam,) = system.lam_vec
    half = 0.1  # the blade's half length in m, for drawing (it does not enter the dynamics)
    return Model(
        "knife-edge",
        "Knife edge on an incline (non-holonomic): it crosses the slope, or rests across it",
        system,
        {"x": x, "y": y, "phi": ph, "m": m, "g": g, "alpha": alpha, "I": I},
        {m: 1.0, g: 9.81, alpha: 0.3, I: 0.1},
        {x: 0.0, y: 0.0, ph: 0.3},
        {x: 0.0, y: 0.0, ph: 2.0},
        reactions={"sideways reaction on the blade": (lam, "N", "λ: the force across the blade")},
        points={
            "contact": (x, y, 0),
            "#heel": (x - half * sp.cos(ph), y - half * sp.sin(ph), 0),
            "#toe": (x + half * sp.cos(ph), y + half * sp.sin(ph), 0),
        },
        links=(("#heel", "#toe"),),
        trail="contact",
        view="xy",
        param_units={m: "kg", g: "m/s²", alpha: "rad", I: "kg·m²"},
    )


def sliding_ladder() -> Model:
    """A ladder (uniform rod of mass m, length L) sliding on a frictionless floor against a
    frictionless wall: centre (x_c, y_c), angle θ from the wall. The floor is a constraint,
    the wall a one-sided one (``x_top ≥ 0``), which lets go when its reaction vanishes: from
    rest at θ0, at ``cos θ = ⅔ cos θ0`` (the top has fallen to ⅔ of its height; Kleppner &
    Kolenkow, problem 7.9). After that the ladder slides with the floor alone."""
    sp, ds = _sp()
    xc, yc, th = ds("x_c y_c theta")
    m, g, L = sp.symbols("m g L", positive=True)
    from .lagrange import LagrangianSystem

    system = LagrangianSystem(
        [xc, yc, th],
        kinetic=m * (xc.diff() ** 2 + yc.diff() ** 2) / 2 + m * L**2 / 12 * th.diff() ** 2 / 2,
        potential=m * g * yc,
        holonomic=[yc - L / 2 * sp.cos(th)],
        unilateral=[xc - L / 2 * sp.sin(th)],
        units={xc: "m", yc: "m", th: "rad"},
    )
    floor, wall = system.lam_vec
    return Model(
        "sliding-ladder",
        "Ladder sliding down a wall: the wall lets go at cos θ = ⅔ cos θ0",
        system,
        {"x_c": xc, "y_c": yc, "theta": th, "m": m, "g": g, "L": L},
        {m: 1.0, g: 9.81, L: 2.0},
        {th: 0.3},
        {th: 0.0},
        guess={xc: 0.3, yc: 1.0},
        reactions={
            "floor reaction N_floor": (floor, "N", "upward push of the floor on the foot"),
            "wall reaction N_wall": (wall, "N", "push of the wall on the top; zero once released"),
        },
        points={
            "top": (xc - L / 2 * sp.sin(th), yc + L / 2 * sp.cos(th), 0),
            "foot": (xc + L / 2 * sp.sin(th), yc - L / 2 * sp.cos(th), 0),
        },
        links=(("top", "foot"),),
        outline={"wall": [(0, 0, 0), (0, 1.1 * L, 0)], "floor": [(0, 0, 0), (1.6 * L, 0, 0)]},
        trail="top",
        param_units={m: "kg", g: "m/s²", L: "m"},
    )


def rolling_coin() -> Model:
    """A thin uniform disc (a coin) of mass m and radius r rolling without slipping on a
    plane, free to lean: contact point (x, y), heading ψ, lean θ from the vertical, spin φ,
    with the two non-holonomic rolling constraints (the disc's material point at the contact
    is at rest). Upright rolling at spin rate Ω is stable exactly when Ω² > g/(3r); the lean
    then wobbles at ``ω² = (4/5)(3Ω² − g/r)`` (Greenwood, *Advanced Dynamics*, §6.3)."""
    sp, ds = _sp()
    from sympy.physics.mechanics import Point, ReferenceFrame, RigidBody, inertia

    x, y, psi, th, ph = ds("x y psi theta phi")
    h = ds("h")  # the contact point's height: the table holds it at 0
    m, r, g = sp.symbols("m r g", positive=True)
    N = ReferenceFrame("N")
    Yf = N.orientnew("Y", "Axis", [psi, N.z])  # heading
    Lf = Yf.orientnew("L", "Axis", [th, Yf.x])  # lean; the disc's plane holds L.x and L.z
    Rf = Lf.orientnew("R", "Axis", [ph, Lf.y])  # spin about the axle L.y
    O = Point("O")
    O.set_vel(N, 0)
    C = O.locatenew("C", x * N.x + y * N.y + h * N.z)
    C.set_vel(N, x.diff() * N.x + y.diff() * N.y + h.diff() * N.z)
    D = C.locatenew("D", r * Lf.z)
    D.set_vel(N, D.pos_from(O).dt(N))
    disc = RigidBody("disc", D, Rf, m, (inertia(Lf, m * r**2 / 4, m * r**2 / 2, m * r**2 / 4), D))
    slip = D.vel(N) + Rf.ang_vel_in(N).cross(-r * Lf.z)  # velocity of the contact material point
    from .lagrange import HiddenConstraint, LagrangianSystem

    system = LagrangianSystem(
        [x, y, psi, th, ph],
        bodies=[disc],
        potential=m * g * (h + r * sp.cos(th)),
        nonholonomic=[slip.dot(N.x), slip.dot(N.y)],
        frame=N,
        units={x: "m", y: "m", psi: "rad", th: "rad", ph: "rad"},
        hidden=[
            HiddenConstraint(h, 0, "normal force N", "N", 1, "the table's upward push on the coin")
        ],
    )
    lam1, lam2 = system.lam_vec
    centre = tuple(D.pos_from(O).to_matrix(N).subs(h, 0))
    u, v = tuple(Rf.x.to_matrix(N)), tuple(Rf.z.to_matrix(N))
    rim, rim_links = _ring("rim", centre, u, v, r)
    return Model(
        "rolling-coin",
        "Coin rolling on a table: stable upright above the spin rate √(g/3r)",
        system,
        {"x": x, "y": y, "psi": psi, "theta": th, "phi": ph, "m": m, "r": r, "g": g},
        {m: 0.01, r: 0.02, g: 9.81},
        {x: 0.0, y: 0.0, psi: 0.0, th: 0.1, ph: 0.0},
        {psi: 0.0, th: 0.0, ph: 25.0},
        reactions={
            "friction F_x": (lam1, "N", "tangential contact force along x"),
            "friction F_y": (lam2, "N", "tangential contact force along y"),
        },
        points={"contact": (x, y, 0), "centre": centre, **rim},
        links=(("centre", "rim#0"), ("centre", "contact"), *rim_links),
        view="3d",
        trail="contact",
        param_units={m: "kg", r: "m", g: "m/s²"},
    )


def rolling_coin_kane():
    """The disc of :func:`rolling_coin` by SymPy's Kane's method, for comparisons with a peer's
    formulation (SymPy's ``Linearizer``, PyDy): a ``KanesMethod`` with its equations formed, and
    the symbols ``(m, r, g)``. The same coordinates (contact x, y, heading ψ, lean θ, spin φ);
    the speeds are u = q̇, in the order (u_ψ, u_θ, u_φ) independent, then (u_x, u_y) dependent
    through the rolling constraints."""
    sp, _ = _sp()
    from sympy.physics.mechanics import (
        KanesMethod,
        Point,
        ReferenceFrame,
        RigidBody,
        dynamicsymbols,
        inertia,
    )

    q = dynamicsymbols("x y psi theta phi")
    u = dynamicsymbols("u_x u_y u_psi u_theta u_phi")
    x, y, psi, th, ph = q
    m, r, g = sp.symbols("m r g", positive=True)
    N = ReferenceFrame("N")
    Yf = N.orientnew("Y", "Axis", [psi, N.z])
    Lf = Yf.orientnew("L", "Axis", [th, Yf.x])
    Rf = Lf.orientnew("R", "Axis", [ph, Lf.y])
    O = Point("O")
    O.set_vel(N, 0)
    C = O.locatenew("C", x * N.x + y * N.y)
    C.set_vel(N, u[0] * N.x + u[1] * N.y)
    D = C.locatenew("D", r * Lf.z)
    to_u = dict(zip([qi.diff() for qi in q], u, strict=True))
    D.set_vel(N, D.pos_from(O).dt(N).subs(to_u))
    Rf.set_ang_vel(N, Rf.ang_vel_in(N).subs(to_u))
    disc = RigidBody("disc", D, Rf, m, (inertia(Lf, m * r**2 / 4, m * r**2 / 2, m * r**2 / 4), D))
    slip = D.vel(N) + Rf.ang_vel_in(N).cross(-r * Lf.z)
    kane = KanesMethod(N, q_ind=q, u_ind=u[2:], u_dependent=u[:2],
                       kd_eqs=[qi.diff() - ui for qi, ui in zip(q, u, strict=True)],
                       velocity_constraints=[slip.dot(N.x), slip.dot(N.y)])  # fmt: skip
    kane.kanes_equations([disc], [(D, -m * g * N.z)])
    return kane, (m, r, g)


def heavy_symmetric_top() -> Model:
    """Heavy symmetric top on a fixed tip in z-x-z Euler angles (ψ, θ, φ):
    ``L = ½ A (θ̇² + ψ̇² sin² θ) + ½ C (φ̇ + ψ̇ cos θ)² − M g l cos θ`` (A, C about the tip).

    The tip's position is a hidden constraint: written with the tip at (x_P, y_P, z_P),
    auxiliary coordinates held at 0 (the centre of mass a point mass M at the tip + l e₃,
    turning with the moments A − M l², C about it), the model reports the pivot's reaction
    force on the top, F = M (a_c − g)."""
    sp, ds = _sp()
    psi, th, ph = ds("psi theta phi")
    xp, yp, zp = ds("x_P y_P z_P")  # the tip, held at the origin by the pivot
    A, C, M, g, l = sp.symbols("A C M g l", positive=True)
    turning = (A - M * l**2) * (th.diff() ** 2 + psi.diff() ** 2 * sp.sin(th) ** 2) / 2 + C * (
        ph.diff() + psi.diff() * sp.cos(th)
    ) ** 2 / 2
    from .lagrange import HiddenConstraint, LagrangianSystem, PointMass
    from .relative.carrier import zxz_matrix

    # body axes: columns of Rz(ψ) Rx(θ) Rz(φ); the rim of radius √(2C/M) (a disc with that C)
    axes = zxz_matrix(psi, th, ph)
    axis = tuple(axes[:, 2])  # e₃ in space: (sin ψ sin θ, −cos ψ sin θ, cos θ)
    centre = [p + l * a for p, a in zip((xp, yp, zp), axis, strict=True)]
    com = tuple(l * axes[:, 2])
    rim, rim_links = _ring("rim", com, tuple(axes[:, 0]), tuple(axes[:, 1]),
                           sp.sqrt(2 * C / M), k=16)  # fmt: skip
    # a cylinder of mass 1, radius 0.3, height 0.2, tip 0.5 below its centre of mass
    A_val = 1.0 * (3 * 0.3**2 + 0.2**2) / 12 + 1.0 * 0.5**2
    C_val = 0.5 * 1.0 * 0.3**2
    system = LagrangianSystem(
        [psi, th, ph],
        kinetic=turning,
        bodies=[PointMass(M, centre)],
        potential=M * g * centre[2],
        units={psi: "rad", th: "rad", ph: "rad"},
        hidden=[
            HiddenConstraint(
                p,
                0,
                f"pivot reaction F_{c}",
                "N",
                1,
                f"{c} component of the pivot's force on the top",
            )
            for p, c in ((xp, "x"), (yp, "y"), (zp, "z"))
        ],
    )
    return Model(
        "heavy-top-euler",
        "Heavy symmetric top in Euler angles",
        system,
        {"psi": psi, "theta": th, "phi": ph, "A": A, "C": C, "M": M, "g": g, "l": l},
        {A: A_val, C: C_val, M: 1.0, g: 9.81, l: 0.5},
        {psi: 0.0, th: 0.6, ph: 0.0},
        {psi: 0.0, th: 0.0, ph: 100.0},
        points={"tip": (0, 0, 0), "centre of mass": com, **rim},
        links=(("tip", "centre of mass"), ("centre of mass", "rim#0"), *rim_links),
        view="3d",
        trail="centre of mass",
        param_units={A: "kg·m²", C: "kg·m²", M: "kg", g: "m/s²", l: "m"},
    )


MODELS = {
    "pendulum-polar": pendulum_polar,
    "pendulum-cartesian": pendulum_cartesian,
    "double-pendulum": double_pendulum,
    "spherical-pendulum": spherical_pendulum,
    "bead-on-hoop": bead_on_rotating_hoop,
    "atwood": atwood_machine,
    "pendulum-on-cart": pendulum_on_cart,
    "rolling-disk": rolling_disk,
    "rolling-coin": rolling_coin,
    "knife-edge": knife_edge,
    "sliding-ladder": sliding_ladder,
    "heavy-top-euler": heavy_symmetric_top,
}
