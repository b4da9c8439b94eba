"""Scenario files (TOML): a body, its forces, initial conditions, integrator, time and outputs.

Everything is validated before anything runs. An error names the key path, what was expected
and what was found — ``body.particles[3].mass: expected a positive number, found -1`` — and an
unknown key is refused with the nearest valid key suggested. Units are SI. The reference of
every key and its default is ``docs/scenarios.md``; bundled examples live in
``poinsot/app/scenarios/``.
"""

from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from .._io import TOMLError, read_toml
from ..simulation import METHODS as RIGID_METHODS
from ..simulation import StepBudgetError
from .scenario_parts import (
    MAX_LEVELS,
    MAX_SAMPLES,
    _orientation,
    build_body,
    build_force,
)
from .tables import _MISSING, ScenarioError, _Table

__all__ = [
    "LagrangianScenario",
    "Scenario",
    "ScenarioError",
    "example_text",
    "list_examples",
    "load_example",
    "load_scenario",
]

#: The methods a scenario may name: the rigid body's front-end's (the core's registry).
METHOD_NAMES = RIGID_METHODS


@dataclass
class Scenario:
    """A validated scenario, ready to run."""

    name: str
    description: str
    body: object
    forces: list
    pivot: np.ndarray | None
    initial: dict
    method: str
    dt: float | None
    rtol: float | None
    atol: float | None
    t_span: tuple[float, float]
    samples: int
    outputs: dict = field(default_factory=dict)
    analysis: dict = field(default_factory=dict)
    source: str = "<built-in>"
    ensemble: dict | None = None
    carrier: dict | None = None
    #: The run, checked and lowered once when the file is read
    #: (:func:`poinsot.simulation.prepare`; :func:`poinsot.ensemble.prepare_ensemble` for an
    #: ensemble, :func:`poinsot.relative.prepare_relative` for a motion relative to a
    #: carrier), and its initial state.
    prepared: object = field(default=None, repr=False, compare=False)
    y0: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: values given with a unit: key path → {"given", "value" (SI), "unit"}
    quantities: dict = field(default_factory=dict)

    @property
    def t_eval(self):
        return np.linspace(self.t_span[0], self.t_span[1], self.samples)

    def ensemble_omegas(self) -> np.ndarray:
        """The ensemble's initial angular velocities (members, 3), drawn as ``[ensemble]``
        states (body frame)."""
        from ..ensemble import sampling

        e = self.ensemble
        if e["distribution"] == "sphere":
            return sampling.uniform_on_sphere(e["members"], e["speed"], e["seed"])
        return sampling.gaussian(e["members"], e["mean"], e["std"], e["seed"])

    def simulate_ensemble(self, progress=None):
        """Run the ensemble of ``[ensemble]``, prepared when the file was read: an
        :class:`~poinsot.ensemble.EnsembleResult` sampled at the scenario's times (final
        states only with ``keep_states = false``)."""
        e = self.ensemble
        initial = {k: v for k, v in self.initial.items() if k in ("Q0", "R0", "V0")}
        return self.prepared.run(omega0=self.ensemble_omegas(), chunk_size=e["chunk_size"],
                                 threads=e["threads"], progress=progress,
                                 **initial)  # fmt: skip

    def simulate(self, progress=None, *, method=None):
        """Run the simulation prepared when the file was read: a
        :class:`~poinsot.trajectory.Trajectory`. ``method`` replaces the scenario's integrator
        (same step or tolerances), to compare methods on one problem; nothing is lowered or
        checked again."""
        run = self.prepared if method is None else self.prepared.with_method(method)
        return run.run(y0=self.y0, progress=progress)

    def simulate_relative(self, progress=None):
        """Run the motion relative to ``[carrier]``, prepared when the file was read: the
        initial state is relative to the carrier (``omega`` = ω_r, body frame;
        ``orientation`` = Q_r; ``position``, ``velocity`` relative to the carrier's origin)."""
        return self.prepared.run(y0=self.y0, progress=progress)


