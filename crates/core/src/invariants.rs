//! Kinetic energy and angular momentum of a rotating body, written once (`docs/theory.md` §1:
//! eq. (12) for the energy, eq. (03) for the momentum, eqs (30)–(31) in principal axes).
//! Everything else in the crate that needs them calls these.

use crate::real::Real;
use crate::so3::{Mat3, Vec3};

/// `A ω`: the angular momentum about the reference point, body frame (eq. (03), first term).
#[inline(always)]
pub fn angular_momentum_body(inertia: &Mat3, w: Vec3) -> Vec3 {
    [
        inertia[0][0] * w[0] + inertia[0][1] * w[1] + inertia[0][2] * w[2],
        inertia[1][0] * w[0] + inertia[1][1] * w[1] + inertia[1][2] * w[2],
        inertia[2][0] * w[0] + inertia[2][1] * w[1] + inertia[2][2] * w[2],
    ]
}

/// `½ ω·Aω`: the rotational kinetic energy (eq. (12), rotational part).
#[inline(always)]
pub fn rotational_energy(inertia: &Mat3, w: Vec3) -> f64 {
    let mut e = 0.0;
    for j in 0..3 {
        e += w[j] * (inertia[j][0] * w[0] + inertia[j][1] * w[1] + inertia[j][2] * w[2]);
    }
    0.5 * e
}

/// `½ Aω·ω + ½ M |V|²`: the kinetic energy (12) of a body with inertia `inertia` about its
/// centre of mass, mass `mass`, centre-of-mass velocity `v`.
#[inline(always)]
pub fn kinetic_energy(inertia: &Mat3, mass: f64, w: Vec3, v: Vec3) -> f64 {
    rotational_energy(inertia, w) + 0.5 * mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
}

/// `(k, a)` in principal axes: `2k = Σ I_i ω_i²` (30) and `a = |L|`, `a² = Σ I_i² ω_i²` (31).
/// Generic over [`Real`] (the exact-flow splittings' free flows in lanes, each lane its
/// single run's numbers).
#[inline(always)]
pub fn principal_invariants<T: Real>(moments: [T; 3], w: [T; 3]) -> (T, T) {
    let mut e = T::splat(0.0);
    let mut m = T::splat(0.0);
    for j in 0..3 {
        let p = moments[j] * w[j];
        e = e + p * w[j];
        m = m + p * p;
    }
    (T::splat(0.5) * e, m.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn principal_and_full_forms_agree() {
        let moments = [1.5, 2.25, 3.5];
        let inertia = [[1.5, 0.0, 0.0], [0.0, 2.25, 0.0], [0.0, 0.0, 3.5]];
        let w = [0.3, -1.2, 0.7];
        let (k, a) = principal_invariants(moments, w);
        assert!((k - rotational_energy(&inertia, w)).abs() < 1e-15);
        let l = angular_momentum_body(&inertia, w);
        assert!((a - (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt()).abs() < 1e-15);
        // 2k = L·ω (Euler's theorem on homogeneous functions)
        assert!((2.0 * k - (l[0] * w[0] + l[1] * w[1] + l[2] * w[2])).abs() < 1e-15);
    }
}
