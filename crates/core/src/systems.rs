//! The rigid-body systems the integrators step (eqs (07)–(09)), as plain data implementing
//! [`VectorField`] and [`RigidStructure`].
//!
//! * [`TorqueFree`]: a free body with no force (Euler's equation (20) and the free flight of
//!   its centre of mass): straight-line code, the fastest path.
//! * [`Rigid`]: a body under built-in forces, free or about a pivot, and optionally forces of
//!   the user's ([`UserWrench`]: a Python callable, a C function), evaluated at the body-frame
//!   state they expect.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::forces::{
    kepler_part, one_force_wrench, total_potential, total_wrench, Force, ForceKind,
};
use crate::layout::{load, Body, FORCE_PARAMS, OMEGA_AT, Q_AT, R_AT, STATE_SIZE, V_AT};
use crate::rigid::{
    attitude_rate, attitude_row_acc, euler_free_coefficients, free_rotor, omega_dot_free,
    omega_dot_free_acc, pivot_constrained, rigid_rates, shift_torque_to_pivot,
    state_from_principal, State,
};

use crate::so3::{dexpinv3, exp_so3, Mat3, Vec3};
use crate::steppers::{rk4_points_driven, rk4_points_driver, splitting_step_with};
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

/// A free body with no force: the rotation by the torque-free Euler equation (20) and
/// `Q̇ = QΩ` (09), the centre of mass in free flight.
pub struct TorqueFree {
    pub body: Body,
    /// The coefficients of eq. (20) ([`euler_free_coefficients`]).
    pub euler: Vec3,
}

impl TorqueFree {
    pub fn new(body: Body) -> Self {
        TorqueFree {
            euler: euler_free_coefficients(body.moments, body.inv_moments),
            body,
        }
    }

    /// The rates of the rotation `x = [Q (9), ω (3)]`.
    #[inline(always)]
    fn rotation_rates(&self, x: &[f64; 12]) -> [f64; 12] {
        let w = [x[9], x[10], x[11]];
        let a = attitude_rate(&x[..9], w);
        let d = omega_dot_free(self.euler, w);
        [
            a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8], d[0], d[1], d[2],
        ]
    }
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
        let mut x = [0.0; 12];
        x.copy_from_slice(&y[Q_AT..STATE_SIZE]);
        let r = self.rotation_rates(&x);
        let mut out = [0.0; STATE_SIZE];
        out[R_AT..R_AT + 3].copy_from_slice(&y[V_AT..V_AT + 3]);
        out[Q_AT..STATE_SIZE].copy_from_slice(&r);
        out
    }
    #[inline(always)]
    fn constrain(&self, _: f64, y: State) -> State {
        y
    }
    /// RK4 on the rotation `[Q, ω]`; the centre of mass by its exact free flight `R + hV`,
    /// `V` (what RK4 computes for `Ṙ = V`, `V̇ = 0` in exact arithmetic). ω moves on its own
    /// (20) and drives each row of Q (09), so the step is taken as ω's stage points, then
    /// each row on them, in RK4's stage-point form ([`TorqueFree::rk4_points`]).
    #[inline(always)]
    fn rk4(&self, _: f64, y: &State, h: f64) -> State {
        self.rk4_points(y, h)
    }
    /// RKMK4 in registers ([`TorqueFree::rkmk4_step`]).
    #[inline(always)]
    fn rkmk4(&self, _: f64, y: &State, h: f64) -> State {
        self.rkmk4_step(y, h)
    }
    /// The splitting step without forces ([`TorqueFree::splitting_free`]).
    #[inline(always)]
    fn splitting(&self, _: f64, z: &State, h: f64) -> State {
        self.splitting_free::<ANY_ROTOR>(z, h)
    }
}

