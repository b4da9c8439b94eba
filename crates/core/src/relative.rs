//! Motion relative to a moving carrier frame (`docs/relative.md`; paper eqs (1)–(18)).
//!
//! A body moves relative to a *carrier* frame that turns with the transport angular velocity
//! `ω_e` and angular acceleration `ε_e`, and whose origin accelerates by `a_O`. Body-frame
//! components throughout; `J` is the inertia about the centre of mass and `ω_r` the body's
//! angular velocity relative to the carrier.
//!
//! * the transport inertia moment `M_e = −J ε_e + Jω_e × ω_e` (2): [`transport_moment`];
//! * the Coriolis inertia moment in its compact form `M_c = 2 ω_r × (J'ω_e)` (5), `J'` the
//!   planar inertia tensor (3)–(4) ([`crate::inertia::planar_inertia`]): [`coriolis_moment`];
//!   its three-term form (2) [`coriolis_three_term`] and its definition as a particle sum (6)
//!   [`coriolis_particles`] are the independent routes the tests compare it with;
//! * the compact relative Euler equation (11) in principal components (12),
//!   `J ω̇_r = Jω_r × ω_r + M_e + M_c + M(F)`: [`relative_rates`];
//! * the system the integrators step: [`Relative`], with the carrier's motion from any
//!   [`CarrierMotion`] (piecewise polynomials [`PPolyCarrier`], compiled expressions, user
//!   callbacks).
//!
//! The relative state ([`RELATIVE_STATE_SIZE`] = 33 components):
//!
//! ```text
//! [r (3), v (3), Q_r (9), ω_r (3), Q_c (9), X_O (3), V_O (3)]
//! ```
//!
//! `r`, `v`: the centre of mass relative to the carrier's origin and its velocity relative to
//! the carrier (carrier components); `Q_r`: the attitude (body → carrier, row-major) and `ω_r`
//! (body components; the principal frame inside the engine); `Q_c`: the carrier's attitude
//! (carrier → inertial), integrated with the body from `Q̇_c = Q_c Ω_e`; `X_O`, `V_O`: the
//! carrier origin's position and velocity (inertial). The carrier's *motion* at a time is the
//! 9-vector `(ω_e, ε_e, a_O)` in carrier components ([`MOTION_SIZE`]).

use std::sync::atomic::{AtomicBool, Ordering};

use crate::expressions::Function;
use crate::inertia::planar_inertia;
use crate::layout::{Body, OMEGA_AT, Q_AT, R_AT, STATE_SIZE, V_AT};
use crate::real::Real;
use crate::rigid::{attitude_rate, omega_dot_principal};
use crate::so3::{cross, cross_t, Mat3, Vec3};
use crate::system::{RigidStructure, VectorField};
use crate::systems::{Rigid, UserWrench};

/// Length of the relative state.
pub const RELATIVE_STATE_SIZE: usize = 33;
/// Where the carrier's attitude `Q_c` (9, row-major; carrier → inertial) starts.
pub const CARRIER_Q_AT: usize = 18;
/// Where the carrier origin's position `X_O` (inertial) starts.
pub const ORIGIN_AT: usize = 27;
/// Where its velocity `V_O` (inertial) starts.
pub const ORIGIN_V_AT: usize = 30;
/// `(ω_e, ε_e, a_O)`, carrier components.
pub const MOTION_SIZE: usize = 9;
/// The carrier's motion at one time.
pub type Motion = [f64; MOTION_SIZE];

#[inline(always)]
fn mat_vec<T: Real>(a: &[[T; 3]; 3], x: [T; 3]) -> [T; 3] {
    [
        a[0][0] * x[0] + a[0][1] * x[1] + a[0][2] * x[2],
        a[1][0] * x[0] + a[1][1] * x[1] + a[1][2] * x[2],
        a[2][0] * x[0] + a[2][1] * x[1] + a[2][2] * x[2],
    ]
}

