//! The torque-free rotation in closed form (`docs/theory.md` §1, "Torque-free body",
//! eqs (20)–(33); `docs/torque_free.md`).
//!
//! Every function works in the *sorted principal frame*: moments ascending `I1 ≤ I2 ≤ I3`, ω in
//! those axes. The batched functions at the end map body-frame inputs through the sorted axes
//! `S` (columns, body coordinates).
//!
//! **The regime.** Everything the closed form needs of one initial ω is computed once by
//! [`Regime::new`]:
//!
//! * the invariants (30)–(31): `k` (`2k = Σ I_i ω_i²`) and `a = |L|`;
//! * the case: [`SPHERICAL`] (ω constant), [`FIXED`] (a fixed point: ω constant),
//!   [`PRECESSION`] (a symmetric body: `π = Aω` turns about the symmetry axis `s` at the rate
//!   `−ν`, `ν = (1/I_s − 1/I⊥) π_s`), or, for three distinct moments, [`AROUND_E3`],
//!   [`AROUND_E1`] (the polhode circles e3 or e1) and [`SEPARATRIX`];
//! * for the last three, the Jacobi form `ω = (σ1 α1 cn u, σ2 α2 sn u, σ3 α3 dn u)` (pole e3)
//!   or `(σ1 α1 dn u, σ2 α2 sn u, σ3 α3 cn u)` (pole e1), `u = u0 + λt`, parameter `m` and its
//!   complement `m1` (formed without cancellation, so the solution stays accurate arbitrarily
//!   close to the separatrix), and the quarter period `K(m)`.
//!
//! The invariants' combinations `P3 = 2k I3 − a² ≥ 0` and `P1 = a² − 2k I1 ≥ 0` are formed as
//! sums of squares (no cancellation), through `hypot` and after scaling ω by a power of two, so
//! that the solution is scale invariant over the whole floating-point range.
//!
//! **The attitude.** z-x-z Euler angles `(ψ, θ, φ)` of the body relative to the invariable
//! frame (z along L), with pole the axis the polhode circles (e3, or e1 through the
//! right-handed relabelling `(e3, −e2, e1)`): `cos θ = π_pole/a`, `tan φ = π_1'/π_2'` and
//! `ψ(t) = a t/I_p + a (I_p − I_q)/(I_p I_q λ) [Π(u) − Π(u0)]`, `Π(u) = ∫₀^u du/(1 − n sn² u)`,
//! `n = −I_p (I2 − I1)/(I1 (I3 − I2))` (pole e3; swap 1 ↔ 3 for pole e1), n < 0 (Landau &
//! Lifshitz, *Mechanics*, §37; Whittaker, *Analytical Dynamics*, §69). Symmetric bodies:
//! `Q(t) = exp(t L̂/I⊥) Q0 exp(ν t ê_s)`; fixed points: `Q0 exp(Ω t)`.
//!
//! **Ensembles in lanes.** The Jacobi form's formulas (the polhode radii, the Jacobi form, the
//! AGM sequence, `u0`, ω(t)) are written once, generic over [`Real`](crate::real::Real):
//! [`Regime::with`] and [`Regime::omega_at`] run them on `f64` for one motion;
//! [`exact_omegas`] runs them on [`WIDTH`](crate::real::WIDTH) motions at a time in SIMD lanes
//! ([`omegas_in_lanes`]: structure of arrays, the member loop innermost, the instruction set
//! chosen at run time), each lane computing bit for bit what its single run computes. The
//! attitude's formulas are generic too ([`EllipticMotion`]: `Π(u)` from the reduction of `u`
//! that ω(t) makes, by Carlson's `R_F` and `R_J` with a polynomial `atan`; θ and φ as ratios
//! of the body momentum's components; ψ's sine and cosine by
//! [`sin_cos`](crate::real::sin_cos)): [`attitude_at`] runs them on `f64`, [`exact_attitudes`]
//! in lanes ([`attitudes_in_lanes`]). Members off the plain elliptic case (fixed points, the
//! separatrix and `m1 <` [`NEAR_ONE`](crate::elliptic::NEAR_ONE), extreme scales, symmetric
//! bodies) run one by one.
//!
//! The files: `regime.rs` (the regime and ω(t) of one motion), `attitude.rs` (its `Q(t)`),
//! `derivatives.rs` (the exact derivatives of ω(t), the period and the flip interval),
//! `batched_omegas.rs` (ω(t), families, periods and flip intervals of many motions, in lanes),
//! `batched_attitudes.rs` (`Q(t)` of many motions, in lanes) and `batched_flows.rs` (the
//! exact-flow splittings' free flows of many bodies, in lanes).

mod attitude;
mod batched_attitudes;
mod batched_flows;
mod batched_omegas;
mod derivatives;
mod regime;

pub use attitude::*;
pub use batched_attitudes::*;
pub use batched_flows::*;
pub use batched_omegas::*;
pub use derivatives::*;
pub use regime::*;

/// Case: a spherical body (ω constant).
pub const SPHERICAL: u8 = 0;
/// Case: a symmetric body, ω precessing about the symmetry axis.
pub const PRECESSION: u8 = 1;
/// Case: a fixed point of Euler's equation (ω constant).
pub const FIXED: u8 = 2;
/// Case: the polhode circles e3.
pub const AROUND_E3: u8 = 3;
/// Case: the polhode circles e1.
pub const AROUND_E1: u8 = 4;
/// Case: on the separatrix (m = 1).
pub const SEPARATRIX: u8 = 5;
/// The polhode family of each case, as `FreeRigidBody.classify` names it.
pub const CASE_NAMES: [&str; 6] = [
    "spherical",
    "symmetric",
    "fixed point",
    "around e3",
    "around e1",
    "separatrix",
];

/// ω within this relative distance of the intermediate axis is taken as that fixed point:
/// leaving it takes longer than ln(1e140)/σ ≈ 322/σ, and the invariants' differences that set
/// the orbit underflow in double precision.
pub const NEAR_UNSTABLE_AXIS: f64 = 1e-140;

/// Offsets of the flat regime row (`poinsot._core.REGIME_OFFSETS` names them for the
/// Python package), see [`Regime::to_row`].
pub mod row {
    pub const CASE: usize = 0;
    pub const ENERGY: usize = 1;
    pub const MOMENTUM: usize = 2;
    pub const ALPHA: usize = 3; // 3 entries
    pub const LAM: usize = 6;
    pub const M: usize = 7;
    pub const M1: usize = 8;
    pub const SIGNS: usize = 9; // 3 entries
    pub const U0: usize = 12;
    pub const POLE: usize = 13;
    pub const QUARTER: usize = 14;
    pub const NU: usize = 15;
    pub const AXIS: usize = 16;
    pub const I_PERP: usize = 17;
    pub const SIZE: usize = 18;
}

pub use crate::so3::zxz_matrix;

#[cfg(test)]
#[path = "torque_free_tests.rs"]
pub(crate) mod tests;
