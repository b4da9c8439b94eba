"""The documentation stands alone: every equation number and section the code cites is in
``docs/theory.md``, and the pages the code and README point to exist."""

from __future__ import annotations

import re
from pathlib import Path

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


@pytest.mark.parametrize("page", sorted((ROOT / "docs" / "tutorials").glob("*.md")))
def test_tutorial_code_runs(page, tmp_path, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    blocks = re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)
    assert blocks, page.name
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, str(page), "exec"), namespace)  # our own docs


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
