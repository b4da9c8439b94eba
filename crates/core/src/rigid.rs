//! Rigid-body equations, frames and the free-rotor flows (`docs/theory.md` §1).
//!
//! * Euler's equation `A ω̇ + ω × Aω = τ` (08), in principal components (27)–(29):
//!   [`omega_dot_principal`].
//! * The motion under a wrench, eqs (07)–(09), free or about a fixed point: [`rigid_rates`],
//!   with [`shift_torque_to_pivot`] and [`pivot_constrained`].
//! * The exact flows of the free rotor that the splitting integrator composes:
//!   [`free_rotor_step`].
//! * States between the body frame and the principal frame in which the engine integrates:
//!   [`state_to_principal`], [`state_from_principal`].

use crate::layout::{Body, OMEGA_AT, Q_AT, R_AT, STATE_SIZE, V_AT};
use crate::real::Real;
use crate::so3::{exp_so3, Mat3, Vec3};

/// A rigid-body state `[R, V, Q, ω]`.
pub type State = [f64; STATE_SIZE];

/// `ω̇` from Euler's equation (08) in principal components, eqs (27)–(29) with a torque:
/// `I1 ω̇1 = τ1 + (I2 − I3) ω2 ω3` and cyclically. `inv[k] = 1/I_k`, or 0 where `I_k = 0`
/// (a degenerate body: no angular acceleration about its line, the minimum-norm solution).
#[inline(always)]
pub fn omega_dot_principal<T: Real>(
    moments: [T; 3],
    inv: [T; 3],
    w: [T; 3],
    tau: [T; 3],
) -> [T; 3] {
    let [i1, i2, i3] = moments;
    [
        inv[0] * (tau[0] + (i2 - i3) * w[1] * w[2]),
        inv[1] * (tau[1] + (i3 - i1) * w[2] * w[0]),
        inv[2] * (tau[2] + (i1 - i2) * w[0] * w[1]),
    ]
}

/// The coefficients of the torque-free Euler equation (20) in principal components,
/// `ω̇1 = c1 ω2 ω3` and cyclically: `c1 = (I2 − I3)/I1`, `c2 = (I3 − I1)/I2`,
/// `c3 = (I1 − I2)/I3`, with `inv[k] = 1/I_k` (0 where `I_k = 0`, as in
/// [`omega_dot_principal`]).
#[inline(always)]
pub fn euler_free_coefficients(moments: Vec3, inv: Vec3) -> Vec3 {
    let [i1, i2, i3] = moments;
    [inv[0] * (i2 - i3), inv[1] * (i3 - i1), inv[2] * (i1 - i2)]
}

/// `ω̇` of the torque-free Euler equation (20) from its coefficients
/// ([`euler_free_coefficients`]): `(c1 ω2 ω3, c2 ω3 ω1, c3 ω1 ω2)`.
#[inline(always)]
pub fn omega_dot_free(c: Vec3, w: Vec3) -> Vec3 {
    [c[0] * w[1] * w[2], c[1] * w[2] * w[0], c[2] * w[0] * w[1]]
}

/// `b + a ω̇` for the torque-free Euler equation (20) ([`omega_dot_free`]): each component
/// one product and one fused multiply-add (the accumulated rate of the stage-point RK4,
/// [`crate::steppers::rk4_points_driver`]).
#[inline(always)]
pub fn omega_dot_free_acc(c: Vec3, b: &Vec3, a: f64, w: &Vec3) -> Vec3 {
    [
        (a * c[0] * w[1]).mul_add(w[2], b[0]),
        (a * c[1] * w[2]).mul_add(w[0], b[1]),
        (a * c[2] * w[0]).mul_add(w[1], b[2]),
    ]
}

