"""What forward sensitivities cost, against the plain run and against finite differences, in
one run (medians of N repeats after a warm-up).

    python benchmarks/sensitivities.py [--repeat N]

Cases:

* ``rigid``: a body under gravity (a full inertia tensor, its centre of mass off the origin),
  10 s, with the derivatives of the motion with respect to p = 6 parameters (ω0 and the three
  principal moments), RK4 and RKMK4 at dt = 1e-4 and DOP853 at rtol 1e-10: the run with its
  sensitivities against the plain run, and against central differences (2p + 1 plain runs,
  the route the sensitivities replace); DOP853 also with the sensitivities left out of the
  error control.
* ``identify``: the output-error fit's Jacobian over one synthetic 0.5 s, 4 kHz throw with the
  flywheel spinning (one segment, 10 columns): the exact derivatives (the gyrostat's
  sensitivities, one run) against central differences of the same model (2p members of the
  batched core call, the route it replaced), and their difference.
* ``segments``: the Jacobian of an 8-segment log: its segments as one ensemble call on the
  core's threads, against one call per segment.
* ``splittings``: an asymmetric heavy top (its centre of mass off the axis, on a pivot), 10 s
  at dt = 1e-2, p = 6 (ω0 and Q0): each splitting and RKMK4 with its sensitivities against
  its own plain run (the exact-flow splittings differentiate the closed form flow by flow).
"""

from __future__ import annotations

import argparse

import numpy as np
from run import timed  # the benchmarks' one timer (benchmarks/run.py)


def case_rigid(repeat):
    from poinsot import RigidBody
    from poinsot.forces import Gravity
    from poinsot.simulation import prepare

    body = RigidBody(2.0, [[2.0, 0.3, -0.1], [0.3, 3.0, 0.2], [-0.1, 0.2, 4.5]], (0.1, -0.2, 0.3))
    forces = (Gravity((0, 0, -9.8)),)
    w0 = np.array([0.4, -1.1, 0.7])
    tev = np.linspace(0, 10, 11)
    for method, kw in (("rk4", {"dt": 1e-4}), ("rkmk4", {"dt": 1e-4}),
                       ("dop853", {"rtol": 1e-10, "atol": 1e-12})):  # fmt: skip
        plain = prepare(body, (0, 10), forces=forces, method=method, t_eval=tev, **kw)
        sens = prepare(body, (0, 10), forces=forces, method=method, t_eval=tev,
                       sensitivities=("omega0", "inertia"), **kw)  # fmt: skip
        t_plain, _ = timed(lambda p=plain: p.run(omega0=w0), repeat)
        t_sens, traj = timed(lambda p=sens: p.run(omega0=w0), repeat)

        def differences(p=plain):  # the ω0 columns only (the moments need new bodies)
            return [p.run(omega0=w0 + s * 1e-6 * e) for e in np.eye(3) for s in (1, -1)]

        t_fd3, _ = timed(differences, repeat)
        t_fd = t_plain + 2 * t_fd3  # 2p runs for p = 6, plus the plain one
        print(f"rigid, gravity, {method}: plain {t_plain * 1e3:.2f} ms; with 6 sensitivities "
              f"{t_sens * 1e3:.2f} ms ({t_sens / t_plain:.2f}x the plain run); central "
              f"differences (13 runs) {t_fd * 1e3:.2f} ms ({t_fd / t_sens:.2f}x the "
              f"sensitivities); steps {traj.nsteps}")  # fmt: skip
        if method == "dop853":
            out = prepare(body, (0, 10), forces=forces, method=method, t_eval=tev,
                          sensitivities=("omega0", "inertia"), control_sensitivities=False,
                          **kw)  # fmt: skip
            t_out, tr = timed(lambda p=out: p.run(omega0=w0), repeat)
            print(f"  dop853, sensitivities out of the error control: {t_out * 1e3:.2f} ms "
                  f"({t_out / t_plain:.2f}x the plain run); steps {tr.nsteps}")  # fmt: skip


def identify_model(duration=0.5, segment=1.0):
    """The output-error model of a synthetic throw of ``duration`` seconds cut into segments of
    ``segment`` seconds, its start ``x`` (log-ratios), the throw and its rotor."""
    from poinsot.identify.output_error import (
        _default_max_step,
        _Model,
        _parameter_vector,
        _segments,
        _start_frame,
        _start_omegas,
    )
    from poinsot.identify.synthetic import synthetic_throw

    th = synthetic_throw(seed=2025, duration=duration)
    t, omega = th.t, th.omega
    segments = _segments(len(t), t, segment)
    m0, E0, I3_0 = _start_frame(th.inertia)
    rotor = (t.copy(), th.rotor_speed, np.asarray(th.rotor_axis))
    model = _Model(t, omega, segments, rotor, th.rotor_inertia, E0, I3_0,
                   _default_max_step(t, omega))  # fmt: skip
    x = _parameter_vector(model.extra, _start_omegas(t, omega, None, segments), m0, 0.0,
                          (0.0, 0.0, 0.0))  # fmt: skip
    lr = slice(3 * model.K, 3 * model.K + 2)
    x[lr] = np.log(x[lr])
    return model, x, th, rotor


