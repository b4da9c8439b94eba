//! Tests of the elliptic functions and integrals ([`super`]): Carlson's published values,
//! complete integrals by the AGM against Carlson's forms and tables, the Legendre relation,
//! Jacobi's identities and limits, the near-one branch against the AGM, the first and third
//! kinds, and the lanes' forms against the single ones.

use super::*;

/// `R_J` for `p ≥ max(x, y, z)` with the lanes' `atan` equals the scalar `R_J` (libm's
/// `atan` in `R_C`) to round-off, and lanes compute what `f64` computes, bit for bit.
#[test]
fn carlson_rj_above_equals_carlson_rj() {
    use crate::real::Wide;
    let mut args = Vec::new();
    for &x in &[0.0, 1e-300, 1e-12, 0.3, 0.99, 1.0] {
        for &y in &[1e-9, 0.2, 0.7, 1.0] {
            for &p in &[1.0, 1.0 + 1e-12, 1.3, 4.0, 1e3, 1e12] {
                args.push((x, y, 1.0, p));
            }
        }
    }
    for &(x, y, z, p) in &args {
        let (a, b) = (carlson_rj_above(x, y, z, p), carlson_rj(x, y, z, p));
        assert!((a - b).abs() <= 2e-15 * b.abs(), "{x} {y} {z} {p}: {a} {b}");
    }
    for chunk in args.chunks(8) {
        let g = |k: usize| {
            let mut v = [0.0; 8];
            for (l, a) in chunk.iter().enumerate() {
                v[l] = [a.0, a.1, a.2, a.3][k];
            }
            Wide(v)
        };
        let lanes = carlson_rj_above(g(0), g(1), g(2), g(3));
        for (l, &(x, y, z, p)) in chunk.iter().enumerate() {
            assert_eq!(lanes.0[l].to_bits(), carlson_rj_above(x, y, z, p).to_bits());
        }
    }
}

/// `R_C(1, 1 + e)` by its series below `RC_SERIES` equals `atan(√e)/√e` (libm's, in
/// [`carlson_rc1p`]) to round-off on both sides of the switch, and is 1 at 0.
#[test]
fn rc1p_series_equals_the_arctangent() {
    assert_eq!(rc1p_above(0.0), 1.0);
    let mut e = 1e-30;
    while e < 1e-1 {
        for x in [e, RC_SERIES * (1.0 - 1e-9), RC_SERIES] {
            let (a, b) = (rc1p_above(x), carlson_rc1p(x));
            assert!((a - b).abs() <= 2.5e-16 * b, "{x}: {a} {b}");
        }
        e *= 1.7;
    }
}

/// `Π(u)` from the reduction ω(t) makes, `u + X(v) + 2p (Π(n|m) − K)`
/// (`third_kind_excess_reduced`), equals `third_kind_u` to round-off, across periods and
/// toward the separatrix.
#[test]
fn third_kind_from_the_reduction_equals_third_kind_u() {
    for &m1 in &[0.9, 0.5, 0.1, 1e-3, 1e-6, 1e-12] {
        let m = 1.0 - m1;
        let k = ellipk_m1(m1);
        let agm = Agm::new(m1);
        for &n in &[-0.1, -0.6, -3.0] {
            let excess = ellippi_excess_complete(n, m, m1, k);
            for i in -40..=40 {
                let u = 0.173 * k * i as f64;
                let (sn, cn, dn, p, _) = jacobi_reduced_with(u, m, m1, k, &agm);
                let par = parity(p);
                let a = u + third_kind_excess_reduced(n, par * sn, par * cn, dn, p, excess);
                let b = third_kind_u(n, u, m, m1, k);
                assert!(
                    (a - b).abs() <= 4e-15 * (1.0 + b.abs()),
                    "m1 {m1} n {n} u {u}: {a} {b}"
                );
            }
        }
    }
}

