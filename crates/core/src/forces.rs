//! The built-in forces as formulas on lowered data (`docs/theory.md` §1, eqs (07)–(08)).
//!
//! A force is lowered (by `poinsot.forces` in Python) to a kind code and a row of
//! [`FORCE_PARAMS`] numbers; body points and body-fixed vectors are expressed, at lowering, in
//! the frame the state uses (the principal frame inside the engine), relative to the centre
//! of mass. Each wrench is `(F, τ)`: the force (space frame) and its torque about the centre of
//! mass (body frame). The parameter rows:
//!
//! | kind | parameters |
//! |---|---|
//! | gravity | `g` (0:3) |
//! | central gravity | `μ` (0), centre (1:4), gradient terms on/off (4) |
//! | spring | body point `b` (0:3), anchor (3:6), stiffness `k` (6), rest length `ℓ₀` (7), damping `c` (8), tether on/off (9) |
//! | linear drag | `c` (0), rotational `c_rot` (1) |
//! | quadratic drag | `c` (0), rotational `c_rot` (1) |
//! | point force | body point `b` (0:3), force `f` (3:6), `f` body-fixed (6) |
//! | torque | torque (0:3), body-fixed (3) |

use crate::layout::{Body, FORCE_PARAMS, OMEGA_AT, Q_AT, R_AT, STATE_SIZE, V_AT};
use crate::real::Scalar;

/// The kinds of built-in force, with the codes the Python package lowers them to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(i64)]
pub enum ForceKind {
    Gravity = 1,
    CentralGravity = 2,
    Spring = 3,
    LinearDrag = 4,
    QuadraticDrag = 5,
    PointForce = 6,
    Torque = 7,
}

impl ForceKind {
    /// The kind of a code; `None` for an unknown code.
    pub fn from_code(code: i64) -> Option<ForceKind> {
        Some(match code {
            1 => ForceKind::Gravity,
            2 => ForceKind::CentralGravity,
            3 => ForceKind::Spring,
            4 => ForceKind::LinearDrag,
            5 => ForceKind::QuadraticDrag,
            6 => ForceKind::PointForce,
            7 => ForceKind::Torque,
            _ => return None,
        })
    }

    /// True for the kinds that depend on the time, position and attitude only (kicks of the
    /// splitting method): not drag, not a damped spring.
    pub fn position_only(self, p: &[f64; FORCE_PARAMS]) -> bool {
        match self {
            ForceKind::LinearDrag | ForceKind::QuadraticDrag => false,
            ForceKind::Spring => p[8] == 0.0,
            _ => true,
        }
    }
}

/// One lowered force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Force {
    pub kind: ForceKind,
    pub p: [f64; FORCE_PARAMS],
}

type State = [f64; STATE_SIZE];

/// `b × Qᵀ F`: the torque about the centre of mass (body frame) of the force `F` (space frame)
/// applied at the body point `b` (body frame, from the centre of mass), eq. (08).
#[inline(always)]
pub fn moment_about_center<T: Scalar>(b: [T; 3], y: &[T; STATE_SIZE], f: [T; 3]) -> [T; 3] {
    let c0 = y[Q_AT] * f[0] + y[Q_AT + 3] * f[1] + y[Q_AT + 6] * f[2];
    let c1 = y[Q_AT + 1] * f[0] + y[Q_AT + 4] * f[1] + y[Q_AT + 7] * f[2];
    let c2 = y[Q_AT + 2] * f[0] + y[Q_AT + 5] * f[1] + y[Q_AT + 8] * f[2];
    [
        b[1] * c2 - b[2] * c1,
        b[2] * c0 - b[0] * c2,
        b[0] * c1 - b[1] * c0,
    ]
}

