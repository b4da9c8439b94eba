"""The reference oracle for the compiled Lagrangian engine: the same equations by an
independent route, SymPy's ``lambdify`` and NumPy's dense solve, integrated by SciPy's
``solve_ivp`` (no part of poinsot's engine, integrators or phase logic).

Each step solves the index-1 system

    [ M   −Gᵀ ] [ q̈ ]   [ f               ]
    [ G    0  ] [ λ  ] = [ −γ − stab(q, q̇) ]

with Baumgarte's stabilisation ``stab = 2α (G q̇ + b) + β² g`` (the position term on the
holonomic rows; Baumgarte 1972), or, with ``"projection"``, Gauss–Newton minimum-norm
corrections of ``g(q) = 0`` then ``q̇ ← q̇ − G⁺ (G q̇ + b)`` after each step. A one-sided
constraint lets go where its multiplier falls through zero (located by ``solve_ivp``'s event
search), and the run goes on with the released system (``LagrangianSystem.released``).

This was the library's second engine (``engine="numpy"``); the tests hold the compiled engine
to it.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

__all__ = ["Lambdified", "simulate"]


class Lambdified:
    """NumPy functions of ``(q, q̇, t)`` of one system under one parameter assignment."""

    def __init__(self, system, params: dict):
        self.system = system
        names = system.plain
        by_name = {str(p): p for p in system.parameters}
        values = {by_name.get(str(k), k): sp.Float(v) for k, v in params.items()}

        def lam(expr):
            entries = list(sp.Matrix(expr)) if hasattr(expr, "shape") else [expr]
            plain = [names.of(e).xreplace(values) for e in entries]
            return sp.lambdify((names.q, names.v, system.t), plain, modules="numpy", cse=True)

        self.n, self.m, self.n_hol = (system.n_coordinates, system.n_constraints,
                                      system.n_holonomic)  # fmt: skip
        self.M, self.f = lam(system.mass_matrix), lam(system.forcing)
        if self.m:
            self.G, self.b = lam(system.constraint_jacobian), lam(system.constraint_rhs)
            self.gamma = lam(system.constraint_gamma)
            self.g = lam(sp.Matrix(system.holonomic)) if self.n_hol else None
        self.energy = lam(system.energy_function)

    def mat(self, fn, q, qd, t, shape):
        return np.asarray(fn(q, qd, t), dtype=float).reshape(shape)

    def accelerations(self, t, q, qd, stab=None):
        """``(q̈, λ)``; ``stab`` (m,) is added to ``−γ``."""
        n, m = self.n, self.m
        M, f = self.mat(self.M, q, qd, t, (n, n)), self.mat(self.f, q, qd, t, (n,))
        if not m:
            return np.linalg.solve(M, f), np.zeros(0)
        G = self.mat(self.G, q, qd, t, (m, n))
        rhs2 = -self.mat(self.gamma, q, qd, t, (m,)) - (0.0 if stab is None else stab)
        K = np.block([[M, -G.T], [G, np.zeros((m, m))]])
        x = np.linalg.solve(K, np.concatenate([f, rhs2]))
        return x[:n], x[n:]

    def residuals(self, t, q, qd):
        """``(g(q, t) (n_hol,), G q̇ + b (m,))``."""
        if not self.m:
            return np.zeros(0), np.zeros(0)
        G = self.mat(self.G, q, qd, t, (self.m, self.n))
        vel = G @ qd + self.mat(self.b, q, qd, t, (self.m,))
        pos = self.mat(self.g, q, qd, t, (self.n_hol,)) if self.n_hol else np.zeros(0)
        return pos, vel

    def project(self, t, q, qd, tol=1e-13, max_iter=20):
        q = np.array(q, dtype=float)
        if self.n_hol:
            for _ in range(max_iter):
                g = self.mat(self.g, q, qd, t, (self.n_hol,))
                if np.max(np.abs(g)) <= tol * (1 + np.max(np.abs(q))):
                    break
                Gh = self.mat(self.G, q, qd, t, (self.m, self.n))[: self.n_hol]
                q = q - np.linalg.lstsq(Gh, g, rcond=None)[0]
        if self.m:
            G = self.mat(self.G, q, qd, t, (self.m, self.n))
            qd = qd - np.linalg.lstsq(G, G @ qd + self.mat(self.b, q, qd, t, (self.m,)),
                                      rcond=None)[0]  # fmt: skip
        return q, qd

    def rhs(self, stabilization, gains):
        """``ẏ(t, y)`` of ``y = [q, q̇]`` with the stabilisation's terms."""
        n, (alpha, beta) = self.n, gains

        def f(t, y):
            q, qd = y[:n], y[n:]
            stab = None
            if stabilization == "baumgarte" and self.m:
                pos, vel = self.residuals(t, q, qd)
                stab = 2 * alpha * vel
                stab[: len(pos)] += beta**2 * pos
            return np.concatenate([qd, self.accelerations(t, q, qd, stab)[0]])

        return f