/// K(m) by the AGM equals Carlson's `R_F(0, m1, 1)` (DLMF 19.25.1) to round-off (a few ulps of
/// the duplication algorithm), from
/// m1 = 1 down to the separatrix.
#[test]
fn complete_integral_by_the_agm_equals_carlsons_form() {
    let mut m1 = 1.0f64;
    while m1 > 1e-300 {
        let (a, b) = (ellipk_m1(m1), carlson_rf(0.0, m1, 1.0));
        assert!((a - b).abs() <= 1.5e-15 * b, "m1 {m1}: {a} {b}");
        m1 *= 0.37;
    }
    assert_eq!(ellipk_m1(1.0), PI / 2.0);
}

/// Bulirsch's descending Landen transformation and the AGM with inverse sines (A&S 16.4)
/// agree to round-off on |u| ≤ K/2 across m; the identities sn² + cn² = 1 and
/// dn² + m sn² = 1 hold.
#[test]
fn bulirsch_equals_the_agm_on_half_quarter_periods() {
    for &m1 in &[0.999, 0.7, 0.5, 0.3, 0.1, 1e-2, 1e-3, 1e-4, 2e-5] {
        let m = 1.0 - m1;
        let k = ellipk_m1(m1);
        let tiny = [-1e-300, 5e-324, 1e-12, -3e-9, 2e-9, 1e-7];
        for u in (-20..=20).map(|i| 0.5 * k * i as f64 / 20.0).chain(tiny) {
            let (s1, c1, d1) = jacobi_bulirsch(u, m1);
            let (s2, c2, d2, _) = jacobi_agm(u, m, m1);
            for (a, b) in [(s1, s2), (c1, c2), (d1, d2)] {
                assert!(
                    (a - b).abs() <= 4e-16 * (1.0 + b.abs()),
                    "m1 {m1}, u {u}: {a} {b}"
                );
            }
            assert!((s1 * s1 + c1 * c1 - 1.0).abs() < 1e-15);
            assert!((d1 * d1 + m * s1 * s1 - 1.0).abs() < 1e-15);
        }
    }
}
use std::f64::consts::FRAC_PI_2;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

#[test]
fn carlson_test_values() {
    // Carlson (1995) §3 test values
    assert!(rel(carlson_rf(1.0, 2.0, 0.0), 1.311_028_777_146_059_9) < 1e-15);
    assert!(rel(carlson_rf(0.5, 1.0, 0.0), 1.854_074_677_301_371_9) < 1e-15);
    assert!(rel(carlson_rj(0.0, 1.0, 2.0, 3.0), 0.776_886_237_785_823_3) < 1e-14);
    assert!(rel(carlson_rj(2.0, 3.0, 4.0, 5.0), 0.142_975_796_671_567_5) < 1e-14);
    // R_F is homogeneous of degree −1/2 and symmetric
    let (x, y, z) = (0.3, 1.7, 2.9);
    let f = carlson_rf(x, y, z);
    assert!(rel(carlson_rf(z, x, y), f) < 1e-15);
    assert!(rel(carlson_rf(4.0 * x, 4.0 * y, 4.0 * z), 0.5 * f) < 1e-15);
    // R_J(x, y, z, z) = R_D(x, y, z); R_J(x, x, x, x) = x^(-3/2)
    assert!(rel(carlson_rj(2.0, 2.0, 2.0, 2.0), 2f64.powf(-1.5)) < 1e-15);
    assert_eq!(carlson_rc1p(0.0), 1.0);
    assert!(rel(carlson_rc1p(1.0), std::f64::consts::FRAC_PI_4) < 1e-15);
}

#[test]
fn complete_integral_table_values() {
    assert!(rel(ellipk_m1(1.0), FRAC_PI_2) < 3e-16);
    assert!(rel(ellipk_m1(0.5), 1.854_074_677_301_371_9) < 1e-15);
    assert!(ellipk_m1(0.0).is_infinite());
    // K(m) ~ ln(4/√m1) as m → 1 (A&S 17.3.26): relative error O(m1 ln m1)
    let m1: f64 = 1e-12;
    let asym = (4.0 / m1.sqrt()).ln();
    assert!(rel(ellipk_m1(m1), asym) < 1e-10);
}