/// Space position `R + Q b` of the body point `b`.
#[inline(always)]
fn body_point<T: Scalar>(b: [T; 3], y: &[T; STATE_SIZE]) -> [T; 3] {
    [
        y[R_AT] + y[Q_AT] * b[0] + y[Q_AT + 1] * b[1] + y[Q_AT + 2] * b[2],
        y[R_AT + 1] + y[Q_AT + 3] * b[0] + y[Q_AT + 4] * b[1] + y[Q_AT + 5] * b[2],
        y[R_AT + 2] + y[Q_AT + 6] * b[0] + y[Q_AT + 7] * b[1] + y[Q_AT + 8] * b[2],
    ]
}

/// Uniform gravity `g`: `F = M g` at the centre of mass and no torque about it
/// (`Σ u_i × Qᵀ m_i g = 0` since `Σ m_i u_i = 0`).
#[inline(always)]
fn gravity<T: Scalar>(p: &[T; FORCE_PARAMS], body: &Body<T>) -> [T; 6] {
    let m = body.mass;
    let z = T::splat(0.0);
    [m * p[0], m * p[1], m * p[2], z, z, z]
}

/// The point-mass part of a central gravity ([`ForceKind::CentralGravity`]): `F = −μM r/|r|³`,
/// `r` from the centre `(p[1], p[2], p[3])` to the centre of mass. The exact-flow splittings
/// solve it exactly (Kepler's flow, [`crate::kepler`]) and kick with the rest.
#[inline(always)]
pub fn central_point_force<T: Scalar>(
    p: &[T; FORCE_PARAMS],
    body: &Body<T>,
    y: &[T; STATE_SIZE],
) -> [T; 3] {
    let rx = y[R_AT] - p[1];
    let ry = y[R_AT + 1] - p[2];
    let rz = y[R_AT + 2] - p[3];
    let r2 = rx * rx + ry * ry + rz * rz;
    let r3 = r2 * r2.sqrt();
    let k = -p[0] * body.mass / r3;
    [k * rx, k * ry, k * rz]
}

/// The force whose point-mass part the exact-flow splittings' drift solves exactly
/// (Kepler's flow, [`crate::kepler`]): the one central gravity of a free body (`μ > 0`, finite).
/// `None` about a pivot, with no central gravity or with more than one (then the drift is
/// `R += d V` and the kicks carry all the forces).
pub fn kepler_part(body: &Body, forces: &[Force]) -> Option<usize> {
    if body.has_pivot {
        return None;
    }
    let mut central = forces
        .iter()
        .enumerate()
        .filter(|(_, f)| f.kind == ForceKind::CentralGravity);
    match (central.next(), central.next()) {
        (Some((i, f)), None) if f.p[0] > 0.0 && f.p[0].is_finite() => Some(i),
        _ => None,
    }
}

