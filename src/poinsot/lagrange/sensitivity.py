"""Forward sensitivities of a Lagrangian system's run: ``∂[q, q̇](tᵢ)/∂p`` at every sample.

A run asks for them through its spec, ``system.simulate(..., sensitivities=("q0",
"params"))``; :meth:`LagrangianSolution.sensitivity(output, wrt)
<poinsot.lagrange.solution.LagrangianSolution.sensitivity>` returns them. The directions are:

* ``"q0"``: one per coordinate given in ``q0`` (those solved from the constraints follow);
* ``"qd0"``: one per velocity given in ``qd0`` (every velocity of an unconstrained system);
* ``"params"``: one per parameter, in the order of ``system.parameters``;
* a single column of one of them: ``"q0[theta]"``, ``"qd0[x]"``, ``"params[L]"``.

The model's Jacobian ``∂[M, f, G, b, γ, g]/∂[q, q̇, p, u]`` is derived by SymPy and compiled with
the model (:func:`~poinsot.lagrange.engine.compile_tangent`); the core integrates the
differentiated KKT system with the motion, by the same method and steps
(``crates/core/src/lagrange/sensitivity.rs``). This module only names the directions; it
holds no physics.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ..sensitivity import SENSITIVE_METHODS, Sensitivities, asked_names

__all__ = ["WRT", "LagrangeDirections", "check_run", "columns", "outputs", "parse",
           "sensitivities"]  # fmt: skip

#: The parameters a Lagrangian run differentiates with respect to, and their meaning.
WRT = {
    "q0": "the coordinates given in q0 (those solved from the constraints follow them)",
    "qd0": "the velocities given in qd0 (every velocity of an unconstrained system)",
    "params": "the parameters, in the order of system.parameters",
}
_PART = re.compile(r"(q0|qd0|params)\[(.+)\]$")
_KIND = {"q0": 1, "qd0": 2}


@dataclass(frozen=True)
class LagrangeDirections:
    """The directions of a Lagrangian run's sensitivities, in the order of its columns.

    Attributes
    ----------
    names : tuple of str
        The parameters asked for, in order.
    columns : dict
        ``name → slice`` of the columns of each.
    labels : tuple of str
        One label per column (``"q0[theta]"``, ``"params[L]"``).
    kinds, components : ndarray (P,)
        Each column's start (the core's codes: 0 a parameter, 1 a coordinate, 2 a velocity)
        and the coordinate's index.
    seeds : ndarray (P, k)
        Each column's move of the parameter vector.
    """

    names: tuple
    columns: dict
    labels: tuple
    kinds: np.ndarray
    components: np.ndarray
    seeds: np.ndarray

    @property
    def size(self) -> int:
        return len(self.labels)


def check_run(solver, *, events, inputs) -> None:
    """Refuse a run that cannot carry sensitivities, before it is lowered: a method without
    them, events, inputs other than constants (``control_sensitivities`` is checked by the
    caller, :func:`~poinsot.sensitivity.check_control`)."""
    if solver.kind not in SENSITIVE_METHODS:
        raise ValueError("`sensitivities` are computed with 'rk4', 'dop853' or an explicit "
                         f"Runge–Kutta tableau; `method` {solver.name!r} has none")  # fmt: skip
    if events:
        raise ValueError("`sensitivities` and `events` cannot be combined yet")
    if inputs is not None and inputs.constant is None:
        raise ValueError("`sensitivities` need constant inputs (numbers): the derivatives of "
                         "inputs given as functions are not taken")  # fmt: skip


def parse(wrt, system) -> tuple:
    """The names of ``wrt`` (a name or a sequence of names), checked: each known, once, and
    naming a coordinate or parameter of ``system``."""
    names = asked_names(wrt)
    coords, params = _names(system)
    asked = {}  # (which, item or None) → the entry that asked for it
    for i, name in enumerate(names):
        part = _PART.match(name)
        which, item = (name, None) if part is None else part.groups()
        clash = [j for (w, it), j in asked.items()
                 if w == which and (item is None or it in (None, item))]  # fmt: skip
        if clash:
            j = clash[0]
            raise ValueError(f"`sensitivities[{i}]`: {name!r} asks again for columns of "
                             f"`sensitivities[{j}]` {names[j]!r}")  # fmt: skip
        asked[(which, item)] = i
        if name in WRT:
            if name == "params" and not params:
                raise ValueError(f"`sensitivities[{i}]`: the system has no parameters")
            continue
        if part is None:
            known = ", ".join(map(repr, WRT))
            raise ValueError(f"`sensitivities[{i}]`: unknown parameter {name!r}; known: {known}, "
                             "and one column of them: 'q0[<coordinate>]', 'qd0[<coordinate>]', "
                             "'params[<parameter>]'")  # fmt: skip
        which, item = part.groups()
        pool = params if which == "params" else coords
        if item not in pool:
            kind = "parameter" if which == "params" else "coordinate"
            raise ValueError(f"`sensitivities[{i}]`: {item!r} is not a {kind} of the system "
                             f"({', '.join(pool)})")  # fmt: skip
    return names


def columns(names, system, given_q, given_v) -> LagrangeDirections:
    """The :class:`LagrangeDirections` of the checked ``names`` for a run whose initial state
    gives the coordinates ``given_q`` and velocities ``given_v`` (bool (n,)); a coordinate or
    velocity solved from the constraints is refused, named, as a direction."""
    coords, params = _names(system)
    k = len(params)
    kinds, comps, seeds, labels, cols = [], [], [], [], {}

    def add(label, kind, comp, seed):
        labels.append(label)
        kinds.append(kind)
        comps.append(comp)
        seeds.append(seed)

    for i, name in enumerate(names):
        start = len(labels)
        part = _PART.match(name)
        which, item = (name, None) if part is None else part.groups()
        if which == "params":
            for j, p in enumerate(params):
                if item in (None, p):
                    add(f"params[{p}]", 0, 0, np.eye(k)[j])
        else:
            given = given_q if which == "q0" else given_v
            for j, c in enumerate(coords):
                if item not in (None, c):
                    continue
                if not given[j]:
                    if item is None:
                        continue  # solved from the constraints: it follows the others
                    raise ValueError(f"`sensitivities[{i}]`: {name!r} is solved from the "
                                     f"constraints, not given in {which}; give it, or omit "
                                     "another")  # fmt: skip
                add(f"{which}[{c}]", _KIND[which], j, np.zeros(k))
        if len(labels) == start:
            raise ValueError(f"`sensitivities[{i}]`: {name!r} has no column: every one of them "
                             "is solved from the constraints")  # fmt: skip
        cols[name] = slice(start, len(labels))
    return LagrangeDirections(tuple(names), cols, tuple(labels), np.array(kinds, np.int64),
                              np.array(comps, np.int64),
                              np.array(seeds, float).reshape(len(labels), k))  # fmt: skip


def _names(system) -> tuple[list, list]:
    """The names of the system's coordinates (``theta`` of ``theta(t)``) and parameters."""
    coords = [str(c.func) if hasattr(c, "func") else str(c) for c in system.coordinates]
    return coords, [str(p) for p in system.parameters]


def outputs(n) -> dict:
    """The outputs a Lagrangian sensitivity is taken of: ``q``, ``qd`` and ``state``."""
    return {"q": slice(0, n), "qd": slice(n, 2 * n), "state": slice(0, 2 * n)}


def sensitivities(y_aug, dirs, n, t0) -> tuple[np.ndarray, Sensitivities]:
    """The states (S, 2n) and :class:`~poinsot.sensitivity.Sensitivities` of augmented states
    ``[y, S (2n × P, row-major)]``, derivatives with respect to the state at ``t0``."""
    from ..sensitivity import split

    return split(y_aug, dirs, size=2 * n, outputs=outputs(n), t0=t0)
