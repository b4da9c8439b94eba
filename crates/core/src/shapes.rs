//! Closed-form inertia of uniform solids, about the centre of mass, in the solid's own axes.
//!
//! Each function returns the 3×3 inertia of a solid of mass `m` centred on its centre of mass,
//! aligned with x, y, z (the symmetry axis, where there is one, along z). Values from
//! Goldstein, Poole & Safko, *Classical Mechanics* (3rd ed.), and Meriam & Kraige, *Engineering
//! Mechanics: Dynamics*, Appendix B ("Properties of homogeneous solids").
//!
//! [`equivalent_box_half_extents`] inverts the box formula: the box with given principal
//! moments (used to draw a body given only by its mass properties).

use crate::so3::{Mat3, Vec3};

fn diag(a: f64, b: f64, c: f64) -> Mat3 {
    [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]]
}

/// Box with edges `(a, b, c)` along x, y, z: `m/12 · diag(b²+c², a²+c², a²+b²)`.
pub fn box_inertia(m: f64, size: Vec3) -> Mat3 {
    let [a, b, c] = size;
    let f = m / 12.0;
    diag(
        f * (b * b + c * c),
        f * (a * a + c * c),
        f * (a * a + b * b),
    )
}

/// Solid sphere: `2/5 m r²` about every axis.
pub fn sphere_inertia(m: f64, r: f64) -> Mat3 {
    let i = 0.4 * m * r * r;
    diag(i, i, i)
}

/// Thin spherical shell: `2/3 m r²` about every axis.
pub fn spherical_shell_inertia(m: f64, r: f64) -> Mat3 {
    let i = 2.0 / 3.0 * m * r * r;
    diag(i, i, i)
}

/// Solid circular cylinder, axis z: `Ixx = Iyy = m(3r² + h²)/12`, `Izz = m r²/2`.
pub fn cylinder_inertia(m: f64, r: f64, h: f64) -> Mat3 {
    let t = m * (3.0 * r * r + h * h) / 12.0;
    diag(t, t, 0.5 * m * r * r)
}

/// Solid ellipsoid of semi-axes `(a, b, c)`: `m/5 · diag(b²+c², a²+c², a²+b²)`.
pub fn ellipsoid_inertia(m: f64, semi_axes: Vec3) -> Mat3 {
    let [a, b, c] = semi_axes;
    let f = m / 5.0;
    diag(
        f * (b * b + c * c),
        f * (a * a + c * c),
        f * (a * a + b * b),
    )
}

/// Thin rod along z: `Ixx = Iyy = m l²/12`, `Izz = 0` (the degenerate, collinear body).
pub fn rod_inertia(m: f64, length: f64) -> Mat3 {
    let t = m * length * length / 12.0;
    diag(t, t, 0.0)
}

/// Solid right circular cone, axis z, about its centre of mass, which lies `h/4` above the
/// base (base disc at `z = −h/4`, apex at `z = 3h/4`): `Izz = 3/10 m r²`,
/// `Ixx = Iyy = 3/20 m r² + 3/80 m h²`.
pub fn cone_inertia(m: f64, r: f64, h: f64) -> Mat3 {
    let t = 3.0 / 20.0 * m * r * r + 3.0 / 80.0 * m * h * h;
    diag(t, t, 0.3 * m * r * r)
}

