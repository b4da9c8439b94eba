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
