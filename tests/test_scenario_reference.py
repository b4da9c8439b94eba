"""The scenario reference is generated from the validator and agrees with it."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from poinsot.app import scenario as sc
from poinsot.app import scenario_parts as parts
from poinsot.app.scenario_reference import USER_NAMED, collect_schema, render_reference

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def reference():
    return render_reference()


def test_checked_in_reference_is_the_generated_one(reference):
    checked_in = (ROOT / "docs" / "scenario-reference.md").read_text(encoding="utf-8")
    assert checked_in.strip() == reference.strip(), (
        "docs/scenario-reference.md is stale: regenerate it with "
        "`poinsot examples --reference > docs/scenario-reference.md`"
    )


def test_every_key_the_validator_names_is_documented(reference):
    app = ROOT / "src" / "poinsot" / "app"
    source = "\n".join((app / name).read_text(encoding="utf-8")
                       for name in ("scenario.py", "scenario_parts.py", "tables.py"))  # fmt: skip
    from poinsot.app.scenario_reference import _KINDS

    # the validator's typed reads: t.get("key", "kind", ...), t.table("key"), t.tables("key")
    typed = re.findall(r'\.get\(\s*"(\w+)",\s*"(\w+)"', source)
    literal = {key for key, kind in typed if kind in _KINDS}
    literal |= set(re.findall(r'\.tables?\(\s*"(\w+)"', source))
    assert len(literal) > 60
    documented = set(re.findall(r"\| `(\w+)` \|", reference))
    assert literal - documented == set()
    for kind in (*parts.BODY_TYPES, *parts.FORCE_TYPES):  # every variant has its section
        assert f'type = "{kind}"' in reference, kind
    for model in ("atwood", "rolling-disk", "heavy-top-euler"):
        assert f"| `{model}` |" in reference


def _keys(data, prefix=""):
    for key, value in data.items():
        if isinstance(value, dict) and not prefix.endswith(("params", "q0", "qd0")):
            yield from _keys(value, f"{prefix}{key}.")
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            for item in value:
                yield from _keys(item, f"{prefix}{key}[].")
        yield prefix, key


def test_every_key_of_the_bundled_examples_is_in_the_schema():
    schema = collect_schema()
    known = {}
    for (_, table, _), keys in schema.items():
        known.setdefault("" if table == "(top level)" else table + ".", set()).update(keys)
    for name in sc.list_examples():
        data = tomllib.loads(sc.example_text(name))
        for prefix, key in _keys(data):
            if prefix.startswith("model.") or prefix.endswith("orientation."):
                continue  # per-model names (own section); orientation tables are documented
            prefix = re.sub(r"^lagrangian\.reactions\.[^.]+\.$", "lagrangian.reactions.NAME.",
                            prefix)  # fmt: skip
            if prefix[:-1] in USER_NAMED:
                key = "NAME"  # the file's own names: a coordinate, a parameter, a point
            assert key in known.get(prefix, set()), (name, prefix, key)


def test_a_misspelt_key_is_refused_the_reference_lists_the_right_one(reference):
    with pytest.raises(sc.ScenarioError, match=r"time\.sapn: unknown key; did you mean 'span'"):
        sc.load_scenario('[model]\nname = "atwood"\n[time]\nsapn = [0, 1]\n')
    assert "| `span` | [a, b] | s | required |" in reference


def test_cli_prints_the_reference(capsys, reference):
    from poinsot.app.cli import main

    assert main(["examples", "--reference"]) == 0
    assert capsys.readouterr().out.strip() == reference.strip()
