//! Mass properties: centre of mass, inertia of particles and polyhedra, the parallel-axis
//! shift, the planar inertia, rotation and principal decomposition (`docs/theory.md` §1,
//! eqs (04), (10)–(15); paper eqs (3)–(4)).
//!
//! Nothing here validates input; the bindings and `poinsot.bodies` do. The symmetry class and
//! degeneracy of a body are decided here, once, with one tolerance, for every caller.

use crate::real::Real;
use crate::so3::{cross, Mat3, Vec3};

/// Two principal moments closer than this, relative to the largest, are equal: the body is
/// symmetric (the exact torque-free solution then takes its symmetric form).
pub const SYMMETRY_RTOL: f64 = 1e-12;
/// A smallest moment below this, relative to the largest, is zero: the body is a line.
pub const DEGENERATE_RTOL: f64 = 1e-12;
/// Names of the codes returned by [`symmetry_code`].
pub const SYMMETRY_CLASSES: [&str; 4] = ["asymmetric", "prolate", "oblate", "spherical"];

/// `R = Σ m_i r_i / Σ m_i` (eq. (04)). `masses` and `positions` have the same length (the
/// shorter one bounds the sum).
pub fn center_of_mass(masses: &[f64], positions: &[Vec3]) -> Vec3 {
    let mut total = 0.0;
    let mut out = [0.0; 3];
    for (m, r) in masses.iter().zip(positions) {
        total += m;
        for k in 0..3 {
            out[k] += m * r[k];
        }
    }
    [out[0] / total, out[1] / total, out[2] / total]
}

/// `tr(C) 𝟙 − C`: the inertia operator of the second moment `C = Σ m u uᵀ` (eqs (13)–(15)).
#[inline(always)]
fn inertia_of_second_moment(second: &Mat3) -> Mat3 {
    let tr = second[0][0] + second[1][1] + second[2][2];
    let mut out = [[0.0; 3]; 3];
    for j in 0..3 {
        for k in 0..3 {
            out[j][k] = -second[j][k];
        }
        out[j][j] += tr;
    }
    out
}

/// The inertia operator about the origin of `offsets`, eqs (04), (13)–(15):
/// `A_jk = Σ_i m_i (|u_i|² δ_jk − u_ij u_ik)`, i.e. `A v = Σ m_i u_i × (v × u_i)` (erratum
/// corrected: the notebook prints `v u` for `v × u`).
pub fn particle_inertia(masses: &[f64], offsets: &[Vec3]) -> Mat3 {
    let mut second = [[0.0; 3]; 3];
    for (m, u) in masses.iter().zip(offsets) {
        for j in 0..3 {
            for k in 0..3 {
                second[j][k] += m * u[j] * u[k];
            }
        }
    }
    inertia_of_second_moment(&second)
}

/// The inertia about the point at `d` from the centre of mass (Huygens–Steiner):
/// `A_P = A_G + M (|d|² 𝟙 − d dᵀ)`.
pub fn parallel_axis(inertia_com: &Mat3, mass: f64, d: Vec3) -> Mat3 {
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let mut out = *inertia_com;
    for j in 0..3 {
        for k in 0..3 {
            out[j][k] -= mass * d[j] * d[k];
        }
        out[j][j] += mass * dd;
    }
    out
}

/// The planar inertia tensor `J' = Σ m ρ ρᵀ = ½ tr(J) 𝟙 − J` (paper eqs (3)–(4)): its diagonal
/// holds the planar moments `Σ m x²`, … (in principal axes `A' = (B + C − A)/2`, …), its
/// off-diagonal the products of inertia. Written once: bodies and relative motion call it.
pub fn planar_inertia<T: Real>(inertia: &[[T; 3]; 3]) -> [[T; 3]; 3] {
    let half = T::splat(0.5) * (inertia[0][0] + inertia[1][1] + inertia[2][2]);
    let mut out = [[T::splat(0.0); 3]; 3];
    for j in 0..3 {
        for k in 0..3 {
            out[j][k] = -inertia[j][k];
        }
        out[j][j] = out[j][j] + half;
    }
    out
}