class EnsembleScenario(Scenario):
    """A scenario with ``[ensemble]``: many initial spins of one body
    (:meth:`simulate_ensemble`)."""


class RelativeScenario(Scenario):
    """A scenario with ``[carrier]``: the body's motion relative to a moving frame."""

    def simulate(self, progress=None, *, method=None):
        """Run the motion relative to ``[carrier]``: a
        :class:`~poinsot.relative.RelativeTrajectory` (:meth:`simulate_relative`; it runs with
        the scenario's own integrator, ``method`` is not used)."""
        del method
        return self.simulate_relative(progress)


#: The ways ``[carrier]`` may give the carrier's rotation (``docs/scenarios.md``).
CARRIER_ROTATIONS = ("omega_e", "euler_angles")


def _expressions(t: _Table, key):
    """Three numbers or expressions in t (strings) of ``[carrier]``."""
    value = t.get(key, "expressions3", None)
    return value


def _carrier(ct: _Table, initial: dict, pivot) -> dict:
    """``[carrier]``: the carrier's rotation (``omega_e`` or ``euler_angles``, numbers or
    expressions in t), ``origin_acceleration``, ``balance_transport``, ``hold_com``."""
    from ..relative import Carrier

    given = [k for k in CARRIER_ROTATIONS if ct.has(k)]
    if len(given) != 1:
        raise ScenarioError(
            f"{ct.where(CARRIER_ROTATIONS[0])}: give the carrier's rotation as exactly one of "
            f"{', '.join(CARRIER_ROTATIONS)}, found {', '.join(given) or 'none'}"
        )
    key = given[0]
    rotation = _expressions(ct, key)
    accel = _expressions(ct, "origin_acceleration")
    options = {
        "balance_transport": ct.get("balance_transport", "bool", False),
        "hold_com": ct.get("hold_com", "bool", False),
    }
    ct.finish()
    if pivot is not None:
        raise ScenarioError(
            f"{ct.where(key)}: a body with a pivot cannot move relative to a carrier"
        )
    if initial.get("omega_frame", "body") != "body" or "particle_velocities" in initial:
        raise ScenarioError(
            "initial: with [carrier], give omega (relative to the carrier, body frame)"
        )
    if options["hold_com"] and "V0" in initial and np.any(initial["V0"] != 0):
        raise ScenarioError("initial.velocity: must be zero with carrier.hold_com")
    import sympy as sp

    t = sp.Symbol("t", real=True)
    try:
        carrier = Carrier(**{key: rotation}, origin_acceleration=accel, t=t, name="carrier")
    except (ValueError, TypeError) as exc:
        raise ScenarioError(f"{ct.where(key)}: {exc}") from None
    return {"carrier": carrier, "given": key, "rotation": rotation, "origin_acceleration": accel,
            **options}  # fmt: skip


def _initial(t: _Table, body, pivot, omega_optional=False):
    out = {}
    if omega_optional and not t.has("omega"):
        pass
    elif t.has("particle_velocities"):
        v = t.get("particle_velocities", "vectors3", unit="m/s")
        if not body.has_particles or len(v) != body.n_particles:
            n = body.n_particles
            raise ScenarioError(
                f"{t.where('particle_velocities')}: expected {n} velocities "
                f"(one per particle), found {len(v)}"
            )
        out["particle_velocities"] = v
    else:
        out["omega0"] = t.get("omega", "vector3", unit="rad/s")
        out["omega_frame"] = t.get("omega_frame", "string", "body", choices=("body", "space"))
    orientation = _orientation(t)
    if orientation is not None:
        out["Q0"] = orientation
    for key, name, unit in (("position", "R0", "m"), ("velocity", "V0", "m/s")):
        value = t.get(key, "vector3", None, unit=unit)
        if value is not None:
            out[name] = value
    if pivot is not None and "V0" in out:
        raise ScenarioError(
            f"{t.where('velocity')}: must be omitted when the body has a pivot "
            "(the velocity follows from omega)"
        )
    t.finish()
    return out


