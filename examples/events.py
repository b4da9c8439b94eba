"""Events and one-sided constraints, in the manner of ``solve_ivp``'s ``events=``.

1. A tennis racket spun near its intermediate axis flips: an event on ω₂ (falling through
   zero) finds every flip, and the time between them is the exact ``2K(m)/λ`` of the
   torque-free solution.
2. A sliding ladder leaves the wall when the wall's reaction vanishes, at cos θ = ⅔ cos θ0: a
   one-sided constraint (``unilateral=``), released by the run.

Run: ``python examples/events.py``.
"""

from __future__ import annotations

import numpy as np

from poinsot import RigidBody, models, simulate
from poinsot.torquefree import FreeRigidBody


def flips():
    racket = RigidBody(0.35, np.diag([0.00121, 0.01638, 0.01748]))  # kg, kg·m²
    w0 = (0.01, 2 * np.pi, 0.01)

    def omega2(t, y):
        return y[16]  # the flat state is [R, V, Q (row-major), ω]: ω₂ is y[16]

    omega2.direction = -1  # a flip starts when ω₂ falls through zero
    traj = simulate(racket, (0, 30), omega0=w0, rtol=1e-11, atol=1e-13, events=omega2)
    measured = np.diff(traj.t_events[0])
    exact = FreeRigidBody.from_body(racket).flip_interval(w0)
    print(f"flips at t = {np.round(traj.t_events[0], 4)} s")
    print(
        f"between two ω₂ zero crossings of one sign: {measured.mean():.6f} s; "
        f"exact period 2·(2K(m)/λ) = {2 * exact:.6f} s"
    )
    return measured, exact


def ladder():
    mdl = models.sliding_ladder()
    th = mdl.symbols["theta"]
    theta0 = 0.3
    sol = mdl.simulate((0, 0.85), q0={th: theta0}, t_eval=np.linspace(0, 0.85, 86))
    ((t_release, constraint, state),) = sol.releases
    print(
        f"the wall ({constraint} ≥ 0) lets go at t = {t_release:.6f} s: cos θ = "
        f"{np.cos(state[2]):.9f}, ⅔ cos θ0 = {2 / 3 * np.cos(theta0):.9f}"
    )
    return sol


def main():
    return {"flips": flips(), "ladder": ladder()}


if __name__ == "__main__":
    main()