/// `Q x` for `Q` stored row-major in `q[..9]`.
#[inline(always)]
fn rows_vec<T: Real>(q: &[T], x: [T; 3]) -> [T; 3] {
    [
        q[0] * x[0] + q[1] * x[1] + q[2] * x[2],
        q[3] * x[0] + q[4] * x[1] + q[5] * x[2],
        q[6] * x[0] + q[7] * x[1] + q[8] * x[2],
    ]
}

/// `Qᵀ x` for `Q` stored row-major in `q[..9]`.
#[inline(always)]
fn rows_t_vec<T: Real>(q: &[T], x: [T; 3]) -> [T; 3] {
    [
        q[0] * x[0] + q[3] * x[1] + q[6] * x[2],
        q[1] * x[0] + q[4] * x[1] + q[7] * x[2],
        q[2] * x[0] + q[5] * x[1] + q[8] * x[2],
    ]
}

#[inline(always)]
fn vec3<T: Real>(y: &[T], at: usize) -> [T; 3] {
    [y[at], y[at + 1], y[at + 2]]
}

// ------------------------------------------------------------------------------ the moments

/// The transport inertia moment `M_e = −J ε_e + Jω_e × ω_e` (paper eq. (2)), `ω_e` and `ε_e`
/// in body components.
#[inline(always)]
pub fn transport_moment<T: Real>(j: &[[T; 3]; 3], omega_e: [T; 3], epsilon_e: [T; 3]) -> [T; 3] {
    let c = cross_t(mat_vec(j, omega_e), omega_e);
    let k = mat_vec(j, epsilon_e);
    [c[0] - k[0], c[1] - k[1], c[2] - k[2]]
}

/// The Coriolis inertia moment in its compact form `M_c = 2 ω_r × (J'ω_e)` (paper eq. (5)),
/// `J' = ½ tr(J) 𝟙 − J` the planar inertia tensor (3)–(4).
#[inline(always)]
pub fn coriolis_moment<T: Real>(j: &[[T; 3]; 3], omega_r: [T; 3], omega_e: [T; 3]) -> [T; 3] {
    let c = cross_t(omega_r, mat_vec(&planar_inertia(j), omega_e));
    let two = T::splat(2.0);
    [two * c[0], two * c[1], two * c[2]]
}

/// The Coriolis inertia moment in its three-term form
/// `M_c = Jω_r × ω_e + Jω_e × ω_r + J(ω_r × ω_e)` (paper eq. (2)).
pub fn coriolis_three_term(j: &Mat3, omega_r: Vec3, omega_e: Vec3) -> Vec3 {
    let u = cross(mat_vec(j, omega_r), omega_e);
    let v = cross(mat_vec(j, omega_e), omega_r);
    let d = mat_vec(j, cross(omega_r, omega_e));
    [u[0] + v[0] + d[0], u[1] + v[1] + d[1], u[2] + v[2] + d[2]]
}

/// The definition of the Coriolis inertia moment (paper eq. (6)): the moment about the centre
/// of mass of the particles' Coriolis inertia forces `−2 m ω_e × (ω_r × ρ)`,
/// `M_c = −2 Σ m ρ × (ω_e × (ω_r × ρ))`; `rho` the particles seen from the centre of mass.
pub fn coriolis_particles(masses: &[f64], rho: &[Vec3], omega_r: Vec3, omega_e: Vec3) -> Vec3 {
    let mut out = [0.0; 3];
    for (m, p) in masses.iter().zip(rho) {
        let c = cross(*p, cross(omega_e, cross(omega_r, *p)));
        for k in 0..3 {
            out[k] -= 2.0 * m * c[k];
        }
    }
    out
}

/// The planar inertia tensor by its definition (paper eqs (3)–(4)), `J' = Σ m ρ ρᵀ`.
pub fn planar_inertia_particles(masses: &[f64], rho: &[Vec3]) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (m, p) in masses.iter().zip(rho) {
        for a in 0..3 {
            for b in 0..3 {
                out[a][b] += m * p[a] * p[b];
            }
        }
    }
    out
}