/// Gravity of a point mass `μ = G M_c` at a centre, with MacCullagh's gravity-gradient terms
/// when switched on: `F = −μM r/|r|³ − 3μ/(2|r|⁵) tr(A) r − 3μ/|r|⁵ Q A b +
/// 15μ/(2|r|⁷) (b·Ab) r` and `τ = 3μ/|r|⁵ b × A b`, `b = Qᵀ r` (Hughes, *Spacecraft Attitude
/// Dynamics*, §8.2). A body at the centre gives non-finite values (the engine stops there).
#[inline(always)]
fn central_gravity<T: Scalar>(
    p: &[T; FORCE_PARAMS],
    body: &Body<T>,
    y: &[T; STATE_SIZE],
) -> [T; 6] {
    let s = T::splat;
    let mu = p[0];
    let point = central_point_force(p, body, y);
    let rx = y[R_AT] - p[1];
    let ry = y[R_AT + 1] - p[2];
    let rz = y[R_AT + 2] - p[3];
    let r2 = rx * rx + ry * ry + rz * rz;
    let r = r2.sqrt();
    let r3 = r2 * r;
    // the gradient terms are formed whether or not they are switched on and then selected,
    // so that a block of lanes has no branch
    let a = &body.inertia_com;
    let b0 = y[Q_AT] * rx + y[Q_AT + 3] * ry + y[Q_AT + 6] * rz;
    let b1 = y[Q_AT + 1] * rx + y[Q_AT + 4] * ry + y[Q_AT + 7] * rz;
    let b2 = y[Q_AT + 2] * rx + y[Q_AT + 5] * ry + y[Q_AT + 8] * rz;
    let a0 = a[0][0] * b0 + a[0][1] * b1 + a[0][2] * b2;
    let a1 = a[1][0] * b0 + a[1][1] * b1 + a[1][2] * b2;
    let a2 = a[2][0] * b0 + a[2][1] * b1 + a[2][2] * b2;
    let bab = b0 * a0 + b1 * a1 + b2 * a2;
    let tra = a[0][0] + a[1][1] + a[2][2];
    let r5 = r3 * r2;
    let r7 = r5 * r2;
    let radial = s(-1.5) * mu * tra / r5 + s(7.5) * mu * bab / r7;
    let s0 = y[Q_AT] * a0 + y[Q_AT + 1] * a1 + y[Q_AT + 2] * a2; // Q A b
    let s1 = y[Q_AT + 3] * a0 + y[Q_AT + 4] * a1 + y[Q_AT + 5] * a2;
    let s2 = y[Q_AT + 6] * a0 + y[Q_AT + 7] * a1 + y[Q_AT + 8] * a2;
    let g = s(3.0) * mu / r5;
    let gradient = [
        point[0] + (radial * rx - s(3.0) * mu * s0 / r5),
        point[1] + (radial * ry - s(3.0) * mu * s1 / r5),
        point[2] + (radial * rz - s(3.0) * mu * s2 / r5),
        g * (b1 * a2 - b2 * a1),
        g * (b2 * a0 - b0 * a2),
        g * (b0 * a1 - b1 * a0),
    ];
    let plain = [point[0], point[1], point[2], s(0.0), s(0.0), s(0.0)];
    let on = p[4].unequal(s(0.0));
    [0, 1, 2, 3, 4, 5].map(|i| if on { gradient[i] } else { plain[i] })
}

/// MacCullagh's formula `U = −μM/|r| − μ/(2|r|³) (tr A − 3 n̂·A n̂)`, `n̂ = Qᵀ r/|r|`.
#[inline(always)]
fn central_gravity_potential(p: &[f64; FORCE_PARAMS], body: &Body, y: &State) -> f64 {
    let mu = p[0];
    let rx = y[R_AT] - p[1];
    let ry = y[R_AT + 1] - p[2];
    let rz = y[R_AT + 2] - p[3];
    let r2 = rx * rx + ry * ry + rz * rz;
    let r = r2.sqrt();
    let mut u = -mu * body.mass / r;
    if p[4] != 0.0 {
        let a = &body.inertia_com;
        let b0 = y[Q_AT] * rx + y[Q_AT + 3] * ry + y[Q_AT + 6] * rz;
        let b1 = y[Q_AT + 1] * rx + y[Q_AT + 4] * ry + y[Q_AT + 7] * rz;
        let b2 = y[Q_AT + 2] * rx + y[Q_AT + 5] * ry + y[Q_AT + 8] * rz;
        let bab = b0 * (a[0][0] * b0 + a[0][1] * b1 + a[0][2] * b2)
            + b1 * (a[1][0] * b0 + a[1][1] * b1 + a[1][2] * b2)
            + b2 * (a[2][0] * b0 + a[2][1] * b1 + a[2][2] * b2);
        let tra = a[0][0] + a[1][1] + a[2][2];
        u -= mu / (2.0 * r2 * r) * (tra - 3.0 * bab / r2);
    }
    u
}