/// Row `i` of `Q̇ = QΩ` (09): `q_i × ω` (`q_i` row i of Q, ω body components). Each row of
/// the attitude moves on its own, driven by ω.
#[inline(always)]
pub fn attitude_row_rate<T: Real>(q: &[T; 3], w: [T; 3]) -> [T; 3] {
    let [w0, w1, w2] = w;
    [
        q[1] * w2 - q[2] * w1,
        q[2] * w0 - q[0] * w2,
        q[0] * w1 - q[1] * w0,
    ]
}

/// `b + a (q_i × ω)`: [`attitude_row_rate`] accumulated, `q_i × (a ω)` with two fused
/// multiply-adds per component (`a ω` is the same for the three rows of Q).
#[inline(always)]
pub fn attitude_row_acc(b: &[f64; 3], a: f64, q: &[f64; 3], w: &Vec3) -> [f64; 3] {
    let s = [a * w[0], a * w[1], a * w[2]];
    [
        q[1].mul_add(s[2], (-q[2]).mul_add(s[1], b[0])),
        q[2].mul_add(s[0], (-q[0]).mul_add(s[2], b[1])),
        q[0].mul_add(s[1], (-q[1]).mul_add(s[0], b[2])),
    ]
}

/// `Q̇ = QΩ` (09), row by row ([`attitude_row_rate`]; Q row-major, ω body components).
#[inline(always)]
pub fn attitude_rate<T: Real>(q: &[T], w: [T; 3]) -> [T; 9] {
    let r0 = attitude_row_rate(&[q[0], q[1], q[2]], w);
    let r1 = attitude_row_rate(&[q[3], q[4], q[5]], w);
    let r2 = attitude_row_rate(&[q[6], q[7], q[8]], w);
    [
        r0[0], r0[1], r0[2], r1[0], r1[1], r1[2], r2[0], r2[1], r2[2],
    ]
}

/// The torque about the reference point, `τ_P = τ_G + c × Qᵀ F` (`c` the centre of mass seen
/// from the reference point, body frame; zero for a free body).
#[inline(always)]
pub fn shift_torque_to_pivot<T: Real>(body: &Body<T>, y: &[T; STATE_SIZE], w: [T; 6]) -> [T; 6] {
    let [c0, c1, c2] = body.com_offset;
    let (fx, fy, fz) = (w[0], w[1], w[2]);
    let b0 = y[Q_AT] * fx + y[Q_AT + 3] * fy + y[Q_AT + 6] * fz; // Qᵀ F
    let b1 = y[Q_AT + 1] * fx + y[Q_AT + 4] * fy + y[Q_AT + 7] * fz;
    let b2 = y[Q_AT + 2] * fx + y[Q_AT + 5] * fy + y[Q_AT + 8] * fz;
    [
        fx,
        fy,
        fz,
        w[3] + c1 * b2 - c2 * b1,
        w[4] + c2 * b0 - c0 * b2,
        w[5] + c0 * b1 - c1 * b0,
    ]
}

/// `ẏ` of a free body under the force `F` (space frame) and the torque `τ` about its centre
/// of mass (principal frame), eqs (07)–(09): `M R̈ = F`, Euler's equation (27)–(29), `Q̇ = QΩ`.
#[inline(always)]
pub fn free_rigid_rates<T: Real>(
    body: &Body<T>,
    y: &[T; STATE_SIZE],
    w: [T; 6],
) -> [T; STATE_SIZE] {
    let om = [y[OMEGA_AT], y[OMEGA_AT + 1], y[OMEGA_AT + 2]];
    let a = attitude_rate(&y[Q_AT..Q_AT + 9], om);
    let d = omega_dot_principal(body.moments, body.inv_moments, om, [w[3], w[4], w[5]]);
    let m = body.inv_mass;
    [
        y[V_AT],
        y[V_AT + 1],
        y[V_AT + 2],
        w[0] * m,
        w[1] * m,
        w[2] * m,
        a[0],
        a[1],
        a[2],
        a[3],
        a[4],
        a[5],
        a[6],
        a[7],
        a[8],
        d[0],
        d[1],
        d[2],
    ]
}

