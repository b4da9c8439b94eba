"""Canonical mechanical systems, shared by the tests, the docs and the command line.

Each function returns a :class:`Model`: the :class:`~poinsot.lagrange.LagrangianSystem`, its
symbols, default parameter values and default initial conditions, so that
``model.simulate((0, 10))`` runs it as is. Parameters stay symbolic in ``model.system``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = [
    "MODELS",
    "Model",
    "atwood_machine",
    "bead_on_rotating_hoop",
    "double_pendulum",
    "heavy_symmetric_top",
    "notebook_body",
    "pendulum_cartesian",
    "pendulum_on_cart",
    "pendulum_polar",
    "rolling_disk",
    "spherical_pendulum",
]


@dataclass
class Model:
    """A canonical system with defaults: ``system``, ``symbols`` (name → SymPy symbol or
    coordinate), ``params`` ({symbol: value}), ``q0``, ``qd0`` ({coordinate: value}),
    ``description``."""

    name: str
    description: str
    system: object
    symbols: dict
    params: dict
    q0: dict
    qd0: dict = field(default_factory=dict)
    guess: dict = field(default_factory=dict)

    def simulate(self, t_span, **kwargs):
        """``system.simulate`` with the model's defaults (any of them overridable)."""
        kwargs.setdefault("q0", self.q0)
        kwargs.setdefault("qd0", self.qd0)
        kwargs.setdefault("params", self.params)
        if self.guess:
            kwargs.setdefault("guess", self.guess)
        return self.system.simulate(t_span, **kwargs)


