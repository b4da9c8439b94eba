"""The README's example runs, and its set-up commands are the ones CI runs."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_example_runs(capsys):
    text = README.read_text(encoding="utf-8")
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    exec(compile(code, "README.md", "exec"), {})
    out = capsys.readouterr().out.split("\n")
    assert "8.333" in out[0] and float(out[1]) < 1e-10 and out[2].startswith("27.53084055")


def test_exactly_two_setup_commands():
    text = README.read_text(encoding="utf-8")
    main = re.search(r"<!-- main-command -->\n```bash\n(.*?)\n```", text, re.S).group(1)
    test = re.search(r"<!-- test-command -->\n```bash\n(.*?)\n```", text, re.S).group(1)
    assert main.strip() == "pip install '.[report]' && poinsot run"
    assert "pytest" in test and "pip install" in test
    ci = (README.parent / ".ci" / "run").read_text()
    assert "<!-- test-command -->" in ci  # CI runs exactly the README's test command


def _command_line_section() -> str:
    text = README.read_text(encoding="utf-8")
    return text[text.index("## Set-up on a fresh machine") : text.index("## Speed")]


#: Rows of a report's "Numbers" that count things (no unit to give).
_COUNTS = ("steps", "samples", "evaluations", "particles", "method", "backend", "symmetry",
           "family", "flips", "polhode family", "model", "coordinates", "constraints")  # fmt: skip


def test_the_readmes_claims_about_outputs_hold(tmp_path, monkeypatch):
    """Every output the README promises for the main command is there, as described: the
    files, the units map, the CSV headers, the grouped tables with units, the manifest, the
    shared plotly.js, and the links of the report."""
    import json
    import re

    from poinsot.app.cli import main
    from poinsot.viz.numbers import rows_of

    section = _command_line_section()
    folder = re.search(r"`\./(poinsot-out/\w+)/`", section).group(1)
    promised = re.findall(r"`([\w.-]+\.(?:npz|csv|nc|json|html))`", section)
    assert {"summary.json", "report.html", "trajectory.nc"} <= set(promised)
    monkeypatch.chdir(tmp_path)
    assert main(["run", "--quiet", "--plotly-js", "shared"]) == 0
    out = tmp_path / folder
    for name in promised:
        if name != "plotly-VERSION.min.js":
            assert (out / name).is_file(), f"README promises {name}"
    # `summary.json` has a `units` map
    assert "`summary.json` has a `units` map" in section
    summary = json.loads((out / "summary.json").read_text())
    assert summary["units"]["initial.omega"] == "rad/s"
    # CSV headers read `omega_x [rad/s]`
    header = re.search(r"CSV headers read `([^`]+)`", section).group(1)
    assert header in (out / "trajectory.csv").read_text().splitlines()[0].split(",")
    # the report's "Numbers" are grouped tables with units: every number has its unit
    page = (out / "report.html").read_text(encoding="utf-8")
    assert page.count("<h3>") >= 5 and "class='unit'>rad/s<" in page
    for group, name, value, unit in rows_of(summary):
        if isinstance(value, bool) or not isinstance(value, int | float | list):
            continue
        assert unit or any(w in name for w in _COUNTS), f"{group}: {name} has no unit"
    # `--plotly-js shared` writes it once beside the output folders
    shared = re.search(r"`(poinsot-out/plotly-VERSION\.min\.js)`", section).group(1)
    files = list((tmp_path / "poinsot-out").glob("plotly-*.min.js"))
    assert len(files) == 1 and shared.startswith("poinsot-out/plotly-")
    assert f'src="../{files[0].name}"' in page
    # the output folder gets a manifest
    manifest = re.search(r"`(\.poinsot-manifest\.json)`", section).group(1)
    assert (out / manifest).is_file()
    # every file the report links is there
    assert "Every file a report links is there" in section
    for target in re.findall(r"""(?:href|src)=["']([^"'#:]+)["']""", page):
        assert (out / target).is_file(), target