/// Half extents (along e1, e2, e3) of the uniform box with the given principal moments and
/// mass: the inverse of [`box_inertia`], `a² = 6 (I2 + I3 − I1)/M` etc. (real by the triangle
/// inequalities; clipped at 0 for round-off).
pub fn equivalent_box_half_extents(moments: Vec3, mass: f64) -> Vec3 {
    let [i1, i2, i3] = moments;
    let k = 6.0 / mass;
    [
        0.5 * (k * (i2 + i3 - i1)).max(0.0).sqrt(),
        0.5 * (k * (i1 + i3 - i2)).max(0.0).sqrt(),
        0.5 * (k * (i1 + i2 - i3)).max(0.0).sqrt(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inertia::{center_of_mass, particle_inertia};

    /// A uniform particle grid of `n³` cells filling the box `[−½, ½]³` scaled by `size`,
    /// kept where `inside` holds: an independent (converging) route to a solid's inertia.
    fn grid_inertia(n: usize, size: Vec3, inside: impl Fn(Vec3) -> bool) -> Mat3 {
        let mut masses = Vec::new();
        let mut pos = Vec::new();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let u = [i, j, k].map(|x| (x as f64 + 0.5) / n as f64 - 0.5);
                    let p = [u[0] * size[0], u[1] * size[1], u[2] * size[2]];
                    if inside(p) {
                        pos.push(p);
                    }
                }
            }
        }
        masses.resize(pos.len(), 1.0 / pos.len() as f64);
        let com = center_of_mass(&masses, &pos);
        let u: Vec<Vec3> = pos
            .iter()
            .map(|p| [p[0] - com[0], p[1] - com[1], p[2] - com[2]])
            .collect();
        particle_inertia(&masses, &u)
    }

    fn rel_close(a: &Mat3, b: &Mat3, rtol: f64) -> bool {
        let scale = (0..3).fold(0.0f64, |s, i| s.max(b[i][i].abs()));
        (0..3).all(|i| (0..3).all(|j| (a[i][j] - b[i][j]).abs() <= rtol * scale))
    }

    #[test]
    fn textbook_values() {
        // Goldstein / Meriam & Kraige: sphere 2/5 m r², shell 2/3 m r², box m(b²+c²)/12
        assert_eq!(sphere_inertia(5.0, 2.0)[0][0], 8.0);
        assert!((spherical_shell_inertia(3.0, 2.0)[1][1] - 8.0).abs() < 1e-15);
        assert_eq!(box_inertia(12.0, [1.0, 2.0, 3.0]), diag(13.0, 10.0, 5.0));
        assert_eq!(cylinder_inertia(12.0, 1.0, 2.0), diag(7.0, 7.0, 6.0));
        assert_eq!(rod_inertia(12.0, 2.0), diag(4.0, 4.0, 0.0));
        assert_eq!(
            ellipsoid_inertia(5.0, [1.0, 2.0, 3.0]),
            diag(13.0, 10.0, 5.0)
        );
        let c = cone_inertia(80.0, 1.0, 2.0);
        assert!((c[0][0] - 24.0).abs() < 1e-13 && (c[2][2] - 24.0).abs() < 1e-13);
    }

    #[test]
    fn solids_match_their_particle_discretisations() {
        let n = 60;
        let bx = [1.0, 1.6, 0.7];
        assert!(rel_close(
            &grid_inertia(n, bx, |_| true),
            &box_inertia(1.0, bx),
            1e-3
        ));
        let ax = [0.8, 1.1, 1.5];
        let ell = grid_inertia(n, ax.map(|x| 2.0 * x), |p| {
            (p[0] / ax[0]).powi(2) + (p[1] / ax[1]).powi(2) + (p[2] / ax[2]).powi(2) <= 1.0
        });
        assert!(rel_close(&ell, &ellipsoid_inertia(1.0, ax), 1e-2));
        let (r, h) = (0.6, 1.4);
        let cyl = grid_inertia(n, [2.0 * r, 2.0 * r, h], |p| {
            p[0] * p[0] + p[1] * p[1] <= r * r
        });
        assert!(rel_close(&cyl, &cylinder_inertia(1.0, r, h), 1e-2));
        // the cone: the grid box is centred on z = 0, the cone's base at −h/2 there
        let cone = grid_inertia(n, [2.0 * r, 2.0 * r, h], |p| {
            let rad = r * (0.5 - p[2] / h); // radius r at z = −h/2, 0 at z = h/2
            p[0] * p[0] + p[1] * p[1] <= rad * rad
        });
        assert!(rel_close(&cone, &cone_inertia(1.0, r, h), 2e-2));
    }

    #[test]
    fn equivalent_box_inverts_the_box_formula() {
        let (m, size) = (3.5, [0.4, 1.3, 2.2]);
        let b = box_inertia(m, size);
        let half = equivalent_box_half_extents([b[0][0], b[1][1], b[2][2]], m);
        for k in 0..3 {
            assert!((2.0 * half[k] - size[k]).abs() < 1e-14);
        }
        // a rod: one edge vanishes (clipped at 0, never NaN)
        assert_eq!(
            equivalent_box_half_extents([1.0, 1.0, 2.0 + 1e-16], 1.0)[2],
            0.0
        );
    }
}