/// A linear spring (or elastic tether) from the body point `b` to a fixed anchor:
/// `d = anchor − (R + Q b)`, `ℓ = |d|`, tension `T = k (ℓ − ℓ₀) − c (d̂·v_b)` with
/// `v_b = V + Q (ω × b)`; `F = T d̂` at the point. A tether pulls only when stretched; at
/// `ℓ = 0` the direction is undefined and the spring exerts nothing.
#[inline(always)]
fn spring<T: Scalar>(p: &[T; FORCE_PARAMS], y: &[T; STATE_SIZE]) -> [T; 6] {
    let zero = T::splat(0.0);
    let b = [p[0], p[1], p[2]];
    let x = body_point(b, y);
    let dx = p[3] - x[0];
    let dy = p[4] - x[1];
    let dz = p[5] - x[2];
    let length = (dx * dx + dy * dy + dz * dz).sqrt();
    let stretch = length - p[7];
    let mut tension = zero;
    let (mut ux, mut uy, mut uz) = (zero, zero, zero);
    if length.gt(zero) && (p[9].equal(zero) || stretch.gt(zero)) {
        ux = dx / length;
        uy = dy / length;
        uz = dz / length;
        tension = p[6] * stretch;
        // no damper, and none asked of a derivative: the term is skipped (`vanishes`)
        if !p[8].vanishes() {
            let (w0, w1, w2) = (y[OMEGA_AT], y[OMEGA_AT + 1], y[OMEGA_AT + 2]);
            let c0 = w1 * b[2] - w2 * b[1];
            let c1 = w2 * b[0] - w0 * b[2];
            let c2 = w0 * b[1] - w1 * b[0];
            let vx = y[V_AT] + y[Q_AT] * c0 + y[Q_AT + 1] * c1 + y[Q_AT + 2] * c2;
            let vy = y[V_AT + 1] + y[Q_AT + 3] * c0 + y[Q_AT + 4] * c1 + y[Q_AT + 5] * c2;
            let vz = y[V_AT + 2] + y[Q_AT + 6] * c0 + y[Q_AT + 7] * c1 + y[Q_AT + 8] * c2;
            tension = tension - p[8] * (ux * vx + uy * vy + uz * vz);
        }
    }
    let f = [tension * ux, tension * uy, tension * uz];
    let t = moment_about_center(b, y, f);
    [f[0], f[1], f[2], t[0], t[1], t[2]]
}

/// `U = ½ k (ℓ − ℓ₀)²`; zero while a tether is slack (the damper has no potential).
#[inline(always)]
fn spring_potential(p: &[f64; FORCE_PARAMS], y: &State) -> f64 {
    let x = body_point([p[0], p[1], p[2]], y);
    let dx = p[3] - x[0];
    let dy = p[4] - x[1];
    let dz = p[5] - x[2];
    let stretch = (dx * dx + dy * dy + dz * dz).sqrt() - p[7];
    if p[9] != 0.0 && stretch <= 0.0 {
        return 0.0;
    }
    0.5 * p[6] * stretch * stretch
}

/// Linear (Stokes) drag `F = −c V` on the centre of mass and the rotational model
/// `τ = −c_rot ω`.
#[inline(always)]
fn linear_drag<T: Scalar>(p: &[T; FORCE_PARAMS], y: &[T; STATE_SIZE]) -> [T; 6] {
    let (c, r) = (p[0], p[1]);
    [
        -c * y[V_AT],
        -c * y[V_AT + 1],
        -c * y[V_AT + 2],
        -r * y[OMEGA_AT],
        -r * y[OMEGA_AT + 1],
        -r * y[OMEGA_AT + 2],
    ]
}

/// Quadratic drag `F = −c |V| V` on the centre of mass and `τ = −c_rot |ω| ω`.
#[inline(always)]
fn quadratic_drag<T: Scalar>(p: &[T; FORCE_PARAMS], y: &[T; STATE_SIZE]) -> [T; 6] {
    let v = (y[V_AT] * y[V_AT] + y[V_AT + 1] * y[V_AT + 1] + y[V_AT + 2] * y[V_AT + 2]).sqrt();
    let w = (y[OMEGA_AT] * y[OMEGA_AT]
        + y[OMEGA_AT + 1] * y[OMEGA_AT + 1]
        + y[OMEGA_AT + 2] * y[OMEGA_AT + 2])
        .sqrt();
    let c = p[0] * v;
    let r = p[1] * w;
    [
        -c * y[V_AT],
        -c * y[V_AT + 1],
        -c * y[V_AT + 2],
        -r * y[OMEGA_AT],
        -r * y[OMEGA_AT + 1],
        -r * y[OMEGA_AT + 2],
    ]
}

