//! # poinsot-core
//!
//! Every formula of poinsot, once, as functions on plain data (`f64`, `[f64; N]`, slices).
//! The Python package `poinsot` calls these through the bindings crate (`poinsot._core`);
//! Python classes hold no physics.
//!
//! One module per concept; equation numbers refer to `docs/theory.md`.

pub mod cmath;
pub mod elliptic;
pub mod freebody;
pub mod invariants;
pub mod so3;
pub mod torque_free;

pub mod version {
    /// The crate's version, for `poinsot._core.__version__`.
    pub const VERSION: &str = env!("CARGO_PKG_VERSION");
}