/// `ẏ` under the force `F` (space frame) and the torque `τ` about the reference point
/// (principal frame): [`free_rigid_rates`] for a free body; about a pivot `R = P + Q c` is
/// slaved to the attitude and `R̈ = Q (ω̇ × c + ω × (ω × c))` (the pivot's reaction does the
/// rest).
#[inline(always)]
pub fn rigid_rates<T: Real>(body: &Body<T>, y: &[T; STATE_SIZE], w: [T; 6]) -> [T; STATE_SIZE] {
    let mut r = free_rigid_rates(body, y, w);
    if body.has_pivot {
        let (w0, w1, w2) = (y[OMEGA_AT], y[OMEGA_AT + 1], y[OMEGA_AT + 2]);
        let (d0, d1, d2) = (r[OMEGA_AT], r[OMEGA_AT + 1], r[OMEGA_AT + 2]);
        let [c0, c1, c2] = body.com_offset;
        let u0 = w1 * c2 - w2 * c1; // ω × c
        let u1 = w2 * c0 - w0 * c2;
        let u2 = w0 * c1 - w1 * c0;
        let a0 = d1 * c2 - d2 * c1 + w1 * u2 - w2 * u1; // ω̇ × c + ω × (ω × c)
        let a1 = d2 * c0 - d0 * c2 + w2 * u0 - w0 * u2;
        let a2 = d0 * c1 - d1 * c0 + w0 * u1 - w1 * u0;
        let q = Q_AT;
        r[3] = y[q] * a0 + y[q + 1] * a1 + y[q + 2] * a2;
        r[4] = y[q + 3] * a0 + y[q + 4] * a1 + y[q + 5] * a2;
        r[5] = y[q + 6] * a0 + y[q + 7] * a1 + y[q + 8] * a2;
    }
    r
}

/// The state with `R = P + Q c` and `V = Q (ω × c)` reset from the attitude, so that the pivot
/// stays exactly fixed; unchanged for a free body.
#[inline(always)]
pub fn pivot_constrained<T: Real>(body: &Body<T>, mut y: [T; STATE_SIZE]) -> [T; STATE_SIZE] {
    if body.has_pivot {
        let [c0, c1, c2] = body.com_offset;
        let (w0, w1, w2) = (y[OMEGA_AT], y[OMEGA_AT + 1], y[OMEGA_AT + 2]);
        let u0 = w1 * c2 - w2 * c1;
        let u1 = w2 * c0 - w0 * c2;
        let u2 = w0 * c1 - w1 * c0;
        let q = Q_AT;
        let p = body.pivot;
        let r0 = p[0] + y[q] * c0 + y[q + 1] * c1 + y[q + 2] * c2;
        let r1 = p[1] + y[q + 3] * c0 + y[q + 4] * c1 + y[q + 5] * c2;
        let r2 = p[2] + y[q + 6] * c0 + y[q + 7] * c1 + y[q + 8] * c2;
        let v0 = y[q] * u0 + y[q + 1] * u1 + y[q + 2] * u2;
        let v1 = y[q + 3] * u0 + y[q + 4] * u1 + y[q + 5] * u2;
        let v2 = y[q + 6] * u0 + y[q + 7] * u1 + y[q + 8] * u2;
        y[R_AT] = r0;
        y[R_AT + 1] = r1;
        y[R_AT + 2] = r2;
        y[V_AT] = v0;
        y[V_AT + 1] = v1;
        y[V_AT + 2] = v2;
    }
    y
}

/// Where the pivot is in space for an engine state: `P = R − Q c`.
#[inline]
pub fn pivot_point(body: &Body, y: &State) -> Vec3 {
    let [c0, c1, c2] = body.com_offset;
    let q = Q_AT;
    [
        y[R_AT] - (y[q] * c0 + y[q + 1] * c1 + y[q + 2] * c2),
        y[R_AT + 1] - (y[q + 3] * c0 + y[q + 4] * c1 + y[q + 5] * c2),
        y[R_AT + 2] - (y[q + 6] * c0 + y[q + 7] * c1 + y[q + 8] * c2),
    ]
}

