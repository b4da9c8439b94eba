//! Constrained systems: Lagrange's equations with multipliers ([L] eqs (6.55)–(6.60),
//! `docs/lagrange.md`), as a [`VectorField`](crate::system::VectorField) the integrators step.
//!
//! A model brings its own expressions, derived in SymPy: the mass matrix `M(q, t)`, the
//! forcing `f(q, q̇, t)` (everything but `M q̈` in Lagrange's equations), the constraint
//! Jacobian `G(q, t)` with its right-hand side `b` (the velocity constraints read
//! `G q̇ + b = 0`) and velocity-product terms `γ = Ġ q̇ + ḃ`, the holonomic residuals `g(q, t)`
//! and the Jacobi integral `h`. They arrive as one compiled
//! [`Function`](crate::expressions::Function) of `[q, q̇, t, p, u]` (coordinates, velocities,
//! time, parameters, inputs) whose outputs are `[M, f, G, b, γ, g, h]` ([`Shape`]); nothing
//! of the model is written here.
//!
//! What is written here, once, is the engine's mathematics:
//!
//! * the index-1 (KKT) system `[[M, −Gᵀ], [G, 0]] [q̈; λ] = [f; −γ − s]` ([L] (6.60)), with
//!   the multipliers' sign of `docs/lagrange.md` (the generalized constraint force is `Gᵀλ`);
//! * Baumgarte's stabilisation `s = 2α (G q̇ + b) + β² g` (the position term on holonomic
//!   rows), so that a residual `e` obeys `ë + 2α ė + β² e = 0` (Baumgarte 1972);
//! * the projection onto the constraints: Gauss–Newton with minimum-norm corrections on
//!   `g(q) = 0`, then `q̇ ← q̇ − G⁺ (G q̇ + b)`;
//! * constraints that can let go (one-sided): a mask of the constraints in play, so that a
//!   released constraint's row leaves the system;
//! * the physical multipliers, generalized constraint forces `Gᵀλ`, residuals and energy at
//!   samples;
//! * a run's events ([`LagrangeEvents`]): the user's compiled expressions or callbacks, and
//!   the multipliers of one-sided constraints, whose zeros [`crate::events::Watch`] locates.
//!
//! The files: `model.rs` (a model's sizes and expressions, the KKT solve, the projection and
//! the post-processing of samples), `system.rs` (the inputs and the constrained system as a
//! vector field), `sensitivity.rs` (the differentiated KKT system: a run's forward
//! sensitivities), `events.rs` (a run's event sources) and `members.rs` (one member's run in
//! phases, and members in parallel).

mod events;
mod members;
mod model;
mod sensitivity;
mod system;

pub use events::*;
pub use members::*;
pub use model::*;
pub use sensitivity::{
    initial_tangents, rates_jacobian, LagrangeSensitive, Start as LagrangeStart,
};
pub use system::*;

#[cfg(test)]
#[path = "lagrange_tests.rs"]
mod tests;
