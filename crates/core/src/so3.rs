//! The rotation group SO(3) and its Lie algebra: hat, the exponential map and the inverse of
//! its derivative (used by the Lie-group steppers and the closed forms at fixed points,
//! `docs/theory.md` §1, eqs (22)–(23)).

use crate::real::{sin_cos, Real};

/// A 3×3 matrix, row-major rows.
pub type Mat3 = [[f64; 3]; 3];
/// A 3-vector.
pub type Vec3 = [f64; 3];

/// Below this angle, the Rodrigues coefficients are taken from their Taylor series.
pub const SMALL_ANGLE: f64 = 1e-4;

/// `hat(w)`: the skew matrix with `hat(w) v = w × v`.
#[inline(always)]
pub fn hat(w: Vec3) -> Mat3 {
    [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]]
}

/// `exp(hat(w))` by Rodrigues' formula:
/// `exp(Ŵ) = I + (sin θ/θ) Ŵ + ((1 − cos θ)/θ²) Ŵ²`, θ = |w|, with the Taylor series of both
/// coefficients below [`SMALL_ANGLE`]. Generic over [`Real`], so that it runs on one rotation
/// or on many in lanes (the sine and cosine are [`sin_cos`]'s, both coefficients computed
/// and the series selected).
#[inline(always)]
pub fn exp_so3<T: Real>(w: [T; 3]) -> [[T; 3]; 3] {
    let c = T::splat;
    let [x, y, z] = w;
    let t2 = x * x + y * y + z * z;
    let theta = t2.sqrt();
    let (s, co) = sin_cos(theta);
    let small = t2.lt(c(SMALL_ANGLE * SMALL_ANGLE));
    // one division: sin θ/θ = θ sin θ/θ², (1 − cos θ)/θ²; the series' constants as products
    let inv = c(1.0) / t2;
    let a = T::select(
        small,
        c(1.0) - t2 * c(1.0 / 6.0) + t2 * t2 * c(1.0 / 120.0),
        theta * s * inv,
    );
    let b = T::select(
        small,
        c(0.5) - t2 * c(1.0 / 24.0) + t2 * t2 * c(1.0 / 720.0),
        (c(1.0) - co) * inv,
    );
    let one = c(1.0);
    // I + a Ŵ + b Ŵ², with Ŵ² = w wᵀ − θ² I
    [
        [one + b * (x * x - t2), b * x * y - a * z, b * x * z + a * y],
        [b * x * y + a * z, one + b * (y * y - t2), b * y * z - a * x],
        [b * x * z - a * y, b * y * z + a * x, one + b * (z * z - t2)],
    ]
}

/// `dexp⁻¹_u(v) = v − ½ u × v + c(θ) u × (u × v)`, `c = (1 − (θ/2) cot(θ/2))/θ²` (series
/// `1/12 + θ²/720 + θ⁴/30240` near 0), θ = |u| (Iserles, Munthe-Kaas, Nørsett & Zanna 2000,
/// Acta Numerica, §2.4). Used by the Runge–Kutta–Munthe-Kaas steps; generic over [`Real`]
/// as [`exp_so3`].
#[inline(always)]
pub fn dexpinv3<T: Real>(u: [T; 3], v: [T; 3]) -> [T; 3] {
    let k = T::splat;
    let [u0, u1, u2] = u;
    let t2 = u0 * u0 + u1 * u1 + u2 * u2;
    let half = k(0.5) * t2.sqrt();
    let (s, co) = sin_cos(half);
    // 1 − (θ/2) cot(θ/2) over θ², in one division
    let c = T::select(
        t2.lt(k(1e-6)),
        k(1.0 / 12.0) + t2 * k(1.0 / 720.0) + t2 * t2 * k(1.0 / 30240.0),
        (s - half * co) / (s * t2),
    );
    let a = cross_t(u, v);
    let b = cross_t(u, a);
    let h = k(0.5);
    [
        v[0] - h * a[0] + c * b[0],
        v[1] - h * a[1] + c * b[1],
        v[2] - h * a[2] + c * b[2],
    ]
}