#[test]
fn legendre_relation() {
    // E K' + E' K − K K' = π/2 with E(m) = R_F(0, m1, 1) − (m/3) R_D(0, m1, 1),
    // R_D(x, y, z) = R_J(x, y, z, z)
    let e_of = |m: f64, m1: f64| carlson_rf(0.0, m1, 1.0) - m / 3.0 * carlson_rj(0.0, m1, 1.0, 1.0);
    for &m in &[0.1, 0.3, 0.5, 0.77, 0.95] {
        let m1 = 1.0 - m;
        let (k, kp) = (ellipk_m1(m1), ellipk_m1(m));
        let (e, ep) = (e_of(m, m1), e_of(m1, m));
        assert!(rel(e * kp + ep * k - k * kp, FRAC_PI_2) < 1e-14, "m = {m}");
    }
}

#[test]
fn jacobi_identities_and_limits() {
    for &m1 in &[1.0, 0.7, 0.2, 1e-3, 1e-6, 1e-12, 1e-20] {
        let m = 1.0 - m1;
        let k = ellipk_m1(m1);
        for j in -40..=40 {
            let u = 0.173 * j as f64;
            let (sn, cn, dn, _, _) = jacobi_reduced(u, m, m1, k);
            assert!((sn * sn + cn * cn - 1.0).abs() < 4e-15, "m1 {m1} u {u}");
            assert!((dn * dn + m * sn * sn - 1.0).abs() < 4e-15, "m1 {m1} u {u}");
            let (sa, ca, da, am) = jacobi_agm(u, m, m1);
            assert!((sa - am.sin()).abs() < 1e-15);
            assert!((sa - sn).abs() < 1e-12 && (ca - cn).abs() < 1e-12 && (da - dn).abs() < 1e-12);
        }
        // sn K = 1, cn K = 0, dn K = √m1
        let (sn, cn, dn, _, _) = jacobi_reduced(k, m, m1, k);
        assert!((sn - 1.0).abs() < 1e-15 && cn.abs() < 1e-15);
        assert!(rel(dn, m1.sqrt()) < 1e-14);
    }
    // m = 0: circular; m = 1: hyperbolic
    let (sn, cn, dn, am) = jacobi_agm(0.7, 0.0, 1.0);
    assert_eq!((sn, cn, dn, am), (0.7f64.sin(), 0.7f64.cos(), 1.0, 0.7));
    let (sn, cn, dn, _) = jacobi_agm(0.7, 1.0, 0.0);
    assert_eq!(
        (sn, cn, dn),
        (0.7f64.tanh(), 1.0 / 0.7f64.cosh(), 1.0 / 0.7f64.cosh())
    );
}

#[test]
fn near_one_branch_agrees_with_the_agm_where_both_apply() {
    let m1 = 0.9e-5;
    let m = 1.0 - m1;
    let k = ellipk_m1(m1);
    for j in 0..50 {
        let u = 0.5 * k * j as f64 / 50.0;
        let (a, b, c) = jacobi_near_one(u, m, m1);
        let (sa, ca, da, _) = jacobi_agm(u, m, m1);
        assert!((a - sa).abs() < 3e-14 && rel(b, ca) < 3e-14 && rel(c, da) < 3e-14);
    }
}