impl TorqueFree {
    /// The splitting method's step ([`crate::steppers::splitting_step`]) for the free body, on
    /// the momentum state `[R, V, Q, π]`: the kicks have no force to give, so the step is the
    /// drift alone, the exact free rotor ([`free_rotor`]; `ROTOR` [`TRIAXIAL`] or
    /// [`SYMMETRIC`] names the branch the body takes, so that a block of lanes has none) and
    /// `R += hV` (the generic step's numbers up to the sign of a zero).
    #[inline(always)]
    pub fn splitting_free<const ROTOR: u8>(&self, z: &State, h: f64) -> State {
        let mut out = *z;
        free_rotor::<ROTOR, f64>(&self.body, &mut out, h);
        for k in 0..3 {
            out[R_AT + k] += h * out[V_AT + k];
        }
        out
    }

    /// Runge–Kutta–Munthe-Kaas with the classical RK4 tableau (`RK4_A`, `RK4_B`): the step of
    /// [`crate::steppers::rkmk_step`] for the free body, bit for bit in Q and ω. ω's rates (20) do not depend on the
    /// attitude, so the stages need no rotated attitude, only the increments of the
    /// exponential coordinates: `θ_i = h Σ_j a_ij kθ_j`, `kθ_i = dexp⁻¹_{−θ_i}(ω_i)` (`kθ_1 = ω`),
    /// and Q moves once, `Q exp(h Σ_i b_i kθ_i)` (on SO(3) to round-off). The centre of mass
    /// moves by `R + hV`. No fused operations, so every
    /// instruction set gives the same numbers, and the ensembles run it in lanes
    /// ([`crate::lanes::BlockRkmk4`]).
    #[inline(always)]
    pub fn rkmk4_step(&self, y: &State, h: f64) -> State {
        use crate::tableaux::{RK4_A, RK4_B};
        let c = self.euler;
        let w = [y[OMEGA_AT], y[OMEGA_AT + 1], y[OMEGA_AT + 2]];
        // a stage point `x + h (a k)`, as the generic step forms it
        let at = |x: &Vec3, a: f64, k: &Vec3| [0, 1, 2].map(|i| x[i] + h * (a * k[i]));
        let k1 = omega_dot_free(c, w);
        let (a21, a32, a43) = (RK4_A[1][0], RK4_A[2][1], RK4_A[3][2]);
        let w2 = at(&w, a21, &k1);
        let th2 = at(&[0.0; 3], a21, &w);
        let kt2 = dexpinv3(th2.map(|x| -x), w2);
        let k2 = omega_dot_free(c, w2);
        let w3 = at(&w, a32, &k2);
        let th3 = at(&[0.0; 3], a32, &kt2);
        let kt3 = dexpinv3(th3.map(|x| -x), w3);
        let k3 = omega_dot_free(c, w3);
        let w4 = at(&w, a43, &k3);
        let th4 = at(&[0.0; 3], a43, &kt3);
        let kt4 = dexpinv3(th4.map(|x| -x), w4);
        let k4 = omega_dot_free(c, w4);
        let b = RK4_B;
        let mean = |k: [&Vec3; 4]| {
            [0, 1, 2]
                .map(|i| 0.0 + b[0] * k[0][i] + b[1] * k[1][i] + b[2] * k[2][i] + b[3] * k[3][i])
        };
        let dw = mean([&k1, &k2, &k3, &k4]);
        let th = mean([&w, &kt2, &kt3, &kt4]);
        let e = exp_so3([h * th[0], h * th[1], h * th[2]]);
        let mut out = *y;
        for r in 0..3 {
            let q = [y[Q_AT + 3 * r], y[Q_AT + 3 * r + 1], y[Q_AT + 3 * r + 2]];
            for k in 0..3 {
                out[Q_AT + 3 * r + k] = q[0] * e[0][k] + q[1] * e[1][k] + q[2] * e[2][k];
            }
        }
        for i in 0..3 {
            out[R_AT + i] = y[R_AT + i] + h * y[V_AT + i];
            out[OMEGA_AT + i] = w[i] + h * dw[i];
        }
        out
    }

