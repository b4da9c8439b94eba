"""The documentation stands alone: every equation number and section the code cites is in
``docs/theory.md``, and the pages the code and README point to exist."""

from __future__ import annotations

import re
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[1]
THEORY = (ROOT / "docs" / "theory.md").read_text(encoding="utf-8")
SOURCES = sorted((ROOT / "src" / "poinsot").rglob("*.py"))

# "eq. (12)", "eqs (07)–(09)", "(6.60)", "(11)–(12)": numbers in parentheses after "eq"/"eqs"/
# "equation", ranges included, and every numbered equation of the lecture (N.NN)
_REF = re.compile(r"(?:\beqs?\.?|\bequations?|\bpaper eq\.?)\s*\((\d+(?:\.\d+)?)\)"
                  r"(?:\s*[–-]\s*\((\d+(?:\.\d+)?)\))?")  # fmt: skip
_LECTURE = re.compile(r"\((6\.\d\d)\)")


def _numbers_in_theory() -> set[str]:
    """The equations the page states: from §1 on (the introduction names the sources' whole
    ranges, which must not count), before the errata."""
    body = THEORY[THEORY.index("## §1") : THEORY.index("## Errata")]
    found = set()
    for a, b in re.findall(r"\((\d+(?:\.\d+)?)\)(?:\s*[–-]\s*\((\d+(?:\.\d+)?)\))?", body):
        found.add(a)
        if b and "." not in a:  # a range (13)–(15) defines 13, 14, 15
            found.update(f"{n:0{len(a)}d}" for n in range(int(a), int(b) + 1))
        elif b:
            lo, hi = (int(x.split(".")[1]) for x in (a, b))
            found.update(f"6.{n}" for n in range(lo, hi + 1))
    return found


def _cited():
    for path in SOURCES:
        text = path.read_text(encoding="utf-8")
        for match in _REF.finditer(text):
            for number in match.groups():
                if number:
                    yield path.relative_to(ROOT), number
        for number in _LECTURE.findall(text):
            yield path.relative_to(ROOT), number


def test_every_cited_equation_is_in_the_theory_page():
    known = _numbers_in_theory()
    missing = sorted({(str(p), n) for p, n in _cited() if n not in known})
    assert not missing, f"equations cited but not in docs/theory.md: {missing}"
    assert len(set(n for _, n in _cited())) > 30  # the check sees the citations


def test_cited_sections_exist():
    headings = [line for line in THEORY.splitlines() if line.startswith("#")]
    for path in SOURCES:
        text = path.read_text(encoding="utf-8")
        for section in re.findall(r"docs/theory\.md`*,? (§\d)", text):
            assert any(section in h for h in headings), (path, section)
        for name in re.findall(r'docs/theory\.md`*,? §\d, "([^"]+)"', text):
            assert any(name in h for h in headings), (path, name)


def test_theory_lists_the_errata_and_the_multiplier_sign():
    assert "## Errata corrected by poinsot" in THEORY
    for erratum in ("Σ m u × (v × u)", "K = ½ Aω·ω + ½ M|Ṙ|²", "a²/(2k)", "−λ(λ² + |ω|²)"):
        assert erratum in THEORY
    assert "sign convention" in THEORY and "T = −2λl" in THEORY


@pytest.mark.parametrize("path", sorted({*ROOT.glob("README.md"), *ROOT.glob("docs/*.md")}))
def test_linked_pages_exist(path):
    text = path.read_text(encoding="utf-8")
    for target in re.findall(r"\]\(((?:docs/)?[\w./-]+\.md)\)", text):
        base = ROOT if target.startswith("docs/") else path.parent
        assert (base / target).is_file(), (path.name, target)
    assert "THEORY.md" not in text and "../shared" not in text


PAGES = sorted((ROOT / "docs").rglob("*.md"))
#: A Python block, with the HTML comment above it if any: ``<!-- script -->`` runs the block as a
#: script of its own in a new process (a Dask recipe: its workers import it again), ``<!-- not
#: run: REASON -->`` leaves it out (a SLURM cluster), saying why; ``<!-- needs: MODULE -->`` runs
#: it where the optional peer is installed (MuJoCo).
_BLOCK = re.compile(r"(?:<!-- (script|needs: \w+|not run: [^>]+) -->\n)?```python\n(.*?)```",
                    re.S)  # fmt: skip


def _blocks(page):
    return _BLOCK.findall(page.read_text(encoding="utf-8"))


@pytest.mark.parametrize("page", [p for p in PAGES if _blocks(p)],
                         ids=lambda p: str(p.relative_to(ROOT / "docs")))  # fmt: skip