@dataclass
class LagrangianScenario:
    """A validated scenario of a canonical constrained system (``[model]``)."""

    name: str
    description: str
    model: object
    q0: dict
    qd0: dict
    params: dict
    method: str
    dt: float | None
    rtol: float | None
    atol: float | None
    stabilization: str | None
    t_span: tuple[float, float]
    samples: int
    outputs: dict = field(default_factory=dict)
    source: str = "<built-in>"
    #: the run checked and lowered when the file was read (``system.prepare``)
    prepared: object = None
    #: the initial state made consistent with the constraints when the file was read (every
    #: coordinate and velocity, by symbol), which the run starts from
    consistent: tuple[dict, dict] | None = None
    #: values given with a unit: key path → {"given", "value" (SI), "unit"}
    quantities: dict = field(default_factory=dict)

    @property
    def t_eval(self):
        return np.linspace(self.t_span[0], self.t_span[1], self.samples)

    def run_options(self) -> dict:
        """The method, step or tolerances and stabilisation, as ``prepare`` takes them."""
        kwargs = {"method": self.method, "dt": self.dt, "stabilization": self.stabilization}
        if self.rtol is not None:
            kwargs["rtol"] = self.rtol
        if self.atol is not None:
            kwargs["atol"] = self.atol
        return kwargs

    def simulate(self, progress=None):
        """Run it: a :class:`~poinsot.lagrange.LagrangianSolution` (the run prepared and the
        initial state made consistent when the file was read)."""
        del progress  # the Lagrangian runs are short; no progress bar
        q0, qd0 = self.consistent
        sol = self.prepared.run(q0=q0, qd0=qd0)
        sol.model = self.model  # its reactions named, its mechanism drawn
        return sol


def _by_name(t: _Table, key, known: dict, what: str, units: dict | None = None):
    """``{symbol: value}`` from a table ``{name = value}`` whose names must be in ``known``;
    ``units`` (name → unit) lets a value be a quantity with a unit."""
    table = t.table(key, None)
    out = {}
    for name in list(table.data):
        if name not in known:
            near = difflib.get_close_matches(name, list(known), n=1, cutoff=0.5)
            hint = f"; did you mean {near[0]!r}?" if near else f"; {what}: {', '.join(known)}"
            raise ScenarioError(f"{table.where(name)}: unknown {what[:-1]}{hint}")
        out[known[name]] = table.get(name, "number", unit=_si((units or {}).get(name)))
    return out


def _si(unit: str | None) -> str | None:
    """A unit as the library writes it (``"kg·m²"``, ``"m/s²"``) in pint's syntax; None for
    none declared (the value is then a bare number)."""
    if not unit:
        return None
    return unit.replace("·", "*").replace("²", "^2").replace("³", "^3")


def _integrator(root: _Table, methods, extra: dict | None = None):
    """``[integrator]``: ``(method, dt, rtol, atol, extra values)``; ``extra`` maps more keys to
    ``(kind, default, choices)``."""
    it = root.table("integrator", None)
    method = it.get("method", "string", "dop853", choices=methods)
    dt = it.get("dt", "positive", None, unit="s")
    rtol = it.get("rtol", "positive", None)
    if rtol is not None and not rtol < 1:
        raise ScenarioError(f"{it.where('rtol')}: expected a number in (0, 1), found {rtol}")
    atol = it.get("atol", "positive", None)
    more = {
        key: it.get(key, kind, default, choices=choices)
        for key, (kind, default, choices) in (extra or {}).items()
    }
    it.finish()
    if method != "dop853" and dt is None:
        raise ScenarioError(f"{it.where('dt')}: required for the fixed-step method {method!r}")
    return method, dt, rtol, atol, more