    /// Classical RK4 on `[Q, ω]` in stage-point form ([`rk4_points_driver`] for ω,
    /// [`rk4_points_driven`] for each row of Q on ω's stage points): in exact arithmetic the
    /// RK4 step of [`crate::steppers::rk4_registers`] on the whole state, with every sum of
    /// products a fused multiply-add (in the AVX-512 lanes, 164 vector operations per eight
    /// members, against 186 with the stage derivatives formed). Only a few numbers are live
    /// at a time, so the ensembles' lanes keep them in vector registers.
    #[inline(always)]
    pub fn rk4_points(&self, y: &State, h: f64) -> State {
        let c = self.euler;
        let w = [y[OMEGA_AT], y[OMEGA_AT + 1], y[OMEGA_AT + 2]];
        let (w1, stages) = rk4_points_driver(|b, a, w| omega_dot_free_acc(c, b, a, w), &w, h);
        let row = |r: usize| {
            let q = [y[Q_AT + 3 * r], y[Q_AT + 3 * r + 1], y[Q_AT + 3 * r + 2]];
            rk4_points_driven(attitude_row_acc, &q, &stages, h)
        };
        let (a, b, c) = (row(0), row(1), row(2));
        [
            h.mul_add(y[V_AT], y[R_AT]),
            h.mul_add(y[V_AT + 1], y[R_AT + 1]),
            h.mul_add(y[V_AT + 2], y[R_AT + 2]),
            y[V_AT],
            y[V_AT + 1],
            y[V_AT + 2],
            a[0],
            a[1],
            a[2],
            b[0],
            b[1],
            b[2],
            c[0],
            c[1],
            c[2],
            w1[0],
            w1[1],
            w1[2],
        ]
    }
}

pub use crate::rigid::{ANY_ROTOR, SYMMETRIC, TRIAXIAL};

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
    crate::default_rigid_steps!(rk4, rkmk4, splitting);
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
    fn orbit(&self) -> Option<Force> {
        kepler_part(&self.body, &self.forces).map(|i| self.forces[i])
    }
}

/// A body under at most one built-in force, of kind `K` (its [`ForceKind`] code; 0: none),
/// free or about a pivot (`PIVOT`), with no force of the user's: [`Rigid`]'s equations with
/// the kind and the pivot known at compile time, so that a block of lanes runs its steps as
/// straight-line vector code (a [`Rigid`] loops over its forces and branches on their kinds,
/// and its lanes run scalar). Its numbers are bit for bit [`Rigid`]'s with the same force
/// ([`one_force_wrench`]; the same functions in the same order).
#[derive(Clone, Copy, Debug)]
pub struct OneForce<const K: i64, const PIVOT: bool> {
    pub body: Body,
    /// The force's parameters (unused when `K` is 0).
    pub params: [f64; FORCE_PARAMS],
}

impl<const K: i64, const PIVOT: bool> OneForce<K, PIVOT> {
    /// The system of a body and its forces when they are `K`'s: none for `K = 0`, else one
    /// force of that kind, and the body's pivot `PIVOT`'s; `None` otherwise.
    pub fn new(body: Body, forces: &[Force]) -> Option<Self> {
        if body.has_pivot != PIVOT {
            return None;
        }
        let params = match forces {
            [] if K == 0 => [0.0; FORCE_PARAMS],
            [f] if K != 0 && f.kind as i64 == K => f.p,
            _ => return None,
        };
        Some(OneForce { body, params })
    }

    /// A copy whose pivot flag is the constant `PIVOT`: every method works on it, so that
    /// inlined into a block of lanes no branch on the flag is left.
    #[inline(always)]
    fn fixed(&self) -> Self {
        let mut s = *self;
        s.body.has_pivot = PIVOT;
        s
    }
}

/// The [`VectorField`] of a rigid system whose pivot flag is the constant `PIVOT`: its
/// [`RigidStructure::rates`], and [`RigidStructure::constrain`] as the projection.
macro_rules! pivot_const_vector_field {
    ([$($gen:tt)*] $ty:ty) => {
        impl<$($gen)*> VectorField for $ty {
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
                PIVOT
            }
        }
    };
}

pivot_const_vector_field!([const K: i64, const PIVOT: bool] OneForce<K, PIVOT>);

