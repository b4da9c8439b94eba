"""Equilibria of a Lagrangian system and its linearisation about them.

Equilibria solve ``f(q, 0, t0) + Gᵀ λ = 0`` (all constraints, non-holonomic included) and
``g(q, t0) = 0`` (q̇ = 0) by Newton's method or least squares from many starting points; the
linearisation is the Jacobian of the first-order equations of motion at an equilibrium or a
steady motion, exact (the KKT system differentiated on the model's compiled Jacobian along
the state, the parameters and the inputs, ``poinsot._core.LagrangianTangent.rates_jacobian``),
restricted to the tangent space of the constraint manifold (null space of the constraint
Jacobian).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Equilibrium", "Linearization", "equilibria", "linearize", "operating_point"]


@dataclass(frozen=True)
class Linearization:
    """A linearisation about an equilibrium or a steady motion.

    The verdict is checked on the nonlinear motion by :meth:`floquet`: the monodromy matrix
    of the run from the operating point over a period, from its sensitivities.

    Attributes
    ----------
    equilibrium : dict {coordinate: value}
        The operating point's coordinates (``speeds`` its velocities, zero at rest).
    matrix : ndarray (d, d)
        ``A``: the linear map of the first-order system ``δẋ = A δx + B δu`` on the tangent
        space of the constraint manifold (d = 2n − m_holonomic − m).
    eigenvalues : ndarray (d,) complex
    frequencies : ndarray
        Natural frequencies in rad/s: the distinct positive imaginary parts of the eigenvalues.
    stable : bool
        True when :attr:`verdict` is ``"spectrally stable"``.
    speeds : dict {coordinate: value}
        The operating point's velocities.
    input_matrix : ndarray (d, k)
        ``B``, one column per input of ``system.inputs`` (k = 0 without inputs).
    verdict : str
        ``"unstable"`` (an eigenvalue with positive real part), ``"secular growth"`` (no such
        eigenvalue, but a zero eigenvalue whose Jordan block grows linearly in time: a free
        cart drifting, a skate turning), or ``"spectrally stable"`` (every eigenvalue on or
        left of the imaginary axis, the zero ones semisimple). Spectral stability is what the
        linearisation can tell; nonlinear terms decide centres.
    ignorable : tuple
        Coordinates the equations do not depend on at this point (cyclic: the azimuth of a
        conical pendulum, the position of a free cart).
    reduced_verdict : str
        The verdict with the ignorable coordinates' positions left out: their drift (a phase,
        a translation) is neutral, so this is the stability of the steady motion itself.
    """

    equilibrium: dict
    matrix: np.ndarray
    eigenvalues: np.ndarray
    frequencies: np.ndarray
    stable: bool
    speeds: dict = field(default_factory=dict)
    input_matrix: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    verdict: str = ""
    ignorable: tuple = ()
    reduced_verdict: str = ""
    # what floquet() runs: the system, its parameters, the inputs' values, the time, and
    # whether it has constraints
    _run: tuple = field(default=(), repr=False, compare=False)

    def floquet(self, period=None, *, rtol=1e-12, atol=1e-14):
        """The :class:`~poinsot.sensitivity.Floquet` picture of the motion from the operating
        point over ``period`` (default: one turn of its fastest coordinate, ``2π/max|q̇|``; at
        an equilibrium, where every time is a period, give one): the monodromy matrix
        ``M = ∂(q, q̇)(T)/∂(q0, q̇0)`` from the forward sensitivities of a DOP853 run at
        ``rtol``, ``atol`` (the KKT system differentiated on the model's compiled Jacobian).

        ``A`` is constant at a steady motion, so its multipliers are ``exp(λ T)`` for the
        eigenvalues λ of :attr:`matrix`: the nonlinear run checks the linearisation. An
        unstable steady motion has a multiplier outside the unit circle, whose exponent is the
        largest real part of λ; an ignorable coordinate's drift is a multiplier 1 in a Jordan
        block.

        With constraints the monodromy is formed on the constraint manifold, in a chart of
        independent coordinates and velocities at the operating point: the columns of the
        constraint Jacobian ``G`` left after QR with column pivoting picks the best-conditioned
        dependent ones (the holonomic rows for the coordinates, all rows for the velocities).
        The run gives only the independent ones (the others are solved from the constraints),
        so its sensitivities are those of the motion on the manifold, and ``M`` is their rows
        for the same coordinates and velocities: ``d = 2n − m_holonomic − m`` multipliers, as
        :attr:`matrix` has eigenvalues. A multiplier does not depend on the chart.

        Examples
        --------
        >>> from poinsot.models import pendulum_polar
        >>> mdl = pendulum_polar()
        >>> th = mdl.system.coordinates[0]
        >>> lin = mdl.system.linearize({th: math.pi}, params=mdl.params)  # inverted
        >>> f = lin.floquet(period=1.0)
        >>> round(float(f.exponents[0]), 6), round(float(lin.eigenvalues.real.max()), 6)
        (3.132092, 3.132092)
        """
        from .._validation import as_scalar
        from ..sensitivity import Floquet, check_returned

        system, params, inputs, t, constrained = self._run
        q0 = np.array(list(self.equilibrium.values()), dtype=float)
        v0 = np.array(list(self.speeds.values()), dtype=float)
        if period is None:
            fastest = float(np.abs(v0).max()) if v0.size else 0.0
            if fastest == 0:
                raise ValueError("`period`: at an equilibrium every time is a period; give one")
            period = 2 * math.pi / fastest
        period = as_scalar(period, "period")
        if not (math.isfinite(period) and period > 0):
            raise ValueError(f"`period` must be a positive finite time, found {period}")
        n = len(q0)
        free_q, free_v = np.ones(n, bool), np.ones(n, bool)
        if constrained:
            free_q, free_v = _chart(system, params, q0, v0, t)
        coords = system.coordinates
        sol = system.simulate(
            (t, t + period), params=params, inputs=inputs, method="dop853", rtol=rtol,
            atol=atol, t_eval=[t, t + period], sensitivities=("q0", "qd0"),
            q0={c: x for c, x, f in zip(coords, q0, free_q, strict=True) if f},
            qd0={c: x for c, x, f in zip(coords, v0, free_v, strict=True) if f},
            guess={c: x for c, x, f in zip(coords, q0, free_q, strict=True) if not f} or None,
        )  # fmt: skip
        # a steady motion returns to its start, its ignorable coordinates moved on uniformly
        moved = np.concatenate([q0 + v0 * period, v0])
        scale = max(float(np.abs(moved).max()), float(np.abs(np.r_[q0, v0]).max()), 1e-300)
        check_returned(np.concatenate([sol.q[-1], sol.qd[-1]]), moved, scale, period,
                       "the state (q, q̇)",
                       "; a shorter one keeps the run by the steady motion")  # fmt: skip
        rows = np.concatenate([np.flatnonzero(free_q), n + np.flatnonzero(free_v)])
        return Floquet.of(sol.sensitivity("state")[-1][rows], period, "dop853")


def _chart(system, params, q0, v0, t):
    """The independent coordinates and velocities (bool (n,) each) of a chart of the
    constraint manifold at ``(q0, v0)``: the columns QR with column pivoting does not pick
    as dependent, from the holonomic rows of the constraint Jacobian for the coordinates and
    from all its rows for the velocities."""
    from scipy.linalg import qr

    num = _numeric(system, params)
    n, m, nh = system.n_coordinates, num.m, num.n_hol
    G = num.mat(num.G, q0, v0, t, (m, n))

    def independent(rows):
        free = np.ones(n, bool)
        if rows.shape[0]:
            _, r, piv = qr(rows, pivoting=True)
            d = np.abs(np.diag(r))
            rank = int(np.sum(d > 1e-10 * max(1.0, d.max())))
            free[piv[:rank]] = False
        return free

    return independent(G[:nh]), independent(G)


def _verdict(A, eig, scale):
    """Classify the spectrum of ``A`` (see :attr:`Linearization.verdict`)."""
    if np.any(eig.real > 1e-6 * scale):
        return "unstable"
    zero = np.abs(eig) <= 1e-7 * scale
    k = int(zero.sum())
    if k:
        # geometric multiplicity of 0: dimension of the null space of A
        s = np.linalg.svd(A, compute_uv=False)
        nullity = int(np.sum(s <= 1e-7 * scale))
        if nullity < k:
            return "secular growth"
    return "spectrally stable"


def _numeric(system, params):
    """The system's compiled model with these parameters (the core evaluates it)."""
    from .arguments import as_params
    from .engine import compile_system
    from .numeric import _EngineNumeric

    return _EngineNumeric(system, as_params(params, system), compile_system(system))


class Equilibrium(dict):
    """An equilibrium ``{coordinate: value}`` (a dict), with what holds it there.

    Attributes
    ----------
    reactions : dict {str: float}
        The multiplier of each constraint (holonomic and non-holonomic, by its expression),
        sign of eq. (6.60): ``Σ_k λ_k G_kj`` is the generalized reaction that balances the
        applied forces. A non-holonomic constraint can hold a system at rest (the knife edge
        across a slope).
    free : tuple
        Coordinates on which nothing depends: the equilibrium holds at any value of them (the
        value given is where the search started).
    """

    reactions: dict
    free: tuple


def equilibria(system, params=None, *, bounds=None, starts=None, t=0.0, tol=1e-10, inputs=None):
    """Equilibria of ``system``: a list of :class:`Equilibrium` (duplicates removed).

    At rest the applied forces must be balanced by the reactions of *all* constraints,
    holonomic and non-holonomic: ``f(q, 0) + Gᵀ λ = 0`` with ``g(q) = 0``; the non-holonomic
    multipliers are unknowns too, so such a system may rest where a holonomic one could not.

    Parameters
    ----------
    bounds : dict {coordinate: (low, high)}, optional
        Where to start the Newton iterations (default ``(−π, π)`` for every coordinate);
        solutions outside the box are kept too.
    starts : int, optional
        Starting points per coordinate (default 13 for one coordinate, 7 for two, else 150
        random points in the box).
    inputs : dict {input: number}, optional
        Constant values of the system's inputs.
    """
    from .._validation import as_scalar
    from .arguments import input_function

    t = as_scalar(t, "t")
    tol = as_scalar(tol, "tol")
    whole = isinstance(starts, int | np.integer) and not isinstance(starts, bool)
    if starts is not None and not (whole and starts >= 1):
        raise ValueError(f"`starts` must be a positive integer, found {starts!r}")

    num = _numeric(system, params)
    u_of = input_function(inputs, system)
    if u_of is not None:
        num = num.bound(u_of)
    n, nh, m = system.n_coordinates, system.n_holonomic, system.n_constraints
    zeros = np.zeros(n)
    lo, hi = _search_box(system, bounds)

    def parts(q):
        f = num.mat(num.f, q, zeros, t, (n,))
        G = num.mat(num.G, q, zeros, t, (m, n)) if m else np.zeros((0, n))
        g = num.mat(num.g, q, zeros, t, (nh,)) if nh else np.zeros(0)
        return f, G, g

    def residual(x):
        q, lam = x[:n], x[n:]
        f, G, g = parts(q)
        return np.concatenate([f + G.T @ lam, g])

    rng = np.random.default_rng(1)
    free = _free_coordinates(parts, rng.uniform(lo, hi))
    solve = [j for j in range(n) if j not in free]
    if n <= 2:
        k = starts or (13 if n == 1 else 7)
        grid = [np.linspace(lo[i], hi[i], k) for i in range(n)]
        points = [np.array(p) for p in itertools.product(*grid)]
    else:
        points = list(rng.uniform(lo, hi, size=(starts or 150, n)))
    found = []
    for p in points:
        p = p.copy()
        p[free] = np.clip(0.0, lo[free], hi[free])
        solution = _rest_from(p, residual, solve, m, square=len(solve) + m == n - len(free) + nh,
                              tol=tol)  # fmt: skip
        if solution is None:
            continue
        q, lam = solution
        if not any(np.max(np.abs(q - f[0])) < 1e-7 * (1 + np.max(np.abs(q))) for f in found):
            found.append((q, lam))
    found.sort(key=lambda ql: tuple(np.round(ql[0], 9)))
    from sympy.physics.vector.printing import vsprint  # q̇ printed as q'

    names = [vsprint(g) for g in [*system.holonomic, *system.nonholonomic]]
    out = []
    for q, lam in found:
        eq = Equilibrium(zip(system.coordinates, map(float, q), strict=True))
        eq.reactions = dict(zip(names, map(float, lam), strict=True))
        eq.free = tuple(system.coordinates[j] for j in free)
        out.append(eq)
    return out


def _search_box(system, bounds):
    """The box ``(lo, hi)`` the Newton iterations start in: ``bounds`` checked, ``(−π, π)``
    for the coordinates it does not name."""
    from .._validation import as_scalar

    n = system.n_coordinates
    lo = np.full(n, -np.pi)
    hi = np.full(n, np.pi)
    if bounds is not None and not isinstance(bounds, dict):
        raise TypeError(f"`bounds` must be a dict {{coordinate: (low, high)}}, found "
                        f"{type(bounds).__name__}")  # fmt: skip
    for q, box in (bounds or {}).items():
        if q not in system.coordinates:
            raise ValueError(f"`bounds`: {q!r} is not a coordinate of the system")
        if isinstance(box, str | bytes) or not hasattr(box, "__len__") or len(box) != 2:
            raise ValueError(f"`bounds[{q}]` must be a pair (low, high), found {box!r}")
        a, b = as_scalar(box[0], f"bounds[{q}][0]"), as_scalar(box[1], f"bounds[{q}][1]")
        if not a < b:
            raise ValueError(f"`bounds[{q}]` must have low < high, found ({a}, {b})")
        lo[system.coordinates.index(q)], hi[system.coordinates.index(q)] = a, b
    return lo, hi


def _free_coordinates(parts, probe):
    """The coordinates nothing depends on (a position on a plane, a heading): ``parts`` (f, G
    and g at rest) unchanged when one moves from ``probe``; held where they start."""
    base = np.concatenate([c.ravel() for c in parts(probe)])
    free = []
    for j in range(len(probe)):
        shifted = probe.copy()
        shifted[j] += 0.37
        if np.allclose(np.concatenate([c.ravel() for c in parts(shifted)]), base, atol=1e-12):
            free.append(j)
    return free


def _rest_from(p, residual, solve, m, *, square, tol):
    """Solve for the coordinates ``solve`` and the ``m`` multipliers from the start ``p`` (Newton
    when the system is ``square``, else least squares): ``(q, λ)``, or None when it fails."""
    from scipy.optimize import least_squares, root

    def reduced(z):
        q = p.copy()
        q[solve] = z[: len(solve)]
        return residual(np.concatenate([q, z[len(solve) :]]))

    z0 = np.concatenate([p[solve], np.zeros(m)])
    with np.errstate(all="ignore"):
        if square:  # square: Newton
            z = root(reduced, z0, method="hybr", tol=1e-14).x
        else:  # more multipliers than holonomic rows: least squares
            z = least_squares(reduced, z0, xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    if not np.all(np.isfinite(z)):
        return None
    r = reduced(z)
    if np.max(np.abs(r)) > tol * (1 + np.max(np.abs(z))):
        return None
    q = p.copy()
    q[solve] = z[: len(solve)]
    return q, z[len(solve) :]


def _null_space(A, n):
    if A.shape[0] == 0:
        return np.eye(n)
    _, s, vt = np.linalg.svd(A)
    rank = int(np.sum(s > 1e-10 * max(1.0, s.max())))
    return vt[rank:].T


def linearize(system, equilibrium, params=None, *, speeds=None, inputs=None, t=0.0):
    """Linearise about an equilibrium or a steady motion.

    Parameters
    ----------
    equilibrium : dict {coordinate: value}
        The operating point: every coordinate (by coordinate or by name, ``{"x": 0.0}``, as
        ``simulate`` reads ``q0``), and optionally velocities keyed by the speeds
        ``q.diff(t)`` (``Derivative(q, t)``, the entries of ``system.speeds``), as one
        operating-point dict for SymPy's ``Linearizer.linearize(op_point=...)`` holds both.
        A key that is neither a coordinate nor a speed is refused, named (see
        :func:`operating_point`). The point must satisfy the constraints as an initial state
        must (``simulate``'s rule and tolerance): coordinates off the holonomic constraints,
        or velocities off the velocity constraints, are refused with the violation.
    speeds : dict {coordinate: value}, optional
        Its velocities, by coordinate, name or speed, the same as velocities in
        ``equilibrium`` (default zero: an equilibrium; a velocity not given is zero, not
        solved from the constraints); a velocity given both ways must agree.
        With speeds the point must be a steady motion: the accelerations vanish there (a
        spinning top's steady precession, a disk rolling upright).
    inputs : dict {input: number}, optional
        The inputs' values at the operating point (every input of ``system.inputs``).

    Returns
    -------
    Linearization
        ``A`` (:attr:`~Linearization.matrix`) and ``B`` (:attr:`~Linearization.input_matrix`)
        of ``δẋ = A δx + B δu`` on the constraint manifold, with eigenvalues, frequencies and
        the stability verdict: both exact (the KKT system differentiated on the model's
        compiled Jacobian along the state and the inputs).
    """
    from .._validation import as_scalar
    from .arguments import input_function, refuse_off_constraints
    from .engine import compile_tangent

    t = as_scalar(t, "t")
    q0, given_v, origin = _operating_point(system, equilibrium, speeds)
    v0 = np.nan_to_num(given_v, nan=0.0)
    num = _numeric(system, params)
    n, m, nh = system.n_coordinates, num.m, num.n_hol
    k = len(system.inputs)
    u_of = input_function(inputs, system)
    u0 = u_of(t, q0, v0) if u_of is not None else np.zeros(0)
    # the inputs held at their values at the operating point (B is their matrix)
    num = num.bound((lambda tt, qq, vv: u0) if k else None)
    # on the constraints, by the rule and tolerance of an initial state: elsewhere the
    # linearisation would be another system's
    zero = [str(c) for c, v in zip(system.coordinates, given_v, strict=True) if np.isnan(v)]
    note = (f" (velocities not given are zero: {', '.join(zero)}; give the values the "
            "constraints require)" if zero else "")  # fmt: skip
    velocities = "equilibrium" if "equilibrium" in origin and "speeds" not in origin else "speeds"
    refuse_off_constraints(num, t, q0, v0, names=("equilibrium", velocities),
                           point="operating point", at="", notes=("", note))  # fmt: skip
    y0 = np.concatenate([q0, v0])
    unsolvable = ValueError(
        "`equilibrium`, `params`: the equations of motion cannot be solved at the operating "
        "point (a singular mass matrix: zero masses, lengths or inertia?)"
    )
    try:
        with np.errstate(all="ignore"):
            f0 = np.concatenate([v0, num.accelerations(t, q0, v0)[0]])
    except np.linalg.LinAlgError:
        raise unsolvable from None
    if not np.isfinite(f0).all():
        raise unsolvable
    what = "a steady motion" if np.any(v0) else "an equilibrium"
    if np.max(np.abs(f0[n:])) > 1e-8 * (1 + np.max(np.abs(f0))):
        raise ValueError(
            f"`equilibrium`: the operating point is not {what}: accelerations "
            f"{np.round(f0[n:], 10).tolist()}"
        )
    # ∂ẏ/∂y and ∂ẏ/∂u exactly: the differentiated KKT system on the model's compiled Jacobian
    tangent = compile_tangent(system)
    try:
        J, _, Bfull = tangent.rates_jacobian(t, y0, num.engine.parameter_vector(num.params), u0)
    except ValueError:
        raise unsolvable from None
    if not (np.isfinite(J).all() and np.isfinite(Bfull).all()):
        raise ValueError(
            "`equilibrium`, `params`: the linearisation is not finite at the operating point "
            "(values beyond the double range: choose other units)"
        )
    G = num.mat(num.G, q0, v0, t, (m, n)) if m else np.zeros((0, n))
    A, B = _on_manifold(J, Bfull, G, nh, np.arange(n))
    eig = np.linalg.eigvals(A)
    scale = max(1.0, float(np.abs(eig).max()), float(np.abs(A).max()))
    freqs = np.unique(np.round(eig.imag[eig.imag > 1e-9 * scale], 10))
    verdict = _verdict(A, eig, scale)
    jscale = max(1.0, float(np.abs(J).max()))
    ignorable = [j for j in range(n) if np.abs(J[:, j]).max() <= 1e-9 * jscale
                 and not np.any(G[:nh, j])]  # fmt: skip
    reduced = verdict
    if ignorable:
        keep = np.array([j for j in range(n) if j not in ignorable], dtype=int)
        rows = np.concatenate([keep, np.arange(n, 2 * n)])
        Ar, _ = _on_manifold(J[np.ix_(rows, rows)], Bfull[rows], G, nh, keep)
        reduced = _verdict(Ar, np.linalg.eigvals(Ar), scale) if Ar.size else "spectrally stable"
    return Linearization(
        {q: float(x) for q, x in zip(system.coordinates, q0, strict=True)},
        A,
        eig,
        freqs,
        verdict == "spectrally stable",
        {q: float(v) for q, v in zip(system.coordinates, v0, strict=True)},
        B,
        verdict,
        tuple(system.coordinates[j] for j in ignorable),
        reduced,
        (system, num.params, inputs, t, m > 0),
    )


def operating_point(system, equilibrium, speeds=None):
    """``(q, q̇)`` arrays (n,) of an operating point: ``equilibrium`` keyed by coordinates
    (all of them, by coordinate or by name) and optionally by speeds ``q.diff(t)``; ``speeds``
    keyed by coordinates, their names or speeds (missing velocities are zero). Unknown keys,
    non-numbers and a velocity given twice with two values are refused, named.

    Examples
    --------
    >>> from poinsot.models import pendulum_polar
    >>> system = pendulum_polar().system
    >>> th = system.coordinates[0]
    >>> operating_point(system, {th: 0.5, th.diff(): 2.0})
    (array([0.5]), array([2.]))
    >>> operating_point(system, {th: 0.5, "omega": 2.0})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: `equilibrium`: 'omega' is neither a coordinate of the system nor a speed (...)
    """
    q0, v0, _ = _operating_point(system, equilibrium, speeds)
    return q0, np.nan_to_num(v0, nan=0.0)


def _operating_point(system, equilibrium, speeds):
    """:func:`operating_point` with the velocities not given NaN, and where each velocity was
    given (``"equilibrium"``, ``"speeds"`` or ``""``)."""
    from collections.abc import Mapping

    from .._validation import as_scalar
    from .arguments import key_index, named

    n = system.n_coordinates
    coords = key_index(system.coordinates)  # by coordinate or by name, as simulate reads q0
    rates = {v: i for i, v in enumerate(system.speeds)}  # hashing: no SymPy comparison
    known = (f"coordinates: {', '.join(map(str, system.coordinates))} (by name "
             f"{named(coords.names)}); speeds: {', '.join(map(str, system.speeds))}")  # fmt: skip
    q0, v0 = np.full(n, np.nan), np.full(n, np.nan)
    origin = [""] * n  # where each velocity was given

    def velocity(i, value, label):
        x = as_scalar(value, label)
        if not np.isnan(v0[i]) and v0[i] != x:
            raise ValueError(f"the velocity of {system.coordinates[i]} is given twice with two "
                             f"values: `{origin[i]}` = {v0[i]} and `{label}` = {x}")  # fmt: skip
        v0[i], origin[i] = x, label

    for name, given in (("equilibrium", equilibrium), ("speeds", speeds)):
        if given is None and name == "speeds":
            continue
        if not isinstance(given, Mapping):
            raise TypeError(f"`{name}` must be a dict {{coordinate: value}}, found "
                            f"{type(given).__name__}")  # fmt: skip
        for key, value in given.items():
            try:
                j = None if isinstance(key, str) else rates.get(key)
            except TypeError:  # unhashable: neither
                j = None
            i = coords(key)
            if j is not None:
                velocity(j, value, f"{name}[{key}]")
            elif i is not None and name == "speeds":
                velocity(i, value, f"{name}[{key}]")
            elif i is not None:
                q0[i] = as_scalar(value, f"{name}[{key}]")
            else:
                raise ValueError(f"`{name}`: {key!r} is neither a coordinate of the system nor "
                                 f"a speed ({known})")  # fmt: skip
    missing = [str(system.coordinates[i]) for i in np.flatnonzero(np.isnan(q0))]
    if missing:
        raise ValueError(f"`equilibrium` must give every coordinate: missing {', '.join(missing)}")
    return q0, v0, [label.split("[")[0] for label in origin]


def _on_manifold(J, B, G, nh, positions):
    """``(A, B)`` restricted to the tangent space of the constraints: positions along the null
    space of the holonomic rows of ``G`` (columns ``positions``), velocities along that of
    all of ``G``."""
    n = G.shape[1]
    Nq = _null_space(G[:nh][:, positions], len(positions))
    Nv = _null_space(G, n)
    T = np.zeros((len(positions) + n, Nq.shape[1] + Nv.shape[1]))
    T[: len(positions), : Nq.shape[1]] = Nq
    T[len(positions) :, Nq.shape[1] :] = Nv
    Tp = np.linalg.pinv(T)
    return Tp @ J @ T, Tp @ B
