//! Formulas of the torque-free body (`docs/theory.md` §1, "Torque-free body", eqs (20)–(33)),
//! in principal axes with ascending moments
//! `I1 ≤ I2 ≤ I3`:
//!
//! * the invariants (30)–(31), `k` with `2k = Σ I_i ω_i²` and `a = |L|`: [`invariants`]
//!   (that is [`crate::invariants::principal_invariants`], written once);
//! * the energy (Poinsot) and momentum ellipsoids' semi-axes;
//! * the cone (32) `Σ b_i ω_i² = 0`, `b_i = I_i (a²/(2k) − I_i)` (erratum: `a²/(2k)`, not the
//!   notebook code's `a^2/2*k`);
//! * Euler's equation (20) in principal components (27)–(29) and its linearisation;
//! * the symmetry class of the moments.

use crate::invariants::angular_momentum_body;
use crate::so3::{hat, Mat3, Vec3};

/// `(k, a)` for principal `moments` and ω in principal axes: `2k = Σ I_i ω_i²` (30),
/// `a² = Σ I_i² ω_i²` (31).
pub use crate::invariants::principal_invariants as invariants;

/// The tolerance and the rule of the symmetry classes, written once in [`crate::inertia`].
pub use crate::inertia::{symmetry_code, SYMMETRY_CLASSES, SYMMETRY_RTOL};

/// Semi-axes `√(2k/I_i)` of the energy (Poinsot) ellipsoid `Σ I_i ω_i² = 2k` (30).
pub fn energy_ellipsoid_semi_axes(moments: Vec3, energy: f64) -> Vec3 {
    moments.map(|i| (2.0 * energy / i).sqrt())
}

/// Semi-axes `a/I_i` of the momentum ellipsoid `Σ I_i² ω_i² = a²` (31).
pub fn momentum_ellipsoid_semi_axes(moments: Vec3, momentum: f64) -> Vec3 {
    moments.map(|i| momentum / i)
}

/// `b_i = I_i (a²/(2k) − I_i)`: the cone (32) `Σ b_i ω_i² = 0` on which every motion with
/// invariants `(k, a)` lies (the combination `a²·(30) − 2k·(31)`).
pub fn cone_coefficients(moments: Vec3, energy: f64, momentum: f64) -> Vec3 {
    let d = momentum * momentum / (2.0 * energy);
    moments.map(|i| i * (d - i))
}

/// `ω̇` of the torque-free Euler equation (20) in principal components, eqs (27)–(29):
/// `I1 ω̇1 = (I2 − I3) ω2 ω3`, `I2 ω̇2 = (I3 − I1) ω3 ω1`, `I3 ω̇3 = (I1 − I2) ω1 ω2`
/// (as [`crate::rigid::omega_dot_principal`] with zero torque; a zero moment gives a zero
/// rate, the minimum-norm solution).
pub fn euler_omega_dot(moments: Vec3, w: Vec3) -> Vec3 {
    let inv = moments.map(|i| if i != 0.0 { 1.0 / i } else { 0.0 });
    crate::rigid::omega_dot_principal(moments, inv, w, [0.0; 3])
}

/// `∂ω̇/∂ω = A⁻¹(hat(Aω) − hat(ω) A)` (3, 3) of Euler's equation (20) `A ω̇ = Aω × ω`, for any
/// symmetric inertia `A` and ω in the same frame: the linearisation whose eigenvalues decide
/// the stability of a fixed point (eqs (22)–(26)). `None` when `A` is singular.
pub fn euler_jacobian(inertia: &Mat3, w: Vec3) -> Option<Mat3> {
    let l = angular_momentum_body(inertia, w);
    let hl = hat(l);
    let hw = hat(w);
    let mut rhs = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            let hw_a =
                hw[r][0] * inertia[0][c] + hw[r][1] * inertia[1][c] + hw[r][2] * inertia[2][c];
            rhs[r][c] = hl[r][c] - hw_a;
        }
    }
    solve3(inertia, rhs)
}