def _time(root: _Table):
    """``[time]``: ``((t0, t1), samples)``."""
    tt = root.table("time")
    span = tt.get("span", "vector2", unit="s")
    if not span[1] > span[0]:
        raise ScenarioError(
            f"{tt.where('span')}: expected [start, end] with end > start, found {span.tolist()}"
        )
    if not math.isfinite(float(span[1]) - float(span[0])):
        raise ScenarioError(
            f"{tt.where('span')}: its length end − start overflows, found {span.tolist()}"
        )
    samples = tt.get("samples", "int", 201)
    if samples < 2:
        raise ScenarioError(f"{tt.where('samples')}: expected at least 2, found {samples}")
    if samples > MAX_SAMPLES:
        raise ScenarioError(
            f"{tt.where('samples')}: at most {MAX_SAMPLES:.0e} (the samples must fit in "
            f"memory), found {samples}"
        )
    tt.finish()
    return (float(span[0]), float(span[1])), samples


def _outputs(root: _Table):
    """``[output]``: which of data, figures and report to write."""
    ot = root.table("output", None)
    outputs = {key: ot.get(key, "bool", True) for key in ("data", "figures", "report")}
    ot.finish()
    return outputs


def _parse_model(root: _Table, name: str, description: str, source: str) -> LagrangianScenario:
    from .. import models

    mt = root.table("model")
    model_name = mt.get("name", "string", choices=tuple(models.MODELS))
    model = models.MODELS[model_name]()
    coords = {str(q).replace("(t)", ""): q for q in model.system.coordinates}
    params_known = {str(p): p for p in model.system.parameters}
    p_units = {name: model.unit_of_parameter(name) for name in params_known}
    q_units = {name: model.system.unit_of(q) for name, q in coords.items()}
    qd_units = {name: f"{u}/s" if u else None for name, u in q_units.items()}
    params = {**model.params, **_by_name(mt, "params", params_known, "parameters", p_units)}
    q0, guess = _model_start(model, _by_name(mt, "q0", coords, "coordinates", q_units))
    qd0 = (_by_name(mt, "qd0", coords, "coordinates", qd_units) if mt.has("qd0")
           else dict(model.qd0))  # fmt: skip
    mt.finish()
    return _lagrangian_scenario(root, name, description, source, model, params, q0, qd0, "model",
                                guess=guess)  # fmt: skip


def _model_start(model, given: dict):
    """``(q0, guess)`` of a ``[model]`` run from the coordinates ``q0`` gives: the model's own
    values for the others. Without holonomic constraints they are kept; with them, the ones
    ``q0`` omits are solved for from the constraints, starting from the model's values (its
    ``q0``, else its ``guess``), and a guess goes only to those."""
    if not given:
        return dict(model.q0), dict(model.guess)
    if not model.system.n_holonomic:
        return {**model.q0, **given}, {}
    seed = {**model.guess, **model.q0}
    return given, {q: v for q, v in seed.items() if q not in given}


def _parse_lagrangian(root: _Table, name: str, description: str,
                      source: str) -> LagrangianScenario:  # fmt: skip
    """``[lagrangian]``: a system written in the file (:mod:`.scenario_lagrangian`)."""
    from .scenario_lagrangian import build_lagrangian_model

    lt = root.table("lagrangian")
    model = build_lagrangian_model(lt, name, description)
    lt.finish()
    return _lagrangian_scenario(root, name, description, source, model, dict(model.params),
                                dict(model.q0), dict(model.qd0), "lagrangian")  # fmt: skip