impl<const K: i64, const PIVOT: bool> RigidStructure for OneForce<K, PIVOT> {
    crate::default_rigid_steps!(rk4, rkmk4);
    #[inline(always)]
    fn body(&self) -> &Body {
        &self.body
    }
    /// The force's wrench, summed as [`total_wrench`] sums a list of one (or none), about the
    /// reference point.
    #[inline(always)]
    fn wrench(&self, t: f64, y: &State) -> [f64; 6] {
        let body = self.fixed().body;
        let mut w = [0.0; 6];
        if K != 0 {
            let v = one_force_wrench::<K>(&self.params, &body, t, y);
            for k in 0..6 {
                w[k] += v[k];
            }
        }
        shift_torque_to_pivot(&body, y, w)
    }
    #[inline(always)]
    fn rates(&self, t: f64, y: &State) -> State {
        let s = self.fixed();
        rigid_rates(&s.body, y, s.wrench(t, y))
    }
    #[inline(always)]
    fn constrain(&self, _: f64, y: State) -> State {
        pivot_constrained(&self.fixed().body, y)
    }
    #[inline(always)]
    fn splitting(&self, t: f64, z: &State, h: f64) -> State {
        self.splitting_rotor::<ANY_ROTOR>(t, z, h)
    }
    fn orbit(&self) -> Option<Force> {
        let force = Force {
            kind: ForceKind::from_code(K)?,
            p: self.params,
        };
        kepler_part(&self.fixed().body, &[force]).map(|_| force)
    }
}

impl<const K: i64, const PIVOT: bool> OneForce<K, PIVOT> {
    /// The splitting step ([`splitting_step_with`]) with the free rotor's branch `ROTOR`
    /// ([`free_rotor`]) named, so that a block of lanes whose bodies take the same branch has
    /// none.
    #[inline(always)]
    pub fn splitting_rotor<const ROTOR: u8>(&self, t: f64, z: &State, h: f64) -> State {
        let mut out = [0.0; STATE_SIZE];
        splitting_step_with::<_, ROTOR>(&self.fixed(), t, z, h, &mut out);
        out
    }
}

/// The most forces a [`SameForces`] body holds.
pub const MAX_SAME_FORCES: usize = 8;

/// A [`Rigid`] body (built-in forces only, at most [`MAX_SAME_FORCES`]) in a block of lanes
/// whose bodies all have the same force kinds in the same order and are all free or all about
/// a pivot (`PIVOT`), their parameters their own: its equations are the [`Rigid`]'s (the same
/// functions in the same order, so its numbers are bit for bit the same) with the pivot flag
/// constant and the forces held in place (no pointer to follow, no length to check in a
/// lane's loop), so that the block can evaluate one force for every lane before the next
/// ([`crate::lanes::LaneRates`]) and its lanes' loops have no branch on a kind.
#[derive(Clone, Copy, Debug)]
pub struct SameForces<const PIVOT: bool> {
    /// The body with its pivot flag the constant `PIVOT`.
    pub body: Body,
    /// The forces, the first `n` of them in use.
    pub forces: [Force; MAX_SAME_FORCES],
    pub n: usize,
}

impl<const PIVOT: bool> SameForces<PIVOT> {
    /// `rigid`'s body and forces when its pivot flag is `PIVOT`, it has no force of the
    /// user's and at most [`MAX_SAME_FORCES`] built-in ones.
    pub fn new<U: UserWrench>(rigid: &Rigid<U>) -> Option<Self> {
        let n = rigid.forces.len();
        if rigid.body.has_pivot != PIVOT || rigid.user.is_some() || n > MAX_SAME_FORCES {
            return None;
        }
        let unused = Force {
            kind: ForceKind::Gravity,
            p: [0.0; FORCE_PARAMS],
        };
        let mut forces = [unused; MAX_SAME_FORCES];
        forces[..n].copy_from_slice(&rigid.forces);
        Some(SameForces {
            body: rigid.body,
            forces,
            n,
        })
    }

    /// The forces in use.
    #[inline(always)]
    pub fn forces(&self) -> &[Force] {
        &self.forces[..self.n.min(MAX_SAME_FORCES)]
    }
}

pivot_const_vector_field!([const PIVOT: bool] SameForces<PIVOT>);

