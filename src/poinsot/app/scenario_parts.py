"""A scenario's body and forces from their tables: ``[body]`` (particles, primitives, meshes,
composites, mass properties) and ``[[forces]]``, each built by the library's own constructors
and refused naming the key path."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .tables import _MISSING, ScenarioError, _convert, _Table

__all__ = ["build_body", "build_force"]

PRIMITIVES = {
    "box": ("size",),
    "sphere": ("radius",),
    "spherical_shell": ("radius",),
    "cylinder": ("radius", "height"),
    "ellipsoid": ("semi_axes",),
    "rod": ("length",),
    "cone": ("radius", "height"),
}
BODY_TYPES = ("particles", "particle_grid", *PRIMITIVES, "mesh", "composite", "mass_properties")


def _orientation(t: _Table):
    """``orientation``: a quaternion [w, x, y, z], a 3×3 matrix, or a table
    ``{euler = [..], seq = "ZXZ", degrees = false}``."""
    t._record("orientation", "orientation", None)
    if not t.has("orientation"):
        t.used.add("orientation")
        return None
    value = t.data["orientation"]
    t.used.add("orientation")
    where = t.where("orientation")
    if isinstance(value, dict):
        e = _Table(value, where)
        degrees = e.get("degrees", "bool", False)
        angles = e.get("euler", "vector3", unit="deg" if degrees else "rad")
        seq = e.get("seq", "string", "ZXZ")
        e.finish()
        from ..rotation import EULER_SEQUENCES, matrix_from_euler

        if seq not in EULER_SEQUENCES:
            raise ScenarioError(
                f"{where}.seq: expected an Euler sequence such as 'ZXZ', found {seq!r}"
            )
        return matrix_from_euler(angles, seq, degrees=degrees)
    if isinstance(value, list) and len(value) == 4:
        q = _convert(value, "vector4", where)
    else:
        q = _convert(value, "matrix3", where)
    from .._validation import as_rotation_matrix

    try:
        return as_rotation_matrix(q, "orientation")
    except ValueError as exc:
        raise ScenarioError(f"{where}: {str(exc).replace('`orientation` ', '')}") from None


#: Limits on sizes a scenario may ask for, so that a typo is refused up front rather than met
#: as a MemoryError: particles of a grid, samples of a run, contour levels of a figure.
MAX_PARTICLES = 10**7
MAX_SAMPLES = 10**7
MAX_LEVELS = 200


def build_body(t: _Table, base_dir: Path, part: bool = False):
    """The :class:`~poinsot.bodies.RigidBody` described by a ``[body]`` table (``part``: one of
    ``[[body.parts]]``, where a pivot has no meaning)."""
    from ..bodies import RigidBody, UnphysicalInertiaError

    kind = t.get(
        "type", "string", "particles" if t.has("particles") else _MISSING, choices=BODY_TYPES
    )
    try:
        if kind == "particles":
            body = _particles_body(t)
        elif kind == "particle_grid":
            body = _particle_grid_body(t)
        elif kind in PRIMITIVES:
            body = _primitive_body(t, kind)
        elif kind == "mesh":
            body = _mesh_body(t, base_dir)
        elif kind == "composite":
            parts = t.tables("parts")
            if not parts:
                raise ScenarioError(f"{t.where('parts')}: expected at least one part")
            body = RigidBody.compose([build_body(p, base_dir, part=True) for p in parts])
        else:  # mass_properties
            body = RigidBody(
                t.get("mass", "positive", unit="kg"),
                t.get("inertia", "matrix3", unit="kg*m^2"),
                t.get("center_of_mass", "vector3", np.zeros(3), unit="m"),
                allow_unphysical=t.get("allow_unphysical", "bool", False),
            )
    except ScenarioError:
        raise
    except UnphysicalInertiaError as exc:
        raise ScenarioError(
            f"{t.where('inertia')}: {exc.reason} (set allow_unphysical = true in "
            f"[{t.path}] to study the equations anyway)"
        ) from None
    except (ValueError, TypeError) as exc:
        raise ScenarioError(f"{t.path}: {exc}") from None
    if part and t.has("pivot"):
        raise ScenarioError(
            f"{t.where('pivot')}: a pivot belongs to the whole body: give it in [body], "
            "not in one of its parts"
        )
    t.finish(set() if part else {"pivot"})
    return body


def _particles_body(t: _Table):
    """A body of point masses, from the ``[[body.particles]]`` tables (at least one)."""
    from ..bodies import RigidBody

    parts = t.tables("particles")
    if not parts:
        raise ScenarioError(f"{t.where('particles')}: expected at least one particle")
    masses, positions = [], []
    for p in parts:
        masses.append(p.get("mass", "positive", unit="kg"))
        positions.append(p.get("position", "vector3", unit="m"))
        p.finish()
    return RigidBody.from_particles(masses, positions)


def _particle_grid_body(t: _Table):
    """A body of equal point masses on a ``counts`` grid from ``lower`` to ``upper``, at most
    :data:`MAX_PARTICLES` of them."""
    from ..bodies import RigidBody

    lower = t.get("lower", "vector3", np.zeros(3), unit="m")
    upper = t.get("upper", "vector3", unit="m")
    counts = t.get("counts", "vector3")
    if np.any(counts < 1) or np.any(counts != np.round(counts)):
        raise ScenarioError(
            f"{t.where('counts')}: expected three positive integers, found {counts.tolist()}"
        )
    if float(np.prod(counts)) > MAX_PARTICLES:
        raise ScenarioError(
            f"{t.where('counts')}: at most {MAX_PARTICLES:.0e} particles in all, found "
            f"{' × '.join(f'{c:.0f}' for c in counts)}"
        )
    total = t.get("total_mass", "positive", unit="kg")
    axes = [np.linspace(lower[k], upper[k], int(counts[k])) for k in range(3)]
    grid = np.array(np.meshgrid(*axes, indexing="ij")).reshape(3, -1).T
    return RigidBody.from_particles(np.full(len(grid), total / len(grid)), grid)


def _primitive_body(t: _Table, kind):
    """A solid of one of the :data:`PRIMITIVES` shapes: its mass, its sizes (positive), its
    position and orientation."""
    from ..bodies import RigidBody

    mass = t.get("mass", "positive", unit="kg")
    args = []
    for name in PRIMITIVES[kind]:
        vec = name in ("size", "semi_axes")
        value = t.get(name, "vector3" if vec else "positive", unit="m")
        if vec and np.any(value <= 0):
            bad = int(np.argmax(value <= 0))
            raise ScenarioError(
                f"{t.where(name)}[{bad}]: expected a positive number, found {value[bad]}"
            )
        args.append(value)
    position = t.get("position", "vector3", None, unit="m")
    return getattr(RigidBody, kind)(mass, *args, position=position, orientation=_orientation(t))


def _mesh_body(t: _Table, base_dir: Path):
    """A solid from a closed triangle mesh file (relative to ``base_dir``), with its mass or
    density."""
    from ..bodies import RigidBody

    path = Path(t.get("path", "string"))
    if not path.is_absolute():
        path = base_dir / path
    mass = t.get("mass", "positive", None, unit="kg")
    density = t.get("density", "positive", None, unit="kg/m^3")
    try:
        return RigidBody.from_mesh(path, mass=mass, density=density)
    except ImportError as exc:
        raise ScenarioError(f"{t.where('path')}: {exc}") from None


# --------------------------------------------------------------------------- forces
FORCE_TYPES = (
    "gravity",
    "central_gravity",
    "spring",
    "linear_drag",
    "quadratic_drag",
    "point_force",
    "torque",
)


def build_force(t: _Table):
    """One force from a ``[[forces]]`` table."""
    from .. import forces as F

    kind = t.get("type", "string", choices=FORCE_TYPES)
    try:
        if kind == "gravity":
            force = F.Gravity(t.get("g", "vector3", np.array([0.0, 0.0, -9.81]), unit="m/s^2"))
        elif kind == "central_gravity":
            force = F.CentralGravity(
                t.get("mu", "positive", unit="m^3/s^2"),
                t.get("center", "vector3", np.zeros(3), unit="m"),
                gradient=t.get("gradient", "bool", True),
            )
        elif kind == "spring":
            force = F.Spring(
                t.get("point", "vector3", unit="m"),
                t.get("anchor", "vector3", unit="m"),
                t.get("stiffness", "positive", unit="N/m"),
                t.get("rest_length", "nonnegative", 0.0, unit="m"),
                damping=t.get("damping", "nonnegative", 0.0, unit="N*s/m"),
                tether=t.get("tether", "bool", False),
            )
        elif kind in ("linear_drag", "quadratic_drag"):
            cls = F.LinearDrag if kind == "linear_drag" else F.QuadraticDrag
            lin = kind == "linear_drag"  # F = −c V, τ = −c_rot ω; or −c |V| V, −c_rot |ω| ω
            force = cls(
                t.get("coefficient", "nonnegative", unit="N*s/m" if lin else "N*s^2/m^2"),
                t.get("rotational", "nonnegative", 0.0, unit="N*m*s" if lin else "N*m*s^2"),
            )
        elif kind == "point_force":
            force = F.PointForce(
                t.get("point", "vector3", unit="m"),
                t.get("force", "vector3", unit="N"),
                frame=t.get("frame", "string", "space", choices=("space", "body")),
            )
        else:
            force = F.Torque(
                t.get("torque", "vector3", unit="N*m"),
                frame=t.get("frame", "string", "body", choices=("space", "body")),
            )
    except ScenarioError:
        raise
    except (ValueError, TypeError) as exc:
        raise ScenarioError(f"{t.path}: {exc}") from None
    t.finish()
    return force


# --------------------------------------------------------------------------- scenario