def _lagrangian_scenario(root, name, description, source, model, params, q0, qd0, table, *,
                         guess=None):  # fmt: skip
    """The rest of a constrained system's scenario — integrator, time, output — and its run
    prepared and its initial state made consistent, once, when the file is read (``guess``:
    the start of the coordinates solved for; default the model's)."""
    guess = model.guess if guess is None else guess
    stab_choices = ("baumgarte", "projection", "none")
    method, dt, rtol, atol, more = _integrator(
        root, ("dop853", "rk4"), {"stabilization": ("string", "baumgarte", stab_choices)}
    )
    stab = more["stabilization"]
    t_span, samples = _time(root)
    outputs = _outputs(root)
    root.finish()
    scenario = LagrangianScenario(
        name,
        description,
        model,
        q0,
        qd0,
        params,
        method,
        dt,
        rtol,
        atol,
        None if stab == "none" else stab,
        t_span,
        samples,
        outputs,
        source,
    )
    try:  # the run checked and lowered, the initial conditions made consistent, once
        from ..lagrange.arguments import _keyed, consistent_initial_state

        system = model.system
        prepared = system.prepare(scenario.t_span, params=params, t_eval=scenario.t_eval,
                                  **scenario.run_options())  # fmt: skip
        q, qd = consistent_initial_state(
            system,
            prepared.num,
            scenario.t_span[0],
            _keyed(q0, system, "q0", allow_missing=system.n_holonomic > 0),
            _keyed(qd0, system, "qd0", allow_missing=True),
            _keyed(guess, system, "guess", allow_missing=True) if guess else None,
        )
    except StepBudgetError as exc:
        raise ScenarioError(_budget_message(exc)) from None
    except ValueError as exc:
        raise ScenarioError(f"{table}: {exc}") from None
    coordinates = system.coordinates
    scenario.prepared = prepared
    scenario.consistent = (dict(zip(coordinates, q.tolist(), strict=True)),
                           dict(zip(coordinates, qd.tolist(), strict=True)))  # fmt: skip
    return scenario


def _parse(data: dict, source: str, base_dir: Path):
    root = _Table(data, "")
    if "lagrangian" in data and "body" not in data and "model" not in data:
        name = root.get("name", "string", Path(source).stem if source != "<built-in>"
                        else "lagrangian")  # fmt: skip
        return _parse_lagrangian(root, name, root.get("description", "string", ""), source)
    if "model" in data and "body" not in data:
        name = root.get(
            "name",
            "string",
            data["model"].get("name", "model") if isinstance(data["model"], dict) else "model",
        )
        return _parse_model(root, name, root.get("description", "string", ""), source)
    name = root.get("name", "string", Path(source).stem if source != "<built-in>" else "default")
    description = root.get("description", "string", "")
    bt = root.table("body")
    body = build_body(bt, base_dir)
    pivot = bt.get("pivot", "vector3", None, unit="m")
    forces = [build_force(f) for f in root.tables("forces")]
    has_ensemble = root.has("ensemble")
    initial = _initial(
        root.table("initial", None if has_ensemble else _MISSING), body, pivot, has_ensemble
    )
    method, dt, rtol, atol, _ = _integrator(root, METHOD_NAMES)
    t_span, samples = _time(root)  # the run is checked whole by its front-end's `prepare`
    outputs = _outputs(root)
    ensemble = _ensemble(root.table("ensemble"), initial) if has_ensemble else None
    carrier = _carrier(root.table("carrier"), initial, pivot) if root.has("carrier") else None
    if carrier is not None and has_ensemble:
        raise ScenarioError("carrier: an ensemble of relative motions is not supported yet")
    at = root.table("analysis", None)
    analysis = {
        "polhodes": at.get("polhodes", "bool", True),
        "energy": at.get("energy", "positive", None, unit="J"),
        "momentum": at.get("momentum", "nonnegative", None, unit="kg*m^2/s"),
        "levels": at.get("levels", "int", 9),
    }
    if analysis["levels"] > MAX_LEVELS:
        raise ScenarioError(
            f"{at.where('levels')}: at most {MAX_LEVELS} polhodes, found {analysis['levels']}"
        )
    at.finish()
    root.finish()
    if ensemble is not None:
        kind = EnsembleScenario
    elif carrier is not None:
        kind = RelativeScenario
    else:
        kind = Scenario
    scenario = kind(
        name,
        description,
        body,
        forces,
        pivot,
        initial,
        method,
        dt,
        rtol,
        atol,
        t_span,
        samples,
        outputs,
        analysis,
        source,
        ensemble,
        carrier,
    )
    _check_physics(scenario)
    return scenario


