//! Small dense linear systems solved in place, for the equations of motion of constrained
//! systems.
//!
//! A constrained system solves, at every evaluation, the index-1 (KKT) system
//! `[[M, −Gᵀ], [G, 0]] [q̈; λ] = [f; r]` of a few to a few tens of unknowns (`docs/theory.md`,
//! [L] eq. (6.60)). At such sizes a library call costs more than the arithmetic, so these are
//! the textbook algorithms on the caller's storage, allocating nothing. Matrices are row-major
//! slices with a leading dimension `ld` (the row length of the storage).

/// Solve `A[:n, :n] x = A[:n, n]` in place by Gaussian elimination with partial pivoting
/// (Golub & Van Loan, *Matrix Computations*, alg. 3.4.1): `x` overwrites column `n` and the
/// matrix is destroyed. `a` is row-major with `ld ≥ n + 1` numbers per row.
///
/// Returns false when a pivot is zero or not finite (a singular or non-finite system; `x` is
/// then meaningless).
pub fn solve_augmented(a: &mut [f64], n: usize, ld: usize) -> bool {
    solve_augmented_many(a, n, ld, 1)
}

/// Solve `A[:n, :n] X = A[:n, n..n + k]` for `k` right-hand sides at once, in place, as
/// [`solve_augmented`] does for one (the same operations on each column): `X` overwrites
/// columns `n..n + k`. `a` is row-major with `ld ≥ n + k` numbers per row.
pub fn solve_augmented_many(a: &mut [f64], n: usize, ld: usize, k: usize) -> bool {
    debug_assert!(ld >= n + k && a.len() >= n * ld);
    let end = n + k;
    for c in 0..n {
        let mut p = c;
        let mut big = a[c * ld + c].abs();
        for i in c + 1..n {
            let v = a[i * ld + c].abs();
            if v > big {
                big = v;
                p = i;
            }
        }
        if !(big > 0.0 && big < 1e308) {
            return false;
        }
        if p != c {
            for j in c..end {
                a.swap(c * ld + j, p * ld + j);
            }
        }
        let inv = 1.0 / a[c * ld + c];
        for i in c + 1..n {
            let factor = a[i * ld + c] * inv;
            if factor != 0.0 {
                for j in c + 1..end {
                    a[i * ld + j] -= factor * a[c * ld + j];
                }
            }
        }
    }
    for col in n..end {
        for r in (0..n).rev() {
            let mut s = a[r * ld + col];
            for j in r + 1..n {
                s -= a[r * ld + j] * a[j * ld + col];
            }
            a[r * ld + col] = s / a[r * ld + r];
        }
    }
    true
}

/// Solve `A[:n, :n] x = A[:n, n]` for a symmetric positive definite matrix (a mass matrix) in
/// place by Cholesky's factorisation `A = L Lᵀ` (Golub & Van Loan, alg. 4.2.1), half the work
/// of [`solve_augmented`]: `x` overwrites column `n`, `L` the lower triangle; only the lower
/// triangle is read.
///
/// Returns false when the matrix is not (numerically) positive definite or not finite; `a` is
/// then partly overwritten.
pub fn solve_spd_augmented(a: &mut [f64], n: usize, ld: usize) -> bool {
    debug_assert!(ld > n && a.len() >= n * ld);
    for j in 0..n {
        let mut d = a[j * ld + j];
        for k in 0..j {
            d -= a[j * ld + k] * a[j * ld + k];
        }
        if !(d > 0.0 && d < 1e308) {
            return false;
        }
        let d = d.sqrt();
        a[j * ld + j] = d;
        let inv = 1.0 / d;
        for i in j + 1..n {
            let mut s = a[i * ld + j];
            for k in 0..j {
                s -= a[i * ld + k] * a[j * ld + k];
            }
            a[i * ld + j] = s * inv;
        }
    }
    for i in 0..n {
        let mut s = a[i * ld + n];
        for k in 0..i {
            s -= a[i * ld + k] * a[k * ld + n];
        }
        a[i * ld + n] = s / a[i * ld + i];
    }
    for i in (0..n).rev() {
        let mut s = a[i * ld + n];
        for k in i + 1..n {
            s -= a[k * ld + i] * a[k * ld + n];
        }
        a[i * ld + n] = s / a[i * ld + i];
    }
    true
}

