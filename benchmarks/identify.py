"""How long one throw takes to identify, and what the compiled forward model buys.

    python benchmarks/identify.py [--repeat N] [--json FILE]

Cases (medians of N repeats after one warm-up, same process):

* ``identify``: one 0.5 s, 4 kHz synthetic throw of the block with the logger (the issue's
  case: flywheel spun 200 → 1300 rad/s, gyro noise 0.02 rad/s), output error included, with
  the flywheel's inertia known; the same torque-free; and the same log with a hand before and a
  catch after it, the accelerometer finding the flight.
* ``cold``: the same in a fresh Python process, imports included (what a user waits for).
* ``forward``: one integration of the gyrostat over the throw (2001 samples), poinsot's core
  (RK4 on the momentum form) against SciPy's ``solve_ivp`` (DOP853, rtol 1e-10) on the same
  momentum form written in NumPy (a Python call per stage): the cost a fit pays per model
  evaluation (a fit needs a few hundred), each side's accuracy against a tight reference
  printed beside it.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import subprocess
import sys

import numpy as np
from run import timed  # the benchmarks' one timer (benchmarks/run.py)


def case_identify(repeat):
    from poinsot.identify import identify, synthetic_throw

    rows = []
    for label, kw in (
        ("rotor throw, J known", {}),
        ("torque-free throw", {"rotor": False}),
        ("rotor throw in a 1.1 s log from the hand, accelerometer", {"accel": True,
                                                                     "hand": True}),
    ):  # fmt: skip
        th = synthetic_throw(seed=2025, **kw)
        t, res = timed(lambda th=th: identify(th.t, th.omega, **th.kwargs()), repeat)
        err = float(np.max(np.abs(res.ratios / th.ratios - 1)))
        rows.append({"case": f"identify: {label}", "seconds": t, "ratio_error": err,
                     "samples": len(th.t), "model_evaluations": res.nfev})  # fmt: skip
    return rows


COLD = """
import time
start = time.perf_counter()
from poinsot.identify import identify, synthetic_throw
th = synthetic_throw(seed=2025)
made = time.perf_counter()
res = identify(th.t, th.omega, **th.kwargs())
print(made - start, time.perf_counter() - made)
"""


def case_cold(repeat):
    made, fit = [], []
    for _ in range(max(1, min(repeat, 5))):
        out = subprocess.run([sys.executable, "-c", COLD], capture_output=True, text=True,
                             check=True).stdout.split()  # fmt: skip
        made.append(float(out[0]))
        fit.append(float(out[1]))
    return [
        {"case": "cold: import + synthetic throw", "seconds": statistics.median(made)},
        {"case": "cold: first identify in a new process", "seconds": statistics.median(fit)},
    ]


def case_forward(repeat):
    from scipy.integrate import solve_ivp

    from poinsot import _core
    from poinsot.identify.output_error import gyrostat_run
    from poinsot.identify.synthetic import logger_block, rotor_profile

    body, _ = logger_block()
    I = np.array(body.inertia)
    m, E = (np.asarray(x) for x in _core.principal_decomposition(I))
    t = np.arange(2001) / 4000.0
    speed, _ = rotor_profile(t)
    a, J = np.array([0.0, 0.0, 1.0]), 1.7e-6
    w0 = np.array([12.0, -20.0, 6.0])

    run = gyrostat_run(t, 0.0)  # one step per sample interval, built once

    def ours():
        return _core.gyrostat_omegas(m[None], E[None], np.array([J]), w0[None], run, t, speed,
                                     a)[0]  # fmt: skip

    Iinv = np.linalg.inv(I)

    def rhs(time, L):  # the momentum form, the rotor speed linear between samples as ours
        return np.cross(L, Iinv @ (L - J * np.interp(time, t, speed) * a))

    def peer():
        L0 = I @ w0 + J * speed[0] * a
        L = solve_ivp(rhs, (0, 0.5), L0, method="DOP853", t_eval=t, rtol=1e-10,
                      atol=1e-12).y.T  # fmt: skip
        return (L - J * speed[:, None] * a) @ Iinv.T

    fine = gyrostat_run(t, 2.5e-4 / 16)
    ref = _core.gyrostat_omegas(m[None], E[None], np.array([J]), w0[None], fine, t, speed,
                                a)[0]  # fmt: skip
    t_ours, w_ours = timed(ours, repeat)
    t_peer, w_peer = timed(peer, max(1, repeat // 3))
    return [{"case": "forward model, one throw (2001 samples)", "seconds": t_ours,
             "peer": "SciPy solve_ivp DOP853 rtol 1e-10, NumPy momentum form",
             "peer_seconds": t_peer, "ratio": t_peer / t_ours,
             "error": float(np.abs(w_ours - ref).max()),
             "peer_error": float(np.abs(w_peer - ref).max())}]  # fmt: skip


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--json", metavar="FILE")
    args = p.parse_args(argv)
    rows = case_identify(args.repeat) + case_forward(args.repeat) + case_cold(args.repeat)
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"NumPy {np.__version__}; medians of {args.repeat}")  # fmt: skip
    for r in rows:
        extra = ""
        if "ratio_error" in r:
            extra = (f"  max ratio error {100 * r['ratio_error']:.3f} %, "
                     f"{r['model_evaluations']} model evaluations")  # fmt: skip
        if "peer" in r:
            extra = (f"  peer {1000 * r['peer_seconds']:.1f} ms ({r['ratio']:.0f}× slower); "
                     f"max |Δω| {r['error']:.1e} vs {r['peer_error']:.1e} rad/s")  # fmt: skip
        print(f"{r['case']:<62s} {1000 * r['seconds']:8.1f} ms{extra}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=2)


if __name__ == "__main__":
    main()