#: Largest ensemble a scenario may ask for (its per-member statistics fit in a few GB).
MAX_MEMBERS = 10**8


#: The keys of the other distribution than ``distribution``: ``sphere`` draws spins of one
#: ``speed``, ``gaussian`` about a ``mean`` with ``std``.
_OTHER_DISTRIBUTION_KEYS = {"sphere": ("mean", "std"), "gaussian": ("speed",)}


def _ensemble(et: _Table, initial: dict) -> dict:
    """``[ensemble]``: how many members, their distribution of initial spins, the seed."""
    from ..ensemble.sampling import DISTRIBUTIONS

    if "particle_velocities" in initial or initial.get("omega_frame", "body") != "body":
        raise ScenarioError(
            f"{et.where('distribution')}: an ensemble draws body-frame spins; "
            "initial.particle_velocities and omega_frame = 'space' do not apply"
        )
    members = et.get("members", "int")
    if members > MAX_MEMBERS:
        raise ScenarioError(f"{et.where('members')}: at most {MAX_MEMBERS}, found {members}")
    out = {
        "members": members,
        "seed": et.get("seed", "nonnegative", 0.0),
        "distribution": et.get("distribution", "string", choices=DISTRIBUTIONS),
        "keep_states": et.get("keep_states", "bool", False),
        "chunk_size": et.get("chunk_size", "int", None),
        "threads": et.get("threads", "int", None),
    }
    if out["seed"] != int(out["seed"]):
        raise ScenarioError(f"{et.where('seed')}: expected an integer, found {out['seed']}")
    out["seed"] = int(out["seed"])
    for key in _OTHER_DISTRIBUTION_KEYS[out["distribution"]]:
        if key in et.data:
            other = "gaussian" if out["distribution"] == "sphere" else "sphere"
            raise ScenarioError(f"{et.where(key)}: not used with distribution = "
                                f"{out['distribution']!r}; it belongs to {other!r}")  # fmt: skip
    if out["distribution"] == "sphere":
        out["speed"] = et.get("speed", "positive", unit="rad/s")
    else:
        mean = initial.get("omega0")
        out["mean"] = et.get("mean", "vector3", mean, unit="rad/s")
        if out["mean"] is None:
            raise ScenarioError(
                f"{et.where('mean')}: required for a gaussian ensemble (or give initial.omega)"
            )
        std = et.get("std", "vector3", unit="rad/s")
        if np.any(std < 0):
            raise ScenarioError(f"{et.where('std')}: expected numbers ≥ 0, found {std.tolist()}")
        out["std"] = std
    et.finish()
    return out


def _check_physics(s: Scenario):
    """Refuse what cannot run: infeasible torque-free invariants, a bad initial state."""
    _check_invariants(s)
    system = _prepare_run(s)
    _check_initial_state(s, system)


def _check_invariants(s: Scenario):
    """Refuse an ``analysis.energy`` or ``analysis.momentum`` no torque-free motion of the body
    has."""
    energy, momentum = s.analysis["energy"], s.analysis["momentum"]
    if energy is not None and not s.body.is_degenerate:
        from ..torquefree import FreeRigidBody

        try:
            FreeRigidBody.from_body(s.body).check_energy_range(energy)
        except ValueError as exc:
            raise ScenarioError(f"analysis.energy: {exc}") from None
    if momentum is not None:
        if energy is None:
            raise ScenarioError("analysis.momentum: needs analysis.energy as well")
        from ..torquefree import FreeRigidBody

        try:
            FreeRigidBody.from_body(s.body).check_feasible(energy, momentum)
        except ValueError as exc:
            raise ScenarioError(f"analysis.momentum: {exc}") from None