// ------------------------------------------------------------------------------ the carrier

/// The carrier's motion `(ω_e, ε_e, a_O)` at a time; `None` when it cannot be evaluated there
/// (a user callback failed): the run then stops.
pub trait CarrierMotion {
    fn motion(&self, t: f64) -> Option<Motion>;
}

impl<T: CarrierMotion + ?Sized> CarrierMotion for &T {
    #[inline(always)]
    fn motion(&self, t: f64) -> Option<Motion> {
        (**self).motion(t)
    }
}

/// A piecewise polynomial of 3-vectors in SciPy's `PPoly` layout: `breaks` (m + 1,)
/// increasing, `coeffs` (k + 1, m, 3) flattened, highest power first.
#[derive(Clone, Debug)]
pub struct PPoly {
    pub breaks: Vec<f64>,
    pub coeffs: Vec<f64>,
    /// Polynomial degree k.
    pub degree: usize,
}

impl PPoly {
    /// Checked: at least one piece, breaks non-decreasing, coefficients of the matching size.
    pub fn new(breaks: Vec<f64>, coeffs: Vec<f64>, degree: usize) -> Result<Self, String> {
        if breaks.len() < 2 {
            return Err("needs at least two breakpoints".into());
        }
        if breaks.windows(2).any(|w| w[1] < w[0]) {
            return Err("breakpoints must not decrease".into());
        }
        let m = breaks.len() - 1;
        if coeffs.len() != (degree + 1) * m * 3 {
            return Err(format!(
                "coefficients must have shape ({}, {m}, 3), found {} numbers",
                degree + 1,
                coeffs.len()
            ));
        }
        Ok(PPoly {
            breaks,
            coeffs,
            degree,
        })
    }

    /// A constant as one piece of degree 0.
    pub fn constant(v: Vec3) -> Self {
        PPoly {
            breaks: vec![0.0, 1.0],
            coeffs: v.to_vec(),
            degree: 0,
        }
    }

    /// The piece `i` with `breaks[i] <= t < breaks[i + 1]`, clipped to the pieces (a time
    /// outside them uses the first or the last piece, as `scipy.interpolate.PPoly` does).
    #[inline]
    fn interval(&self, t: f64) -> usize {
        let m = self.breaks.len() - 1;
        let i = self.breaks.partition_point(|&b| b <= t);
        i.saturating_sub(1).min(m - 1)
    }

    /// Value and first derivative at `t`, by Horner's rule.
    #[inline]
    pub fn value_and_derivative(&self, t: f64) -> (Vec3, Vec3) {
        let m = self.breaks.len() - 1;
        let i = self.interval(t);
        let x = t - self.breaks[i];
        let at = |j: usize, c: usize| self.coeffs[(j * m + i) * 3 + c];
        let mut v = [at(0, 0), at(0, 1), at(0, 2)];
        let mut d = [0.0; 3];
        for j in 1..=self.degree {
            for c in 0..3 {
                d[c] = d[c] * x + v[c];
                v[c] = v[c] * x + at(j, c);
            }
        }
        (v, d)
    }
}

/// A carrier whose `ω_e` and `a_O` are piecewise polynomials (a constant is one piece of
/// degree 0): `ε_e` is the exact derivative of `ω_e`.
#[derive(Clone, Debug)]
pub struct PPolyCarrier {
    pub omega: PPoly,
    pub accel: PPoly,
}

impl CarrierMotion for PPolyCarrier {
    #[inline]
    fn motion(&self, t: f64) -> Option<Motion> {
        let (w, e) = self.omega.value_and_derivative(t);
        let (a, _) = self.accel.value_and_derivative(t);
        Some([w[0], w[1], w[2], e[0], e[1], e[2], a[0], a[1], a[2]])
    }
}