impl<const PIVOT: bool> RigidStructure for SameForces<PIVOT> {
    crate::default_rigid_steps!(rk4, rkmk4, splitting);
    #[inline(always)]
    fn body(&self) -> &Body {
        &self.body
    }
    /// [`Rigid`]'s wrench without the user's: the built-in forces summed in their order
    /// ([`total_wrench`]), about the reference point.
    #[inline(always)]
    fn wrench(&self, t: f64, y: &State) -> [f64; 6] {
        let w = total_wrench(self.forces(), &self.body, t, y);
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
    fn orbit(&self) -> Option<Force> {
        kepler_part(&self.body, self.forces()).map(|i| self.forces[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::steppers::rk4_registers;

    /// A free body of principal moments `moments` (mass 4) and a state of mixed signs and
    /// sizes (its attitude not a rotation).
    fn free_body_and_state(moments: Vec3) -> (TorqueFree, State) {
        let a = [0, 1, 2].map(|r| [0, 1, 2].map(|c| if r == c { moments[r] } else { 0.0 }));
        let body = Body::from_slice(&Body::vector(
            4.0, moments, [0.0; 3], &a, [0.0; 3], false, -1,
        ))
        .unwrap();
        let mut y = [0.0; STATE_SIZE];
        for (k, v) in y.iter_mut().enumerate() {
            *v = (1.7 * k as f64 + 0.3).sin();
        }
        (TorqueFree::new(body), y)
    }

    #[test]
    fn torque_free_rkmk4_step_is_the_generic_rkmk_step() {
        // the same numbers as rkmk_step with the RK4 tableau on the whole state, bit for bit
        // in Q and ω, for small and large steps (the series and the formulas of exp and
        // dexp⁻¹), the centre of mass in free flight
        use crate::steppers::{rkmk_step, RK4};
        for moments in [[1.0, 2.0, 3.5], [2.0, 2.0, 3.0], [0.7, 1.9, 1.9]] {
            let (sys, mut y) = free_body_and_state(moments);
            let q = exp_so3([0.4, -1.2, 2.0]);
            for i in 0..3 {
                y[Q_AT + 3 * i..Q_AT + 3 * i + 3].copy_from_slice(&q[i]);
            }
            for h in [1e-6, 1e-3, 0.05, 0.7] {
                let mut z = y;
                let (mut k, mut ytmp, mut kth) =
                    (vec![0.0; 4 * STATE_SIZE], [0.0; STATE_SIZE], [[0.0; 3]; 4]);
                for _ in 0..50 {
                    let mut generic = [0.0; STATE_SIZE];
                    rkmk_step(
                        &sys,
                        &RK4,
                        0.0,
                        &z,
                        h,
                        &mut k,
                        &mut ytmp,
                        &mut kth,
                        &mut generic,
                    );
                    let own = sys.rkmk4(0.0, &z, h);
                    for k in Q_AT..STATE_SIZE {
                        assert_eq!(
                            own[k].to_bits(),
                            generic[k].to_bits(),
                            "{moments:?} {h} {k}"
                        );
                    }
                    for k in 0..3 {
                        assert_eq!(own[R_AT + k], z[R_AT + k] + h * z[V_AT + k]);
                        assert_eq!(own[V_AT + k], z[V_AT + k]);
                    }
                    z = own;
                }
            }
        }
    }

    #[test]
    fn torque_free_stage_point_step_is_rk4_on_the_whole_state() {
        // ω's stage points first, then each row of Q on them: RK4 on [R, V, Q, ω] with the
        // centre of mass in free flight, to round-off at every step (the same formulas in
        // exact arithmetic, rounded differently), with R + hV fused
        for moments in [[1.0, 2.0, 3.5], [2.0, 2.0, 3.0], [0.7, 1.9, 1.9]] {
            let (sys, y) = free_body_and_state(moments);
            for h in [1e-3, 0.05, 0.7] {
                let mut z = y;
                for _ in 0..50 {
                    let whole = rk4_registers(|t, y| sys.rates(t, y), 0.0, &z, h);
                    let points = sys.rk4(0.0, &z, h);
                    for k in Q_AT..STATE_SIZE {
                        let tol = 4e-15 * (1.0 + whole[k].abs());
                        assert!((points[k] - whole[k]).abs() < tol, "{moments:?} {h} {k}");
                    }
                    for k in 0..3 {
                        assert_eq!(points[R_AT + k], h.mul_add(z[V_AT + k], z[R_AT + k]));
                        assert_eq!(points[V_AT + k], z[V_AT + k]);
                    }
                    z = whole;
                }
            }
        }
    }

    const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    /// A body (mass 4, the centre of mass off the reference point when `pivot`) and one force
    /// of every kind (parameters that make each act: a spring stretched, a body-fixed point
    /// force, a couple in space, gravity's gradient on).
    fn forced_body(pivot: bool) -> (Body, Vec<Force>) {
        forced_body_with(pivot, [1.0, 2.0, 3.5], -1)
    }

    /// [`forced_body`] with the principal `moments` and the free rotor's kind `rotor` (−1:
    /// three distinct moments; else the symmetry axis).
    fn forced_body_with(pivot: bool, moments: Vec3, rotor: i32) -> (Body, Vec<Force>) {
        use crate::forces::ForceKind;
        let a = [[1.2, 0.1, 0.0], [0.1, 2.1, -0.2], [0.0, -0.2, 3.0]];
        let c = if pivot { [0.1, -0.2, 0.4] } else { [0.0; 3] };
        let body = Body::from_slice(&Body::vector(
            4.0,
            moments,
            c,
            &a,
            [0.3, 0.0, -0.1],
            pivot,
            rotor,
        ))
        .unwrap();
        let force = |kind: ForceKind, p: &[f64]| {
            let mut params = [0.0; FORCE_PARAMS];
            params[..p.len()].copy_from_slice(p);
            Force { kind, p: params }
        };
        let forces = vec![
            force(ForceKind::Gravity, &[0.0, 0.0, -9.8]),
            force(ForceKind::CentralGravity, &[40.0, -6.0, 1.0, 0.5, 1.0]),
            force(
                ForceKind::Spring,
                &[0.1, 0.2, 0.0, 2.0, 1.0, -1.0, 0.0, 0.5, 0.3, 1.0],
            ),
            force(ForceKind::LinearDrag, &[0.3, 0.05]),
            force(ForceKind::QuadraticDrag, &[0.2, 0.04]),
            force(ForceKind::PointForce, &[0.0, 0.3, 0.1, 1.0, -2.0, 0.5, 1.0]),
            force(ForceKind::Torque, &[0.4, -0.1, 0.2, 1.0]),
        ];
        (body, forces)
    }

    /// `OneForce::<K, P>`'s rates and steps against [`Rigid`]'s with the same force, bit for
    /// bit (`Rigid` loops over its forces and reads the pivot flag at run time).
    fn one_force_is_rigid<const K: i64, const P: bool>(forces: &[Force], body: Body, y: &State) {
        let rigid = Rigid::<NoUser>::new(body, forces.to_vec(), IDENTITY, None);
        let one = OneForce::<K, P>::new(body, forces).expect("the force's kind and pivot");
        let bits = |x: &State| x.map(f64::to_bits);
        for t in [0.0, 0.7] {
            assert_eq!(bits(&one.rates(t, y)), bits(&rigid.rates(t, y)), "{K} {P}");
            for h in [1e-3, 0.05] {
                assert_eq!(bits(&one.rk4(t, y, h)), bits(&rigid.rk4(t, y, h)));
                assert_eq!(bits(&one.rkmk4(t, y, h)), bits(&rigid.rkmk4(t, y, h)));
                let split = bits(&rigid.splitting(t, y, h));
                assert_eq!(bits(&one.splitting(t, y, h)), split);
                // the rotor's branch named as the lanes name it
                let named = if body.rotor < 0 {
                    one.splitting_rotor::<TRIAXIAL>(t, y, h)
                } else {
                    one.splitting_rotor::<SYMMETRIC>(t, y, h)
                };
                assert_eq!(bits(&named), split);
                let c = one.constrain(t, *y);
                assert_eq!(bits(&c), bits(&rigid.constrain(t, *y)));
            }
        }
        // the wrong kind or pivot is refused
        assert!(OneForce::<K, P>::new(body, &[forces, forces].concat()).is_none() || K == 0);
        let mut other = body;
        other.has_pivot = !P;
        assert!(OneForce::<K, P>::new(other, forces).is_none());
    }

    #[test]
    fn one_force_systems_are_rigid_systems_bit_for_bit() {
        // free and pivoted, triaxial and symmetric (about the third and the second axis), at
        // 20 states drawn at random: positions within a few units of the central body's
        // centre, velocities and rates of mixed signs and sizes, attitudes on SO(3)
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = move |lo: f64, hi: f64| {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
        };
        for (pivot, moments, rotor) in [
            (false, [1.0, 2.0, 3.5], -1),
            (true, [1.0, 2.0, 3.5], -1),
            (false, [2.0, 2.0, 3.0], 2),
            (true, [2.0, 3.0, 2.0], 1),
        ] {
            let (body, forces) = forced_body_with(pivot, moments, rotor);
            for _ in 0..20 {
                let mut y = [0.0; STATE_SIZE];
                for v in y.iter_mut() {
                    *v = uniform(-3.0, 3.0);
                }
                let q = exp_so3([uniform(-3.0, 3.0), uniform(-3.0, 3.0), uniform(-3.0, 3.0)]);
                for i in 0..3 {
                    y[Q_AT + 3 * i..Q_AT + 3 * i + 3].copy_from_slice(&q[i]);
                }
                check_one_force_systems(pivot, &forces, body, &y);
            }
        }
    }

    /// [`one_force_is_rigid`] for every kind at the state `y`.
    fn check_one_force_systems(pivot: bool, forces: &[Force], body: Body, y: &State) {
        macro_rules! check {
            ($p:literal) => {
                one_force_is_rigid::<0, $p>(&[], body, y);
                one_force_is_rigid::<1, $p>(&forces[0..1], body, y);
                one_force_is_rigid::<2, $p>(&forces[1..2], body, y);
                one_force_is_rigid::<3, $p>(&forces[2..3], body, y);
                one_force_is_rigid::<4, $p>(&forces[3..4], body, y);
                one_force_is_rigid::<5, $p>(&forces[4..5], body, y);
                one_force_is_rigid::<6, $p>(&forces[5..6], body, y);
                one_force_is_rigid::<7, $p>(&forces[6..7], body, y);
            };
        }
        if pivot {
            check!(true);
        } else {
            check!(false);
        }
    }

    #[test]
    fn rkmk4_in_registers_is_the_generic_rkmk_step() {
        // RKMK4 on a body under every force, free and about a pivot: the register step
        // against rkmk_step with the RK4 tableau, bit for bit, for small and large steps
        use crate::steppers::{rkmk_step, RK4};
        for pivot in [false, true] {
            let (body, forces) = forced_body(pivot);
            let sys = Rigid::<NoUser>::new(body, forces, IDENTITY, None);
            let (_, mut z) = free_body_and_state([1.0, 2.0, 3.5]);
            let q = exp_so3([0.4, -1.2, 2.0]);
            for i in 0..3 {
                z[Q_AT + 3 * i..Q_AT + 3 * i + 3].copy_from_slice(&q[i]);
            }
            for h in [1e-6, 1e-3, 0.05, 0.3] {
                let (mut k, mut ytmp, mut kth) =
                    (vec![0.0; 4 * STATE_SIZE], [0.0; STATE_SIZE], [[0.0; 3]; 4]);
                let mut y = z;
                for step in 0..20 {
                    let t = step as f64 * h;
                    let mut generic = [0.0; STATE_SIZE];
                    rkmk_step(
                        &sys,
                        &RK4,
                        t,
                        &y,
                        h,
                        &mut k,
                        &mut ytmp,
                        &mut kth,
                        &mut generic,
                    );
                    let own = sys.rkmk4(t, &y, h);
                    assert_eq!(
                        own.map(f64::to_bits),
                        generic.map(f64::to_bits),
                        "{pivot} {h}"
                    );
                    y = sys.constrain(t + h, own);
                }
            }
        }
    }
}
