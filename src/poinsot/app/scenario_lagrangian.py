"""A scenario's ``[lagrangian]`` table: any Lagrangian system written in the file.

The table gives the coordinates with their units, the parameters with their values (and
units), the kinetic and potential energies — or the Lagrangian, or bodies whose positions are
expressions — the holonomic, non-holonomic and one-sided constraints, the generalized forces,
named inputs (functions of t), the initial values and the reactions to report. Every
expression is text read by :func:`poinsot.expressions.parse` from its syntax tree, with only
the names the table declares: never evaluated as Python. The system is then the library's own
:class:`~poinsot.lagrange.LagrangianSystem`, wrapped in a :class:`~poinsot.models.Model` so that
it runs, reports and draws as the bundled models do (``docs/scenarios.md``)::

    [lagrangian]
    coordinates = { x = "m", theta = "rad" }            # name = unit, in order
    parameters = { M = "2 kg", m = "1 kg", l = "1 m", g = "9.81 m/s^2", k = "20 N/m" }
    kinetic = "(M + m)/2*x_dot^2 + m*l*cos(theta)*x_dot*theta_dot + m*l^2/2*theta_dot^2"
    potential = "k/2*x^2 - m*g*l*cos(theta)"
    q0 = { x = 0.1, theta = "30 deg" }
    qd0 = { x = 0, theta = 0 }
"""

from __future__ import annotations

import difflib
import math

from .tables import _MISSING, ScenarioError, _quantity, _Table

__all__ = ["build_lagrangian_model"]

#: The keys of ``[lagrangian]`` (``docs/scenario-reference.md`` lists them from the reads).
ENERGY_KEYS = ("lagrangian", "kinetic", "potential")
#: The units a coordinate may be declared in: lengths and angles, in SI (``lagrangian.q0``
#: converts a quantity such as ``"20 deg"`` or ``"5 cm"`` to them).
COORDINATE_UNITS = ("m", "rad")


def _sp():
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols

    return sp, dynamicsymbols


def _number_with_unit(value, where) -> tuple[float, str]:
    """A parameter's value: a bare number (SI, no unit known) or a quantity converted to SI
    base units, with that unit (``"2 kg"`` → (2.0, "kg"), ``"20 N/m"`` → (20.0, "kg/s²"))."""
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ScenarioError(f"{where}: expected a number or a quantity such as \"2 kg\", "
                            f"found {value!r}")  # fmt: skip
    if not isinstance(value, str):
        if not math.isfinite(value):
            raise ScenarioError(f"{where}: expected a finite number, found {value}")
        return float(value), ""
    from .tables import _registry

    try:
        ureg = _registry()
    except ImportError:
        raise ScenarioError(
            f"{where} = {value!r}: quantities with units need pint: pip install "
            "'poinsot[units]' (or give the number in SI units)"
        ) from None
    try:
        q = ureg.parse_expression(value)
    except Exception:
        q = None
    if q is None or not isinstance(q, ureg.Quantity):
        x = _quantity(value, "1", where)  # a bare number in a string, or the error message
        return x, ""
    si = q.to_base_units()
    coherent = abs(float(q.magnitude) - float(si.magnitude)) <= 1e-12 * abs(float(si.magnitude))
    shown = q if coherent else si  # "20 N/m" stays in N/m; "2000 g" becomes kg
    unit = f"{shown.units:~P}"
    return _quantity(value, str(si.units), where), unit


def _expr(text, names, where):
    from ..expressions import parse

    if isinstance(text, int | float) and not isinstance(text, bool):
        return _sp()[0].Float(text) if isinstance(text, float) else _sp()[0].Integer(text)
    try:
        return parse(text, names, where)
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None


def _exprs(t: _Table, key, names, size=None):
    """A list of expressions (``size`` of them when given)."""
    raw = t.get(key, "any_list", [] if size is None else _MISSING)
    where = t.where(key)
    if size is not None and len(raw) != size:
        raise ScenarioError(f"{where}: expected {size} expressions, found {len(raw)}")
    return [_expr(e, names, f"{where}[{i}]") for i, e in enumerate(raw)]


