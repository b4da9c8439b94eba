"""The scenario file reference, generated from the validator itself.

The validator in :mod:`poinsot.app.scenario` declares every key where it reads it (its table, the
``type`` it belongs to, the kind of value, the default, the allowed values). This module turns
on its recorder, loads the bundled examples and a set of probe scenarios that between them
take every branch of the validator (every body type, force, carrier rotation, ensemble
distribution and model), and renders what was read as Markdown. ``docs/scenario-reference.md``
is that output, and a test checks that the two agree; ``poinsot examples --reference`` prints
it from the installed package.
"""

from __future__ import annotations

import re

__all__ = ["collect_schema", "render_reference"]

_PARTICLE = "[[body.particles]]\nmass = 1.0\nposition = [0.0, 0.0, 0.0]\n"
_TIME = "[time]\nspan = [0.0, 1.0]\n"

#: Scenarios that take the validator's branches the bundled examples do not.
PROBES = (
    '[body]\ntype = "particles"\n' + _PARTICLE + "[[body.particles]]\nmass = 1.0\n"
    "position = [1.0, 0.0, 0.0]\n[[body.particles]]\nmass = 1.0\nposition = [0.0, 1.0, 0.0]\n"
    "[initial]\nparticle_velocities = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]\n"
    + _TIME,
    '[body]\ntype = "box"\nmass = 1.0\nsize = [1.0, 2.0, 3.0]\nposition = [0.0, 0.0, 0.0]\n'
    'orientation = { euler = [0.0, 0.1, 0.0], seq = "ZXZ", degrees = false }\n'
    '[initial]\nomega = [0.0, 1.0, 0.0]\nomega_frame = "body"\nposition = [0.0, 0.0, 0.0]\n'
    "velocity = [0.0, 0.0, 0.0]\n"
    '[[forces]]\ntype = "central_gravity"\nmu = 1.0\ncenter = [0.0, 0.0, -10.0]\n'
    "gradient = true\n"
    '[[forces]]\ntype = "spring"\npoint = [0.5, 0.0, 0.0]\nanchor = [1.0, 0.0, 0.0]\n'
    "stiffness = 1.0\nrest_length = 0.0\ndamping = 0.0\ntether = false\n"
    '[[forces]]\ntype = "linear_drag"\ncoefficient = 0.1\nrotational = 0.0\n'
    '[[forces]]\ntype = "quadratic_drag"\ncoefficient = 0.1\nrotational = 0.0\n'
    '[[forces]]\ntype = "point_force"\npoint = [0.0, 0.0, 0.5]\nforce = [1.0, 0.0, 0.0]\n'
    'frame = "space"\n'
    '[[forces]]\ntype = "torque"\ntorque = [0.0, 0.0, 0.1]\nframe = "body"\n'
    '[integrator]\nmethod = "dop853"\nrtol = 1e-8\natol = 1e-10\n'
    "[time]\nspan = [0.0, 1.0]\nsamples = 11\n[output]\ndata = true\nfigures = true\n"
    "report = true\n[analysis]\npolhodes = true\nlevels = 5\n",
    *(
        f'[body]\ntype = "{kind}"\nmass = 1.0\n{extra}\n[initial]\nomega = [0.0, 1.0, 0.0]\n'
        + _TIME
        for kind, extra in (
            ("sphere", "radius = 1.0"),
            ("spherical_shell", "radius = 1.0"),
            ("cylinder", "radius = 1.0\nheight = 1.0"),
            ("ellipsoid", "semi_axes = [1.0, 2.0, 3.0]"),
            ("rod", "length = 1.0"),
            ("cone", "radius = 1.0\nheight = 1.0"),
            (
                "mass_properties",
                "inertia = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]\n"
                "center_of_mass = [0.0, 0.0, 0.0]\nallow_unphysical = false",
            ),
            ("mesh", 'path = "a-mesh-that-is-not-there.stl"\ndensity = 1.0'),
        )
    ),
    '[body]\ntype = "composite"\n[[body.parts]]\ntype = "sphere"\nmass = 1.0\nradius = 1.0\n'
    "position = [0.0, 0.0, 1.0]\n[initial]\nomega = [0.0, 1.0, 0.0]\n" + _TIME,
    '[body]\ntype = "box"\nmass = 1.0\nsize = [1.0, 2.0, 3.0]\n[initial]\n'
    'omega = [0.0, 1.0, 0.0]\n[ensemble]\nmembers = 4\ndistribution = "sphere"\nspeed = 1.0\n'
    "seed = 0\nkeep_states = true\nchunk_size = 2\nthreads = 1\n" + _TIME,
    '[body]\ntype = "box"\nmass = 1.0\nsize = [1.0, 2.0, 3.0]\n[initial]\n'
    'omega = [0.0, 1.0, 0.0]\n[ensemble]\nmembers = 4\ndistribution = "gaussian"\n'
    "mean = [0.0, 1.0, 0.0]\nstd = [0.1, 0.0, 0.1]\n" + _TIME,
    '[body]\ntype = "box"\nmass = 1.0\nsize = [1.0, 2.0, 3.0]\n[initial]\n'
    'omega = [0.0, 1.0, 0.0]\n[carrier]\neuler_angles = ["0.1*t", "0.2", "0"]\n'
    "balance_transport = true\n" + _TIME,
    '[model]\nname = "pendulum-cartesian"\nparams = { m = 1.0 }\nq0 = { x = 0.0, y = -1.0 }\n'
    'qd0 = { x = 0.0, y = 0.0 }\n[integrator]\nmethod = "dop853"\n'
    'stabilization = "baumgarte"\n' + _TIME,
    '[lagrangian]\ncoordinates = { x = "m" }\nparameters = { m = "1 kg", c = 0.5 }\n'
    'inputs = { u = "sin(t)" }\nkinetic = "m*x_dot^2/2"\nforces = { x = "u - c*x_dot" }\n'
    "q0 = { x = 0.0 }\n[lagrangian.draw]\noutline = { wall = [[0, 0, 0], [0, 1, 0]] }\n" + _TIME,
)