/// A constant force `f` at the body point `b`: `F = f` (space frame) or `F = Q f`
/// (body-fixed), with its moment `b × Qᵀ F`.
#[inline(always)]
fn point_force<T: Scalar>(p: &[T; FORCE_PARAMS], y: &[T; STATE_SIZE]) -> [T; 6] {
    let (f0, f1, f2) = (p[3], p[4], p[5]);
    let f = if p[6].unequal(T::splat(0.0)) {
        [
            y[Q_AT] * f0 + y[Q_AT + 1] * f1 + y[Q_AT + 2] * f2,
            y[Q_AT + 3] * f0 + y[Q_AT + 4] * f1 + y[Q_AT + 5] * f2,
            y[Q_AT + 6] * f0 + y[Q_AT + 7] * f1 + y[Q_AT + 8] * f2,
        ]
    } else {
        [f0, f1, f2]
    };
    let t = moment_about_center([p[0], p[1], p[2]], y, f);
    [f[0], f[1], f[2], t[0], t[1], t[2]]
}

/// A pure couple `τ`: body-fixed, or fixed in space (body components `Qᵀ τ`).
#[inline(always)]
fn torque<T: Scalar>(p: &[T; FORCE_PARAMS], y: &[T; STATE_SIZE]) -> [T; 6] {
    let z = T::splat(0.0);
    let (t0, t1, t2) = (p[0], p[1], p[2]);
    if p[3].unequal(z) {
        return [z, z, z, t0, t1, t2];
    }
    [
        z,
        z,
        z,
        y[Q_AT] * t0 + y[Q_AT + 3] * t1 + y[Q_AT + 6] * t2,
        y[Q_AT + 1] * t0 + y[Q_AT + 4] * t1 + y[Q_AT + 7] * t2,
        y[Q_AT + 2] * t0 + y[Q_AT + 5] * t1 + y[Q_AT + 8] * t2,
    ]
}

impl Force {
    /// The wrench `(Fx, Fy, Fz, τx, τy, τz)`: force (space frame), torque about the centre of
    /// mass (body frame).
    #[inline(always)]
    pub fn wrench(&self, body: &Body, _t: f64, y: &State) -> [f64; 6] {
        wrench_of(self.kind, &self.p, body, y)
    }

    /// The potential energy (zero for kinds without one): `U = −M g·R` for gravity.
    #[inline(always)]
    pub fn potential(&self, body: &Body, _t: f64, y: &State) -> f64 {
        let p = &self.p;
        match self.kind {
            ForceKind::Gravity => {
                -body.mass * (p[0] * y[R_AT] + p[1] * y[R_AT + 1] + p[2] * y[R_AT + 2])
            }
            ForceKind::CentralGravity => central_gravity_potential(p, body, y),
            ForceKind::Spring => spring_potential(p, y),
            _ => 0.0,
        }
    }
}

/// The wrench of a force of kind `kind` with the parameter row `p`, in numbers of type `T`
/// (`f64`, or dual numbers that differentiate it with respect to the state, the body and the
/// parameters): [`Force::wrench`].
#[inline(always)]
pub fn wrench_of<T: Scalar>(
    kind: ForceKind,
    p: &[T; FORCE_PARAMS],
    body: &Body<T>,
    y: &[T; STATE_SIZE],
) -> [T; 6] {
    match kind {
        ForceKind::Gravity => gravity(p, body),
        ForceKind::CentralGravity => central_gravity(p, body, y),
        ForceKind::Spring => spring(p, y),
        ForceKind::LinearDrag => linear_drag(p, y),
        ForceKind::QuadraticDrag => quadratic_drag(p, y),
        ForceKind::PointForce => point_force(p, y),
        ForceKind::Torque => torque(p, y),
    }
}