def case_identify(repeat):
    from poinsot._bindings import identify as core_identify

    model, x, th, rotor = identify_model()
    t = th.t
    cols = [*model.shared, 0, 1, 2]
    steps = [1e-6 * max(abs(x[j]), 1.0) for j in cols]

    def differences():
        members = []
        for j, h in zip(cols, steps, strict=True):
            for s in (1, -1):
                xj = x.copy()
                xj[j] += s * h
                w0, rho, delta, extra, _ = model.unpack(xj)
                members.append((*model.physical(rho, delta, extra), w0[0]))
        moments = np.array([m[0] for m in members])
        axes = np.array([m[1] for m in members])
        J = np.array([m[2] for m in members])
        w0s = np.array([m[3] for m in members])
        return core_identify.gyrostat_omegas(moments, axes, J, w0s, model.runs[0], *rotor)

    t_exact, J = timed(lambda: model.jacobian(x), repeat)
    t_fd, out = timed(differences, repeat)
    exact = -J.reshape(len(t), 3, model.p)[:, :, cols]
    fd = np.stack([(out[2 * i] - out[2 * i + 1]) / (2 * h) for i, h in enumerate(steps)], -1)
    diff = float(np.abs(exact - fd).max() / np.abs(exact).max())
    print(f"identify Jacobian, {len(t)} samples, {len(cols)} columns: exact "
          f"{t_exact * 1e3:.2f} ms; central differences {t_fd * 1e3:.2f} ms "
          f"({t_fd / t_exact:.2f}x the exact); largest difference {diff:.1e} of the largest "
          "entry (the differences' own error)")  # fmt: skip


def case_segments(repeat, k=8):
    """A log of k throws' length as k segments: the Jacobian's segments as one ensemble call
    on the core's threads, against one call per segment (the route before)."""
    from poinsot._bindings import identify as core_identify

    model, x, th, rotor = identify_model(duration=0.5 * k, segment=0.5)
    t, E0 = th.t, model.E0
    w0, rho, delta, extra, _ = model.unpack(x)
    moments, _, J = model.physical(rho, delta, extra)
    _, dm, dd, dj, dw = model._seeds(x, 0)
    c = np.ascontiguousarray

    def one_by_one():
        return [core_identify.gyrostat_sensitivities(
            c(moments), dm, c(E0), c(delta), dd, float(J), dj, c(w0[i : i + 1]), dw,
            [model.runs[i]], *rotor)[0] for i in range(model.K)]  # fmt: skip

    t_ens, _ = timed(lambda: model.jacobian(x), repeat)
    t_one, _ = timed(one_by_one, repeat)
    print(f"identify Jacobian, {model.K} segments, {len(t)} samples: the segments as one "
          f"ensemble call {t_ens * 1e3:.2f} ms; one call per segment {t_one * 1e3:.2f} ms "
          f"({t_one / t_ens:.2f}x)")  # fmt: skip


def case_splittings(repeat):
    from poinsot import RigidBody
    from poinsot.forces import Gravity
    from poinsot.simulation import prepare

    body = RigidBody(2.0, np.diag([2.0, 3.0, 4.5]), (0.05, -0.02, 0.3))
    w0 = np.array([0.4, -1.1, 5.0])
    for method in ("exact-splitting", "exact-splitting6", "splitting", "rkmk4"):
        kw = {"forces": (Gravity(),), "pivot": (0, 0, -0.4), "method": method, "dt": 1e-2,
              "t_eval": [0.0, 10.0]}  # fmt: skip
        plain = prepare(body, (0, 10), **kw)
        sens = prepare(body, (0, 10), sensitivities=("omega0", "Q0"), **kw)
        t_plain, _ = timed(lambda p=plain: p.run(omega0=w0), repeat)
        t_sens, _ = timed(lambda p=sens: p.run(omega0=w0), repeat)
        print(f"heavy top, {method}: plain {t_plain * 1e3:.2f} ms; with 6 sensitivities "
              f"{t_sens * 1e3:.2f} ms ({t_sens / t_plain:.2f}x the plain run)")  # fmt: skip


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    case_rigid(args.repeat)
    case_identify(args.repeat)
    case_segments(args.repeat)
    case_splittings(args.repeat)


if __name__ == "__main__":
    main()