/// `max |QᵀQ − I|` of the attitude of one state.
#[inline]
pub fn orthogonality_error(y: &[f64]) -> f64 {
    let mut worst: f64 = 0.0;
    let q = Q_AT;
    for a in 0..3 {
        for b in 0..3 {
            let mut s =
                y[q + a] * y[q + b] + y[q + 3 + a] * y[q + 3 + b] + y[q + 6 + a] * y[q + 6 + b];
            if a == b {
                s -= 1.0;
            }
            worst = worst.max(s.abs());
        }
    }
    worst
}

/// A state from the body frame to the principal frame of `axes` (columns e1, e2, e3 in body
/// coordinates): `Q_p = Q E`, `ω_p = Eᵀ ω`; R and V unchanged.
#[inline]
pub fn state_to_principal(axes: &Mat3, y: &[f64], out: &mut [f64]) {
    for k in 0..3 {
        out[R_AT + k] = y[R_AT + k];
        out[V_AT + k] = y[V_AT + k];
        out[OMEGA_AT + k] =
            axes[0][k] * y[OMEGA_AT] + axes[1][k] * y[OMEGA_AT + 1] + axes[2][k] * y[OMEGA_AT + 2];
    }
    for r in 0..3 {
        for k in 0..3 {
            out[Q_AT + 3 * r + k] = y[Q_AT + 3 * r] * axes[0][k]
                + y[Q_AT + 3 * r + 1] * axes[1][k]
                + y[Q_AT + 3 * r + 2] * axes[2][k];
        }
    }
}

/// The inverse of [`state_to_principal`]: `Q = Q_p Eᵀ`, `ω = E ω_p`.
#[inline]
pub fn state_from_principal(axes: &Mat3, z: &[f64], out: &mut [f64]) {
    for k in 0..3 {
        out[R_AT + k] = z[R_AT + k];
        out[V_AT + k] = z[V_AT + k];
        out[OMEGA_AT + k] =
            axes[k][0] * z[OMEGA_AT] + axes[k][1] * z[OMEGA_AT + 1] + axes[k][2] * z[OMEGA_AT + 2];
    }
    for r in 0..3 {
        for k in 0..3 {
            out[Q_AT + 3 * r + k] = z[Q_AT + 3 * r] * axes[k][0]
                + z[Q_AT + 3 * r + 1] * axes[k][1]
                + z[Q_AT + 3 * r + 2] * axes[k][2];
        }
    }
}

/// The sub-flow of a rotation by `angle` about principal axis `axis`, in place on the momentum
/// state `z` (the body momentum π in the ω slot): `π ← Rotᵀ π`, `Q ← Q Rot`.
#[inline(always)]
pub fn rotate_pair<T: Real>(axis: usize, angle: T, z: &mut [T]) {
    // polynomials, so that ensembles run the sub-flows in lanes
    let (s, c) = crate::real::sin_cos(angle);
    let i = (axis + 1) % 3;
    let j = (axis + 2) % 3;
    let pi_i = z[OMEGA_AT + i];
    let pi_j = z[OMEGA_AT + j];
    z[OMEGA_AT + i] = c * pi_i + s * pi_j;
    z[OMEGA_AT + j] = -s * pi_i + c * pi_j;
    for r in 0..3 {
        let qi = z[Q_AT + 3 * r + i];
        let qj = z[Q_AT + 3 * r + j];
        z[Q_AT + 3 * r + i] = c * qi + s * qj;
        z[Q_AT + 3 * r + j] = -s * qi + c * qj;
    }
}