_KINDS = {
    "number": "number",
    "positive": "number > 0",
    "nonnegative": "number ≥ 0",
    "int": "integer ≥ 1",
    "bool": "true or false",
    "string": "string",
    "vector3": "[x, y, z]",
    "vector4": "[w, x, y, z]",
    "vector2": "[a, b]",
    "vector": "array of numbers",
    "expressions3": "[e1, e2, e3]: numbers or expressions in t",
    "matrix3": "3×3 array",
    "vectors3": "array of [x, y, z]",
    "table": "table",
    "tables": "array of tables",
    "orientation": "[w, x, y, z], a 3×3 matrix, or { euler = [..], seq, degrees }",
    "expression": "expression (text) or number",
    "any_list": "array",
    "quantity": 'number, or quantity ("2 kg")',
}


#: Tables of ``[lagrangian]`` whose keys are the file's own names (a coordinate, a
#: parameter, a reaction, a point), listed as one row ``NAME``.
USER_NAMED = (
    "lagrangian.coordinates", "lagrangian.parameters", "lagrangian.inputs", "lagrangian.forces",
    "lagrangian.q0", "lagrangian.qd0", "lagrangian.guess", "lagrangian.reactions",
    "lagrangian.draw.points", "lagrangian.draw.outline",
)  # fmt: skip


def collect_schema() -> dict:
    """``{(scenario kind, table, variant): {key: Key}}`` in the order the validator reads them,
    over the bundled examples and :data:`PROBES`. A key is *required* when the validator
    reads it without a default every time it reads its table, *conditional* when it does so
    only in some scenarios (one of two alternatives, a key of a present table)."""
    from . import scenario as sc
    from . import tables as reader

    schema, visits, seen = {}, {}, {}
    texts = [sc.example_text(name) for name in sc.list_examples()] + list(PROBES)
    for text in texts:
        records = []
        reader._SCHEMA_RECORDER = records
        try:
            sc.load_scenario(text)
        except sc.ScenarioError:
            pass  # a probe may stop at a check after its keys were read (the mesh file)
        finally:
            reader._SCHEMA_RECORDER = None
        kind = (
            "constrained model"
            if re.search(r"^\[(model|lagrangian)\]", text, re.M)
            else "rigid body"
        )
        tables = set()
        for path, variant, key, vkind, default, choices, unit in records:
            table = re.sub(r"\[\d+\]", "[]", path) or "(top level)"
            table = re.sub(r"^lagrangian\.reactions\..+$", "lagrangian.reactions.NAME", table)
            if table in USER_NAMED:  # keys the file names itself: one row, NAME
                key = "NAME"
            if table.startswith("model.") or key == "type":
                variant = None if key == "type" else variant
            where = (kind, table, variant)
            tables.add(where)
            entry = schema.setdefault(where, {})
            entry.setdefault(key, []).append((vkind, default, choices, unit))
            seen.setdefault((where, key), set()).add(id(text))
        for where in tables:
            visits.setdefault(where, set()).add(id(text))
    order = list(schema)  # first reads; variants of one table are kept together
    first = {}
    for kind, table, _ in order:
        first.setdefault((kind, table), len(first))
    pos = {w: i for i, w in enumerate(order)}
    kinds = {}
    for kind, _, _ in order:  # one section per kind of scenario, in the order first met
        kinds.setdefault(kind, len(kinds))
    order.sort(key=lambda w: (kinds[w[0]], first[(w[0], w[1])], w[2] is not None, pos[w]))
    out = {}
    for where in order:
        keys = schema[where]
        if where[1].startswith("model."):
            continue  # the models' own names: rendered from poinsot.models, as they are read
        out[where] = {}
        for key, reads in keys.items():
            always = seen[(where, key)] == visits[where]
            out[where][key] = (reads, always)
    return out