def _prepare_run(s: Scenario):
    """Check and lower the run once into ``s.prepared``: a rigid body's (or an ensemble's), or
    the carrier's relative motion; returns the rigid-body system of the body."""
    from ..dynamics import RigidBodySystem

    system = None
    if s.carrier is not None:
        try:
            system = RigidBodySystem(s.body, s.forces, s.pivot)
        except (ValueError, TypeError) as exc:
            raise ScenarioError(f"body: {exc}") from None
    try:
        s.prepared = _prepared_rigid(s) if s.carrier is None else _prepared_relative(s)
    except StepBudgetError as exc:
        raise ScenarioError(_budget_message(exc)) from None
    except (ValueError, TypeError) as exc:
        raise ScenarioError(f"{_key_of(exc)}: {exc}") from None
    return s.prepared.system if system is None else system


def _prepared_rigid(s: Scenario):
    """A rigid body's run (or an ensemble's), checked and lowered by its front-end."""
    from ..simulation import prepare

    if s.ensemble is None:
        return prepare(s.body, s.t_span, forces=s.forces, pivot=s.pivot,
                       method=s.method, dt=s.dt, rtol=s.rtol, atol=s.atol,
                       t_eval=s.t_eval)  # fmt: skip
    from ..ensemble import prepare_ensemble

    # the members' statistics (drifts, errors) are over the [time] samples, kept or not
    return prepare_ensemble(s.body, s.t_span, forces=s.forces,
                            pivot=s.pivot, method=s.method, dt=s.dt,
                            rtol=s.rtol, atol=s.atol, t_eval=s.t_eval,
                            keep_states=s.ensemble["keep_states"])  # fmt: skip


def _prepared_relative(s: Scenario):
    """The carrier's relative motion, checked and lowered by its front-end."""
    from ..relative import prepare_relative

    c = s.carrier
    return prepare_relative(s.body, s.t_span, carrier=c["carrier"],
                            forces=s.forces,
                            balance_transport=c["balance_transport"],
                            hold_com=c["hold_com"], method=s.method, dt=s.dt,
                            rtol=s.rtol, atol=s.atol,
                            t_eval=s.t_eval)  # fmt: skip


def _check_initial_state(s: Scenario, system):
    """Set ``s.y0`` from ``[initial]`` (particle velocities first turned into V0 and ω0),
    refusing a bad initial state; nothing for an ensemble or a start without ω0."""
    from ..simulation import ForceUndefinedError, initial_velocities

    initial = dict(s.initial)
    if "particle_velocities" in initial:
        try:
            initial["V0"], initial["omega0"] = initial_velocities(
                s.body, initial.pop("particle_velocities"), s.pivot
            )
        except ValueError as exc:
            raise ScenarioError(f"initial.particle_velocities: {exc}") from None
    if "omega0" not in initial or s.ensemble is not None:
        return
    fields = {k: initial.get(k) for k in ("omega0", "Q0", "R0", "V0")}
    frame = initial.get("omega_frame", "body")
    if s.carrier is not None:  # a relative motion's start, in the carrier's frame
        try:
            system.initial_state(**fields, omega_frame=frame)
            s.y0 = s.prepared.initial_state(omega_r0=fields["omega0"], Q_r0=fields["Q0"],
                                            r0=fields["R0"], v_r0=fields["V0"])  # fmt: skip
        except (ValueError, TypeError) as exc:
            raise ScenarioError(f"initial: {exc}") from None
        return
    try:
        s.y0 = s.prepared.initial_state(**fields, omega_frame=frame)
    except ForceUndefinedError as exc:
        raise ScenarioError(f"forces[{exc.index}]: {exc.force_name} {exc.reason}") from None
    except (ValueError, TypeError) as exc:
        raise ScenarioError(f"initial: {exc}") from None