/// Advance the torque-free rotor by `h`, in place, exactly or by a symmetric split.
///
/// `z` is the momentum state (π, the body angular momentum in principal axes, in the ω slot;
/// Q the attitude of the principal frame).
///
/// * Symmetric rotor (symmetry axis s, `I_e` the repeated moment):
///   `H = |π|²/(2 I_e) + (1/I_s − 1/I_e) π_s²/2`; both terms commute and each flow is a
///   rotation: about π itself by `h|π|/I_e` (`Q ← Q exp(h π/I_e)`) and about `e_s` by
///   `h (1/I_s − 1/I_e) π_s`. Their product is the exact flow. A zero moment (a rod) has no
///   spin flow.
/// * Otherwise the symmetric composition `H1(h/2) H2(h/2) H3(h) H2(h/2) H1(h/2)` of the exact
///   flows of `H_i = π_i²/(2 I_i)` (McLachlan 1993, Phys. Rev. Lett. 71): second order,
///   symplectic, and it keeps `|π|` and the spatial momentum `Q π` exactly.
#[inline(always)]
pub fn free_rotor_step<T: Real>(body: &Body<T>, z: &mut [T], h: f64) {
    if body.rotor < 0 {
        free_rotor_triaxial(body, z, h);
    } else {
        free_rotor_symmetric(body, z, h);
    }
}

/// Which branch of [`free_rotor_step`] a step takes, named at compile time: whichever the body
/// is ([`ANY_ROTOR`]: the branch at run time), three distinct moments ([`TRIAXIAL`]), or
/// symmetric ([`SYMMETRIC`]).
pub const ANY_ROTOR: u8 = 0;
pub const TRIAXIAL: u8 = 1;
pub const SYMMETRIC: u8 = 2;

/// [`free_rotor_step`] with its branch `ROTOR` named, so that a block of lanes whose bodies
/// all take it has no branch (with [`TRIAXIAL`] or [`SYMMETRIC`] the body must be of that
/// kind).
#[inline(always)]
pub fn free_rotor<const ROTOR: u8, T: Real>(body: &Body<T>, z: &mut [T], h: f64) {
    match ROTOR {
        TRIAXIAL => free_rotor_triaxial(body, z, h),
        SYMMETRIC => free_rotor_symmetric(body, z, h),
        _ => free_rotor_step(body, z, h),
    }
}

/// [`free_rotor_step`] of a body with three distinct moments: the five sub-flows, each about
/// an axis known at compile time, a zero moment turning by 0 (its 1/I is 0), so that the
/// ensembles' lanes run the step without gathers or branches.
#[inline(always)]
pub fn free_rotor_triaxial<T: Real>(body: &Body<T>, z: &mut [T], h: f64) {
    let inv = body.inv_moments;
    let sub = |axis: usize, frac: f64, z: &mut [T]| {
        rotate_pair(axis, T::splat(frac * h) * z[OMEGA_AT + axis] * inv[axis], z)
    };
    sub(0, 0.5, z);
    sub(1, 0.5, z);
    sub(2, 1.0, z);
    sub(1, 0.5, z);
    sub(0, 0.5, z);
}

/// [`free_rotor_step`] of a symmetric body (`body.rotor` its symmetry axis): the turn about π
/// and the spin about the axis (none for a rod, whose π_s is 0).
#[inline(always)]
pub fn free_rotor_symmetric<T: Real>(body: &Body<T>, z: &mut [T], h: f64) {
    let s = body.rotor as usize;
    let ie = body.moments[(s + 1) % 3];
    let c = T::splat(h) / ie;
    let e = exp_so3([c * z[OMEGA_AT], c * z[OMEGA_AT + 1], c * z[OMEGA_AT + 2]]);
    let mut p = [[T::splat(0.0); 3]; 3];
    for r in 0..3 {
        for k in 0..3 {
            p[r][k] = z[Q_AT + 3 * r] * e[0][k]
                + z[Q_AT + 3 * r + 1] * e[1][k]
                + z[Q_AT + 3 * r + 2] * e[2][k];
        }
    }
    for r in 0..3 {
        for k in 0..3 {
            z[Q_AT + 3 * r + k] = p[r][k];
        }
    }
    let spin = |s: usize, z: &mut [T]| {
        let rate = body.inv_moments[s] - T::splat(1.0) / ie;
        rotate_pair(s, T::splat(h) * rate * z[OMEGA_AT + s], z)
    };
    match s {
        0 => spin(0, z),
        1 => spin(1, z),
        _ => spin(2, z),
    }
}