def _default(default, missing) -> str:
    if default is missing:
        return "required"
    if default is None or (isinstance(default, tuple) and not default):
        return "optional"
    try:
        import numpy as np

        if isinstance(default, np.ndarray):
            return "default " + "[" + ", ".join(f"{x:g}" for x in default.ravel()) + "]"
    except ImportError:  # pragma: no cover
        pass
    if isinstance(default, bool):
        return f"default {str(default).lower()}"
    if isinstance(default, str):
        return f'default "{default}"'
    return f"default {default}"


def _requirement(reads, always, missing) -> str:
    defaults = {repr(d) for _, d, _, _ in reads}
    if all(d is missing for _, d, _, _ in reads):
        return "required" if always else "conditional"
    if len(defaults) > 1:
        return "optional (default depends on the scenario)"
    return _default(reads[0][1], missing)


def _models_section() -> list[str]:
    """``[model]``'s names, parameters and coordinates, from :mod:`poinsot.models` (where the
    validator takes them)."""
    from .. import models

    lines = ["## `model.params`, `model.q0`, `model.qd0`", "",
             "The keys are the model's own parameter and coordinate names (any subset; the rest "
             "keep the model's defaults); a value may carry its unit (`\"30 deg\"`), converted "
             "to the unit shown (`qd0` in that unit per second):", "",
             "| `model.name` | `params` (numbers) | `q0`, `qd0` (coordinates) |",
             "| --- | --- | --- |"]  # fmt: skip
    for name, build in models.MODELS.items():
        model = build()
        system = model.system
        params = ", ".join(f"`{p}` [{model.unit_of_parameter(p) or '—'}]"
                           for p in system.parameters)  # fmt: skip
        coords = ", ".join(
            f"`{str(q).replace('(t)', '')}` [{system.unit_of(q) or '—'}]"
            for q in system.coordinates
        )
        lines.append(f"| `{name}` | {params} | {coords} |")
    return [*lines, ""]


def render_reference() -> str:
    """The Markdown reference of every key of a scenario file."""
    from .scenario import _MISSING

    schema = collect_schema()
    lines = [
        "# Scenario file reference",
        "",
        "Generated from the validator by `poinsot.app.scenario_reference` (print it with",
        "`poinsot examples --reference`); `tests/test_scenario_reference.py` checks that this",
        "file is its current output. How to write a scenario is in",
        "[`docs/scenarios.md`](scenarios.md); `poinsot examples --show NAME` prints a bundled",
        "one as a template. Bare numbers are SI (kg, m, s, rad, N); a key with a unit also takes",
        'a quantity written with its unit, such as `"100 rpm"`, `"34.4 deg"` or',
        '`"1.5 g/cm^3"` (parsed by pint: the `units` extra), converted to the unit shown and',
        "echoed in `summary.json` under `scenario.quantities`. A table may hold only the keys",
        "listed, and a misspelt key is refused with a suggestion. *conditional*: required in",
        "some cases only (one of two alternatives, such as `initial.omega` or",
        "`initial.particle_velocities`; a key of a table that is itself optional).",
        "",
    ]
    current = None
    for (kind, table, variant), keys in schema.items():
        if kind != current:
            lines += [f"# A {kind} scenario", ""]
            current = kind
        title = f"`{table}`" + (f' with `type = "{variant}"`' if variant else "")
        lines += [f"## {title}", "", "| key | value | unit | required / default | allowed |",
                  "| --- | --- | --- | --- | --- |"]  # fmt: skip
        for key, (reads, always) in keys.items():
            kind_ = reads[0][0]
            choices = sorted({c for _, _, ch, _ in reads if ch for c in ch},
                             key=lambda c: next(i for _, _, ch, _ in reads if ch
                                                for i, x in enumerate(ch) if x == c))  # fmt: skip
            allowed = ", ".join(f"`{c}`" for c in choices)
            units = sorted({u for _, _, _, u in reads if u})
            unit = " or ".join(units) if units else ""
            lines.append(f"| `{key}` | {_KINDS.get(kind_, kind_)} | {unit} | "
                         f"{_requirement(reads, always, _MISSING)} | {allowed} |")  # fmt: skip
        lines.append("")
        if table == "model":
            lines += _models_section()
    return "\n".join(lines)