def test_every_python_block_of_every_page_runs(page, tmp_path, monkeypatch):
    """Each page's blocks run in order in one namespace, as a reader pastes them; a script runs
    as ``python recipe.py`` in a new process. Only a block marked with the reason it cannot run
    here is left out."""
    import subprocess
    import sys

    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "__main__"}
    for mark, block in _blocks(page):
        if mark.startswith("not run: "):
            assert len(mark) > len("not run: ") + 5, "say why the block cannot run"
        elif mark.startswith("needs: "):
            pytest.importorskip(mark.removeprefix("needs: "))
            exec(compile(block, str(page), "exec"), namespace)  # our own docs
        elif mark == "script":
            script = tmp_path / "recipe.py"
            script.write_text(block, encoding="utf-8")
            done = subprocess.run([sys.executable, str(script)], capture_output=True,
                                  text=True, timeout=600, cwd=tmp_path)  # fmt: skip
            assert done.returncode == 0, done.stderr[-3000:]
        else:
            exec(compile(block, str(page), "exec"), namespace)  # our own docs


def test_pages_that_need_a_cluster_say_so_and_nothing_else_is_left_out():
    skipped = [(p.name, m) for p in PAGES for m, _ in _blocks(p) if m.startswith("not run")]
    assert {name for name, _ in skipped} <= {"ensembles.md"}, skipped
    assert len(skipped) == 2


def _documented():
    """``(module, name)`` of every object the API reference documents: a module's ``__all__``
    under ``:members:``, or the names it lists."""
    import importlib

    rst = (ROOT / "docs" / "api.rst").read_text(encoding="utf-8")
    out = []
    for module, options in re.findall(r"\.\. automodule:: ([\w.]+)\n((?:   :[^\n]*\n)*)", rst):
        mod = importlib.import_module(module)
        listed = re.search(r":members:(.*)", options)
        names = [n.strip() for n in listed.group(1).split(",") if n.strip()] if listed else []
        for name in names or list(getattr(mod, "__all__", [])):
            out.append((module, name, getattr(mod, name)))
    return out


def _public_modules():
    """``poinsot``, its modules and subpackages (not private, not the CLI's ``app``), and every
    module the pages and examples import from."""
    import pkgutil

    import poinsot

    names = {"poinsot"} | {f"poinsot.{m.name}" for m in pkgutil.iter_modules(poinsot.__path__)
                           if not m.name.startswith("_") and m.name != "app"}  # fmt: skip
    for path in [*PAGES, ROOT / "README.md", *sorted((ROOT / "examples").glob("*.py"))]:
        text = path.read_text(encoding="utf-8")
        names |= set(re.findall(r"^\s*from (poinsot(?:\.\w+)*) import", text, re.M))
    return sorted(names)


def test_the_api_reference_lists_every_public_name():
    """Every name in the ``__all__`` of a public module (and every name the pages import) is
    documented in ``docs/api.rst``: ``poinsot.integrate.events.Event``, which the constrained
    tutorial imports, was missing."""
    import importlib

    documented = _documented()
    objects = {id(obj) for _, _, obj in documented}
    names = {name for _, name, _ in documented}
    names |= set(re.findall(r"\.\. automodule:: ([\w.]+)", (ROOT / "docs" / "api.rst").read_text()))
    missing = []
    for module in _public_modules():
        mod = importlib.import_module(module)
        for name in getattr(mod, "__all__", []):
            obj = getattr(mod, name)
            plain = isinstance(obj, int | float | str | tuple | dict)
            if (
                not name.startswith("__")
                and id(obj) not in objects
                and not (plain and name in names)
            ):
                missing.append(f"{module}.{name}")
    for path in [*PAGES, ROOT / "README.md"]:
        for module, imported in re.findall(
            r"^\s*from (poinsot(?:\.\w+)*) import ([\w, ]+)$",
            path.read_text(encoding="utf-8"),
            re.M,
        ):
            for name in (n.strip() for n in imported.split(",")):
                obj = getattr(importlib.import_module(module), name)
                plain = isinstance(obj, int | float | str | tuple | dict)
                if isinstance(obj, ModuleType):  # `from poinsot import models`
                    plain, name = True, obj.__name__
                if id(obj) not in objects and not (plain and name in names):
                    missing.append(f"{module}.{name} (imported in {path.name})")
    assert not missing, f"public names missing from docs/api.rst: {sorted(set(missing))}"
    assert "Event" in names  # the check sees the reference


def test_sphinx_builds_the_api_reference_without_warnings(tmp_path):
    """The API reference and the pages build with warnings as errors (``-W``)."""
    import os
    import subprocess
    import sys

    try:
        import myst_parser  # noqa: F401
        import sphinx  # noqa: F401
    except ImportError:
        if os.environ.get("CI"):
            pytest.fail("CI must install the docs tools (the test extra has sphinx)")
        pytest.skip("sphinx is not installed")
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         str(ROOT / "docs"), str(tmp_path / "html")],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    api = (tmp_path / "html" / "api.html").read_text(encoding="utf-8")
    for name in ("simulate", "FreeRigidBody", "LagrangianSystem", "simulate_relative",
                 "invariants_of"):  # fmt: skip
        assert 'id="poinsot.' in api and name in api