/// Body-frame initial state of one motion by the rules of `poinsot.simulate`: `q` the
/// attitude, `w` the body-frame ω; `r`, `v` given or `None` (the defaults).
///
/// Free body: `R` defaults to the centre of mass `com`, `V` to 0. About a pivot (`c` = centre
/// of mass − pivot, body frame): `R` defaults to `pivot + Q c` and `V = Q (ω × c)` follows from
/// ω. A degenerate body (all mass on the unit `line`; zeros otherwise) loses its spin about
/// the line, which is undefined.
#[allow(clippy::too_many_arguments)]
pub fn initial_state(
    q: &Mat3,
    w: Vec3,
    r: Option<Vec3>,
    v: Option<Vec3>,
    com: Vec3,
    c: Vec3,
    pivot: Vec3,
    has_pivot: bool,
    line: Vec3,
) -> State {
    let mut out = [0.0; STATE_SIZE];
    let spin = w[0] * line[0] + w[1] * line[1] + w[2] * line[2];
    let w0 = w[0] - spin * line[0];
    let w1 = w[1] - spin * line[1];
    let w2 = w[2] - spin * line[2];
    for k in 0..3 {
        out[R_AT + k] = match r {
            Some(r) => r[k],
            None if has_pivot => pivot[k] + q[k][0] * c[0] + q[k][1] * c[1] + q[k][2] * c[2],
            None => com[k],
        };
    }
    let u0 = w1 * c[2] - w2 * c[1];
    let u1 = w2 * c[0] - w0 * c[2];
    let u2 = w0 * c[1] - w1 * c[0];
    for k in 0..3 {
        out[V_AT + k] = if has_pivot {
            q[k][0] * u0 + q[k][1] * u1 + q[k][2] * u2
        } else {
            v.map_or(0.0, |v| v[k])
        };
        for j in 0..3 {
            out[Q_AT + 3 * k + j] = q[k][j];
        }
    }
    out[OMEGA_AT] = w0;
    out[OMEGA_AT + 1] = w1;
    out[OMEGA_AT + 2] = w2;
    out
}

/// Position of a particle of a rigid motion, `r = Q u + R` (the rigidity theorem of
/// `docs/theory.md` §1).
#[inline(always)]
pub fn particle_position(r: Vec3, q: &Mat3, u: Vec3) -> Vec3 {
    [0, 1, 2].map(|j| r[j] + q[j][0] * u[0] + q[j][1] * u[1] + q[j][2] * u[2])
}

/// Velocity of a particle, `ṙ = Q(ω × u) + Ṙ` (ω body frame).
#[inline(always)]
pub fn particle_velocity(v: Vec3, q: &Mat3, w: Vec3, u: Vec3) -> Vec3 {
    let c = crate::so3::cross(w, u);
    [0, 1, 2].map(|j| v[j] + q[j][0] * c[0] + q[j][1] * c[1] + q[j][2] * c[2])
}