def build_lagrangian_model(lt: _Table, name: str, description: str):
    """The :class:`~poinsot.models.Model` of a ``[lagrangian]`` table, with its parameters'
    values, initial values and units; every error names its key path."""
    sp, _ = _sp()
    from ..lagrange import LagrangianSystem
    from ..models import Model

    # ---------------------------------------------------------------- names
    coords, units = _read_coordinates(lt)
    t = sp.Symbol("t")
    names = {"t": t}
    for cname, q in coords.items():
        names[cname] = q
        names[f"{cname}_dot"] = q.diff(t)
    hidden_tables = lt.tables("hidden")
    aux = _read_auxiliary_coordinates(hidden_tables, names, t)
    params, param_units, symbols = _read_parameters(lt, names)
    _read_inputs(lt, names, symbols, t)
    # ---------------------------------------------------------------- the system
    kwargs = _read_energies(lt, names)
    bodies, points, positive = _read_bodies(lt, names)
    if not (kwargs or bodies):
        raise ScenarioError(f"{lt.path}: give kinetic (and potential) energy, the lagrangian, or "
                            "[[lagrangian.bodies]]")  # fmt: skip
    constraints = {key: _exprs(lt, key, names) for key in ("holonomic", "nonholonomic",
                                                           "unilateral")}  # fmt: skip
    forces = _read_forces(lt, coords, names)
    hidden = _read_hidden(hidden_tables, aux, {"t": t, **symbols, **coords})
    try:
        system = LagrangianSystem(list(coords.values()), bodies=bodies, forces=forces,
                                  units=units, hidden=hidden, **kwargs,
                                  **constraints)  # fmt: skip
    except (ValueError, TypeError) as exc:
        raise ScenarioError(f"{lt.path}: {exc}") from None
    # ---------------------------------------------------------------- initial values, reports
    q0 = _values(lt, "q0", coords, units, "")
    qd0 = _values(lt, "qd0", coords, units, "/s")
    guess = _values(lt, "guess", coords, units, "")
    reactions = _read_reactions(lt, names, system)
    points, links, outline, view, trail = _read_drawing(lt, names, symbols, t, points)
    _check_positive(positive, params)
    # every parameter has an effect or is refused; the system takes those of its equations,
    # the others (a drawing's size, a reaction's factor) are put in as numbers where used
    used = _free_symbols(kwargs, bodies, constraints, forces, hidden, reactions, points,
                         outline)  # fmt: skip
    for pname, sym in symbols.items():
        if sym in params and sym not in used:
            raise ScenarioError(f"{lt.where('parameters')}.{pname}: used by nothing (not by the "
                                "energies, the bodies, the constraints, the forces, the "
                                "reactions or the drawing): remove it")  # fmt: skip
    taken = set(system.parameters)
    fixed = {sym: sp.Float(v) for sym, v in params.items() if sym not in taken}
    if fixed:
        reactions = {k: (e.xreplace(fixed), u, m) for k, (e, u, m) in reactions.items()}
        points = {k: tuple(sp.sympify(c).xreplace(fixed) for c in p) for k, p in points.items()}
        outline = {k: [tuple(sp.sympify(c).xreplace(fixed) for c in v) for v in vs]
                   for k, vs in outline.items()}  # fmt: skip
    params = {sym: v for sym, v in params.items() if sym in taken}
    param_units = {sym: u for sym, u in param_units.items() if sym in taken}
    return Model(name, description, system, {**coords, **symbols}, params, q0, qd0,
                 guess=guess, reactions=reactions, points=points, links=links, outline=outline,
                 view=view, trail=trail, param_units=param_units)  # fmt: skip


