"""The source notebook ("Movimiento de un cuerpo rígido"), reproduced with poinsot, in order.

Every computation of the notebook, in English, with the errata of docs/theory.md corrected (each one
noted where it matters), and the 3D figures the notebook could not render. Run it with

    python examples/notebook.py [OUTPUT_DIR]

It writes its figures to OUTPUT_DIR (default ``./notebook-figures``) and prints the numbers.
``tests/test_examples.py`` runs it as a smoke test and checks the numbers.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import numpy as np

from poinsot import Gravity, RigidBody, simulate
from poinsot.torquefree import FreeRigidBody


def section(title):
    print(f"\n== {title} ==")


def worked_example():
    """§1: three unit masses at (0,0,0), (1,0,0), (0,1,0)."""
    section("Worked example: three unit masses")
    body = RigidBody.from_particles([1, 1, 1], [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    print("centre of mass R =", body.center_of_mass)
    print("offsets u_i =\n", body.u)
    print("inertia A (eq. 13) =\n", body.inertia)
    print("principal moments I =", body.principal_moments)
    print("principal axes (columns e1, e2, e3) =\n", body.principal_axes)
    print("(erratum: the notebook prints e3 = (0,0,1)/√2; the unit vector is (0,0,1))")
    return body


def reference_body():
    """The notebook's 27-particle body: a 3×3×3 grid (a, b, c) = (1, 2, 3), total mass 10."""
    from poinsot.models import notebook_body

    return notebook_body()


def gravity_run(body, out):
    """The notebook's simulation: gravity on every particle, ω(0) = (0, 1, 1), classical RK4."""
    section("27 particles under gravity, RK4, t ∈ [0, 20]")
    print("principal moments:", body.principal_moments, "(25/3, 50/3, 65/3)")
    t = np.linspace(0, 20, 101)
    traj = simulate(
        body,
        (0, 20),
        omega0=(0, 1, 1),
        forces=[Gravity((0, 0, -9.8))],
        method="rk4",
        dt=0.2,
        t_eval=t,
    )
    print("fall of the centre of mass at t = 20:", traj.R[-1] - traj.R[0], "(−½ g t² = −1960)")
    d = traj.diagnostics()
    print(
        "RK4 drift reported: |QᵀQ − I| ≤ {:.2e}, energy {:.2e}".format(
            d["orthogonality_error"], d["energy_drift"]
        )
    )
    free = FreeRigidBody.from_body(body)
    exact = free.exact_omega((0, 1, 1), t)
    err = np.abs(traj.omega - exact).max()
    print(f"max |ω_RK4 − ω_exact| = {err:.2e} (gravity exerts no torque about the centre of mass)")
    from poinsot.viz import plot_omega

    fig = plot_omega(t, traj.omega, exact=exact)
    fig.axes[0].set_title("ω(t), RK4 with dt = 0.2 (solid) and the exact solution (dashed)")
    fig.savefig(out / "omega_gravity.png", dpi=110)
    return traj


def torque_free_theory(body):
    """Euler's equation: fixed points, stability, conservation laws (30)–(33)."""
    section("Torque-free body: Euler's equation")
    free = FreeRigidBody.from_body(body)
    for fp in free.fixed_points():
        print(f"fixed points: {fp.label:22s} stable = {fp.stable}")
    I1, _I2, I3 = free.principal_moments
    w = np.array([0.0, 1.0, 0.0])
    s = free.stability(free._from_sorted(w))
    print(
        "intermediate axis, |ω| = 1: eigenvalues",
        np.round(s.eigenvalues, 6),
        " growth rate σ =",
        round(s.growth_rate, 6),
    )
    w0 = np.array([0.3, 0.2, 0.1])
    k, a = free.invariants(w0)
    print(f"ω0 = {w0}: 2k = Σ I ω² = {2 * k:.6g} (30), a² = Σ I² ω² = {a * a:.6g} (31)")
    print("(erratum: the second law multiplies by I_i² ω_i, not I2² ω_i)")
    print(f"I1 = {I1:.4g} ≤ a²/2k = {a * a / (2 * k):.4g} ≤ I3 = {I3:.4g}  (33)")
    print("cone coefficients b_i = I_i(a²/2k − I_i) (32):", free.cone_coefficients(k, a))
    return free