/// The inertia of a body rotated by `r`: `R J Rᵀ` (rotation covariance of the operator).
pub fn rotate_inertia(inertia: &Mat3, r: &Mat3) -> Mat3 {
    let mut rj = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            rj[i][j] = r[i][0] * inertia[0][j] + r[i][1] * inertia[1][j] + r[i][2] * inertia[2][j];
        }
    }
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = rj[i][0] * r[j][0] + rj[i][1] * r[j][1] + rj[i][2] * r[j][2];
        }
    }
    out
}

/// Eigen-decomposition of a symmetric 3×3 matrix by the cyclic Jacobi method (Jacobi 1846;
/// Golub & Van Loan, *Matrix Computations*, 4th ed., alg. 8.5.3, with the rotation and
/// stopping rule of Press et al., *Numerical Recipes*, 3rd ed., §11.1). Returns the
/// eigenvalues, unsorted, and the eigenvectors as the columns of the second matrix.
///
/// Each rotation zeroes one off-diagonal entry; the sweeps converge quadratically, and an
/// entry negligible next to both its diagonal entries is set to zero, so the loop ends (at
/// most 50 sweeps, reached only by non-finite input). Jacobi's method computes small
/// eigenvalues to high relative accuracy (Demmel & Veselić 1992).
pub fn symmetric_eigen(a: &Mat3) -> (Vec3, Mat3) {
    let mut a = *a;
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for sweep in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off == 0.0 || !off.is_finite() {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            let apq = a[p][q];
            let g = 100.0 * apq.abs();
            if sweep > 3 && a[p][p].abs() + g == a[p][p].abs() && a[q][q].abs() + g == a[q][q].abs()
            {
                a[p][q] = 0.0;
                a[q][p] = 0.0;
                continue;
            }
            if apq == 0.0 {
                continue;
            }
            let h = a[q][q] - a[p][p];
            let t = if h.abs() + g == h.abs() {
                apq / h // tan φ ≈ 1/(2θ) when θ² would overflow
            } else {
                let theta = 0.5 * h / apq;
                let t = 1.0 / (theta.abs() + (1.0 + theta * theta).sqrt());
                if theta < 0.0 {
                    -t
                } else {
                    t
                }
            };
            let c = 1.0 / (1.0 + t * t).sqrt();
            let s = t * c;
            let tau = s / (1.0 + c);
            a[p][p] -= t * apq;
            a[q][q] += t * apq;
            a[p][q] = 0.0;
            a[q][p] = 0.0;
            let r = 3 - p - q; // the third index
            let (gr, hr) = (a[r][p], a[r][q]);
            a[r][p] = gr - s * (hr + gr * tau);
            a[r][q] = hr + s * (gr - hr * tau);
            a[p][r] = a[r][p];
            a[q][r] = a[r][q];
            for row in v.iter_mut() {
                let (gv, hv) = (row[p], row[q]);
                row[p] = gv - s * (hv + gv * tau);
                row[q] = hv + s * (gv - hv * tau);
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2]], v)
}

/// Principal moments (ascending) and axes of a symmetric inertia matrix (eqs (10)–(11)).
///
/// Returns `moments` with `I1 ≤ I2 ≤ I3` and `axes` whose columns `e1, e2, e3` are orthonormal
/// and right-handed, `inertia ≈ axes · diag(moments) · axesᵀ`. The symmetric part
/// `(J + Jᵀ)/2` is decomposed, by [`symmetric_eigen`].
///
/// Sign rule (deterministic): `e1` and `e2` are flipped so that their component of largest
/// magnitude is positive (the first such component when several tie within 1e-9), then
/// `e3 = e1 × e2`. For repeated moments the eigenspace basis is whatever the eigensolver
/// returns, normalised by the same rule.
pub fn principal_decomposition(inertia: &Mat3) -> (Vec3, Mat3) {
    let mut sym = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            sym[i][j] = 0.5 * (inertia[i][j] + inertia[j][i]);
        }
    }
    let (values, vectors) = symmetric_eigen(&sym);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| values[i].total_cmp(&values[j]));
    let moments = [values[order[0]], values[order[1]], values[order[2]]];
    let mut cols: [Vec3; 3] = [[0.0; 3]; 3];
    for (c, &k) in cols.iter_mut().zip(&order) {
        *c = [vectors[0][k], vectors[1][k], vectors[2][k]];
    }
    for col in cols.iter_mut().take(2) {
        let biggest = col.iter().fold(0.0f64, |b, x| b.max(x.abs()));
        let mut k = 0;
        while k < 2 && col[k].abs() < biggest - 1e-9 {
            k += 1;
        }
        if col[k] < 0.0 {
            *col = col.map(|x| -x);
        }
    }
    cols[2] = cross(cols[0], cols[1]);
    let mut axes = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            axes[i][j] = cols[j][i];
        }
    }
    (moments, axes)
}