def _free_symbols(*objects) -> set:
    """The free symbols of every expression in ``objects`` (expressions, matrices, bodies,
    hidden constraints, and lists, tuples and dicts of them)."""
    sp, _ = _sp()
    out, stack = set(), list(objects)
    while stack:
        obj = stack.pop()
        if isinstance(obj, sp.Basic | sp.MatrixBase):
            out |= obj.free_symbols
        elif isinstance(obj, dict):
            stack += list(obj.values())
        elif isinstance(obj, list | tuple):
            stack += list(obj)
        elif isinstance(obj, int | float | str) or obj is None:
            continue
        else:  # a point mass, a rigid body's namespace, a hidden constraint
            stack += [v for v in getattr(obj, "__dict__", {}).values() if not callable(v)]
    return out


def _check_positive(positive, params):
    """The bodies' masses and moments of inertia, ``(where, expression or matrix)``, positive
    (a matrix: symmetric, positive definite) once the parameters' values are put in; one that
    still depends on the coordinates or the time is not checked."""
    import numpy as np

    sp, _ = _sp()
    values = {sym: sp.Float(v) for sym, v in params.items()}
    for where, expr in positive:
        x = expr.xreplace(values)
        if isinstance(x, sp.MatrixBase):
            if not all(c.is_number for c in x):
                continue
            A = np.array(x.evalf(), dtype=float)
            if not np.allclose(A, A.T, rtol=1e-12, atol=0.0):
                raise ScenarioError(f"{where}: an inertia matrix must be symmetric, found "
                                    f"{A.tolist()}")  # fmt: skip
            moments = np.linalg.eigvalsh(A)
            if not moments.min() > 0:
                raise ScenarioError(f"{where}: an inertia matrix must be positive definite "
                                    f"(principal moments > 0), found principal moments "
                                    f"{moments.tolist()} with the parameters' values")  # fmt: skip
        elif x.is_number and not float(x) > 0:
            raise ScenarioError(f"{where}: must be positive, found {expr} = {float(x):g} with "
                                "the parameters' values")  # fmt: skip


def _read_coordinates(lt: _Table):
    """The ``coordinates`` table: ``{name: dynamic symbol}`` and ``{symbol: unit}``, in order;
    at least one."""
    _, dynamicsymbols = _sp()
    coord_table = lt.table("coordinates")
    coords, units = {}, {}
    for cname in coord_table.data:
        unit = coord_table.get(cname, "string")
        _check_name(cname, coord_table.where(cname))
        if unit not in COORDINATE_UNITS:  # the equations are integrated in SI units
            example = f'q0 = {{ {cname} = "20 {unit.strip()}" }}' if unit.strip() else "q0"
            raise ScenarioError(
                f"{coord_table.where(cname)}: a coordinate's unit must be "
                f"{' or '.join(map(repr, COORDINATE_UNITS))} (the equations are integrated in "
                f"SI units), found {unit!r}; initial values may still be given in another "
                f"unit as quantities, converted ({example})"
            )
        q = dynamicsymbols(cname)
        coords[cname], units[q] = q, unit
    coord_table.finish()
    if not coords:
        raise ScenarioError(f"{lt.where('coordinates')}: give at least one coordinate")
    return coords, units


def _read_auxiliary_coordinates(hidden_tables, names, t):
    """The auxiliary coordinates of the ``[[hidden]]`` tables, named (with their speeds) in
    ``names`` before any expression is read; ``{name: dynamic symbol}``."""
    _, dynamicsymbols = _sp()
    aux = {}
    for ht in hidden_tables:
        aname = ht.get("coordinate", "string")
        _check_name(aname, ht.where("coordinate"), taken=names)
        aux[aname] = dynamicsymbols(aname)
        names[aname], names[f"{aname}_dot"] = aux[aname], aux[aname].diff(t)
    return aux


