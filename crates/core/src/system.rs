//! The contract between a model and the integrators (diffsol's `OdeEquations`, in small):
//! a system is plain data with a right-hand side. The steppers and drivers of this crate see
//! nothing else of it.
//!
//! 1. [`VectorField::dim`]: the length of the state (a constant where the system fixes it, so
//!    the compiler unrolls the steppers' loops).
//! 2. [`VectorField::rhs`]: `out = ẏ(t, y)`.
//! 3. [`VectorField::project`]: put `y` back on the system's constraint manifold at `t`, in
//!    place, and say whether the system is constrained (the drivers then recompute a cached
//!    derivative). Unconstrained systems keep the default, a no-op returning `false`.
//! 4. [`VectorField::error_blocks`]: what the adaptive error control weighs (the state, and
//!    the sensitivities one direction at a time)
//!    (all by default).
//! 5. [`VectorField::failed`]: a system that calls out (a Python callback) reports here that a
//!    call failed; the drivers stop with [`crate::drivers::Status::CallbackFailed`].
//!
//! Rigid bodies offer more structure ([`RigidStructure`]): their parameters, for the steppers
//! that use the free-rotor flows, and the wrench of their forces, for the splitting method's
//! kicks; their rates on a state held in registers, for the fixed-step fast path; and their
//! steps in registers, which the steppers write (`crate::default_rigid_steps!`) unless the
//! system has cheaper ones. This module names no stepper: the steppers depend on it, not it
//! on them.

use crate::forces::Force;
use crate::layout::{Body, STATE_SIZE};

/// An ordinary differential equation `ẏ = f(t, y)` on a flat state.
pub trait VectorField {
    /// Length of the state.
    fn dim(&self) -> usize;
    /// `out = ẏ(t, y)`.
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]);
    /// Put `y` on the constraint manifold at `t`, in place; `true` when constrained.
    #[inline(always)]
    fn project(&self, _t: f64, _y: &mut [f64]) -> bool {
        false
    }
    /// What the adaptive method's error control weighs, `(n, p)`: the first `n` components
    /// (the system's own state; all of them unless the system says otherwise) and, when
    /// `p > 0`, the forward sensitivities of `p` directions stored after them component by
    /// component (`y[n + p i + j] = ∂y_i/∂p_j`). The error is then the largest of the state's
    /// norm and each direction's, as CVODES' `errconS` takes it (Serban & Hindmarsh 2005, §3);
    /// `p = 0` leaves the sensitivities out.
    #[inline(always)]
    fn error_blocks(&self) -> (usize, usize) {
        (self.dim(), 0)
    }
    /// True once a call out of the engine (a user callback) has failed.
    #[inline(always)]
    fn failed(&self) -> bool {
        false
    }
}

/// The rigid-body structure of a system whose state is the 18-vector `[R, V, Q, ω]` in the
/// principal frame (`layout`).
pub trait RigidStructure: VectorField {
    /// The body's parameters (principal frame of the inertia about the reference point).
    fn body(&self) -> &Body;
    /// `(F, τ)`: total force (space frame) and torque about the reference point (principal
    /// frame) at `(t, y)`.
    fn wrench(&self, t: f64, y: &[f64; STATE_SIZE]) -> [f64; 6];
    /// `ẏ` of a state held in registers (eqs (07)–(09)).
    fn rates(&self, t: f64, y: &[f64; STATE_SIZE]) -> [f64; STATE_SIZE];
    /// The state put back on its constraint (the pivot), or unchanged.
    fn constrain(&self, t: f64, y: [f64; STATE_SIZE]) -> [f64; STATE_SIZE];
    /// One classical RK4 step of the state in registers (before [`RigidStructure::constrain`]).
    /// A system whose structure offers nothing cheaper takes the stages on the whole state
    /// ([`crate::default_rigid_steps!`]); one whose structure lets part of the step be exact
    /// says so.
    fn rk4(&self, t: f64, y: &[f64; STATE_SIZE], h: f64) -> [f64; STATE_SIZE];
    /// One Runge–Kutta–Munthe-Kaas step with the classical RK4 tableau on the state in
    /// registers (before [`VectorField::project`]), the same way.
    fn rkmk4(&self, t: f64, y: &[f64; STATE_SIZE], h: f64) -> [f64; STATE_SIZE];
    /// One step of the splitting method on the momentum state in registers, the same way.
    fn splitting(&self, t: f64, z: &[f64; STATE_SIZE], h: f64) -> [f64; STATE_SIZE];
    /// The central gravity whose point-mass part the exact-flow splittings' drift solves
    /// exactly ([`crate::forces::kepler_part`]): none unless the system has one.
    fn orbit(&self) -> Option<Force> {
        None
    }
}
