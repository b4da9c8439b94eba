"""The run contract: the method registry (kinds, tableaux, compositions), the run specification,
its state and statistics, the statuses a run ends with, a general vector field's run, and the
instruction sets compiled (``crates/core/src/spec.rs``, ``run.rs``).
"""

from .._core import (
    CALLBACK_FAILED,
    COMPILED_ISAS,
    FIELD_KINDS,
    FINISHED,
    ISA,
    METHOD_KINDS,
    METHODS,
    NONFINITE,
    OUTPUT_FULL,
    RUNNING,
    STEP_TOO_SMALL,
    TERMINATED,
    RunSpec,
    RunState,
    RunStats,
    composition,
    integrate_python,
    tableau,
)

__all__ = [
    "CALLBACK_FAILED",
    "COMPILED_ISAS",
    "FIELD_KINDS",
    "FINISHED",
    "ISA",
    "METHODS",
    "METHOD_KINDS",
    "NONFINITE",
    "OUTPUT_FULL",
    "RUNNING",
    "STEP_TOO_SMALL",
    "TERMINATED",
    "RunSpec",
    "RunState",
    "RunStats",
    "composition",
    "integrate_python",
    "tableau",
]
