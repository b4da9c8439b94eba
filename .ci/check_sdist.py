"""Check an sdist's contents: what a source build needs, and nothing a checkout collects.

Usage: python .ci/check_sdist.py poinsot-VERSION.tar.gz

Fails (exit 1, naming each offender) on build outputs (``target/``, compiled extensions),
caches (``__pycache__``, ``.pytest_cache``, ``.hypothesis``, ``.ruff_cache``), virtual
environments, CI leftovers, output folders, or any file over 1 MiB; and when a file the build
needs is missing (the crates' manifests and sources, the Python package, the README).
"""

from __future__ import annotations

import sys
import tarfile

MAX_BYTES = 1 << 20
FORBIDDEN_PARTS = {"target", "__pycache__", ".pytest_cache", ".hypothesis", ".ruff_cache",
                   ".venv", ".ci-venv", ".ci-wheel-venv", ".ci-dist", "poinsot-out", ".git",
                   "docs/_build"}  # fmt: skip
FORBIDDEN_SUFFIXES = (".so", ".pyd", ".dylib", ".dll", ".dis", ".pyc", ".whl", ".tar.gz")
REQUIRED = ("pyproject.toml", "Cargo.toml", "Cargo.lock", "README.md",
            "crates/core/Cargo.toml", "crates/core/build.rs", "crates/core/src/lib.rs",
            "crates/jit/src/lib.rs", "crates/python/src/lib.rs", "src/poinsot/__init__.py",
            "src/poinsot/py.typed")  # fmt: skip


def main(path: str) -> int:
    problems = []
    with tarfile.open(path) as tar:
        members = [m for m in tar.getmembers() if m.isfile()]
    root = members[0].name.split("/", 1)[0]
    names = {m.name.split("/", 1)[1]: m for m in members if "/" in m.name}
    for name, member in sorted(names.items()):
        parts = name.split("/")
        joined = {"/".join(parts[i : i + 2]) for i in range(len(parts))}
        if FORBIDDEN_PARTS & (set(parts) | joined):
            problems.append(f"{name}: a build output, cache or checkout leftover")
        elif name.endswith(FORBIDDEN_SUFFIXES):
            problems.append(f"{name}: a compiled or packed file")
        elif member.size > MAX_BYTES:
            problems.append(f"{name}: {member.size / 2**20:.1f} MiB (over 1 MiB)")
    for name in REQUIRED:
        if name not in names:
            problems.append(f"{name}: missing (a source build needs it)")
    total = sum(m.size for m in members)
    print(f"{path}: {len(members)} files, {total / 2**20:.2f} MiB unpacked, under {root}/")
    for p in problems:
        print(f"  sdist: {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