/// [`Force::wrench`] of a force whose kind `K` (its code) is known at compile time.
#[inline(always)]
pub fn one_force_wrench<const K: i64>(
    p: &[f64; FORCE_PARAMS],
    body: &Body,
    _t: f64,
    y: &State,
) -> [f64; 6] {
    match K {
        1 => gravity(p, body),
        2 => central_gravity(p, body, y),
        3 => spring(p, y),
        4 => linear_drag(p, y),
        5 => quadratic_drag(p, y),
        6 => point_force(p, y),
        _ => torque(p, y),
    }
}

/// Total wrench of `forces` about the centre of mass. Always inlined, into the drivers' copy
/// for each instruction set: out of line, it was compiled for the baseline alone, a call at
/// every evaluation.
#[inline(always)]
pub fn total_wrench(forces: &[Force], body: &Body, t: f64, y: &State) -> [f64; 6] {
    let mut w = [0.0; 6];
    for f in forces {
        let v = f.wrench(body, t, y);
        for k in 0..6 {
            w[k] += v[k];
        }
    }
    w
}

/// Total potential energy of `forces`.
#[inline]
pub fn total_potential(forces: &[Force], body: &Body, t: f64, y: &State) -> f64 {
    forces.iter().map(|f| f.potential(body, t, y)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::Body;

    fn identity_state(r: [f64; 3]) -> State {
        let mut y = [0.0; STATE_SIZE];
        y[R_AT..R_AT + 3].copy_from_slice(&r);
        y[Q_AT] = 1.0;
        y[Q_AT + 4] = 1.0;
        y[Q_AT + 8] = 1.0;
        y
    }

    fn body() -> Body {
        let a = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.5]];
        Body::from_slice(&Body::vector(
            2.0,
            [1.0, 2.0, 3.5],
            [0.0; 3],
            &a,
            [0.0; 3],
            false,
            -1,
        ))
        .unwrap()
    }

    /// Every conservative kind: F = −∂U/∂R by central differences (an independent route).
    #[test]
    fn forces_are_minus_the_gradient_of_their_potential() {
        let b = body();
        let mut p_spring = [0.0; FORCE_PARAMS];
        p_spring[..8].copy_from_slice(&[0.1, -0.2, 0.3, 2.0, 1.0, -1.0, 7.0, 0.5]);
        let mut p_central = [0.0; FORCE_PARAMS];
        p_central[..5].copy_from_slice(&[3.0, 0.5, -0.5, 0.2, 1.0]);
        let mut p_gravity = [0.0; FORCE_PARAMS];
        p_gravity[..3].copy_from_slice(&[0.0, 0.0, -9.8]);
        for (kind, p) in [
            (ForceKind::Spring, p_spring),
            (ForceKind::CentralGravity, p_central),
            (ForceKind::Gravity, p_gravity),
        ] {
            let f = Force { kind, p };
            let y = identity_state([1.3, 0.4, -2.1]);
            let w = f.wrench(&b, 0.0, &y);
            for k in 0..3 {
                let h = 1e-6;
                let (mut yp, mut ym) = (y, y);
                yp[R_AT + k] += h;
                ym[R_AT + k] -= h;
                let g = (f.potential(&b, 0.0, &yp) - f.potential(&b, 0.0, &ym)) / (2.0 * h);
                assert!((w[k] + g).abs() < 1e-7 * (1.0 + g.abs()), "{kind:?} {k}");
            }
        }
    }

    #[test]
    fn point_force_moment_is_b_cross_f() {
        let mut p = [0.0; FORCE_PARAMS];
        p[..6].copy_from_slice(&[1.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
        let w = Force {
            kind: ForceKind::PointForce,
            p,
        }
        .wrench(&body(), 0.0, &identity_state([0.0; 3]));
        assert_eq!(w, [0.0, 2.0, 0.0, 0.0, 0.0, 2.0]);
    }
}