/// `A⁻¹ B` by LU with partial pivoting (LAPACK's `dgesv` algorithm); `None` for a singular `A`.
#[allow(clippy::needless_range_loop)] // column-wise substitution reads best with indices
fn solve3(a: &Mat3, mut b: Mat3) -> Option<Mat3> {
    let mut lu = *a;
    for k in 0..3 {
        let mut piv = k;
        for r in k + 1..3 {
            if lu[r][k].abs() > lu[piv][k].abs() {
                piv = r;
            }
        }
        if lu[piv][k] == 0.0 || !lu[piv][k].is_finite() {
            return None;
        }
        lu.swap(k, piv);
        b.swap(k, piv);
        let recip = 1.0 / lu[k][k];
        for r in k + 1..3 {
            lu[r][k] *= recip;
            for c in k + 1..3 {
                lu[r][c] -= lu[r][k] * lu[k][c];
            }
        }
    }
    for c in 0..3 {
        for k in 0..3 {
            for r in k + 1..3 {
                b[r][c] -= b[k][c] * lu[r][k];
            }
        }
        for k in (0..3).rev() {
            b[k][c] /= lu[k][k];
            for r in 0..k {
                b[r][c] -= b[k][c] * lu[r][k];
            }
        }
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ellipsoids_contain_the_motion_and_the_cone_vanishes_on_it() {
        let moments = [1.0, 2.0, 3.0];
        let w = [0.3, -0.8, 0.55];
        let (k, a) = invariants(moments, w);
        let b = cone_coefficients(moments, k, a);
        let cone: f64 = (0..3).map(|i| b[i] * w[i] * w[i]).sum();
        assert!(cone.abs() < 1e-15 * b.iter().map(|x| x.abs()).sum::<f64>());
        // the ends of the semi-axes lie on their ellipsoids
        let e = energy_ellipsoid_semi_axes(moments, k);
        let m = momentum_ellipsoid_semi_axes(moments, a);
        for i in 0..3 {
            let mut x = [0.0; 3];
            x[i] = e[i];
            assert!((invariants(moments, x).0 - k).abs() < 1e-15);
            x[i] = m[i];
            assert!((invariants(moments, x).1 - a).abs() < 1e-15);
        }
    }

    #[test]
    fn euler_rate_conserves_the_invariants_and_matches_the_jacobian() {
        let moments = [1.0, 2.0, 3.0];
        let w = [0.3, -0.8, 0.55];
        let wd = euler_omega_dot(moments, w);
        // d(2k)/dt = 2 Σ I ω ω̇ = 0 and d(a²)/dt = 2 Σ I² ω ω̇ = 0
        let dk: f64 = (0..3).map(|i| moments[i] * w[i] * wd[i]).sum();
        let da: f64 = (0..3).map(|i| moments[i] * moments[i] * w[i] * wd[i]).sum();
        assert!(dk.abs() < 1e-15 && da.abs() < 1e-15);
        // the Jacobian is the derivative of the rate (central differences)
        let inertia = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
        let j = euler_jacobian(&inertia, w).unwrap();
        let h = 1e-6;
        for c in 0..3 {
            let (mut p, mut m) = (w, w);
            p[c] += h;
            m[c] -= h;
            let (fp, fm) = (euler_omega_dot(moments, p), euler_omega_dot(moments, m));
            for r in 0..3 {
                assert!(((fp[r] - fm[r]) / (2.0 * h) - j[r][c]).abs() < 1e-9);
            }
        }
        // a full (non-diagonal) inertia: A J = hat(Aω) − hat(ω) A
        let a = [[2.0, 0.3, -0.1], [0.3, 1.5, 0.2], [-0.1, 0.2, 1.1]];
        let j = euler_jacobian(&a, w).unwrap();
        let (hl, hw) = (hat(angular_momentum_body(&a, w)), hat(w));
        for r in 0..3 {
            for c in 0..3 {
                let aj: f64 = (0..3).map(|k| a[r][k] * j[k][c]).sum();
                let want = hl[r][c] - (0..3).map(|k| hw[r][k] * a[k][c]).sum::<f64>();
                assert!((aj - want).abs() < 1e-14);
            }
        }
        assert!(euler_jacobian(&[[0.0; 3]; 3], w).is_none());
    }

    #[test]
    fn symmetry_classes() {
        assert_eq!(symmetry_code([1.0, 2.0, 3.0], SYMMETRY_RTOL), 0);
        assert_eq!(symmetry_code([1.0, 2.0, 2.0], SYMMETRY_RTOL), 1);
        assert_eq!(symmetry_code([1.0, 1.0, 2.0], SYMMETRY_RTOL), 2);
        assert_eq!(symmetry_code([2.0, 2.0, 2.0], SYMMETRY_RTOL), 3);
        assert_eq!(SYMMETRY_CLASSES[1], "prolate");
    }
}
