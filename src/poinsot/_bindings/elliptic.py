"""Special functions: complete and incomplete elliptic integrals, Jacobi elliptic functions and
Carlson's symmetric forms (``crates/core/src/elliptic.rs``).
"""

from .._core import (
    ELLIPTIC_NEAR_ONE,
    ELLIPTIC_TINY_M1,
    carlson_rf,
    carlson_rj,
    ellipf,
    ellipk_m1,
    ellippi,
    ellippi_complete,
    first_kind_from_sn_cn,
    jacobi_reduced,
    jacobi_sn_cn_dn_am,
    third_kind_u,
)

__all__ = [
    "ELLIPTIC_NEAR_ONE",
    "ELLIPTIC_TINY_M1",
    "carlson_rf",
    "carlson_rj",
    "ellipf",
    "ellipk_m1",
    "ellippi",
    "ellippi_complete",
    "first_kind_from_sn_cn",
    "jacobi_reduced",
    "jacobi_sn_cn_dn_am",
    "third_kind_u",
]