def _read_parameters(lt: _Table, names):
    """The ``parameters`` table, each a symbol added to ``names``: their SI values, their units
    and ``{name: symbol}``."""
    sp, _ = _sp()
    param_table = lt.table("parameters", None)
    params, param_units, symbols = {}, {}, {}
    for pname in param_table.data:
        _check_name(pname, param_table.where(pname), taken=names)
        param_table._record(pname, "quantity", None)
        param_table.used.add(pname)
        value, unit = _number_with_unit(param_table.data[pname], param_table.where(pname))
        sym = sp.Symbol(pname, positive=True) if value > 0 else sp.Symbol(pname, real=True)
        names[pname] = symbols[pname] = sym
        params[sym], param_units[sym] = value, unit
    param_table.finish()
    return params, param_units, symbols


def _read_inputs(lt: _Table, names, symbols, t):
    """The ``inputs`` table: each a function of t and the parameters, added to ``names`` and
    ``symbols``."""
    input_table = lt.table("inputs", None)
    for iname in input_table.data:
        _check_name(iname, input_table.where(iname), taken=names)
        text = input_table.get(iname, "string")
        expr = _expr(text, {"t": t, **symbols}, input_table.where(iname))
        names[iname] = symbols[iname] = expr
    input_table.finish()


def _read_energies(lt: _Table, names):
    """The Lagrangian, or the kinetic and potential energies, as keyword arguments of
    :class:`~poinsot.lagrange.LagrangianSystem`; not both."""
    given = [k for k in ENERGY_KEYS if lt.has(k)]
    kwargs = {}
    if "lagrangian" in given and len(given) > 1:
        raise ScenarioError(f"{lt.where('lagrangian')}: give the Lagrangian, or kinetic and "
                            "potential energies, not both")  # fmt: skip
    for key in ENERGY_KEYS:
        if lt.has(key):
            kwargs[key] = _expr(lt.get(key, "expression"), names, lt.where(key))
    return kwargs


def _read_bodies(lt: _Table, names):
    """The ``[[bodies]]``, point masses or rigid bodies, the named ones' positions as points
    to draw, and ``(key path, expression)`` of the masses and inertia matrices, to be positive
    (:func:`_check_positive`)."""
    from ..lagrange import PointMass

    bodies, points, positive = [], {}, []
    for bt in lt.tables("bodies"):
        kind = bt.get("type", "string", "point", choices=("point", "rigid"))
        label = bt.get("name", "string", None)  # named: drawn as a point of the mechanism
        mass = _expr(bt.get("mass", "expression"), names, bt.where("mass"))
        positive.append((bt.where("mass"), mass))
        position = _exprs(bt, "position", names, 3)
        if kind == "point":
            bodies.append(PointMass(mass, position))
        else:  # T = ½ M |Ṙ|² + ½ ωᵀ A ω, ω from the orientation (the library forms it)
            bodies.append(_rigid(bt, mass, position, names))
            positive.append((bt.where("inertia"), bodies[-1][0].inertia))
        bt.finish()
        if label is not None:
            points[label] = tuple(position)
    return bodies, points, positive


def _read_forces(lt: _Table, coords, names):
    """The ``forces`` table: one ``{coordinate: generalized force}`` per entry."""
    force_table = lt.table("forces", None)
    forces = []
    for cname in force_table.data:
        if cname not in coords:
            raise ScenarioError(_unknown(force_table.where(cname), cname, coords, "coordinate"))
        text = force_table.get(cname, "expression")
        forces.append({coords[cname]: _expr(text, names, force_table.where(cname))})
    force_table.finish()
    return forces


def _read_hidden(hidden_tables, aux, fixed):
    """The :class:`~poinsot.lagrange.HiddenConstraint` of each ``[[hidden]]`` table, its value
    an expression of ``fixed`` (t, the parameters and the coordinates)."""
    from ..lagrange import HiddenConstraint

    hidden = []
    for ht, (aname, rho) in zip(hidden_tables, aux.items(), strict=True):
        value = _expr(ht.get("value", "expression"), fixed, ht.where("value"))
        hidden.append(HiddenConstraint(
            rho, value, ht.get("name", "string", f"force holding {aname}"),
            ht.get("unit", "string", "N"), ht.get("sign", "number", 1.0),
            ht.get("meaning", "string", "")))  # fmt: skip
        if hidden[-1].sign not in (1.0, -1.0):
            raise ScenarioError(f"{ht.where('sign')}: expected 1 or -1, found {hidden[-1].sign}")
        ht.finish()
    return hidden


