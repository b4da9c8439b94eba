//! The heavy symmetric top on a fixed tip: its steady precessions.
//!
//! A symmetric body turns about a fixed tip under gravity; `A` is its moment about any axis
//! through the tip perpendicular to the symmetry axis, `C` its moment about the symmetry axis,
//! `M g l` the weight times the distance from the tip to the centre of mass (along the symmetry
//! axis), θ the angle of the symmetry axis from the upward vertical and `ω₃ = φ̇ + ψ̇ cos θ` the
//! spin about the symmetry axis (a constant of the motion). In z-x-z Euler angles,
//! `L = ½ A (θ̇² + ψ̇² sin² θ) + ½ C ω₃² − M g l cos θ` (Goldstein, Poole & Safko, *Classical
//! Mechanics*, 3rd ed., §5.7).
//!
//! A steady precession keeps θ constant: `∂L/∂θ = 0` with `θ̇ = θ̈ = 0` gives
//!
//! ```text
//!     A cos θ · Ω² − C ω₃ · Ω + M g l = 0,        Ω = ψ̇,
//! ```
//!
//! whose two roots are the slow and the fast precession. For a fast top (`C² ω₃² ≫ 4 A M g l
//! cos θ`) the slow root tends to the gyroscopic estimate `Ω ≈ M g l / (C ω₃)`, independent of
//! θ; the fast one to `C ω₃ / (A cos θ)`.

use crate::so3::{cross, Mat3, Vec3};

/// The symmetry axis (unit, the principal frame's coordinates of `axes`' columns) of a body
/// that is a symmetric top about a fixed point, or `None`: with ascending principal `moments`
/// about the point (columns of `axes` their axes) two of them equal to `rtol · I3`, and `c`
/// (the centre of mass from the point) on the third axis, to `rtol · |c|`. A body spherical
/// about the point has every axis for one: the axis through the centre of mass (`None` when
/// the centre of mass is the point). The one criterion of a symmetric top: whether a top's
/// axial momentum `L · e₃` is conserved under gravity, and whether it is Lagrange's top.
pub fn symmetric_top_axis(moments: Vec3, axes: &Mat3, c: Vec3, rtol: f64) -> Option<Vec3> {
    let tol = rtol * moments[2];
    let norm = |v: Vec3| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let column = |k: usize| [axes[0][k], axes[1][k], axes[2][k]];
    let axis = if moments[2] - moments[0] <= tol {
        let l = norm(c);
        return (l > 0.0).then(|| c.map(|x| x / l));
    } else if moments[1] - moments[0] <= tol {
        column(2)
    } else if moments[2] - moments[1] <= tol {
        column(0)
    } else {
        return None;
    };
    let off = norm(cross(c, axis));
    (off <= rtol * norm(c)).then_some(axis)
}

/// The gyroscopic estimate of a fast top's precession rate, `Ω = M g l / (C ω₃)`
/// (Goldstein §5.7): the slow root of the steady-precession condition as `ω₃ → ∞`.
/// Infinite at `ω₃ = 0`.
pub fn gyroscopic_precession_rate(c: f64, mgl: f64, spin: f64) -> f64 {
    mgl / (c * spin)
}