/// The minimum-norm solution `x = Jᵀ (J Jᵀ)⁻¹ r` of the underdetermined system `J x = r`,
/// `J` (rows × cols, row-major, `rows ≤ cols`, full row rank): the correction of least length
/// that a Gauss–Newton step onto constraints takes (equal to `lstsq`'s for such J).
/// `work` holds at least `rows · (rows + 1)` numbers. Returns false when `J Jᵀ` is singular.
pub fn min_norm_solve(
    j: &[f64],
    rows: usize,
    cols: usize,
    r: &[f64],
    x: &mut [f64],
    work: &mut [f64],
) -> bool {
    let ld = rows + 1;
    for a in 0..rows {
        for b in 0..=a {
            let mut s = 0.0;
            for k in 0..cols {
                s += j[a * cols + k] * j[b * cols + k];
            }
            work[a * ld + b] = s;
            work[b * ld + a] = s;
        }
        work[a * ld + rows] = r[a];
    }
    let ok = solve_spd_augmented(work, rows, ld) || {
        // J Jᵀ not numerically positive definite: pivoted elimination decides
        for a in 0..rows {
            for b in 0..=a {
                let mut s = 0.0;
                for k in 0..cols {
                    s += j[a * cols + k] * j[b * cols + k];
                }
                work[a * ld + b] = s;
                work[b * ld + a] = s;
            }
            work[a * ld + rows] = r[a];
        }
        solve_augmented(work, rows, ld)
    };
    if !ok {
        return false;
    }
    for k in 0..cols {
        let mut s = 0.0;
        for a in 0..rows {
            s += j[a * cols + k] * work[a * ld + rows];
        }
        x[k] = s;
    }
    true
}

/// The least-squares solution of least norm of `A x = r`, `A` (rows × cols, row-major, of
/// full rank), as NumPy's `lstsq` gives it for such `A`: [`min_norm_solve`] when
/// `rows ≤ cols`, else the normal equations `AᵀA x = Aᵀ r` (Cholesky). `work` holds at least
/// `k (k + 1)` numbers, `k = max(rows, cols)`. Returns false when the system is singular.
pub fn least_squares_solve(
    a: &[f64],
    rows: usize,
    cols: usize,
    r: &[f64],
    x: &mut [f64],
    work: &mut [f64],
) -> bool {
    if rows <= cols {
        return min_norm_solve(a, rows, cols, r, x, work);
    }
    let ld = cols + 1;
    for i in 0..cols {
        for j in 0..=i {
            let s: f64 = (0..rows).map(|k| a[k * cols + i] * a[k * cols + j]).sum();
            work[i * ld + j] = s;
            work[j * ld + i] = s;
        }
        work[i * ld + cols] = (0..rows).map(|k| a[k * cols + i] * r[k]).sum();
    }
    if !solve_spd_augmented(work, cols, ld) {
        return false;
    }
    for i in 0..cols {
        x[i] = work[i * ld + cols];
    }
    true
}