/// The notebook's initial conditions from particle data (`docs/theory.md` §1), at
/// `Q(0) = I`: `Ṙ(0) = Σ m_i ṙ_i / M` and `A ω(0) = L(0) − M R(0) × Ṙ(0)` with
/// `L(0) = Σ m_i r_i × ṙ_i` (eq. (03)); `inertia_inv` is `A⁻¹` (a pseudo-inverse for a
/// degenerate body: the minimum-norm ω). Returns `(V, ω)` and fills `residual` with
/// `|ṙ_i − (Ṙ + ω × u_i)|`, zero when the velocities are a rigid motion.
pub fn rigid_motion_from_particles(
    masses: &[f64],
    positions: &[Vec3],
    velocities: &[Vec3],
    center: Vec3,
    inertia_inv: &Mat3,
    residual: &mut [f64],
) -> (Vec3, Vec3) {
    let mut m_total = 0.0;
    let mut p = [0.0; 3];
    let mut l = [0.0; 3];
    for i in 0..masses.len() {
        let m = masses[i];
        let (r, v) = (positions[i], velocities[i]);
        m_total += m;
        for j in 0..3 {
            p[j] += m * v[j];
        }
        l[0] += m * (r[1] * v[2] - r[2] * v[1]);
        l[1] += m * (r[2] * v[0] - r[0] * v[2]);
        l[2] += m * (r[0] * v[1] - r[1] * v[0]);
    }
    let vel = [p[0] / m_total, p[1] / m_total, p[2] / m_total];
    let rhs = [
        l[0] - m_total * (center[1] * vel[2] - center[2] * vel[1]),
        l[1] - m_total * (center[2] * vel[0] - center[0] * vel[2]),
        l[2] - m_total * (center[0] * vel[1] - center[1] * vel[0]),
    ];
    let omega = crate::invariants::angular_momentum_body(inertia_inv, rhs);
    let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for i in 0..masses.len() {
        let u = [0, 1, 2].map(|j| positions[i][j] - center[j]);
        let rigid = particle_velocity(vel, &eye, omega, u);
        let mut d = 0.0;
        for j in 0..3 {
            d += (velocities[i][j] - rigid[j]).powi(2);
        }
        residual[i] = d.sqrt();
    }
    (vel, omega)
}

/// Which exact free-rotor flow applies to the ascending principal `moments`: −1 for three
/// distinct moments (McLachlan's split), or the index of the symmetry axis (0 for a prolate
/// body or a rod, 2 for an oblate or spherical one).
pub fn rotor_code(moments: Vec3, rtol: f64) -> i32 {
    match crate::inertia::symmetry_code(moments, rtol) {
        0 => -1,
        1 => 0,
        _ => 2,
    }
}