/// A carrier given by expressions of t: a compiled [`Function`] of one input (t) and nine
/// outputs `(ω_e, ε_e, a_O)` (`ε_e` differentiated exactly before it was compiled).
impl CarrierMotion for Function {
    #[inline]
    fn motion(&self, t: f64) -> Option<Motion> {
        let mut m = [0.0; MOTION_SIZE];
        self.eval(&[t], &mut m);
        Some(m)
    }
}

// ------------------------------------------------------------------------------ the state

/// The absolute 18-state `[R, V, Q, ω]` of a relative state `y` (33) under the carrier's
/// `motion`: `R = X_O + Q_c r`, `V = V_O + Q_c (v + ω_e × r)`, `Q = Q_c Q_r`,
/// `ω = ω_r + Q_rᵀ ω_e` (eq. (15): ω_e projected on the body axes).
pub fn absolute_state<T: Real>(y: &[T], motion: &Motion) -> [T; STATE_SIZE] {
    let qc = &y[CARRIER_Q_AT..CARRIER_Q_AT + 9];
    let q = &y[Q_AT..Q_AT + 9];
    let we = [motion[0], motion[1], motion[2]].map(T::splat);
    let r = vec3(y, R_AT);
    let x = cross_t(we, r);
    let u = [y[V_AT] + x[0], y[V_AT + 1] + x[1], y[V_AT + 2] + x[2]];
    let pr = rows_vec(qc, r);
    let pu = rows_vec(qc, u);
    let wb = rows_t_vec(q, we);
    let mut s = [T::splat(0.0); STATE_SIZE];
    for k in 0..3 {
        s[R_AT + k] = y[ORIGIN_AT + k] + pr[k];
        s[V_AT + k] = y[ORIGIN_V_AT + k] + pu[k];
        s[OMEGA_AT + k] = y[OMEGA_AT + k] + wb[k];
        for j in 0..3 {
            s[Q_AT + 3 * k + j] =
                qc[3 * k] * q[j] + qc[3 * k + 1] * q[3 + j] + qc[3 * k + 2] * q[6 + j];
        }
    }
    s
}

/// Options of the relative equation.
#[derive(Clone, Copy, Debug, Default)]
pub struct RelativeOptions {
    /// The physical moment cancels the transport moment (case (16)): `M_e` is left out.
    pub balance_transport: bool,
    /// The centre of mass is held at its place in the carrier (a gimbal mount).
    pub hold_com: bool,
}