def _read_reactions(lt: _Table, names, system):
    """The ``reactions`` to report: ``{name: (expression, unit, meaning)}``, the expressions
    also of the multipliers ``lambda1``, ``lambda2``, ..."""
    lam = {f"lambda{k + 1}": v for k, v in enumerate(system.lam_vec)}
    reactions = {}
    rt = lt.table("reactions", None)
    for rname in rt.data:
        entry = rt.table(rname)
        expr = _expr(entry.get("expression", "expression"), {**names, **lam},
                     entry.where("expression"))  # fmt: skip
        reactions[rname] = (expr, entry.get("unit", "string", ""),
                            entry.get("meaning", "string", ""))  # fmt: skip
        entry.finish()
    rt.finish()
    return reactions


def _read_drawing(lt: _Table, names, symbols, t, points):
    """The ``draw`` table, with the bodies' named ``points``: the points, links, outline, view
    and trail of the mechanism's drawing."""
    sp, _ = _sp()
    draw = lt.table("draw", None)
    extra = draw.table("points", None)
    for pname in extra.data:
        extra.used.add(pname)
        points[pname] = tuple(_exprs(extra, pname, names, 3))
    extra.finish()
    ring_links = _read_rings(draw, names, points)
    links = tuple(tuple(pair) for pair in draw.get("links", "any_list", []))
    for i, pair in enumerate(links):
        if len(pair) != 2 or any(p not in points for p in pair):
            raise ScenarioError(
                f"{draw.where('links')}[{i}]: expected two of the points "
                f"{', '.join(points) or '(none)'}, found {list(pair)!r}"
            )
    outline = _read_outline(draw, {"t": t, **symbols})
    trail = draw.get("trail", "string", None)
    if trail is not None and trail not in points:
        raise ScenarioError(_unknown(draw.where("trail"), trail, points, "point"))
    links += tuple(ring_links)
    flat = all(sp.sympify(p[2]) == 0 for p in points.values())
    view = draw.get("view", "string", "xy" if flat else "3d", choices=("xy", "3d"))
    draw.finish()
    return points, links, outline, view, trail


def _read_rings(draw: _Table, names, points):
    """The ``[[draw.rings]]``, circles drawn as polygons (a rim, a hoop): their vertices added
    to ``points``; returns their links."""
    ring_links = []
    for rt_ in draw.tables("rings"):
        from ..models import _ring

        rname = rt_.get("name", "string")
        ring, rl = _ring(rname, _exprs(rt_, "center", names, 3), _exprs(rt_, "u", names, 3),
                         _exprs(rt_, "v", names, 3),
                         _expr(rt_.get("radius", "expression"), names, rt_.where("radius")),
                         k=rt_.get("sides", "int", 24))  # fmt: skip
        rt_.finish()
        points |= ring
        ring_links += rl
    return ring_links


def _read_outline(draw: _Table, fixed):
    """The ``draw.outline`` table: ``{name: [vertex, ...]}``, each vertex three expressions of
    ``fixed`` (t and the parameters)."""
    outline = {}
    ot = draw.table("outline", None)
    for oname in ot.data:
        vertices = ot.get(oname, "any_list")
        outline[oname] = [tuple(_expr(c, fixed, f"{ot.where(oname)}[{i}][{j}]")
                                for j, c in enumerate(_three(v, f"{ot.where(oname)}[{i}]")))
                          for i, v in enumerate(vertices)]  # fmt: skip
    ot.finish()
    return outline


