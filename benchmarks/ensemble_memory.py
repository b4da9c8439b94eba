"""Peak memory of `poinsot run` on a streamed ensemble against the size of what it writes
(issue 44): the tennis-racket ensemble with N members and 2 RK4 steps, final states only
(`keep_states = false`), each N in a fresh process; peak RSS from the kernel (`ru_maxrss` of
the child), results = the bytes of ensemble.nc. Goal: peak ≤ 2 × results + 0.5 GB.

    python benchmarks/ensemble_memory.py [N ...]     # default 1e5 1e6 1e7 3e7

3·10⁷ members need about 11 GB of memory and 6 GB of disk.
"""

from __future__ import annotations

import resource
import subprocess
import sys
import tempfile
import time
from importlib.resources import files
from pathlib import Path


def scenario(members: int) -> str:
    text = (files("poinsot.app") / "scenarios" / "tennis-racket-ensemble.toml").read_text()
    text = text.replace("members = 2000", f"members = {members}")
    return text.replace("span = [0.0, 10.0]", "span = [0.0, 2e-3]")  # dt = 1e-3: 2 steps


def measure(members: int) -> tuple[float, int, float]:
    """(peak RSS in bytes, bytes written to ensemble.nc, wall seconds) of one run."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "e.toml"
        path.write_text(scenario(members))
        before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "poinsot", "run", str(path), "--out",
                        str(Path(tmp) / "o"), "--quiet"], check=True)  # fmt: skip
        wall = time.perf_counter() - start
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        if peak <= before:  # the children's maximum: an earlier, larger run hides this one
            raise SystemExit("run the sizes in increasing order")
        return peak * 1024.0, (Path(tmp) / "o" / "ensemble.nc").stat().st_size, wall


def main(argv) -> None:
    sizes = [int(float(a)) for a in argv] or [10**5, 10**6, 10**7, 3 * 10**7]
    print(f"{'members':>10} {'peak RSS':>10} {'results':>10} {'goal':>10} {'ratio':>6} "
          f"{'wall':>7}")  # fmt: skip
    for n in sorted(sizes):
        peak, written, wall = measure(n)
        goal = 2 * written + 0.5e9
        print(f"{n:>10.0e} {peak / 1e9:>8.3f} GB {written / 1e9:>8.3f} GB {goal / 1e9:>8.3f} GB "
              f"{peak / goal:>6.2f} {wall:>6.1f}s")  # fmt: skip


if __name__ == "__main__":
    main(sys.argv[1:])
