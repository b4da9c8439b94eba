//! The rotation group SO(3) and its Lie algebra: hat, the exponential map and the inverse of
//! its derivative (used by the Lie-group steppers and the closed forms at fixed points,
//! `docs/theory.md` §1, eqs (22)–(23)).

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
/// coefficients below [`SMALL_ANGLE`].
#[inline(always)]
pub fn exp_so3(w: Vec3) -> Mat3 {
    let [x, y, z] = w;
    let t2 = x * x + y * y + z * z;
    let (a, b) = if t2 < SMALL_ANGLE * SMALL_ANGLE {
        (
            1.0 - t2 / 6.0 + t2 * t2 / 120.0,
            0.5 - t2 / 24.0 + t2 * t2 / 720.0,
        )
    } else {
        let theta = t2.sqrt();
        (theta.sin() / theta, (1.0 - theta.cos()) / t2)
    };
    // I + a Ŵ + b Ŵ², with Ŵ² = w wᵀ − θ² I
    [
        [1.0 + b * (x * x - t2), b * x * y - a * z, b * x * z + a * y],
        [b * x * y + a * z, 1.0 + b * (y * y - t2), b * y * z - a * x],
        [b * x * z - a * y, b * y * z + a * x, 1.0 + b * (z * z - t2)],
    ]
}

/// `dexp⁻¹_u(v) = v − ½ u × v + c(θ) u × (u × v)`, `c = (1 − (θ/2) cot(θ/2))/θ²` (series
/// `1/12 + θ²/720 + θ⁴/30240` near 0), θ = |u| (Iserles, Munthe-Kaas, Nørsett & Zanna 2000,
/// Acta Numerica, §2.4). Used by the Runge–Kutta–Munthe-Kaas steps.
#[inline(always)]
pub fn dexpinv3(u: Vec3, v: Vec3) -> Vec3 {
    let [u0, u1, u2] = u;
    let t2 = u0 * u0 + u1 * u1 + u2 * u2;
    let c = if t2 < 1e-6 {
        1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    } else {
        let half = 0.5 * t2.sqrt();
        (1.0 - half * half.cos() / half.sin()) / t2
    };
    let a = cross(u, v);
    let b = cross(u, a);
    [
        v[0] - 0.5 * a[0] + c * b[0],
        v[1] - 0.5 * a[1] + c * b[1],
        v[2] - 0.5 * a[2] + c * b[2],
    ]
}

/// `a × b`.
#[inline(always)]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
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
}