/// Everything the engine needs of a body, in one call: `(parameters, degenerate)`.
///
/// `moments` (ascending) and `axes` (columns) are the principal decomposition of the inertia
/// about the reference point; `com_offset` the centre of mass from it and `inertia_com` the
/// inertia about the centre of mass, both in the body frame. A moment below
/// `DEGENERATE_RTOL` times the largest (a body on a line) is set to zero, so that its line has
/// no angular acceleration (the minimum-norm solution); the free-rotor flow is chosen by
/// [`rotor_code`].
pub fn body_parameters(
    mass: f64,
    moments: Vec3,
    axes: &Mat3,
    com_offset: Vec3,
    inertia_com: &Mat3,
    has_pivot: bool,
) -> ([f64; crate::layout::BODY_SIZE], bool) {
    use crate::inertia::{is_degenerate, DEGENERATE_RTOL, SYMMETRY_RTOL};
    let mut m = moments;
    let degenerate = is_degenerate(m, DEGENERATE_RTOL);
    if degenerate {
        let top = m[2];
        for v in m.iter_mut() {
            if *v <= DEGENERATE_RTOL * top {
                *v = 0.0;
            }
        }
    }
    let c = [0, 1, 2].map(|k| {
        axes[0][k] * com_offset[0] + axes[1][k] * com_offset[1] + axes[2][k] * com_offset[2]
    });
    let mut a = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let mut s = 0.0;
            for p in 0..3 {
                for q in 0..3 {
                    s += axes[p][i] * inertia_com[p][q] * axes[q][j];
                }
            }
            a[i][j] = s;
        }
    }
    let params = Body::vector(
        mass,
        m,
        c,
        &a,
        [0.0; 3],
        has_pivot,
        rotor_code(m, SYMMETRY_RTOL),
    );
    (params, degenerate)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::invariants::principal_invariants;

    fn body(moments: Vec3, rotor: i32) -> Body {
        let a = [
            [moments[0], 0.0, 0.0],
            [0.0, moments[1], 0.0],
            [0.0, 0.0, moments[2]],
        ];
        Body::from_slice(&Body::vector(
            1.0, moments, [0.0; 3], &a, [0.0; 3], false, rotor,
        ))
        .unwrap()
    }

    #[test]
    fn torque_free_euler_keeps_energy_and_momentum_rates_zero() {
        // d/dt (½ Σ I ω²) = Σ I ω ω̇ = 0 and d/dt |Iω|² = 0 under (27)–(29)
        let m = [1.0, 2.0, 3.5];
        let inv = [1.0, 0.5, 1.0 / 3.5];
        let w = [0.3, -1.1, 0.8];
        let d = omega_dot_principal(m, inv, w, [0.0; 3]);
        let de: f64 = (0..3).map(|k| m[k] * w[k] * d[k]).sum();
        let dl: f64 = (0..3).map(|k| m[k] * m[k] * w[k] * d[k]).sum();
        assert!(de.abs() < 1e-15 && dl.abs() < 1e-15);
    }

    #[test]
    fn free_rotor_flows_keep_momentum_and_energy() {
        for (moments, rotor) in [
            ([1.0, 2.0, 3.0], -1),
            ([1.0, 3.0, 3.0], 0),
            ([2.0, 2.0, 3.0], 2),
        ] {
            let b = body(moments, rotor);
            let mut z = [0.0; STATE_SIZE];
            z[Q_AT] = 1.0;
            z[Q_AT + 4] = 1.0;
            z[Q_AT + 8] = 1.0;
            let pi0 = [0.4, 1.3, -0.7];
            z[OMEGA_AT..OMEGA_AT + 3].copy_from_slice(&pi0);
            let spatial = |z: &[f64]| {
                let p = [z[OMEGA_AT], z[OMEGA_AT + 1], z[OMEGA_AT + 2]];
                [0, 1, 2].map(|r| (0..3).map(|k| z[Q_AT + 3 * r + k] * p[k]).sum::<f64>())
            };
            let l0 = spatial(&z);
            for _ in 0..1000 {
                free_rotor_step(&b, &mut z, 0.01);
            }
            let l1 = spatial(&z);
            for k in 0..3 {
                assert!((l0[k] - l1[k]).abs() < 1e-12, "{rotor} {}", l0[k] - l1[k]);
            }
            assert!(orthogonality_error(&z) < 1e-13);
            if rotor >= 0 {
                // the symmetric rotor's flow is exact: energy kept to round-off
                let w0 = [0, 1, 2].map(|k| pi0[k] / moments[k]);
                let w1 = [0, 1, 2].map(|k| z[OMEGA_AT + k] / moments[k]);
                let (k0, _) = principal_invariants(moments, w0);
                let (k1, _) = principal_invariants(moments, w1);
                assert!((k0 - k1).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn frames_round_trip() {
        let axes = exp_so3([0.3, -0.2, 0.9]);
        let y: Vec<f64> = (0..STATE_SIZE).map(|k| (k as f64).sin()).collect();
        let mut z = [0.0; STATE_SIZE];
        let mut back = [0.0; STATE_SIZE];
        state_to_principal(&axes, &y, &mut z);
        state_from_principal(&axes, &z, &mut back);
        for k in 0..STATE_SIZE {
            assert!((back[k] - y[k]).abs() < 1e-15);
        }
    }
}
