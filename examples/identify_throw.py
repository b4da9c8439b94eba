"""Identify a body's inertia from one simulated throw.

poinsot throws the 70 × 60 × 30 mm block with its 45 × 40 × 25 mm logger (half a second at
4 kHz, |ω| up to 30 rad/s), while the logger's flywheel (J = 1.7e-6 kg m²) spins from 200 up
to 1300 rad/s over 0.2 s and back; the gyro reads the motion with 0.02 rad/s of noise, a
0.01 rad/s bias and a 35 rad/s range, and the accelerometer the throw from the hand, the
flight and the catch. Then it forgets the body and identifies it from the log:

1. with the flywheel's inertia known: the inertia in kg m²;
2. with the flywheel's inertia fitted: the ratios and axes;
3. ignoring the flywheel: the torque-free model cannot explain the log, and says so.

    python examples/identify_throw.py [OUT_DIR]

With OUT_DIR it also writes the report (report.html and its figures) there.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

from poinsot.identify import ModelMismatchWarning, identify, synthetic_throw


def main(out=None) -> dict:
    throw = synthetic_throw(seed=2025, accel=True, hand=True)
    truth = throw.inertia
    print(f"the log: {len(throw.t)} samples over {throw.t[-1] - throw.t[0]:.2f} s, "
          f"free flight {throw.window[0]:.3f} … {throw.window[1]:.3f} s")  # fmt: skip
    print(f"true ratios I1/I3, I2/I3 = {throw.ratios.round(5)}, "
          f"trace = {np.trace(truth):.6g} kg m²\n")  # fmt: skip

    known = identify(throw.t, throw.omega, **throw.kwargs())
    fitted = identify(throw.t, throw.omega, **throw.kwargs(rotor_inertia_known=False))
    for name, res in (("J known", known), ("J fitted", fitted)):
        err = res.ratios / throw.ratios - 1
        r, dr = res.ratios, res.ratios_stderr
        print(f"{name}: I1/I3 = {r[0]:.5f} ± {dr[0]:.1e} (error {100 * err[0]:+.3f} %), "
              f"I2/I3 = {r[1]:.5f} ± {dr[1]:.1e} (error {100 * err[1]:+.3f} %)")  # fmt: skip
        off, sd = throw.axis_errors_deg(res.axes), res.axes_stderr_deg
        print(
            "  axes off by "
            + ", ".join(f"{a:.3f}° (± {b:.3f}°)" for a, b in zip(off, sd, strict=True))
        )
    trace_error = known.trace / np.trace(truth) - 1
    print(f"  J known: trace {known.trace:.6g} ± {known.trace_stderr:.2g} kg m² "
          f"(error {100 * trace_error:+.3f} %)")  # fmt: skip
    print(
        f"  free flight found at {known.window[0]:.3f} … {known.window[1]:.3f} s, lever arm "
        f"{1000 * known.lever_arm.round(4)} mm (true {1000 * throw.lever_arm.round(4)})"
    )
    print(f"  J fitted: J/trace(I) = {fitted.rotor_inertia:.5g} "
          f"(true {throw.rotor_inertia / np.trace(truth):.5g})\n")  # fmt: skip

    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always", ModelMismatchWarning)
        blind = identify(throw.t, throw.omega, accel=throw.accel)  # the flywheel left out
    print(f"ignoring the flywheel: residuals {blind.residual_ratio:.3g}× the gyro noise, "
          f"ok = {blind.ok}")  # fmt: skip
    print(f"  {blind.flags[0]}")

    if out is not None:
        from poinsot.viz.identify import write_identify_report_folder

        Path(out).mkdir(parents=True, exist_ok=True)
        write_identify_report_folder(out, known, name="identify_throw")
        print(f"\nwrote {out}/report.html")
    return {"throw": throw, "known": known, "fitted": fitted, "blind": blind,
            "trace_error": trace_error}  # fmt: skip


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