def _rk4(f, t0, y0, t1, times, dt, project):
    """Classical RK4 with steps ``dt`` shortened to land on every sample (as poinsot's fixed
    step driver samples), projected after each step when ``project``."""
    out, t, y = [], t0, np.array(y0, float)
    for target in times:
        while t < target:
            h = min(dt, target - t)
            if target - (t + h) < 1e-9 * dt:
                h = target - t
            k1 = f(t, y)
            k2 = f(t + h / 2, y + h / 2 * k1)
            k3 = f(t + h / 2, y + h / 2 * k2)
            k4 = f(t + h, y + h * k3)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            t = target if h == target - t else t + h
            if project is not None:
                y = project(t, y)
        out.append(y.copy())
    return np.array(out)


def _phase(num, y0, t0, t1, times, method, dt, rtol, atol, stabilization, gains, watch):
    """One run from ``t0`` to ``t1`` (or the first release among ``watch``, constraint indices
    of ``num``'s system): samples at ``times`` and ``(t, k, y)`` of the release or None."""
    f = num.rhs(stabilization, gains)
    n = num.n
    project = None
    if stabilization == "projection" and num.m:

        def project(t, y):
            return np.concatenate(num.project(t, y[:n], y[n:]))

    events = []
    for k in watch:

        def release(t, y, k=k):
            return num.accelerations(t, y[:n], y[n:])[1][k]

        release.terminal, release.direction = True, -1
        events.append(release)
    if method == "rk4" and not events:
        return _rk4(f, t0, y0, t1, times, dt, project), None
    if method == "rk4":  # a release to locate: the exact motion, tightly, stands for RK4's
        rtol, atol = 1e-12, 1e-14
    sol = solve_ivp(f, (t0, t1), y0, method="DOP853", t_eval=times, rtol=rtol, atol=atol,
                    events=events or None, dense_output=bool(events))  # fmt: skip
    assert sol.status >= 0, sol.message
    hit = next((k for k, te in enumerate(sol.t_events or []) if len(te)), None)
    if hit is None:
        return sol.y.T, None
    tz = float(sol.t_events[hit][0])
    return sol.y.T[sol.t <= tz], (tz, watch[hit], sol.y_events[hit][0])


def simulate(model, t_span, *, t_eval, method="dop853", dt=None, rtol=1e-10, atol=1e-12,
             stabilization="baumgarte", baumgarte=(10.0, 10.0), params=None, q0=None):  # fmt: skip
    """A model's motion (``poinsot.models``: its system, initial state, parameters) by the
    oracle: ``t``, ``q``, ``qd``, ``multipliers``, ``energy``, ``constraint_residual`` (before
    any release) and ``releases`` ``[(t, constraint, y)]``. The initial state is completed
    and checked by the library's ``consistent_initial_state`` on the oracle's functions."""
    from poinsot.lagrange.arguments import _keyed, as_params, consistent_initial_state

    system = model.system
    params = as_params(dict(model.params if params is None else params), system)
    q = _keyed(model.q0 if q0 is None else q0, system, "q0", allow_missing=True)
    qd = _keyed(model.qd0, system, "qd0", allow_missing=True)
    guess = _keyed(model.guess, system, "guess", allow_missing=True) if model.guess else None
    q, qd = consistent_initial_state(system, Lambdified(system, params), t_span[0], q, qd, guess)
    y = np.concatenate([q, qd])
    times = np.asarray(t_eval, float)
    t0, t1 = t_span
    active, rows, releases, parts = system, list(range(system.n_holonomic)), [], []
    while True:
        num = Lambdified(active, params)
        at = times[(times >= t0) & (times <= t1)]
        ys, hit = _phase(num, y, t0, t1, at, method, dt, rtol, atol, stabilization, baumgarte,
                         list(active.unilateral))  # fmt: skip
        parts.append(ys)
        if hit is None:
            break
        t0, k, y = hit
        releases.append((t0, str(active.holonomic[k]), y.copy()))
        active, _ = active.released(k), rows.pop(k)
        times = times[times > t0]
    Y = np.vstack(parts)
    n = system.n_coordinates
    first = Lambdified(system, params)
    T = np.asarray(t_eval, float)[: len(Y)]
    lam = np.array([first.accelerations(t, y[:n], y[n:])[1] for t, y in zip(T, Y, strict=True)])
    res = np.array([first.residuals(t, y[:n], y[n:])[0] for t, y in zip(T, Y, strict=True)])
    energy = np.array([float(first.mat(first.energy, y[:n], y[n:], t, ()))
                       for t, y in zip(T, Y, strict=True)])  # fmt: skip
    return SimpleNamespace(t=T, q=Y[:, :n], qd=Y[:, n:], multipliers=lam.reshape(len(T), -1),
                           energy=energy, constraint_residual=res.reshape(len(T), -1),
                           releases=releases)  # fmt: skip
