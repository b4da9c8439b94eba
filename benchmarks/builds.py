"""Two builds of poinsot against each other, in one run: the workloads of the reference
measurements (``../shared/bench``: one trajectory, the ensemble, the Lagrangian pendulum on a
cart) and the forced ensembles in lanes, each timed in a fresh process of each build in turn,
rounds alternated, so that both builds see the same machine.

Usage::

    python benchmarks/builds.py OLD NEW [--rounds 5] [--only NAME ...]

``OLD`` and ``NEW`` are folders that hold a ``poinsot`` package (a ``site-packages``, or a
checkout's ``src``) or Python executables of environments where poinsot is installed. Each
line gives the best and median times of each build over the rounds (the best of a few calls
per round) and the ratio of the medians, old/new (> 1: the new build is faster). Use it when
the build changes (profiles, LTO, codegen units, the dispatched copies): the results must be
identical and the ratios within noise.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import textwrap
from pathlib import Path

#: The notebook's 27-particle body, as the reference measurements build it.
NOTEBOOK = """
        import poinsot as po
        vals = (0.0, 0.5, 1.0)
        r = np.array([[i, 2 * j, 3 * k] for i in vals for j in vals for k in vals])
        body = po.RigidBody.from_particles(np.full(27, 10 / 27), r)
"""

#: name -> (setup, call, repeats): ``call`` is timed ``repeats`` times after one warm-up call.
WORKLOADS = {
    "single_rk4": (
        NOTEBOOK
        + """
        t_eval = np.linspace(0, 20, 101)
    """,
        "po.simulate(body, (0, 20), omega0=(0.1, 1, 0.2), method='rk4', dt=1e-3, "
        "t_eval=t_eval).omega[-1]",
        30,
    ),
    "single_dop853": (
        NOTEBOOK
        + """
        t_eval = np.linspace(0, 20, 101)
    """,
        "po.simulate(body, (0, 20), omega0=(0.1, 1, 0.2), rtol=1e-10, atol=1e-12, "
        "t_eval=t_eval).omega[-1]",
        30,
    ),
    "ensemble_rk4": (
        NOTEBOOK
        + """
        from poinsot.ensemble import simulate_ensemble
        w0 = np.random.default_rng(0).normal(size=(100_000, 3))
    """,
        "np.asarray(simulate_ensemble(body, (0.0, 1.0), omega0=w0, method='rk4', "
        "dt=1e-3).omega)[:, -1].sum(0)",
        3,
    ),
    "heavy_top_lanes": (
        """
        import poinsot as po
        from poinsot.ensemble import simulate_ensemble
        body = po.RigidBody.cylinder(1.0, 0.05, 0.5)
        w0 = np.random.default_rng(1).normal(size=(4000, 3)) + (0, 0, 50)
        forces = [po.Gravity((0, 0, -9.81))]
    """,
        "np.asarray(simulate_ensemble(body, (0.0, 1.0), omega0=w0, method='rk4', dt=1e-3, "
        "pivot=(0, 0, -0.25), forces=forces).omega)[:, -1].sum(0)",
        3,
    ),
    "lagrange_n10": (
        """
        import sympy as sp
        from sympy import cos, sin
        from sympy.physics.mechanics import dynamicsymbols
        from poinsot.lagrange import LagrangianSystem, PointMass
        n = 10
        q = dynamicsymbols(f"q:{n + 1}")
        ms = sp.symbols(f"m:{n + 1}")
        ls = sp.symbols(f"l:{n}")
        g = sp.Symbol("g")
        pts = [sp.Matrix([q[0], 0, 0])]
        for i in range(n):
            pts.append(pts[-1] + ls[i] * sp.Matrix([-sin(q[i + 1]), cos(q[i + 1]), 0]))
        system = LagrangianSystem(q, bodies=[PointMass(mi, p) for mi, p in zip(ms, pts)],
                                  potential=sum(mi * g * p[1] for mi, p in zip(ms, pts)))
        params = {s: (9.81 if str(s) == "g" else (1.0 if str(s).startswith("m") else 0.5))
                  for s in (*ms, *ls, g)}
        q0 = {q[0]: 0.0, **{q[i]: np.pi + 0.1 * i for i in range(1, n + 1)}}
        kw = dict(q0=q0, params=params, rtol=1e-8, atol=1e-8, t_eval=np.linspace(0, 10, 201))
    """,
        "np.asarray(system.simulate((0, 10), **kw).q)[-1]",
        5,
    ),
}

CHILD = """
import json, time
import numpy as np
{setup}
def call():
    return {call}
first = np.asarray(call(), dtype=float)
times = []
for _ in range({repeats}):
    t0 = time.perf_counter(); call(); times.append(time.perf_counter() - t0)
print(json.dumps({{"best": min(times), "result": first.tolist(),
                  "file": __import__("poinsot").__file__}}))
"""


def _command(build: str) -> tuple[list[str], dict]:
    """The interpreter and environment that import ``build``'s poinsot."""
    path = Path(build)
    env = dict(os.environ)
    if path.is_file():  # a Python executable
        return [str(path)], env
    env["PYTHONPATH"] = str(path.resolve())
    return [sys.executable], env


def _time(build: str, name: str) -> dict:
    setup, call, repeats = WORKLOADS[name]
    code = CHILD.format(setup=textwrap.dedent(setup), call=call, repeats=repeats)
    cmd, env = _command(build)
    proc = subprocess.run([*cmd, "-c", code], env=env, capture_output=True, text=True,
                          timeout=900)  # fmt: skip
    if proc.returncode:
        raise SystemExit(f"{build}: {name} failed:\n{proc.stderr}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--only", nargs="*", choices=sorted(WORKLOADS))
    args = ap.parse_args(argv)
    names = args.only or list(WORKLOADS)
    print(f"old: {args.old}\nnew: {args.new}\n{args.rounds} rounds, alternated; seconds")
    print(f"{'workload':18s} {'old best':>9s} {'old med':>9s} {'new best':>9s} {'new med':>9s}"
          f" {'old/new':>8s}  results")  # fmt: skip
    for name in names:
        runs = {"old": [], "new": []}
        results = {}
        for _ in range(args.rounds):
            for label, build in (("old", args.old), ("new", args.new)):
                out = _time(build, name)
                runs[label].append(out["best"])
                results[label] = out["result"]
        same = "identical" if results["old"] == results["new"] else "DIFFER"
        med = {k: statistics.median(v) for k, v in runs.items()}
        print(
            f"{name:18s} {min(runs['old']):9.4g} {med['old']:9.4g} {min(runs['new']):9.4g} "
            f"{med['new']:9.4g} {med['old'] / med['new']:8.3f}  {same}",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
