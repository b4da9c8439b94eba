//! # poinsot-core
//!
//! Every formula of poinsot, once, as functions on plain data (`f64`, `[f64; N]`, slices).
//! The Python package `poinsot` calls these through the bindings crate (`poinsot._core`);
//! Python classes hold no physics.
//!
//! One module per concept; equation numbers refer to `docs/theory.md`:
//!
//! * the data: [`layout`] (state, body parameters), [`so3`], [`invariants`];
//! * bodies: [`inertia`], [`shapes`];
//! * the physics: [`forces`], [`rigid`] (eqs (07)–(09), the free-rotor flows);
//! * the exact torque-free motion: [`elliptic`] (with [`cmath`]), [`freebody`],
//!   [`torque_free`];
//! * the heavy symmetric top's steady precessions: [`tops`];
//! * motion relative to a moving carrier: [`relative`] (eqs (1)–(18) of the paper);
//! * a body carrying a spinning rotor, the gyrostat: [`gyrostat`] (§4);
//! * a model's own expressions compiled at run time: [`expressions`];
//! * the contract between models and integrators: [`system`], with the rigid-body systems in
//!   [`systems`];
//! * constrained systems (Lagrange's equations with multipliers): [`lagrange`], on small
//!   dense solvers ([`linalg`]);
//! * ensembles of runs, in parallel, members in SIMD lanes: [`ensemble`], [`lanes`];
//! * the integrators: [`spec`] (what a run is: method, step, sampling, budget), [`tableaux`]
//!   (as data), [`steppers`] (pure steps), [`observers`], [`events`] (zeros located inside the
//!   time loop) and [`drivers`] (time loops).

// Index loops mirror the equations (sums over components and stages) in this crate.
#![allow(clippy::needless_range_loop)]

pub mod cmath;
pub mod drivers;
pub mod dual;
pub mod elliptic;
pub mod ensemble;
pub mod events;
pub mod exact_splitting;
pub mod expressions;
pub mod forces;
pub mod freebody;
pub mod gyrostat;
pub mod heavy_top;
pub mod inertia;
pub mod invariants;
pub mod isa;
pub mod kepler;
pub mod lagrange;
pub mod lanes;
pub mod layout;
pub mod linalg;
pub mod observers;
pub mod real;
pub mod relative;
pub mod rigid;
pub mod run;
pub mod sensitivity;
pub mod shapes;
pub mod so3;
pub mod spec;
pub mod steppers;
pub mod system;
pub mod systems;
pub mod tableaux;
pub mod tops;
pub mod torque_free;

pub mod version {
    /// The crate's version, for `poinsot._core.__version__`.
    pub const VERSION: &str = env!("CARGO_PKG_VERSION");
}