/// The symmetry class of ascending principal moments, as an index into [`SYMMETRY_CLASSES`]:
/// 0 asymmetric, 1 prolate (I1 < I2 = I3), 2 oblate (I1 = I2 < I3), 3 spherical (I1 = I3);
/// moments are equal when they differ by at most `rtol · I3`.
pub fn symmetry_code(moments: Vec3, rtol: f64) -> u8 {
    let tol = rtol * moments[2];
    if moments[2] - moments[0] <= tol {
        3
    } else if moments[1] - moments[0] <= tol {
        2
    } else if moments[2] - moments[1] <= tol {
        1
    } else {
        0
    }
}

/// True when the smallest of the ascending `moments` vanishes (relative `rtol`): all the mass
/// lies on one line and the spin about that line is undefined (singular `A`).
pub fn is_degenerate(moments: Vec3, rtol: f64) -> bool {
    moments[0] <= rtol * moments[2] || moments[2] == 0.0
}

/// What a 3×3 matrix is, as a rigid body's inertia ([`check_inertia`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InertiaCheck {
    /// A rigid body's inertia, with its principal moments (ascending).
    Valid(Vec3),
    /// An entry is not finite.
    NotFinite,
    /// Not symmetric: the largest `|J − Jᵀ|`.
    NotSymmetric(f64),
    /// Not positive semi-definite: its moments (ascending).
    NotPositive(Vec3),
    /// Its moments (ascending) break the triangle inequality `I1 + I2 ≥ I3` (eq. (10)): no
    /// mass distribution has them.
    Triangle(Vec3),
}

impl InertiaCheck {
    /// A small code for the bindings: 0 valid, 1 not finite, 2 not symmetric, 3 not positive,
    /// 4 the triangle inequality.
    pub fn code(&self) -> i64 {
        match self {
            InertiaCheck::Valid(_) => 0,
            InertiaCheck::NotFinite => 1,
            InertiaCheck::NotSymmetric(_) => 2,
            InertiaCheck::NotPositive(_) => 3,
            InertiaCheck::Triangle(_) => 4,
        }
    }
}

/// The one check of an inertia tensor, every front-end's: finite; symmetric to `rtol` of its
/// largest entry; positive semi-definite and with moments that satisfy the triangle inequality
/// `I1 + I2 ≥ I3` (eq. (10): `I3 = Σ m (x² + y²) ≤ Σ m (x² + z²) + Σ m (y² + z²)`), both to
/// `rtol · I3`. Its symmetric part is decomposed ([`principal_decomposition`]).
pub fn check_inertia(j: &Mat3, rtol: f64) -> InertiaCheck {
    if j.iter().flatten().any(|x| !x.is_finite()) {
        return InertiaCheck::NotFinite;
    }
    let scale = j
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()))
        .max(f64::MIN_POSITIVE);
    let mut asym = 0.0f64;
    for r in 0..3 {
        for c in 0..3 {
            asym = asym.max((j[r][c] - j[c][r]).abs());
        }
    }
    if asym > rtol * scale {
        return InertiaCheck::NotSymmetric(asym);
    }
    // decomposed at the scale of its largest entry, by a power of two (exact): entries near
    // ±1.8e308 no longer overflow to moments of −inf
    let pow2 = 2f64.powi(scale.log2().floor() as i32);
    let scaled = j.map(|row| row.map(|x| x / pow2));
    let m = principal_decomposition(&scaled).0.map(|x| x * pow2);
    let tol = rtol * m[2].abs().max(f64::MIN_POSITIVE);
    if m[0] < -tol {
        InertiaCheck::NotPositive(m)
    } else if m[0] + m[1] < m[2] - tol {
        InertiaCheck::Triangle(m)
    } else {
        InertiaCheck::Valid(m)
    }
}