/// `exp(A)` of a small square matrix by scaling and squaring of its Taylor series: `A/2^s`
/// with `‖A/2^s‖₁ ≤ 1/2`, the series summed until its terms fall below the unit round-off
/// of the sum, then squared `s` times (Moler & Van Loan, *SIAM Review* 45 (2003), method 3):
/// the linear flows of the exact-flow splittings' derivatives at a fixed point.
pub fn expm<const N: usize>(a: [[f64; N]; N]) -> [[f64; N]; N] {
    let norm = (0..N)
        .map(|c| (0..N).map(|r| a[r][c].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut s = 0;
    while norm / f64::powi(2.0, s) > 0.5 && s < 1100 {
        s += 1;
    }
    let scale = f64::powi(2.0, -s);
    let x = a.map(|row| row.map(|v| v * scale));
    let mul = |p: &[[f64; N]; N], q: &[[f64; N]; N]| {
        let mut out = [[0.0; N]; N];
        for i in 0..N {
            for k in 0..N {
                for j in 0..N {
                    out[i][j] += p[i][k] * q[k][j];
                }
            }
        }
        out
    };
    let mut sum = [[0.0; N]; N];
    let mut term = [[0.0; N]; N];
    for i in 0..N {
        sum[i][i] = 1.0;
        term[i][i] = 1.0;
    }
    for k in 1..=30 {
        term = mul(&term, &x).map(|row| row.map(|v| v / k as f64));
        let size: f64 = term.iter().flatten().map(|v| v.abs()).fold(0.0, f64::max);
        for i in 0..N {
            for j in 0..N {
                sum[i][j] += term[i][j];
            }
        }
        if size <= f64::EPSILON * 1e-2 {
            break;
        }
    }
    for _ in 0..s {
        sum = mul(&sum, &sum);
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `expm` against two closed forms: a rotation generator (Rodrigues, [`crate::so3::exp_so3`])
    /// and a Jordan block with a hyperbolic pair, `exp([[a, 1], [0, a]]) = e^a [[1, 1], [0, 1]]`
    /// and `exp([[0, σ], [σ, 0]]) = [[cosh σ, sinh σ], [sinh σ, cosh σ]]`, at sizes that take
    /// several squarings.
    #[test]
    fn expm_equals_closed_forms() {
        let w = [0.7, -2.1, 1.4];
        let g = [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]];
        let (a, b) = (expm(g), crate::so3::exp_so3(w));
        for r in 0..3 {
            for c in 0..3 {
                assert!((a[r][c] - b[r][c]).abs() < 1e-14, "{r}{c}");
            }
        }
        for x in [0.3, 4.0, -7.5] {
            let j = expm([[x, 1.0], [0.0, x]]);
            let e = f64::exp(x);
            for (got, want) in [(j[0][0], e), (j[0][1], e), (j[1][0], 0.0), (j[1][1], e)] {
                assert!((got - want).abs() <= 1e-14 * e, "{x}: {got} against {want}");
            }
            let h = expm([[0.0, x], [x, 0.0]]);
            let (ch, sh) = (x.cosh(), x.sinh());
            assert!((h[0][0] - ch).abs() <= 1e-14 * ch && (h[0][1] - sh).abs() <= 1e-14 * ch);
        }
    }

    /// A pseudo-random number in [-1, 1) (a fixed linear congruential sequence).
    fn rng(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*state >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
    }

    #[test]
    fn gaussian_elimination_solves_with_pivoting() {
        // 2y = 4, x + y = 3 needs a row swap
        let mut a = [0.0, 2.0, 4.0, 1.0, 1.0, 3.0];
        assert!(solve_augmented(&mut a, 2, 3));
        assert_eq!([a[2], a[5]], [1.0, 2.0]);
        // random systems: the residual of the solution is at round-off
        let mut s = 7u64;
        for n in 1..12 {
            let m: Vec<f64> = (0..n * n).map(|_| rng(&mut s)).collect();
            let b: Vec<f64> = (0..n).map(|_| rng(&mut s)).collect();
            let ld = n + 1;
            let mut a = vec![0.0; n * ld];
            for i in 0..n {
                a[i * ld..i * ld + n].copy_from_slice(&m[i * n..(i + 1) * n]);
                a[i * ld + n] = b[i];
            }
            assert!(solve_augmented(&mut a, n, ld));
            for i in 0..n {
                let r: f64 = (0..n).map(|j| m[i * n + j] * a[j * ld + n]).sum::<f64>() - b[i];
                assert!(r.abs() < 1e-10, "n = {n}: residual {r}");
            }
        }
    }

    #[test]
    fn singular_and_non_finite_systems_are_refused() {
        let mut a = [1.0, 2.0, 3.0, 2.0, 4.0, 6.0];
        assert!(!solve_augmented(&mut a, 2, 3));
        let mut a = [f64::NAN, 0.0, 1.0, 0.0, 1.0, 1.0];
        assert!(!solve_augmented(&mut a, 2, 3));
        let mut a = [1.0, 2.0, 1.0, 2.0, 1.0, 1.0]; // indefinite
        assert!(!solve_spd_augmented(&mut a, 2, 3));
    }

    #[test]
    fn cholesky_equals_elimination_on_spd_matrices() {
        // [[4, 2], [2, 3]] x = [2, 5] → x = (−0.5, 2)
        let mut a = [4.0, 2.0, 2.0, 2.0, 3.0, 5.0];
        assert!(solve_spd_augmented(&mut a, 2, 3));
        assert!((a[2] + 0.5).abs() < 1e-15 && (a[5] - 2.0).abs() < 1e-15);
        let mut s = 11u64;
        for n in 1..10 {
            let b: Vec<f64> = (0..n * n).map(|_| rng(&mut s)).collect();
            let ld = n + 1;
            let mut spd = vec![0.0; n * ld];
            let rhs: Vec<f64> = (0..n).map(|_| rng(&mut s)).collect();
            for i in 0..n {
                for j in 0..n {
                    // Bᵀ B + n I is symmetric positive definite
                    let mut v: f64 = (0..n).map(|k| b[k * n + i] * b[k * n + j]).sum();
                    if i == j {
                        v += n as f64;
                    }
                    spd[i * ld + j] = v;
                }
                spd[i * ld + n] = rhs[i];
            }
            let mut lu = spd.clone();
            assert!(solve_spd_augmented(&mut spd, n, ld));
            assert!(solve_augmented(&mut lu, n, ld));
            for i in 0..n {
                assert!((spd[i * ld + n] - lu[i * ld + n]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn the_minimum_norm_solution_solves_and_is_orthogonal_to_the_null_space() {
        // x + y = 2: the least-norm solution is (1, 1)
        let mut x = [0.0; 2];
        let mut w = [0.0; 2];
        assert!(min_norm_solve(&[1.0, 1.0], 1, 2, &[2.0], &mut x, &mut w));
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
        let mut s = 3u64;
        for (rows, cols) in [(1, 3), (2, 5), (3, 3), (4, 9)] {
            let j: Vec<f64> = (0..rows * cols).map(|_| rng(&mut s)).collect();
            let r: Vec<f64> = (0..rows).map(|_| rng(&mut s)).collect();
            let mut x = vec![0.0; cols];
            let mut w = vec![0.0; rows * (rows + 1)];
            assert!(min_norm_solve(&j, rows, cols, &r, &mut x, &mut w));
            for a in 0..rows {
                let v: f64 = (0..cols).map(|k| j[a * cols + k] * x[k]).sum();
                assert!((v - r[a]).abs() < 1e-10);
            }
            // x lies in the row space: x = Jᵀ y, so it is orthogonal to any null vector z
            // (J z = 0); a null vector from the projection of a random vector
            let v: Vec<f64> = (0..cols).map(|_| rng(&mut s)).collect();
            let jv: Vec<f64> = (0..rows)
                .map(|a| (0..cols).map(|k| j[a * cols + k] * v[k]).sum())
                .collect();
            let mut p = vec![0.0; cols];
            assert!(min_norm_solve(&j, rows, cols, &jv, &mut p, &mut w));
            let z: Vec<f64> = (0..cols).map(|k| v[k] - p[k]).collect();
            let dot: f64 = (0..cols).map(|k| x[k] * z[k]).sum();
            assert!(dot.abs() < 1e-10, "{dot}");
        }
    }

    #[test]
    fn many_right_hand_sides_equal_one_at_a_time_bit_for_bit() {
        let mut s = 3u64;
        for n in 1..9 {
            let k = 5;
            let m: Vec<f64> = (0..n * n).map(|_| rng(&mut s)).collect();
            let b: Vec<f64> = (0..n * k).map(|_| rng(&mut s)).collect();
            let ld = n + k;
            let mut a = vec![0.0; n * ld];
            for i in 0..n {
                a[i * ld..i * ld + n].copy_from_slice(&m[i * n..(i + 1) * n]);
                a[i * ld + n..i * ld + n + k].copy_from_slice(&b[i * k..(i + 1) * k]);
            }
            assert!(solve_augmented_many(&mut a, n, ld, k));
            for c in 0..k {
                let mut one = vec![0.0; n * (n + 1)];
                for i in 0..n {
                    one[i * (n + 1)..i * (n + 1) + n].copy_from_slice(&m[i * n..(i + 1) * n]);
                    one[i * (n + 1) + n] = b[i * k + c];
                }
                assert!(solve_augmented(&mut one, n, n + 1));
                for i in 0..n {
                    assert_eq!(one[i * (n + 1) + n].to_bits(), a[i * ld + n + c].to_bits());
                }
            }
        }
    }

    #[test]
    fn least_squares_satisfies_the_normal_equations_and_takes_the_least_norm() {
        let mut s = 5u64;
        for (rows, cols) in [(4, 2), (3, 3), (2, 5), (6, 1)] {
            let a: Vec<f64> = (0..rows * cols).map(|_| rng(&mut s)).collect();
            let r: Vec<f64> = (0..rows).map(|_| rng(&mut s)).collect();
            let mut x = vec![0.0; cols];
            let k = rows.max(cols);
            let mut work = vec![0.0; k * (k + 1)];
            assert!(least_squares_solve(&a, rows, cols, &r, &mut x, &mut work));
            let res: Vec<f64> = (0..rows)
                .map(|i| (0..cols).map(|j| a[i * cols + j] * x[j]).sum::<f64>() - r[i])
                .collect();
            if rows <= cols {
                // consistent: A x = r, and x in the row space of A (least norm)
                assert!(
                    res.iter().all(|e| e.abs() < 1e-12),
                    "{rows}×{cols}: {res:?}"
                );
            }
            // Aᵀ (A x − r) = 0 in both cases
            for j in 0..cols {
                let g: f64 = (0..rows).map(|i| a[i * cols + j] * res[i]).sum();
                assert!(g.abs() < 1e-12, "{rows}×{cols}: gradient {g}");
            }
        }
    }
}