/// `a × b` over [`Real`].
#[inline(always)]
pub fn cross_t<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a × b`.
#[inline(always)]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    cross_t(a, b)
}

/// `A B` for 3×3 matrices.
#[inline(always)]
pub fn matmul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    c
}

/// A unit quaternion, scalar first: `(w, x, y, z)` (Hamilton product; acts on vectors as
/// `q v q*`, the active rotation).
pub type Quat = [f64; 4];

/// `vee(B)`: the vector of the skew part of `B`, the inverse of [`hat`]:
/// `vee(B) = vee((B − Bᵀ)/2) = (−B23, B13, −B12)` for a skew `B` (`docs/theory.md` §1;
/// 0-based `(B[2][1], B[0][2], B[1][0])`), so round-off in `B` does not bias the result.
#[inline(always)]
pub fn vee(b: &Mat3) -> Vec3 {
    [
        0.5 * (b[2][1] - b[1][2]),
        0.5 * (b[0][2] - b[2][0]),
        0.5 * (b[1][0] - b[0][1]),
    ]
}

/// `log(R)`: the rotation vector `w` with `exp_so3(w) = R` and `|w| ≤ π`, through the
/// quaternion of `R` by Shepperd's method ([`matrix_to_quat`]) and [`quat_to_rotvec`], which
/// stays accurate near θ = π where `arccos((tr R − 1)/2)` loses half the digits.
#[inline(always)]
pub fn log_so3(r: &Mat3) -> Vec3 {
    quat_to_rotvec(matrix_to_quat(r))
}

/// The rotation matrix by `angle` about the coordinate axis `axis` ∈ {0, 1, 2} (x, y, z).
/// An `axis` outside 0..3 is taken modulo 3.
#[inline(always)]
pub fn axis_rotation(axis: usize, angle: f64) -> Mat3 {
    let c = angle.cos();
    let s = angle.sin();
    let mut r = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let i = (axis + 1) % 3;
    let j = (axis + 2) % 3;
    r[i][i] = c;
    r[j][j] = c;
    r[i][j] = -s;
    r[j][i] = s;
    r
}

/// `p ⊗ q`: the Hamilton product of two scalar-first quaternions.
#[inline(always)]
pub fn quat_multiply(p: Quat, q: Quat) -> Quat {
    let [pw, px, py, pz] = p;
    let [qw, qx, qy, qz] = q;
    [
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    ]
}

/// The conjugate `(w, −x, −y, −z)`: the inverse of a unit quaternion.
#[inline(always)]
pub fn quat_conjugate(q: Quat) -> Quat {
    [q[0], -q[1], -q[2], -q[3]]
}

/// `q/|q|`; `None` for the zero quaternion (which has no direction).
#[inline(always)]
pub fn quat_normalize(q: Quat) -> Option<Quat> {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if n == 0.0 {
        return None;
    }
    Some([q[0] / n, q[1] / n, q[2] / n, q[3] / n])
}

/// The rotation matrix of a unit quaternion `(w, x, y, z)`:
/// `R = (w² − |u|²) I + 2 u uᵀ + 2 w û` written with `w² + |u|² = 1`.
#[inline(always)]
pub fn quat_to_matrix(q: Quat) -> Mat3 {
    let [w, x, y, z] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// `q v q*` for a unit quaternion `q = (w, u)`: `v + 2w (u × v) + 2 u × (u × v)`.
#[inline(always)]
pub fn quat_rotate(q: Quat, v: Vec3) -> Vec3 {
    let [w, ux, uy, uz] = q;
    let tx = 2.0 * (uy * v[2] - uz * v[1]);
    let ty = 2.0 * (uz * v[0] - ux * v[2]);
    let tz = 2.0 * (ux * v[1] - uy * v[0]);
    [
        v[0] + w * tx + (uy * tz - uz * ty),
        v[1] + w * ty + (uz * tx - ux * tz),
        v[2] + w * tz + (ux * ty - uy * tx),
    ]
}

/// The unit quaternion (w ≥ 0) of a rotation matrix, by Shepperd's method (Shepperd 1978,
/// J. Guidance Control 1(3)): the largest of `4w², 4x², 4y², 4z²` is computed from the diagonal
/// and the other components from off-diagonal sums, so no branch divides by a small number.
#[inline(always)]
pub fn matrix_to_quat(r: &Mat3) -> Quat {
    let tr = r[0][0] + r[1][1] + r[2][2];
    let c0 = 1.0 + tr;
    let c1 = 1.0 + 2.0 * r[0][0] - tr;
    let c2 = 1.0 + 2.0 * r[1][1] - tr;
    let c3 = 1.0 + 2.0 * r[2][2] - tr;
    let mut k = 0;
    let mut big = c0;
    if c1 > big {
        k = 1;
        big = c1;
    }
    if c2 > big {
        k = 2;
        big = c2;
    }
    if c3 > big {
        k = 3;
        big = c3;
    }
    let s = big.max(0.0).sqrt(); // 2|q_k|
    let d21 = r[2][1] - r[1][2];
    let d02 = r[0][2] - r[2][0];
    let d10 = r[1][0] - r[0][1];
    let s01 = r[0][1] + r[1][0];
    let s02 = r[0][2] + r[2][0];
    let s12 = r[1][2] + r[2][1];
    let ss = s * s;
    let (w, x, y, z) = match k {
        0 => (ss, d21, d02, d10),
        1 => (d21, ss, s01, s02),
        2 => (d02, s01, ss, s12),
        _ => (d10, s02, s12, ss),
    };
    let mut n = (w * w + x * x + y * y + z * z).sqrt();
    if w < 0.0 {
        n = -n;
    }
    [w / n, x / n, y / n, z / n]
}

/// The unit quaternion of the rotation vector `w` (angle |w| about w/|w|):
/// `(cos(θ/2), sin(θ/2) w/θ)`, with `sin(θ/2)/θ = 1/2 − θ²/48 + θ⁴/3840` below
/// [`SMALL_ANGLE`].
#[inline(always)]
pub fn rotvec_to_quat(w: Vec3) -> Quat {
    let t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    let theta = t2.sqrt();
    let s = if theta < SMALL_ANGLE {
        0.5 - t2 / 48.0 + t2 * t2 / 3840.0
    } else {
        (0.5 * theta).sin() / theta
    };
    [(0.5 * theta).cos(), s * w[0], s * w[1], s * w[2]]
}

/// The rotation vector (angle in [0, π]) of a unit quaternion: `θ = 2 atan2(|v|, |w|)`,
/// accurate at every angle, including near 0 and π.
#[inline(always)]
pub fn quat_to_rotvec(q: Quat) -> Vec3 {
    let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
    let w = sign * q[0];
    let x = sign * q[1];
    let y = sign * q[2];
    let z = sign * q[3];
    let sv = (x * x + y * y + z * z).sqrt();
    let factor = if sv < 1e-12 {
        if w != 0.0 {
            2.0 / w
        } else {
            2.0
        }
    } else {
        2.0 * sv.atan2(w) / sv
    };
    [factor * x, factor * y, factor * z]
}

/// `Rz(ψ) Rx(θ) Rz(φ)`: the rotation of z-x-z Euler angles (intrinsic, as SciPy's
/// `Rotation.from_euler("ZXZ", …)`; the paper's precession, nutation and proper rotation,
/// eq. (13)).
#[inline(always)]
pub fn zxz_matrix(psi: f64, theta: f64, phi: f64) -> Mat3 {
    let (sps, cps) = (psi.sin(), psi.cos());
    let (st, ct) = (theta.sin(), theta.cos());
    let (sph, cph) = (phi.sin(), phi.cos());
    zxz_matrix_sc([sps, cps], [st, ct], [sph, cph])
}

/// [`zxz_matrix`] from the angles' sines and cosines `[sin, cos]` of ψ, θ and φ, generic over
/// [`Real`] (the attitude of free bodies in lanes, whose angles come as ratios).
#[inline(always)]
pub fn zxz_matrix_sc<T: Real>(psi: [T; 2], theta: [T; 2], phi: [T; 2]) -> [[T; 3]; 3] {
    let [sps, cps] = psi;
    let [st, ct] = theta;
    let [sph, cph] = phi;
    [
        [
            cps * cph - sps * ct * sph,
            -cps * sph - sps * ct * cph,
            sps * st,
        ],
        [
            sps * cph + cps * ct * sph,
            -sps * sph + cps * ct * cph,
            -cps * st,
        ],
        [st * sph, st * cph, ct],
    ]
}

/// Body-frame angular velocity `(p, q, r)` from z-x-z Euler angles `(ψ, θ, φ)` and their
/// rates (paper eq. (13); the same form gives the carrier's ω_e from its angles, eq. (14)):
/// `p = ψ̇ sin θ sin φ + θ̇ cos φ`, `q = ψ̇ sin θ cos φ − θ̇ sin φ`, `r = φ̇ + ψ̇ cos θ`.
/// Generic over [`Real`] (the heavy top's closed-form derivatives run it on dual numbers).
#[inline(always)]
pub fn zxz_body_rates<T: Real>(angles: [T; 3], rates: [T; 3]) -> [T; 3] {
    let (st, ct) = angles[1].sin_cos_std();
    let (sp, cp) = angles[2].sin_cos_std();
    [
        rates[0] * st * sp + rates[1] * cp,
        rates[0] * st * cp - rates[1] * sp,
        rates[2] + rates[0] * ct,
    ]
}

/// The inverse of [`zxz_body_rates`]: `ψ̇ = (p sin φ + q cos φ)/sin θ`,
/// `θ̇ = p cos φ − q sin φ`, `φ̇ = r − ψ̇ cos θ`. Singular at θ = 0, π (sin θ = 0), where
/// the result is infinite or NaN; callers check.
#[inline(always)]
pub fn zxz_angle_rates(angles: Vec3, omega: Vec3) -> Vec3 {
    let st = angles[1].sin();
    let sp = angles[2].sin();
    let cp = angles[2].cos();
    let psid = (omega[0] * sp + omega[1] * cp) / st;
    [
        psid,
        omega[0] * cp - omega[1] * sp,
        omega[2] - psid * angles[1].cos(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Mat3, b: &Mat3, tol: f64) -> bool {
        (0..3).all(|i| (0..3).all(|j| (a[i][j] - b[i][j]).abs() <= tol))
    }

    #[test]
    fn exp_is_orthogonal_and_matches_its_series() {
        // exp(Ŵ) is a rotation: QᵀQ = I; and the two branches meet at SMALL_ANGLE.
        for k in 0..200 {
            let s = (k as f64) * 0.037 - 3.0;
            let w = [0.3 * s, -0.7 * s.sin(), 1.1 * s.cos()];
            let q = exp_so3(w);
            let qt = [
                [q[0][0], q[1][0], q[2][0]],
                [q[0][1], q[1][1], q[2][1]],
                [q[0][2], q[1][2], q[2][2]],
            ];
            let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            assert!(close(&matmul(&qt, &q), &eye, 1e-14));
        }
        let d = SMALL_ANGLE / 3f64.sqrt();
        let (lo, hi) = (exp_so3([d * 0.999999, d, d]), exp_so3([d * 1.000001, d, d]));
        assert!(close(&lo, &hi, 1e-9));
    }

    #[test]
    fn exp_and_dexpinv_over_many_angles_and_in_lanes() {
        // exp against the rotation of the unit quaternion (cos θ/2, sin θ/2 n) with the
        // standard library's trigonometry, and dexp⁻¹ against the inverse of dexp's closed
        // form, over angles from 1e-9 to 20 rad (both sides of the series' thresholds); the
        // lanes give each rotation's numbers bit for bit
        use crate::real::Wide;
        let mut ws = Vec::new();
        for (k, v) in sample_vectors(4000, 1.0).into_iter().enumerate() {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-3);
            let angle = 10f64.powf(-9.0 + 10.3 * (k as f64 / 4000.0));
            ws.push(v.map(|x| x / n * angle));
        }
        let us = sample_vectors(4000, 1.0);
        for (w, v) in ws.iter().zip(&us) {
            let th = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            let (sh, ch) = (0.5 * th).sin_cos();
            let f = if th > 0.0 { sh / th } else { 0.5 };
            let q = quat_to_matrix([ch, f * w[0], f * w[1], f * w[2]]);
            assert!(close(&exp_so3(*w), &q, 4e-16 * (1.0 + th)), "{w:?}");
            // dexp_w(v) = v + (1 − cos θ)/θ² w×v + (θ − sin θ)/θ³ w×(w×v), near 0 its series
            let t2 = th * th;
            let (c1, c2) = if th < 1e-3 {
                (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
            } else {
                ((1.0 - th.cos()) / t2, (th - th.sin()) / (t2 * th))
            };
            let a = cross(*w, *v);
            let b = cross(*w, a);
            let d = [0, 1, 2].map(|i| v[i] + c1 * a[i] + c2 * b[i]);
            if th < 6.0 {
                let back = dexpinv3(*w, d);
                for i in 0..3 {
                    assert!((back[i] - v[i]).abs() < 1e-12 * (1.0 + t2), "{w:?} {i}");
                }
            }
        }
        const L: usize = 8;
        for chunk in ws.chunks_exact(L).zip(us.chunks_exact(L)) {
            let (w, v) = chunk;
            let wide = |x: &[Vec3], i: usize| Wide::<L>(std::array::from_fn(|l| x[l][i]));
            let e = exp_so3([wide(w, 0), wide(w, 1), wide(w, 2)]);
            let d = dexpinv3(
                [wide(w, 0), wide(w, 1), wide(w, 2)],
                [wide(v, 0), wide(v, 1), wide(v, 2)],
            );
            for l in 0..L {
                let (e1, d1) = (exp_so3(w[l]), dexpinv3(w[l], v[l]));
                for i in 0..3 {
                    assert_eq!(d[i].0[l].to_bits(), d1[i].to_bits());
                    for j in 0..3 {
                        assert_eq!(e[i][j].0[l].to_bits(), e1[i][j].to_bits());
                    }
                }
            }
        }
    }

    #[test]
    fn exp_about_z_is_the_plane_rotation() {
        let q = exp_so3([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        assert!(close(
            &q,
            &[[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            1e-15
        ));
    }

    #[test]
    fn dexpinv_inverts_the_derivative_of_exp() {
        // dexp_u(v) by its closed form, then dexpinv_u must return v; and dexp_u(v) must be the
        // derivative of exp along v (a central finite difference).
        let u = [0.4, -0.9, 0.7];
        let v = [0.2, 0.5, -1.3];
        // dexp_u(v) = v + (1 − cos θ)/θ² u×v + (θ − sin θ)/θ³ u×(u×v)
        let t2: f64 = u.iter().map(|x| x * x).sum();
        let th = t2.sqrt();
        let a = cross(u, v);
        let b = cross(u, a);
        let c1 = (1.0 - th.cos()) / t2;
        let c2 = (th - th.sin()) / (t2 * th);
        let w = [
            v[0] + c1 * a[0] + c2 * b[0],
            v[1] + c1 * a[1] + c2 * b[1],
            v[2] + c1 * a[2] + c2 * b[2],
        ];
        let back = dexpinv3(u, w);
        for i in 0..3 {
            assert!((back[i] - v[i]).abs() < 1e-14);
        }
        // and dexp_u(v) is the left-trivialised derivative of exp: a finite difference
        let h = 1e-6;
        let e0 = exp_so3(u);
        let ep = exp_so3([u[0] + h * v[0], u[1] + h * v[1], u[2] + h * v[2]]);
        let em = exp_so3([u[0] - h * v[0], u[1] - h * v[1], u[2] - h * v[2]]);
        let mut d = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                d[i][j] = (ep[i][j] - em[i][j]) / (2.0 * h);
            }
        }
        // d exp = hat(dexp_u v) exp(u)
        let expect = matmul(&hat(w), &e0);
        assert!(close(&d, &expect, 1e-8));
    }

    fn transpose(a: &Mat3) -> Mat3 {
        let mut t = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                t[i][j] = a[j][i];
            }
        }
        t
    }

    fn matvec(a: &Mat3, v: Vec3) -> Vec3 {
        [
            a[0][0] * v[0] + a[0][1] * v[1] + a[0][2] * v[2],
            a[1][0] * v[0] + a[1][1] * v[1] + a[1][2] * v[2],
            a[2][0] * v[0] + a[2][1] * v[1] + a[2][2] * v[2],
        ]
    }

    /// A small deterministic generator of test vectors (no dependency on `rand`).
    fn sample_vectors(n: usize, scale: f64) -> Vec<Vec3> {
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        (0..n)
            .map(|_| [scale * next(), scale * next(), scale * next()])
            .collect()
    }

    #[test]
    fn vee_inverts_hat_and_ignores_the_symmetric_part() {
        for w in sample_vectors(50, 3.0) {
            let mut b = hat(w);
            b[0][1] += 0.25; // a symmetric perturbation is discarded
            b[1][0] += 0.25;
            b[2][2] += 1.0;
            let v = vee(&b);
            for k in 0..3 {
                assert!((v[k] - w[k]).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn log_inverts_exp_up_to_pi() {
        // |w| ≤ π: log(exp(w)) = w; the small-angle series and the near-π branch included.
        let mut cases = sample_vectors(300, 1.8);
        cases.push([1e-9, -2e-9, 5e-10]);
        cases.push([0.0, 0.0, 0.0]);
        cases.push([0.0, 0.0, std::f64::consts::PI - 1e-7]);
        cases.push([1.0, 1.0, 1.0].map(|x: f64| x * (std::f64::consts::PI - 1e-9) / 3f64.sqrt()));
        for w in cases {
            let th = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            if th > std::f64::consts::PI {
                continue;
            }
            let back = log_so3(&exp_so3(w));
            let tol = if th > 3.0 { 1e-8 } else { 1e-13 };
            for k in 0..3 {
                assert!((back[k] - w[k]).abs() < tol, "{w:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn quaternions_and_matrices_round_trip() {
        for w in sample_vectors(200, 3.0) {
            let q = rotvec_to_quat(w);
            let n: f64 = q.iter().map(|x| x * x).sum();
            assert!((n - 1.0).abs() < 1e-15);
            // the quaternion's matrix is the exponential of the same rotation vector
            assert!(close(&quat_to_matrix(q), &exp_so3(w), 1e-14));
            // matrix -> quaternion -> matrix, with w ≥ 0
            let q2 = matrix_to_quat(&quat_to_matrix(q));
            assert!(q2[0] >= 0.0);
            let s = if q[0] < 0.0 { -1.0 } else { 1.0 };
            for k in 0..4 {
                assert!((q2[k] - s * q[k]).abs() < 1e-14);
            }
            // rotating a vector: q v q* = R v = (q ⊗ (0, v) ⊗ q*).xyz
            let v = [0.3, -1.1, 0.8];
            let a = quat_rotate(q, v);
            let b = matvec(&quat_to_matrix(q), v);
            let c = quat_multiply(quat_multiply(q, [0.0, v[0], v[1], v[2]]), quat_conjugate(q));
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() < 1e-14);
                assert!((a[k] - c[k + 1]).abs() < 1e-14);
            }
            // rotvec -> quaternion -> rotvec
            let th = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            if th < 3.0 {
                let back = quat_to_rotvec(q);
                for k in 0..3 {
                    assert!((back[k] - w[k]).abs() < 1e-13);
                }
            }
        }
    }

    #[test]
    fn quaternion_product_is_matrix_product() {
        let ws = sample_vectors(40, 2.5);
        for pair in ws.chunks(2) {
            let (p, q) = (rotvec_to_quat(pair[0]), rotvec_to_quat(pair[1]));
            let pq = quat_multiply(p, q);
            let m = matmul(&quat_to_matrix(p), &quat_to_matrix(q));
            assert!(close(&quat_to_matrix(pq), &m, 1e-14));
            // q ⊗ q* = 1, and normalising a scaled quaternion gives it back
            let one = quat_multiply(q, quat_conjugate(q));
            assert!((one[0] - 1.0).abs() < 1e-15 && one[1..].iter().all(|x| x.abs() < 1e-15));
            let back = quat_normalize(q.map(|x| 7.5 * x)).unwrap();
            for k in 0..4 {
                assert!((back[k] - q[k]).abs() < 1e-15);
            }
        }
        assert!(quat_normalize([0.0; 4]).is_none());
    }

    #[test]
    fn matrix_to_quat_near_a_half_turn() {
        // θ = π about a skew axis: the w-branch would divide by ~0; Shepperd picks another.
        let n = [2.0f64, -1.0, 0.5];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let w = n.map(|x| x / len * std::f64::consts::PI);
        let r = exp_so3(w);
        let q = matrix_to_quat(&r);
        assert!(q[0].abs() < 1e-15);
        assert!(close(&quat_to_matrix(q), &r, 1e-15));
    }

    #[test]
    fn axis_rotations_are_exponentials_and_compose_zxz() {
        let e = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for (axis, unit) in e.iter().enumerate() {
            for &angle in &[-2.0, 0.3, 1.7, 3.1] {
                let w = unit.map(|x| x * angle);
                assert!(close(&axis_rotation(axis, angle), &exp_so3(w), 1e-15));
            }
        }
        let (psi, theta, phi) = (0.7, 1.2, -2.3);
        let r = matmul(
            &matmul(&axis_rotation(2, psi), &axis_rotation(0, theta)),
            &axis_rotation(2, phi),
        );
        assert!(close(&zxz_matrix(psi, theta, phi), &r, 1e-15));
    }

    #[test]
    fn zxz_rates_are_the_derivative_of_the_matrix() {
        // Q̇ = Q hat(ω) with ω the body rates: compare with a central difference of
        // zxz_matrix along (ψ̇, θ̇, φ̇), then invert with zxz_angle_rates.
        let h = 1e-6;
        for (k, a) in sample_vectors(30, 3.0).into_iter().enumerate() {
            let angles = [a[0], 0.2 + 0.9 * (a[1] + 1.0), a[2]]; // θ in (0.2, 2.0)
            let rates = sample_vectors(30, 2.0)[k];
            let at = |t: f64| {
                zxz_matrix(
                    angles[0] + t * rates[0],
                    angles[1] + t * rates[1],
                    angles[2] + t * rates[2],
                )
            };
            let (qp, qm) = (at(h), at(-h));
            let mut dq = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    dq[i][j] = (qp[i][j] - qm[i][j]) / (2.0 * h);
                }
            }
            let omega_fd = vee(&matmul(&transpose(&at(0.0)), &dq));
            let omega = zxz_body_rates(angles, rates);
            let back = zxz_angle_rates(angles, omega);
            for i in 0..3 {
                assert!(
                    (omega[i] - omega_fd[i]).abs() < 1e-8,
                    "{omega:?} {omega_fd:?}"
                );
                assert!((back[i] - rates[i]).abs() < 1e-12);
            }
        }
    }
}
