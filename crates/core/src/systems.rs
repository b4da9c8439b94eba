//! The rigid-body systems the integrators step (eqs (07)–(09)), as plain data implementing
//! [`VectorField`] and [`RigidStructure`].
//!
//! * [`TorqueFree`]: a free body with no force (Euler's equation (20) and the free flight of
//!   its centre of mass): straight-line code, the fastest path.
//! * [`Rigid`]: a body under built-in forces, free or about a pivot, and optionally forces of
//!   the user's ([`UserWrench`]: a Python callable, a C function), evaluated at the body-frame
//!   state they expect.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::forces::{total_potential, total_wrench, Force};
use crate::layout::{load, Body, STATE_SIZE};
use crate::rigid::{
    pivot_constrained, rigid_rates, shift_torque_to_pivot, state_from_principal, State,
};
use crate::so3::Mat3;
use crate::system::{RigidStructure, VectorField};

/// Forces of the user's: `(F, τ)` at the body-frame state (force in space, torque about the
/// centre of mass in the body frame); `None` when the call failed (the run then stops).
pub trait UserWrench {
    fn wrench(&self, t: f64, y_body: &State) -> Option<[f64; 6]>;
}

/// No user forces.
pub struct NoUser;

impl UserWrench for NoUser {
    #[inline(always)]
    fn wrench(&self, _: f64, _: &State) -> Option<[f64; 6]> {
        Some([0.0; 6])
    }
}

/// A free body with no force.
pub struct TorqueFree {
    pub body: Body,
}

impl VectorField for TorqueFree {
    #[inline(always)]
    fn dim(&self) -> usize {
        STATE_SIZE
    }
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        out[..STATE_SIZE].copy_from_slice(&self.rates(t, &load(y)));
    }
}

impl RigidStructure for TorqueFree {
    #[inline(always)]
    fn body(&self) -> &Body {
        &self.body
    }
    #[inline(always)]
    fn wrench(&self, _: f64, _: &State) -> [f64; 6] {
        [0.0; 6]
    }
    #[inline(always)]
    fn rates(&self, _: f64, y: &State) -> State {
        crate::rigid::free_rigid_rates(&self.body, y, [0.0; 6])
    }
    #[inline(always)]
    fn constrain(&self, _: f64, y: State) -> State {
        y
    }
}

/// A body under built-in forces and the user's, free or about a pivot.
pub struct Rigid<U: UserWrench = NoUser> {
    pub body: Body,
    pub forces: Vec<Force>,
    /// Principal axes (columns) in body coordinates: the user's forces see body-frame states.
    pub axes: Mat3,
    pub user: Option<U>,
    failed: AtomicBool,
}

impl<U: UserWrench> Rigid<U> {
    pub fn new(body: Body, forces: Vec<Force>, axes: Mat3, user: Option<U>) -> Self {
        Rigid {
            body,
            forces,
            axes,
            user,
            failed: AtomicBool::new(false),
        }
    }

    /// Total potential energy of the built-in forces.
    pub fn potential(&self, t: f64, y: &State) -> f64 {
        total_potential(&self.forces, &self.body, t, y)
    }
}

impl<U: UserWrench> VectorField for Rigid<U> {
    #[inline(always)]
    fn dim(&self) -> usize {
        STATE_SIZE
    }
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        out[..STATE_SIZE].copy_from_slice(&self.rates(t, &load(y)));
    }
    #[inline(always)]
    fn project(&self, t: f64, y: &mut [f64]) -> bool {
        let c = self.constrain(t, load(y));
        y[..STATE_SIZE].copy_from_slice(&c);
        self.body.has_pivot
    }
    #[inline(always)]
    fn failed(&self) -> bool {
        self.failed.load(Ordering::Relaxed)
    }
}

impl<U: UserWrench> RigidStructure for Rigid<U> {
    #[inline(always)]
    fn body(&self) -> &Body {
        &self.body
    }
    /// The built-in forces plus the user's (their torques turned to the principal frame:
    /// `τ_p = Eᵀ τ`), about the reference point (`τ_P = τ_G + c × QᵀF`).
    #[inline(always)]
    fn wrench(&self, t: f64, y: &State) -> [f64; 6] {
        let mut w = total_wrench(&self.forces, &self.body, t, y);
        if let Some(user) = &self.user {
            let mut yb = [0.0; STATE_SIZE];
            state_from_principal(&self.axes, y, &mut yb);
            match user.wrench(t, &yb) {
                Some(u) => {
                    let e = &self.axes;
                    w[0] += u[0];
                    w[1] += u[1];
                    w[2] += u[2];
                    for k in 0..3 {
                        w[3 + k] += e[0][k] * u[3] + e[1][k] * u[4] + e[2][k] * u[5];
                    }
                }
                None => {
                    self.failed.store(true, Ordering::Relaxed);
                    w = [f64::NAN; 6];
                }
            }
        }
        shift_torque_to_pivot(&self.body, y, w)
    }
    #[inline(always)]
    fn rates(&self, t: f64, y: &State) -> State {
        rigid_rates(&self.body, y, self.wrench(t, y))
    }
    #[inline(always)]
    fn constrain(&self, _: f64, y: State) -> State {
        pivot_constrained(&self.body, y)
    }
}