def cone_figures(free, out):
    """The notebook's cone figures: (a) the 27-particle body, (b) two equal moments,
    (c) all equal moments."""
    from poinsot.viz import plot_energy_ellipsoid

    section("Energy ellipsoid ∩ cone (32)")
    k, a = 2.0, 4.0
    try:
        free.check_feasible(k, a)
    except ValueError as exc:
        print("notebook's k = 2, a = 4:", exc)
        print(
            "(erratum: its code computes a^2/2*k = a²k/2 = 16 instead of a²/(2k) = 4, which is",
            "why its picture looked feasible; we draw its intended a²/2k = 16, i.e. a = 8)",
        )
    fig = plot_energy_ellipsoid(free, 2.0, math.sqrt(2 * 2.0 * 16.0))
    fig.savefig(out / "cone_reference_body.png", dpi=110)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (3, 3, 9) breaks I1 + I2 ≥ I3: noted below
        sym = FreeRigidBody((3.0, 3.0, 9.0), allow_unphysical=True)
    print(
        "note: the notebook's moments (3, 3, 9) break I1 + I2 ≥ I3 — no mass distribution has",
        "them; Euler's equation is still well posed, so we follow the notebook",
    )
    k = 0.5
    fig = plot_energy_ellipsoid(sym, k, math.sqrt(2 * k * 3.0))
    fig.savefig(out / "cone_two_equal_plane.png", dpi=110)
    print("two equal moments, a²/2k = I1 = 3: the cone is the plane ω3 = 0, the polhode a circle")
    fig = plot_energy_ellipsoid(sym, k, 2.0)
    fig.savefig(out / "cone_two_equal.png", dpi=110)
    print("two equal moments, a = 2: a²/2k = 4, two circles")
    sphere = FreeRigidBody((1.0, 1.0, 1.0))
    fig = plot_energy_ellipsoid(sphere, k, math.sqrt(2 * k * 1.0))
    fig.savefig(out / "cone_all_equal.png", dpi=110)
    print("all moments equal: every ω is a fixed point; the ellipsoid is a sphere")


def polhode_sweep(body, free, out, n_grid=3):
    """The notebook's sweep: initial ω on the energy ellipsoid k = ½, integrated on [0, 40]
    with RK4 (100 output points), against the exact polhodes."""
    from poinsot.viz import plot_polhode_family

    section("Polhode sweep on the energy ellipsoid k = 1/2")
    k = 0.5
    fig = plot_polhode_family(free, k)
    ax = fig.axes[0]
    I = body.principal_moments
    E = body.principal_axes
    x1 = math.sqrt(2 * k / I[0])
    worst = 0.0
    t = np.linspace(0, 40, 101)
    for om1 in np.linspace(-x1, x1, n_grid + 2)[1:-1]:
        x2 = math.sqrt((2 * k - I[0] * om1**2) / I[1])
        for om2 in np.linspace(-x2, x2, n_grid + 2)[1:-1]:
            om3 = math.sqrt(max(2 * k - I[0] * om1**2 - I[1] * om2**2, 0) / I[2])
            w0 = E @ np.array([om1, om2, om3])  # principal components → body frame
            traj = simulate(body, (0, 40), omega0=w0, method="rk4", dt=0.4, t_eval=t)
            ax.plot(*traj.omega.T, ".", ms=2, color="0.25")
            worst = max(worst, np.abs(traj.omega - free.exact_omega(w0, t)).max())
    print(f"{n_grid**2} RK4 runs (dots) vs exact polhodes (lines): max |Δω| = {worst:.2e}")
    fig.savefig(out / "polhode_family.png", dpi=110)
    return worst


def tumbling(free, out):
    """The intermediate-axis flip (Dzhanibekov effect), exactly."""
    from poinsot.viz import animate_tumbling, plot_attitude_frames

    section("Tumbling about the intermediate axis")
    w0 = free._from_sorted(np.array([1e-3, 1.0, 1e-3]))
    T = free.flip_interval(w0)
    print(f"flip interval for ω0 ≈ e2: {T:.6f}")
    t = np.linspace(0, 2 * T, 121)
    Q = free.exact_attitude(w0, t)
    fig = plot_attitude_frames(Q, t, indices=np.linspace(0, 60, 5).astype(int))
    fig.savefig(out / "tumbling_frames.png", dpi=110)
    animate_tumbling(Q[::2], t[::2], out / "tumbling.gif", fps=15)
    return T


def main(out="notebook-figures"):
    import matplotlib

    matplotlib.use("Agg")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    worked_example()
    body = reference_body()
    traj = gravity_run(body, out)
    free = torque_free_theory(body)
    cone_figures(free, out)
    worst = polhode_sweep(body, free, out)
    flip = tumbling(free, out)
    print(f"\nfigures written to {out.resolve()}")
    return {"trajectory": traj, "free": free, "sweep_error": worst, "flip_interval": flip}


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "notebook-figures")