/// `ẏ` (33) of the relative state `y` (principal frame) under the carrier's `motion`, the
/// physical force `F` (inertial, `wrench[0..3]`) and its moment `τ` about the centre of mass
/// (principal frame, `wrench[3..6]`), for a body with principal moments (A, B, C):
///
/// * the compact relative Euler equation (11) in principal components (12):
///   `J ω̇_r = Jω_r × ω_r + M_e + M_c + M(F)`, with `M_e` left out when the physical moment
///   balances it (case (16));
/// * `Q̇_r = Q_r Ω_r` and `Q̇_c = Q_c Ω_e` (eq. (09) for the body and for the carrier);
/// * the centre of mass relative to the carrier,
///   `M a_r = Q_cᵀ F − M (a_O + ε_e × r + ω_e × (ω_e × r) + 2 ω_e × v)`, or at rest in the
///   carrier (`hold_com`);
/// * the carrier's origin: `Ẋ_O = V_O`, `V̇_O = Q_c a_O`.
pub fn relative_rates<T: Real>(
    body: &Body<T>,
    options: RelativeOptions,
    y: &[T],
    motion: &Motion,
    wrench: [T; 6],
    out: &mut [T],
) {
    let (moments, inv_mass) = (body.moments, body.inv_mass);
    let q = &y[Q_AT..Q_AT + 9];
    let qc = &y[CARRIER_Q_AT..CARRIER_Q_AT + 9];
    let we = [motion[0], motion[1], motion[2]].map(T::splat);
    let ee = [motion[3], motion[4], motion[5]].map(T::splat);
    let ao = [motion[6], motion[7], motion[8]].map(T::splat);
    let zero = T::splat(0.0);
    // ω_e and ε_e on the body axes (eq. (15)): Q_rᵀ ω_e
    let wb = rows_t_vec(q, we);
    let eb = rows_t_vec(q, ee);
    let wr = vec3(y, OMEGA_AT);
    let j = [
        [moments[0], zero, zero],
        [zero, moments[1], zero],
        [zero, zero, moments[2]],
    ];
    let mut m = coriolis_moment(&j, wr, wb);
    if !options.balance_transport {
        let t = transport_moment(&j, wb, eb);
        for k in 0..3 {
            m[k] = m[k] + t[k];
        }
    }
    let tau = [wrench[3] + m[0], wrench[4] + m[1], wrench[5] + m[2]];
    let wdot = omega_dot_principal(moments, body.inv_moments, wr, tau);
    let ar = attitude_rate(q, wr);
    let ac = attitude_rate(qc, we);
    let g = rows_vec(qc, ao); // the carrier origin's acceleration, inertial: Q_c a_O
    let (rdot, vdot) = if options.hold_com {
        ([zero; 3], [zero; 3])
    } else {
        let v = vec3(y, V_AT);
        let f = rows_t_vec(qc, [wrench[0], wrench[1], wrench[2]]); // Q_cᵀ F
        let r = vec3(y, R_AT);
        let euler = cross_t(ee, r);
        let centripetal = cross_t(we, cross_t(we, r));
        let coriolis = cross_t(we, v);
        let mut a = [zero; 3];
        for k in 0..3 {
            a[k] =
                f[k] * inv_mass - ao[k] - euler[k] - centripetal[k] - T::splat(2.0) * coriolis[k];
        }
        (v, a)
    };
    out[R_AT..R_AT + 3].copy_from_slice(&rdot);
    out[V_AT..V_AT + 3].copy_from_slice(&vdot);
    out[Q_AT..Q_AT + 9].copy_from_slice(&ar);
    out[OMEGA_AT..OMEGA_AT + 3].copy_from_slice(&wdot);
    out[CARRIER_Q_AT..CARRIER_Q_AT + 9].copy_from_slice(&ac);
    out[ORIGIN_AT..ORIGIN_AT + 3].copy_from_slice(&y[ORIGIN_V_AT..ORIGIN_V_AT + 3]);
    out[ORIGIN_V_AT..ORIGIN_V_AT + 3].copy_from_slice(&g);
}

// ------------------------------------------------------------------------------ the system

/// A body moving relative to a carrier under physical forces (built-in and the user's): the
/// forces act on the absolute state ([`absolute_state`]), through the rigid-body system's
/// wrench, so they are lowered and evaluated exactly as for [`Rigid`].
pub struct Relative<C: CarrierMotion, U: UserWrench> {
    pub rigid: Rigid<U>,
    pub carrier: C,
    pub options: RelativeOptions,
    failed: AtomicBool,
}

impl<C: CarrierMotion, U: UserWrench> Relative<C, U> {
    pub fn new(rigid: Rigid<U>, carrier: C, options: RelativeOptions) -> Self {
        Relative {
            rigid,
            carrier,
            options,
            failed: AtomicBool::new(false),
        }
    }

    /// The carrier's motion at `t`; NaN (and the run marked failed) when it cannot be had.
    #[inline]
    pub fn motion(&self, t: f64) -> Motion {
        self.carrier.motion(t).unwrap_or_else(|| {
            self.failed.store(true, Ordering::Relaxed);
            [f64::NAN; MOTION_SIZE]
        })
    }
}

impl<C: CarrierMotion, U: UserWrench> VectorField for Relative<C, U> {
    #[inline(always)]
    fn dim(&self) -> usize {
        RELATIVE_STATE_SIZE
    }
    fn rhs(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let motion = self.motion(t);
        let s = absolute_state(y, &motion);
        let w = self.rigid.wrench(t, &s);
        relative_rates(self.rigid.body(), self.options, y, &motion, w, out);
    }
    #[inline(always)]
    fn failed(&self) -> bool {
        self.failed.load(Ordering::Relaxed) || self.rigid.failed()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::so3::{exp_so3, matmul};
    use crate::systems::NoUser;

    fn sample(n: usize, seed: u64) -> Vec<Vec3> {
        let mut s = seed;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        (0..n).map(|_| [next(), next(), next()]).collect()
    }

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (0..3).all(|k| (a[k] - b[k]).abs() <= tol * (1.0 + b[k].abs()))
    }