def _budget_message(exc) -> str:
    """A fixed-step run over its step budget, in the scenario's keys."""
    return (
        f"integrator.dt: the run needs {exc.needed:.3g} steps of dt = {exc.dt:g} over "
        f"time.span = [{exc.t0:g}, {exc.t1:g}]; a run may take at most {exc.budget:.3g} steps "
        "(take a larger integrator.dt or a shorter time.span)"
    )


def _key_of(exc) -> str:
    """The scenario key a front-end's refusal is about, from the argument it names."""
    text = str(exc)
    for name in ("method", "dt", "rtol", "atol"):
        if text.startswith(f"`{name}`"):
            return f"integrator.{name}"
    if text.startswith("`forces["):
        return text[1 : text.index("]") + 1]
    return "body"


def load_scenario(source) -> Scenario:
    """Read and validate a scenario from a path (``.toml``), from TOML text or from bytes
    (UTF-8, a byte-order mark allowed). Anything wrong raises :class:`ScenarioError` naming
    the file and the key."""
    if isinstance(source, Path) or (
        isinstance(source, str) and source.endswith(".toml") and "\n" not in source
    ):
        path = Path(source)
        try:
            raw = path.read_bytes()
        except OSError as exc:
            raise ScenarioError(f"{path}: cannot read: {exc.strerror}") from None
        label, base = str(path), path.parent
        text = _decode(raw, label)
    elif isinstance(source, bytes | bytearray):
        label, base = "<bytes>", Path.cwd()
        text = _decode(bytes(source), label)
    else:
        text, label, base = str(source), "<built-in>", Path.cwd()
    text = text.removeprefix("\ufeff")  # a byte-order mark, as some editors write
    try:
        data = read_toml(text, label)
    except TOMLError as exc:
        raise ScenarioError(str(exc)) from None
    from . import tables

    quantities: dict = {}
    outer, tables._QUANTITY_RECORDER = tables._QUANTITY_RECORDER, quantities
    try:
        scenario = _parse(data, label, base)
    except ScenarioError as exc:
        raise ScenarioError(f"{label}: {exc}") from None
    except RecursionError:
        raise ScenarioError(f"{label}: arrays or tables are nested too deeply") from None
    finally:
        tables._QUANTITY_RECORDER = outer
    scenario.quantities = quantities
    return scenario


def _decode(raw: bytes, label: str) -> str:
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ScenarioError(
            f"{label}: not UTF-8 text: byte 0x{raw[exc.start]:02x} at line {line} (save the "
            "file as UTF-8)"
        ) from None


# --------------------------------------------------------------------------- examples
def _example_files():
    return resources.files("poinsot.app") / "scenarios"


def list_examples() -> dict[str, str]:
    """``{name: one-line description}`` of the bundled example scenarios."""
    out = {}
    for entry in sorted(_example_files().iterdir(), key=lambda p: p.name):
        if entry.name.endswith(".toml"):
            data = tomllib.loads(entry.read_text(encoding="utf-8"))
            out[entry.name[:-5]] = data.get("description", "").split("\n")[0]
    return out


def example_text(name: str) -> str:
    """The TOML text of a bundled example scenario, a starting template for your own."""
    names = list_examples()
    if name not in names:
        near = difflib.get_close_matches(name, list(names), n=1)
        hint = f" (did you mean {near[0]!r}?)" if near else ""
        raise ScenarioError(f"no example named {name!r}{hint}; available: {', '.join(names)}")
    return (_example_files() / f"{name}.toml").read_text(encoding="utf-8")


def load_example(name: str) -> Scenario:
    """A bundled example scenario by name (see :func:`list_examples`)."""
    scenario = load_scenario(example_text(name))
    scenario.source = f"example:{name}"
    return scenario