/// The rates `[slow, fast]` of steady precession of a heavy symmetric top at the angle `theta`
/// from the upward vertical: the roots of `A cos θ Ω² − C ω₃ Ω + M g l = 0` (module docs).
///
/// They are formed without cancellation: with `q = ½ (C ω₃ + s √D)`, `s = ±1` the sign of
/// `ω₃` (+1 at 0) and `D = C² ω₃² − 4 A M g l cos θ`, the slow root is `M g l / q` and the fast
/// one `q / (A cos θ)`. A horizontal axis (`cos θ = 0`) has the slow root `M g l / (C ω₃)`
/// exactly and no fast one (infinite). `D < 0` (a top spinning too slowly for its tilt) has no
/// steady precession at that angle: both are NaN.
pub fn steady_precession_rates(a: f64, c: f64, mgl: f64, theta: f64, spin: f64) -> [f64; 2] {
    let cos = theta.cos();
    let b = c * spin;
    let disc = b * b - 4.0 * a * mgl * cos;
    if disc < 0.0 || !disc.is_finite() {
        return [f64::NAN, f64::NAN];
    }
    let s = if spin < 0.0 { -1.0 } else { 1.0 };
    let q = 0.5 * (b + s * disc.sqrt());
    let slow = mgl / q;
    let fast = if cos == 0.0 {
        f64::INFINITY * s
    } else {
        q / (a * cos)
    };
    [slow, fast]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_symmetric_top_has_its_axis_and_others_none() {
        let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        // oblate (I1 = I2 < I3), centre of mass on e3: the axis is e3
        assert_eq!(
            symmetric_top_axis([1.0, 1.0, 2.0], &eye, [0.0, 0.0, 0.3], 1e-9),
            Some([0.0, 0.0, 1.0])
        );
        // prolate (I1 < I2 = I3), centre of mass on e1: the axis is e1
        assert_eq!(
            symmetric_top_axis([1.0, 3.0, 3.0], &eye, [-0.2, 0.0, 0.0], 1e-9),
            Some([1.0, 0.0, 0.0])
        );
        // the centre of mass off the axis, or three distinct moments: no top
        assert_eq!(
            symmetric_top_axis([1.0, 1.0, 2.0], &eye, [0.1, 0.0, 0.3], 1e-9),
            None
        );
        assert_eq!(
            symmetric_top_axis([1.0, 2.0, 3.0], &eye, [0.0, 0.0, 0.3], 1e-9),
            None
        );
        // spherical about the point: the axis through the centre of mass, if any
        let axis = symmetric_top_axis([2.0, 2.0, 2.0], &eye, [0.0, 3.0, 4.0], 1e-9).unwrap();
        assert!((axis[1] - 0.6).abs() < 1e-15 && (axis[2] - 0.8).abs() < 1e-15);
        assert_eq!(
            symmetric_top_axis([2.0, 2.0, 2.0], &eye, [0.0; 3], 1e-9),
            None
        );
    }

    /// Both roots satisfy the quadratic, to round-off.
    #[test]
    fn roots_solve_the_steady_precession_condition() {
        for &(a, c, mgl, theta, spin) in &[
            (0.2758, 0.045, 4.905, 0.6, 100.0),
            (1.0, 0.5, 2.0, 1.2, -30.0),
            (0.3, 0.2, 1.0, 2.5, 1.0),
            (0.3, 0.2, 1.0, 2.5, 0.0),
        ] {
            for w in steady_precession_rates(a, c, mgl, theta, spin) {
                let residual = a * theta.cos() * w * w - c * spin * w + mgl;
                let scale = (a * theta.cos() * w * w).abs() + (c * spin * w).abs() + mgl;
                assert!(residual.abs() <= 1e-13 * scale, "{residual} at {w}");
            }
        }
    }

    /// The slow root tends to the gyroscopic estimate for a fast top, with the relative
    /// correction A M g l cos θ / (C ω₃)² of the expansion of the square root.
    #[test]
    fn slow_root_tends_to_the_gyroscopic_estimate() {
        let (a, c, mgl, theta) = (0.2758, 0.045, 4.905, 0.6);
        for spin in [1e2, 1e3, 1e4] {
            let slow = steady_precession_rates(a, c, mgl, theta, spin)[0];
            let gyro = gyroscopic_precession_rate(c, mgl, spin);
            let eps = a * mgl * theta.cos() / (c * spin).powi(2);
            assert!((slow / gyro - 1.0 - eps).abs() <= 3.0 * eps * eps, "{spin}");
        }
    }

    #[test]
    fn horizontal_and_too_slow_tops() {
        // cos(π/2) rounds to 6e-17: the fast root is then huge, the slow one M g l/(C ω₃)
        let half_pi = std::f64::consts::FRAC_PI_2;
        let [slow, fast] = steady_precession_rates(1.0, 0.5, 2.0, half_pi, 10.0);
        assert!((slow - 2.0 / 5.0).abs() < 1e-15 && fast.abs() > 1e15);
        let [slow, fast] = steady_precession_rates(1.0, 0.5, 2.0, 0.0, 0.0);
        assert!(slow.is_nan() && fast.is_nan()); // upright and not spinning: no steady motion
        let none = steady_precession_rates(1.0, 0.5, 2.0, 0.3, 0.1);
        assert!(none[0].is_nan() && none[1].is_nan());
    }
}