    /// Particles and the inertia they make about their centre of mass.
    fn particles() -> (Vec<f64>, Vec<Vec3>, Mat3) {
        let mut p = sample(7, 7);
        let masses: Vec<f64> = (0..7).map(|i| 0.5 + i as f64 * 0.3).collect();
        let total: f64 = masses.iter().sum();
        let mut c = [0.0; 3];
        for (m, x) in masses.iter().zip(&p) {
            for k in 0..3 {
                c[k] += m * x[k] / total;
            }
        }
        for x in p.iter_mut() {
            for k in 0..3 {
                x[k] -= c[k];
            }
        }
        let mut j = [[0.0; 3]; 3];
        for (m, x) in masses.iter().zip(&p) {
            let r2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
            for a in 0..3 {
                for b in 0..3 {
                    j[a][b] += m * ((if a == b { r2 } else { 0.0 }) - x[a] * x[b]);
                }
            }
        }
        (masses, p, j)
    }

    /// The compact Coriolis moment (5) equals its three-term form (2) and its definition as a
    /// particle sum (6); the planar inertia `½ tr J − J` equals `Σ m ρ ρᵀ` (3)–(4).
    #[test]
    fn coriolis_moment_three_routes() {
        let (m, rho, j) = particles();
        let pp = planar_inertia_particles(&m, &rho);
        let pj = planar_inertia(&j);
        for a in 0..3 {
            assert!(close(pp[a], pj[a], 1e-13));
        }
        for (wr, we) in sample(20, 3).into_iter().zip(sample(20, 11)) {
            let compact = coriolis_moment(&j, wr, we);
            assert!(close(compact, coriolis_three_term(&j, wr, we), 1e-13));
            assert!(close(compact, coriolis_particles(&m, &rho, wr, we), 1e-13));
        }
    }