/// Exact volume, centroid and inertia (unit density) of a closed triangulated polyhedron.
///
/// Each outward-wound triangle `(a, b, c)` spans a signed tetrahedron with the origin, of
/// volume `V = a·(b × c)/6`, first moment `V (a+b+c)/4` and second moment
/// `C = V/20 (aaᵀ + bbᵀ + ccᵀ + (a+b+c)(a+b+c)ᵀ)` (the closed form of ∫ x xᵀ over a
/// tetrahedron with one vertex at the origin; Tonon 2004, J. Math. Stat. 1(1)). Summing over
/// faces gives the solid's integrals by the divergence theorem; the inertia about the centroid
/// follows from `tr(C) 𝟙 − C` and the parallel-axis theorem.
///
/// Returns `(volume, centroid, inertia about the centroid)`, or `None` when a face indexes a
/// vertex that does not exist. A consistently inward-wound mesh gives a negative volume; the
/// caller decides.
pub fn polyhedron_mass_properties(
    vertices: &[Vec3],
    faces: &[[usize; 3]],
) -> Option<(f64, Vec3, Mat3)> {
    let mut vol6_total = 0.0;
    let mut first = [0.0; 3];
    let mut second = [[0.0; 3]; 3];
    for face in faces {
        let a = *vertices.get(face[0])?;
        let b = *vertices.get(face[1])?;
        let c = *vertices.get(face[2])?;
        let vol6 = a[0] * (b[1] * c[2] - b[2] * c[1])
            + a[1] * (b[2] * c[0] - b[0] * c[2])
            + a[2] * (b[0] * c[1] - b[1] * c[0]);
        vol6_total += vol6;
        for j in 0..3 {
            let s_j = a[j] + b[j] + c[j];
            first[j] += vol6 * s_j;
            for k in 0..3 {
                let s_k = a[k] + b[k] + c[k];
                second[j][k] += vol6 * (a[j] * a[k] + b[j] * b[k] + c[j] * c[k] + s_j * s_k);
            }
        }
    }
    let volume = vol6_total / 6.0;
    let scale = 24.0 * volume;
    let centroid = [first[0] / scale, first[1] / scale, first[2] / scale];
    for row in second.iter_mut() {
        for x in row.iter_mut() {
            *x /= 120.0;
        }
    }
    let inertia_origin = inertia_of_second_moment(&second);
    // shift from the origin to the centroid (the parallel-axis theorem, run backwards)
    Some((
        volume,
        centroid,
        parallel_axis(&inertia_origin, -volume, centroid),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inertia_check_tells_each_problem() {
        let box_j = [[5.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(
            check_inertia(&box_j, 1e-12),
            InertiaCheck::Valid([1.0, 4.0, 5.0])
        );
        let mut j = box_j;
        j[0][1] = 1e-3;
        assert!(matches!(check_inertia(&j, 1e-12), InertiaCheck::NotSymmetric(a) if a == 1e-3));
        j[0][1] = f64::NAN;
        assert_eq!(check_inertia(&j, 1e-12), InertiaCheck::NotFinite);
        let rod = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]; // a rod: I1 = 0, valid
        assert_eq!(
            check_inertia(&rod, 1e-12),
            InertiaCheck::Valid([0.0, 1.0, 1.0])
        );
        let neg = [[-1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
        assert_eq!(check_inertia(&neg, 1e-12).code(), 3);
        let tri = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0]];
        assert_eq!(
            check_inertia(&tri, 1e-12),
            InertiaCheck::Triangle([1.0, 1.0, 3.0])
        );
        // the same inequality as the particles that make any inertia: a flat plate's
        // I1 + I2 = I3 is on the edge, and accepted
        let plate = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
        assert!(matches!(
            check_inertia(&plate, 1e-12),
            InertiaCheck::Valid(_)
        ));
        // loose enough a tolerance (a fit's) lets a slightly broken triangle through
        let near = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.001]];
        assert_eq!(check_inertia(&near, 1e-12).code(), 4);
        assert_eq!(check_inertia(&near, 1e-3).code(), 0);
    }
    use crate::so3::{exp_so3, matmul};

    fn close(a: &Mat3, b: &Mat3, tol: f64) -> bool {
        (0..3).all(|i| (0..3).all(|j| (a[i][j] - b[i][j]).abs() <= tol))
    }

    fn diag(d: Vec3) -> Mat3 {
        [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]]
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

    /// The unit cube [0, 1]³ as 12 outward-wound triangles.
    fn unit_cube() -> (Vec<Vec3>, Vec<[usize; 3]>) {
        let mut v = Vec::new();
        for i in 0..8 {
            v.push([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
        }
        let quads = [
            [0, 2, 3, 1], // z = 0, normal −z
            [4, 5, 7, 6], // z = 1
            [0, 1, 5, 4], // y = 0
            [2, 6, 7, 3], // y = 1
            [0, 4, 6, 2], // x = 0
            [1, 3, 7, 5], // x = 1
        ];
        let mut f = Vec::new();
        for q in quads {
            f.push([q[0], q[1], q[2]]);
            f.push([q[0], q[2], q[3]]);
        }
        (v, f)
    }

    #[test]
    fn particles_give_the_textbook_values() {
        // A dumbbell of two masses m at ±l along x: I = 2 m l² about y and z, 0 about x.
        let (m, l) = (1.5, 0.7);
        let a = particle_inertia(&[m, m], &[[l, 0.0, 0.0], [-l, 0.0, 0.0]]);
        assert!(close(
            &a,
            &diag([0.0, 2.0 * m * l * l, 2.0 * m * l * l]),
            1e-15
        ));
        // The notebook's three unit masses (docs/theory.md §1): moments 1/3, 1, 4/3.
        let r = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let com = center_of_mass(&[1.0; 3], &r);
        assert!((com[0] - 1.0 / 3.0).abs() < 1e-15 && com[2] == 0.0);
        let u: Vec<Vec3> = r
            .iter()
            .map(|p| [p[0] - com[0], p[1] - com[1], p[2] - com[2]])
            .collect();
        let (moments, _) = principal_decomposition(&particle_inertia(&[1.0; 3], &u));
        for (x, y) in moments.iter().zip([1.0 / 3.0, 1.0, 4.0 / 3.0]) {
            assert!((x - y).abs() < 1e-14);
        }
    }

    #[test]
    fn parallel_axis_matches_the_particles_about_another_point() {
        // Σ m (|r|² 𝟙 − r rᵀ) about a point P equals the centroidal inertia shifted to P.
        let masses = [1.0, 2.5, 0.3, 4.0];
        let r = [
            [0.1, 0.2, -0.3],
            [1.0, -0.5, 0.25],
            [-0.7, 0.9, 1.1],
            [0.4, 0.4, -0.8],
        ];
        let com = center_of_mass(&masses, &r);
        let u: Vec<Vec3> = r
            .iter()
            .map(|p| [p[0] - com[0], p[1] - com[1], p[2] - com[2]])
            .collect();
        let p = [0.3, -1.2, 0.6];
        let about_p: Vec<Vec3> = r
            .iter()
            .map(|x| [x[0] - p[0], x[1] - p[1], x[2] - p[2]])
            .collect();
        let direct = particle_inertia(&masses, &about_p);
        let total: f64 = masses.iter().sum();
        let d = [p[0] - com[0], p[1] - com[1], p[2] - com[2]];
        let shifted = parallel_axis(&particle_inertia(&masses, &u), total, d);
        assert!(close(&direct, &shifted, 1e-13));
    }

    #[test]
    fn planar_inertia_is_the_second_moment() {
        // J' = Σ m ρ ρᵀ (paper eq. (4)), computed directly from the particles.
        let masses = [1.0, 2.0, 0.5];
        let rho = [[0.3, -0.2, 0.9], [-0.4, 0.1, 0.2], [0.5, 0.7, -1.0]];
        let mut second = [[0.0; 3]; 3];
        for (m, u) in masses.iter().zip(&rho) {
            for j in 0..3 {
                for k in 0..3 {
                    second[j][k] += m * u[j] * u[k];
                }
            }
        }
        assert!(close(
            &planar_inertia(&particle_inertia(&masses, &rho)),
            &second,
            1e-15
        ));
        // in principal axes A' = (B + C − A)/2, …
        assert!(close(
            &planar_inertia(&diag([2.0, 3.0, 4.0])),
            &diag([2.5, 1.5, 0.5]),
            0.0
        ));
    }

    #[test]
    fn eigenvalues_are_rotation_invariant_and_axes_reconstruct() {
        let base = [1.25, 2.0, 2.9];
        for k in 0..100 {
            let s = k as f64 * 0.173;
            let q = exp_so3([1.3 * s.sin(), 0.4 - 0.9 * s.cos(), 2.0 * (0.3 * s).sin()]);
            let j = rotate_inertia(&diag(base), &q);
            let (moments, axes) = principal_decomposition(&j);
            for i in 0..3 {
                assert!((moments[i] - base[i]).abs() < 1e-14);
            }
            // right-handed orthonormal, J = E diag(I) Eᵀ
            let eye = diag([1.0; 3]);
            assert!(close(&matmul(&transpose(&axes), &axes), &eye, 1e-14));
            let e1 = [axes[0][0], axes[1][0], axes[2][0]];
            let e2 = [axes[0][1], axes[1][1], axes[2][1]];
            let e3 = cross(e1, e2);
            assert!((0..3).all(|i| (e3[i] - axes[i][2]).abs() < 1e-15));
            let back = matmul(&matmul(&axes, &diag(moments)), &transpose(&axes));
            assert!(close(&back, &j, 1e-14));
            // sign rule: the largest component of e1 and e2 is positive
            for e in [e1, e2] {
                let big = e.iter().cloned().fold(0.0f64, |b, x| b.max(x.abs()));
                let first = e.iter().find(|x| x.abs() >= big - 1e-9).unwrap();
                assert!(*first > 0.0);
            }
        }
    }

    #[test]
    fn eigen_handles_repeated_zero_and_extreme_scales() {
        for scale in [1e-300, 1e-8, 1.0, 1e150, 1e300] {
            let q = exp_so3([0.3, -0.8, 0.5]);
            let j = rotate_inertia(&diag([0.0, scale, scale]), &q);
            let (moments, axes) = principal_decomposition(&j);
            assert!(moments[0].abs() <= 1e-14 * scale);
            assert!((moments[1] / scale - 1.0).abs() < 1e-14);
            assert!((moments[2] / scale - 1.0).abs() < 1e-14);
            // the rod's axis is the rotated x axis, up to sign
            let e1 = [axes[0][0], axes[1][0], axes[2][0]];
            let dot = e1[0] * q[0][0] + e1[1] * q[1][0] + e1[2] * q[2][0];
            assert!((dot.abs() - 1.0).abs() < 1e-14);
        }
        // a sphere: the identity is already diagonal
        let (moments, axes) = principal_decomposition(&diag([2.0; 3]));
        assert_eq!(moments, [2.0; 3]);
        assert!(close(&axes, &diag([1.0; 3]), 0.0));
    }

    #[test]
    fn symmetry_and_degeneracy() {
        assert_eq!(symmetry_code([1.0, 1.0, 1.0], SYMMETRY_RTOL), 3);
        assert_eq!(symmetry_code([1.0, 1.0, 2.0], SYMMETRY_RTOL), 2);
        assert_eq!(symmetry_code([1.0, 2.0, 2.0], SYMMETRY_RTOL), 1);
        assert_eq!(symmetry_code([1.0, 2.0, 3.0], SYMMETRY_RTOL), 0);
        assert_eq!(symmetry_code([1.0, 2.0, 2.0 + 1e-13], SYMMETRY_RTOL), 1);
        assert!(is_degenerate([0.0, 1.0, 1.0], DEGENERATE_RTOL));
        assert!(is_degenerate([0.0, 0.0, 0.0], DEGENERATE_RTOL));
        assert!(!is_degenerate([1e-6, 1.0, 1.0], DEGENERATE_RTOL));
    }

    #[test]
    fn unit_cube_polyhedron_is_the_box_formula() {
        // a uniform cube of edge 1 and mass 1: m(b² + c²)/12 = 1/6 about every axis
        let (v, f) = unit_cube();
        let (volume, centroid, inertia) = polyhedron_mass_properties(&v, &f).unwrap();
        assert!((volume - 1.0).abs() < 1e-15);
        assert!(centroid.iter().all(|c| (c - 0.5).abs() < 1e-15));
        assert!(close(&inertia, &diag([1.0 / 6.0; 3]), 1e-15));
        // a box (2, 3, 5) shifted off the origin: m/12 diag(b²+c², a²+c², a²+b²), m = 30
        let (a, b, c) = (2.0, 3.0, 5.0);
        let moved: Vec<Vec3> = v
            .iter()
            .map(|p| [a * p[0] + 1.0, b * p[1] - 2.0, c * p[2] + 0.5])
            .collect();
        let (volume, centroid, inertia) = polyhedron_mass_properties(&moved, &f).unwrap();
        let m = a * b * c;
        assert!((volume - m).abs() < 1e-13);
        assert!((centroid[0] - 2.0).abs() < 1e-14 && (centroid[1] + 0.5).abs() < 1e-14);
        let expect = diag([
            m * (b * b + c * c) / 12.0,
            m * (a * a + c * c) / 12.0,
            m * (a * a + b * b) / 12.0,
        ]);
        assert!(close(&inertia, &expect, 1e-12));
        // an inward-wound mesh gives the negative volume; an out-of-range face gives None
        let inward: Vec<[usize; 3]> = f.iter().map(|t| [t[0], t[2], t[1]]).collect();
        assert!(polyhedron_mass_properties(&v, &inward).unwrap().0 < 0.0);
        assert!(polyhedron_mass_properties(&v, &[[0, 1, 8]]).is_none());
    }

    /// Entries near the largest double are decomposed without overflow: the moments are those
    /// of the same tensor at a small scale times that scale (a power of two: exact).
    #[test]
    fn huge_entries_give_finite_moments() {
        let neg = [
            [-1.7e308, 0.0, 0.0],
            [0.0, 0.01638, 0.0],
            [0.0, 0.0, 0.01748],
        ];
        let InertiaCheck::NotPositive(m) = check_inertia(&neg, 1e-12) else {
            panic!("not positive")
        };
        assert_eq!(m[0], -1.7e308); // the small ones keep 12 digits (subnormal when scaled)
        assert!((m[1] / 0.01638 - 1.0).abs() < 1e-12 && (m[2] / 0.01748 - 1.0).abs() < 1e-12);
        let big = [
            [1.7e308, 0.0, 0.0],
            [0.0, 1.6e308, 0.0],
            [0.0, 0.0, 0.3e308],
        ];
        let small = big.map(|r| r.map(|x| x / 2f64.powi(1000)));
        let (InertiaCheck::Valid(m), InertiaCheck::Valid(s)) =
            (check_inertia(&big, 1e-12), check_inertia(&small, 1e-12))
        else {
            panic!("both valid")
        };
        assert_eq!(m, s.map(|x| x * 2f64.powi(1000)));
    }
}