#[test]
fn first_and_third_kinds() {
    // F inverts am: F(am u) = u; first_kind_from_sn_cn inverts (sn, cn) on (−2K, 2K]
    for &m1 in &[0.9, 0.4, 1e-4, 1e-9] {
        let m = 1.0 - m1;
        let k = ellipk_m1(m1);
        for j in -9..=9 {
            let u = 0.2 * k * j as f64;
            let (sn, cn, _, am) = jacobi_agm(u, m, m1);
            // dF/dφ = 1/dn ≤ 1/√m1 amplifies the amplitude's round-off
            assert!((ellipf(am, m, m1) - u).abs() < 1e-14 * (1.0 + u.abs()) / m1.sqrt());
            assert!((first_kind_from_sn_cn(sn, cn, m, m1) - u).abs() < 1e-12 * k);
        }
        // Π(0; φ) = F(φ); Π(n; π/2) = Π(n)
        assert!(rel(ellippi(0.0, 1.1, m, m1), ellipf(1.1, m, m1)) < 1e-15);
        // (the double nearest π/2 is 6e-17 short of it: an error 6e-17/√m1)
        let full = ellippi(-0.7, FRAC_PI_2, m, m1);
        assert!(rel(full, ellippi_complete(-0.7, m, m1)) < 1e-15 + 1e-16 / m1.sqrt());
        // ∫ du/(1 − n sn²) along u equals Π(n; am u)
        for j in -7..=7 {
            let u = 0.37 * k * j as f64;
            let (_, _, _, am) = jacobi_agm(u, m, m1);
            let a = third_kind_u(-0.6, u, m, m1, k);
            assert!((a - ellippi(-0.6, am, m, m1)).abs() < 1e-12 * (1.0 + a.abs()));
        }
    }
    // Π(n|0) = π/(2√(1 − n)) (DLMF 19.6.3)
    assert!(rel(ellippi_complete(-3.0, 0.0, 1.0), FRAC_PI_2 / 2.0) < 1e-15);
    // the separatrix form: its derivative is 1/(1 − n tanh²u)
    let (n, u, h) = (-2.5, 0.8, 1e-5);
    let d = (third_kind_separatrix(n, u + h) - third_kind_separatrix(n, u - h)) / (2.0 * h);
    assert!(rel(d, 1.0 / (1.0 - n * u.tanh().powi(2))) < 1e-9);
    let d = (third_kind_separatrix(0.4, u + h) - third_kind_separatrix(0.4, u - h)) / (2.0 * h);
    assert!(rel(d, 1.0 / (1.0 - 0.4 * u.tanh().powi(2))) < 1e-9);
}

/// The first kind by Bulirsch's `el1` on the AGM sequence equals Carlson's form
/// `s R_F(c², c² + m1 s², 1)` (DLMF 19.25.5; `sign(s) 2K − …` for c < 0) to round-off,
/// from m1 = 1 to 1e-300, over the whole period, tiny `cn` and tiny `sn` included.
#[test]
fn el1_equals_carlsons_form() {
    let carlson = |s: f64, c: f64, m1: f64, k: f64| {
        let r = s * carlson_rf(c * c, c * c + m1 * s * s, 1.0);
        if c >= 0.0 {
            r
        } else {
            (if s >= 0.0 { 1.0 } else { -1.0 }) * 2.0 * k - r
        }
    };
    let mut worst: f64 = 0.0;
    let mut m1 = 1.0f64;
    while m1 > 1e-300 {
        let agm = Agm::new(m1);
        let k = agm.quarter();
        let mut angles: Vec<f64> = (-200..=200).map(|i| PI * i as f64 / 200.0).collect();
        for tiny in [1e-300, 1e-200, 1e-17, 1e-12, 1e-8, 1e-4] {
            for base in [0.0, FRAC_PI_2, -FRAC_PI_2, PI] {
                angles.extend([base + tiny, base - tiny]);
            }
        }
        for phi in angles {
            let (s, c) = phi.sin_cos();
            let a = first_kind_in_period((c / s).abs(), s, c, &agm, k);
            let b = carlson(s, c, m1, k);
            // R_F's own error is a few ulps of u; el1's is measured against K
            let err = (a - b).abs() / (EPS * (k + b.abs()));
            worst = worst.max(err);
            assert!(err < 3.0, "m1 {m1} φ {phi}: {a} {b} ({err} eps)");
            assert!(
                a.signum() == b.signum() || a == 0.0 && b == 0.0,
                "{m1} {phi}"
            );
        }
        m1 *= 0.1;
    }
    eprintln!("el1 against R_F: worst {worst} eps (K + |u|)");
    // the levels suffice down to the smallest parameter
    let deep = Agm::new(5e-324);
    assert!(deep.top < AGM_LEVELS - 1, "{}", deep.top);
    eprintln!("AGM levels at m1 = 5e-324: {}", deep.top + 1);
}