    /// The transport moment (2) is the particles' transport inertia forces' moment,
    /// `−Σ m ρ × (ε_e × ρ + ω_e × (ω_e × ρ))`.
    #[test]
    fn transport_moment_is_the_particle_sum() {
        let (m, rho, j) = particles();
        for (we, ee) in sample(20, 5).into_iter().zip(sample(20, 9)) {
            let mut sum = [0.0; 3];
            for (mi, p) in m.iter().zip(&rho) {
                let a = cross(ee, *p);
                let b = cross(we, cross(we, *p));
                let c = cross(*p, [a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
                for k in 0..3 {
                    sum[k] -= mi * c[k];
                }
            }
            assert!(close(transport_moment(&j, we, ee), sum, 1e-13));
        }
    }

    /// Horner's value and derivative of a cubic piece equal the polynomial's closed form, on
    /// both sides of a break and outside the breaks (the end pieces extended).
    #[test]
    fn ppoly_values_and_derivatives() {
        // piece 0 on [0, 1): 1 + 2x + 3x² + 4x³ ; piece 1 on [1, 3): −x² + 5, x = t − 1
        let coeffs = vec![
            4.0, 4.0, 4.0, 0.0, 0.0, 0.0, // x³
            3.0, 3.0, 3.0, -1.0, -1.0, -1.0, // x²
            2.0, 2.0, 2.0, 0.0, 0.0, 0.0, // x
            1.0, 1.0, 1.0, 5.0, 5.0, 5.0, // 1
        ];
        let p = PPoly::new(vec![0.0, 1.0, 3.0], coeffs, 3).unwrap();
        for t in [-0.5, 0.0, 0.3, 0.999, 1.0, 2.5, 4.0] {
            let (v, d) = p.value_and_derivative(t);
            let (ve, de) = if t < 1.0 {
                (
                    1.0 + 2.0 * t + 3.0 * t * t + 4.0 * t * t * t,
                    2.0 + 6.0 * t + 12.0 * t * t,
                )
            } else {
                let x = t - 1.0;
                (5.0 - x * x, -2.0 * x)
            };
            assert!(
                (v[1] - ve).abs() < 1e-12 && (d[2] - de).abs() < 1e-12,
                "t = {t}"
            );
        }
        assert!(PPoly::new(vec![0.0, 1.0], vec![1.0; 5], 0).is_err());
        assert!(PPoly::new(vec![1.0, 0.0], vec![1.0; 3], 0).is_err());
    }

    fn body(moments: Vec3, mass: f64) -> Body {
        let j = [
            [moments[0], 0.0, 0.0],
            [0.0, moments[1], 0.0],
            [0.0, 0.0, moments[2]],
        ];
        let v = Body::vector(mass, moments, [0.0; 3], &j, [0.0; 3], false, -1);
        Body::from_slice(&v).unwrap()
    }

    fn relative_state(q_r: &Mat3, w_r: Vec3, q_c: &Mat3, r: Vec3, v: Vec3) -> Vec<f64> {
        let mut y = vec![0.0; RELATIVE_STATE_SIZE];
        y[R_AT..R_AT + 3].copy_from_slice(&r);
        y[V_AT..V_AT + 3].copy_from_slice(&v);
        y[OMEGA_AT..OMEGA_AT + 3].copy_from_slice(&w_r);
        for i in 0..3 {
            for k in 0..3 {
                y[Q_AT + 3 * i + k] = q_r[i][k];
                y[CARRIER_Q_AT + 3 * i + k] = q_c[i][k];
            }
        }
        y
    }

    /// A second formulation: the relative equation (11) predicts the absolute motion. The
    /// absolute ω = ω_r + Q_rᵀω_e (15) must obey Euler's equation (08) under the physical
    /// moment alone: d/dt (ω_r + Q_rᵀ ω_e) with the relative rates equals the torque-free
    /// `ω̇` of the absolute state, for a carrier that turns and accelerates.
    #[test]
    fn relative_rates_reproduce_eulers_equation() {
        let moments = [1.0, 2.0, 3.5];
        let b = body(moments, 2.0);
        let motion: Motion = [0.3, -0.7, 1.1, 0.2, 0.5, -0.4, 0.1, 0.2, 0.3];
        let q_r = exp_so3([0.3, -0.2, 0.9]);
        let q_c = exp_so3([-0.5, 0.4, 0.1]);
        let y = relative_state(
            &q_r,
            [0.4, 1.3, -0.6],
            &q_c,
            [0.2, 0.1, -0.3],
            [0.5, 0.0, 0.2],
        );
        let mut dy = vec![0.0; RELATIVE_STATE_SIZE];
        let opts = RelativeOptions::default();
        relative_rates(&b, opts, &y, &motion, [0.0; 6], &mut dy);
        // d/dt (Q_rᵀ ω_e) = Q̇_rᵀ ω_e + Q_rᵀ ε_e
        let qd = &dy[Q_AT..Q_AT + 9];
        let we = [motion[0], motion[1], motion[2]];
        let ee = [motion[3], motion[4], motion[5]];
        let a = rows_t_vec(qd, we);
        let e = rows_t_vec(&y[Q_AT..Q_AT + 9], ee);
        let wdot_abs = [
            dy[OMEGA_AT] + a[0] + e[0],
            dy[OMEGA_AT + 1] + a[1] + e[1],
            dy[OMEGA_AT + 2] + a[2] + e[2],
        ];
        let s = absolute_state(&y, &motion);
        let w = vec3(&s, OMEGA_AT);
        let expect = omega_dot_principal(b.moments, b.inv_moments, w, [0.0; 3]);
        assert!(close(wdot_abs, expect, 1e-13), "{wdot_abs:?} vs {expect:?}");
        // and the centre of mass: d/dt of the absolute velocity is F/M = 0 (no force)
        // V = V_O + Q_c (v + ω_e × r): V̇ = Q_c a_O + Q̇_c (v + ω_e × r) + Q_c (v̇ + ε_e × r + ω_e × ṙ)
        let r = vec3(&y, R_AT);
        let v = vec3(&y, V_AT);
        let x = cross(we, r);
        let u = [v[0] + x[0], v[1] + x[1], v[2] + x[2]];
        let part1 = rows_vec(&dy[CARRIER_Q_AT..CARRIER_Q_AT + 9], u);
        let er = cross(ee, r);
        let wv = cross(we, v);
        let inner = [
            dy[V_AT] + er[0] + wv[0],
            dy[V_AT + 1] + er[1] + wv[1],
            dy[V_AT + 2] + er[2] + wv[2],
        ];
        let part2 = rows_vec(&y[CARRIER_Q_AT..CARRIER_Q_AT + 9], inner);
        let acc = [
            dy[ORIGIN_V_AT] + part1[0] + part2[0],
            dy[ORIGIN_V_AT + 1] + part1[1] + part2[1],
            dy[ORIGIN_V_AT + 2] + part1[2] + part2[2],
        ];
        assert!(close(acc, [0.0; 3], 1e-13), "{acc:?}");
    }

    /// Case (16): with the transport moment balanced, the relative rotational energy
    /// `½ ω_r·Jω_r` is constant (17): its rate `ω_r·J ω̇_r` vanishes.
    #[test]
    fn balanced_transport_conserves_relative_energy() {
        let b = body([1.0, 2.0, 3.5], 1.0);
        let opts = RelativeOptions {
            balance_transport: true,
            hold_com: true,
        };
        for (i, w) in sample(10, 13).into_iter().enumerate() {
            let motion: Motion = [w[0], w[1], w[2], 0.3 * i as f64, -0.2, 0.5, 0.0, 0.0, 0.0];
            let q_r = exp_so3(w);
            let y = relative_state(
                &q_r,
                [0.7, -0.3, 0.2],
                &matmul(&q_r, &q_r),
                [0.0; 3],
                [0.0; 3],
            );
            let mut dy = vec![0.0; RELATIVE_STATE_SIZE];
            relative_rates(&b, opts, &y, &motion, [0.0; 6], &mut dy);
            let rate: f64 = (0..3)
                .map(|k| y[OMEGA_AT + k] * b.moments[k] * dy[OMEGA_AT + k])
                .sum();
            assert!(rate.abs() < 1e-14, "{rate}");
            assert_eq!(&dy[R_AT..R_AT + 6], &[0.0; 6]);
        }
    }

    /// The system: a carrier at rest reduces [`Relative`] to the free rigid body.
    #[test]
    fn a_carrier_at_rest_gives_the_rigid_body() {
        let b = body([1.0, 2.0, 3.5], 2.0);
        let carrier = PPolyCarrier {
            omega: PPoly::constant([0.0; 3]),
            accel: PPoly::constant([0.0; 3]),
        };
        let rigid: Rigid<NoUser> = Rigid::new(
            b,
            vec![],
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            None,
        );
        let sys = Relative::new(rigid, carrier, RelativeOptions::default());
        let q = exp_so3([0.1, 0.2, 0.3]);
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let y = relative_state(&q, [0.4, 1.3, -0.6], &id, [1.0, 2.0, 3.0], [0.1, 0.2, 0.3]);
        let mut dy = vec![0.0; RELATIVE_STATE_SIZE];
        sys.rhs(0.0, &y, &mut dy);
        let s = absolute_state(&y, &[0.0; 9]);
        let rates = crate::rigid::free_rigid_rates(&b, &s, [0.0; 6]);
        assert_eq!(&dy[..STATE_SIZE], &rates[..]);
        assert!(!sys.failed());
    }
}