def _rigid(bt: _Table, mass, position, names):
    """A rigid body's ``(body, position, orientation)``: ``inertia`` about its centre of mass in
    its own axes (three principal moments, or a 3×3 array), ``orientation`` = ``{ euler =
    [three angles], seq = "ZXZ" }``, the axes' rotations applied in order, each about the
    turned axis (intrinsic, as :func:`poinsot.rotation.matrix_from_euler`)."""
    from types import SimpleNamespace

    sp, _ = _sp()
    raw = bt.get("inertia", "any_list")
    where = bt.where("inertia")
    if len(raw) == 3 and all(not isinstance(r, list) for r in raw):
        A = sp.diag(*(_expr(v, names, f"{where}[{i}]") for i, v in enumerate(raw)))
    elif len(raw) == 3 and all(isinstance(r, list) and len(r) == 3 for r in raw):
        A = sp.Matrix([[_expr(v, names, f"{where}[{i}][{j}]") for j, v in enumerate(row)]
                       for i, row in enumerate(raw)])  # fmt: skip
    else:
        raise ScenarioError(f"{where}: expected three principal moments or a 3×3 array")
    ot = bt.table("orientation")
    seq = ot.get("seq", "string", "ZXZ")
    if len(seq) != 3 or any(c not in "XYZ" for c in seq):
        raise ScenarioError(f"{ot.where('seq')}: expected three of X, Y, Z such as 'ZXZ', "
                            f"found {seq!r}")  # fmt: skip
    angles = _exprs(ot, "euler", names, 3)
    ot.finish()
    Q = sp.eye(3)
    for axis, angle in zip(seq, angles, strict=True):
        c, s_ = sp.cos(angle), sp.sin(angle)
        R = {"X": sp.Matrix([[1, 0, 0], [0, c, -s_], [0, s_, c]]),
             "Y": sp.Matrix([[c, 0, s_], [0, 1, 0], [-s_, 0, c]]),
             "Z": sp.Matrix([[c, -s_, 0], [s_, c, 0], [0, 0, 1]])}[axis]  # fmt: skip
        Q = Q * R
    return (SimpleNamespace(mass=mass, inertia=A), position, Q)


def _three(value, where):
    if not isinstance(value, list) or len(value) != 3:
        raise ScenarioError(f"{where}: expected a point [x, y, z], found {value!r}")
    return value


def _values(lt: _Table, key, coords, units, per):
    """``q0`` or ``qd0``: ``{coordinate: value}``, each in its coordinate's unit (``per`` = "/s"
    for the speeds); a quantity with a unit is converted to it."""
    from .scenario import _si

    table = lt.table(key, None)
    out = {}
    for cname in table.data:
        if cname not in coords:
            raise ScenarioError(_unknown(table.where(cname), cname, coords, "coordinate"))
        unit = units[coords[cname]]
        out[coords[cname]] = table.get(cname, "number", unit=_si(unit + per) if unit else None)
    table.finish()
    return out


def _check_name(name, where, taken=None):
    """A name an expression can use: an identifier, not a function, constant or taken name."""
    from ..expressions import TEXT_CONSTANTS, TEXT_FUNCTIONS

    if not name.isidentifier() or name.startswith("_") or name.startswith("lambda"):
        raise ScenarioError(f"{where}: {name!r} cannot name a quantity (letters, digits and _, "
                            "not starting with _ or 'lambda')")  # fmt: skip
    if name in TEXT_FUNCTIONS or name in TEXT_CONSTANTS or name == "t":
        raise ScenarioError(f"{where}: {name!r} is taken (a function, a constant or the time)")
    if taken is not None and name in taken:
        raise ScenarioError(f"{where}: {name!r} is already a coordinate, a speed or a name")


def _unknown(where, name, known, what):
    near = difflib.get_close_matches(name, list(known), n=1, cutoff=0.5)
    hint = f"; did you mean {near[0]!r}?" if near else f"; the {what}s: {', '.join(known)}"
    return f"{where}: unknown {what}{hint}"