def notebook_body():
    """The source notebook's reference body (THEORY.md §1): 27 equal particles at
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
        LagrangianSystem([theta], L),
        {"theta": theta, "m": m, "g": g, "l": l},
        {m: 1.0, g: 9.81, l: 1.0},
        {theta: theta0},
        {theta: 0.0},
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
    )


def double_pendulum() -> Model:
    """Planar double pendulum in the two absolute angles from the downward vertical."""
    sp, ds = _sp()
    t1, t2 = ds("theta1 theta2")
    m1, m2, l1, l2, g = sp.symbols("m1 m2 l1 l2 g", positive=True)
    x1, y1 = l1 * sp.sin(t1), -l1 * sp.cos(t1)
    x2, y2 = x1 + l2 * sp.sin(t2), y1 - l2 * sp.cos(t2)
    from .lagrange import LagrangianSystem, PointMass

    system = LagrangianSystem(
        [t1, t2],
        bodies=[PointMass(m1, [x1, y1, 0]), PointMass(m2, [x2, y2, 0])],
        potential=m1 * g * y1 + m2 * g * y2,
    )
    return Model(
        "double-pendulum",
        "Planar double pendulum (chaotic at large amplitude)",
        system,
        {"theta1": t1, "theta2": t2, "m1": m1, "m2": m2, "l1": l1, "l2": l2, "g": g},
        {m1: 1.0, m2: 1.0, l1: 1.0, l2: 1.0, g: 9.81},
        {t1: 2.0, t2: 1.0},
        {t1: 0.0, t2: 0.0},
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
        LagrangianSystem([th, ph], L),
        {"theta": th, "phi": ph, "m": m, "g": g, "l": l},
        {m: 1.0, g: 9.81, l: 1.0},
        {th: 0.8, ph: 0.0},
        {th: 0.0, ph: 2.0},
    )


def bead_on_rotating_hoop() -> Model:
    """Bead on a hoop of radius R spinning at ω about its vertical diameter; θ from the bottom:
    ``L = ½ m R² (θ̇² + ω² sin² θ) + m g R cos θ``. For ω² > g/R the bottom is unstable and
    ``cos θ* = g/(ω² R)`` is stable with frequency ``ω sin θ*``."""
    sp, ds = _sp()
    th = ds("theta")
    m, R, w, g = sp.symbols("m R omega g", positive=True)
    L = m * R**2 * (th.diff() ** 2 + w**2 * sp.sin(th) ** 2) / 2 + m * g * R * sp.cos(th)
    from .lagrange import LagrangianSystem

    return Model(
        "bead-on-hoop",
        "Bead on a rotating hoop: a pitchfork bifurcation at ω² = g/R",
        LagrangianSystem([th], L),
        {"theta": th, "m": m, "R": R, "omega": w, "g": g},
        {m: 1.0, R: 1.0, w: 5.0, g: 9.81},
        {th: 0.3},
        {th: 0.0},
    )


def atwood_machine() -> Model:
    """Atwood machine with a pulley of inertia I and radius r: heights y1, y2 (up) and pulley
    angle φ, with constraints ``y1 + y2 = const`` (inextensible string) and ``r φ + y1 = const``
    (no slip). The multipliers give the tensions: ``T2 = λ1`` on mass 2 and ``T1 = λ1 + λ2`` on
    mass 1; the acceleration is ``(m1 − m2) g / (m1 + m2 + I/r²)``."""
    sp, ds = _sp()
    y1, y2, ph = ds("y1 y2 phi")
    m1, m2, I, r, g, c = sp.symbols("m1 m2 I r g c", positive=True)
    T = (m1 * y1.diff() ** 2 + m2 * y2.diff() ** 2 + I * ph.diff() ** 2) / 2
    U = m1 * g * y1 + m2 * g * y2
    from .lagrange import LagrangianSystem

    system = LagrangianSystem(
        [y1, y2, ph], kinetic=T, potential=U, holonomic=[y1 + y2 - c, r * ph + y1]
    )
    return Model(
        "atwood",
        "Atwood machine with pulley inertia; tensions from the multipliers",
        system,
        {"y1": y1, "y2": y2, "phi": ph, "m1": m1, "m2": m2, "I": I, "r": r, "g": g, "c": c},
        {m1: 3.0, m2: 2.0, I: 0.05, r: 0.1, g: 9.81, c: 0.0},
        {y1: 0.0},
        {y1: 0.0},
    )


def pendulum_on_cart() -> Model:
    """Cart of mass M on a horizontal rail (x) carrying a pendulum (m, l) at angle θ."""
    sp, ds = _sp()
    x, th = ds("x theta")
    M, m, l, g = sp.symbols("M m l g", positive=True)
    from .lagrange import LagrangianSystem, PointMass

    bob = PointMass(m, [x + l * sp.sin(th), -l * sp.cos(th), 0])
    cart = PointMass(M, [x, 0, 0])
    system = LagrangianSystem([x, th], bodies=[cart, bob], potential=-m * g * l * sp.cos(th))
    return Model(
        "pendulum-on-cart",
        "Pendulum on a free cart (momentum along the rail conserved)",
        system,
        {"x": x, "theta": th, "M": M, "m": m, "l": l, "g": g},
        {M: 2.0, m: 1.0, l: 1.0, g: 9.81},
        {x: 0.0, th: 1.0},
        {x: 0.0, th: 0.0},
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
    )
    return Model(
        "rolling-disk",
        "Vertical disk rolling without slipping (non-holonomic)",
        system,
        {"x": x, "y": y, "phi": ph, "theta": th, "m": m, "R": R},
        {m: 1.0, R: 0.5},
        {x: 0.0, y: 0.0, ph: 0.0, th: 0.0},
        {ph: 0.8, th: 4.0},
    )


def heavy_symmetric_top() -> Model:
    """Heavy symmetric top on a fixed tip in z-x-z Euler angles (ψ, θ, φ):
    ``L = ½ A (θ̇² + ψ̇² sin² θ) + ½ C (φ̇ + ψ̇ cos θ)² − M g l cos θ`` (A, C about the tip)."""
    sp, ds = _sp()
    psi, th, ph = ds("psi theta phi")
    A, C, M, g, l = sp.symbols("A C M g l", positive=True)
    L = (
        A * (th.diff() ** 2 + psi.diff() ** 2 * sp.sin(th) ** 2) / 2
        + C * (ph.diff() + psi.diff() * sp.cos(th)) ** 2 / 2
        - M * g * l * sp.cos(th)
    )
    from .lagrange import LagrangianSystem

    # a cylinder of mass 1, radius 0.3, height 0.2, tip 0.5 below its centre of mass
    A_val = 1.0 * (3 * 0.3**2 + 0.2**2) / 12 + 1.0 * 0.5**2
    C_val = 0.5 * 1.0 * 0.3**2
    return Model(
        "heavy-top-euler",
        "Heavy symmetric top in Euler angles",
        LagrangianSystem([psi, th, ph], L),
        {"psi": psi, "theta": th, "phi": ph, "A": A, "C": C, "M": M, "g": g, "l": l},
        {A: A_val, C: C_val, M: 1.0, g: 9.81, l: 0.5},
        {psi: 0.0, th: 0.6, ph: 0.0},
        {psi: 0.0, th: 0.0, ph: 100.0},
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
    "heavy-top-euler": heavy_symmetric_top,
}
