"""The 34-digit reference of the closed-form heavy top (``heavy_top_mpmath.json``): each case's
angles θ, ψ, φ at 23 times over ten nutation periods, from mpmath's Taylor ODE solver
(``mpmath.odefun``, 34 digits) on Lagrange's equations of the top in Euler angles, written
here independently of poinsot: ``ψ̇ = (b − a cos θ)/sin²θ``, ``φ̇ = ω₃ − ψ̇ cos θ``,
``θ̈ = sin θ (ψ̇² cos θ − a ψ̇ + β/2)``, ``a = C ω₃/A``, ``b = L_z/A``, ``β = 2 M g l/A``
(Goldstein, *Classical Mechanics*, §5.7). The times are ten nutation periods by SciPy's
quadrature of the cubic (independent of the closed form). Run: ``python
tests/data/make_heavy_top_reference.py`` (minutes)."""

import json
from pathlib import Path

import mpmath as mp
import numpy as np
from scipy.integrate import quad

TOP = {"A": 0.2758, "C": 0.045, "mgl": 4.905}
CASES = {  # initial (ψ, θ, φ) and (ψ̇, θ̇, φ̇)
    "fast": ([0.3, 0.6, 0.1], [0.5, 0.2, 100.0]),
    "slow": ([0.0, 1.1, 0.0], [0.2, 0.5, 12.0]),
    "cusp": ([0.0, 0.6, 0.0], [0.0, 0.0, 5.0]),
    "near_sleeping": ([0.0, 0.01, 0.0], [0.0, 0.0, 100.0]),
}


def period(A, C, mgl, ang, rat):
    """Ten nutation periods, 2∫du/√f(u) between the turning points (roots by NumPy)."""
    _, th, _ = ang
    psid, thd, phid = rat
    w3 = phid + psid * np.cos(th)
    a, beta = C * w3 / A, 2 * mgl / A
    b = psid * np.sin(th) ** 2 + a * np.cos(th)
    alpha = beta * np.cos(th) + thd**2 + psid**2 * np.sin(th) ** 2
    roots = np.sort(np.roots([beta, -(alpha + a * a), 2 * a * b - beta, alpha - b * b]).real)
    u1, u2, u3 = roots
    # u = u1 + (u2 − u1) sin²χ: du/√f = 2 dχ / √(β (u3 − u))
    g = lambda chi: 2.0 / np.sqrt(beta * (u3 - u1 - (u2 - u1) * np.sin(chi) ** 2))  # noqa: E731
    return 2 * quad(g, 0, np.pi / 2, epsabs=0, epsrel=2e-14)[0]


def reference(A, C, mgl, ang, rat, ts):
    mp.mp.dps = 34
    psi0, th0, phi0 = (mp.mpf(x) for x in ang)
    psid0, thd0, phid0 = (mp.mpf(x) for x in rat)
    A, C, mgl = mp.mpf(A), mp.mpf(C), mp.mpf(mgl)
    w3 = phid0 + psid0 * mp.cos(th0)
    a, beta = C * w3 / A, 2 * mgl / A
    b = psid0 * mp.sin(th0) ** 2 + a * mp.cos(th0)

    def f(_, y):
        th, thd, _, _ = y
        s, c = mp.sin(th), mp.cos(th)
        psid = (b - a * c) / s**2
        return [thd, s * (psid**2 * c - a * psid + beta / 2), psid, w3 - psid * c]

    sol = mp.odefun(f, 0, [th0, thd0, psi0, phi0])
    return [[mp.nstr(v, 34) for v in sol(mp.mpf(t))] for t in ts]


def main():
    out = {"top": TOP, "cases": {}}
    for name, (ang, rat) in CASES.items():
        T = period(TOP["A"], TOP["C"], TOP["mgl"], ang, rat)
        ts = np.linspace(0, 10 * T, 23)  # not at whole periods: θ is sampled across its band
        rows = reference(TOP["A"], TOP["C"], TOP["mgl"], ang, rat, ts)
        out["cases"][name] = {"angles": ang, "rates": rat, "period": T, "t": ts.tolist(),
                              "theta_thetadot_psi_phi": rows}  # fmt: skip
        print(name, T, flush=True)
    path = Path(__file__).with_name("heavy_top_mpmath.json")
    path.write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
