//! Kepler's flow against independent routes: Stumpff's functions against their closed forms,
//! an ellipse against its classical elements (Kepler's equation in the eccentric anomaly), a
//! hyperbola against its own conservation laws and group property, and the dual numbers'
//! derivatives against central differences.

use super::*;
use crate::dual::Dual;
use crate::torque_free::tests::richardson;

fn dot(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn flow(mu: f64, r0: &Vec3, v0: &Vec3, t: f64) -> (Vec3, Vec3) {
    kepler_flow(mu, r0, v0, t, universal_anomaly(mu, r0, v0, t))
}

#[test]
fn stumpff_functions_match_their_closed_forms() {
    for z in [
        -400.0, -50.0, -3.0, -0.5, -1e-3, -1e-9, 0.0, 1e-9, 1e-3, 0.05, 0.099, 0.5, 3.0, 30.0,
        400.0,
    ] {
        let (c2, c3) = stumpff(z);
        let (e2, e3) = if z > 0.0 {
            let s: f64 = f64::sqrt(z);
            (2.0 * (s / 2.0).sin().powi(2) / z, (s - s.sin()) / (z * s))
        } else if z < 0.0 {
            let s: f64 = f64::sqrt(-z);
            (
                2.0 * (s / 2.0).sinh().powi(2) / -z,
                (s.sinh() - s) / (-z * s),
            )
        } else {
            (0.5, 1.0 / 6.0)
        };
        // the closed forms cancel at small z (their own error ~ eps/|z|): there, the first
        // four terms of the Taylor series instead
        let (e2, e3) = if z.abs() <= 1e-3 {
            (
                0.5 - z / 24.0 + z * z / 720.0 - z * z * z / 40320.0,
                1.0 / 6.0 - z / 120.0 + z * z / 5040.0 - z * z * z / 362880.0,
            )
        } else {
            (e2, e3)
        };
        assert!(
            (c2 - e2).abs() <= 1e-14 * e2,
            "c2({z}) = {c2}, against {e2}"
        );
        assert!(
            (c3 - e3).abs() <= 1e-13 * e3,
            "c3({z}) = {c3}, against {e3}"
        );
    }
}

/// An ellipse by its classical elements: `a`, `e`, the perifocal frame, Kepler's equation
/// `E − e sin E = M` solved by Newton's method to the last bit.
fn ellipse_by_elements(mu: f64, r0: &Vec3, v0: &Vec3, t: f64) -> (Vec3, Vec3) {
    let r = dot(r0, r0).sqrt();
    let h = cross(r0, v0);
    let vxh = cross(v0, &h);
    let ev: Vec3 = std::array::from_fn(|i| vxh[i] / mu - r0[i] / r);
    let e = dot(&ev, &ev).sqrt();
    let a = 1.0 / (2.0 / r - dot(v0, v0) / mu);
    let n = (mu / (a * a * a)).sqrt();
    let p_hat: Vec3 = ev.map(|x| x / e);
    let hn = dot(&h, &h).sqrt();
    let q_hat = cross(&h.map(|x| x / hn), &p_hat);
    let (cos_e0, sin_e0) = ((1.0 - r / a) / e, dot(r0, v0) / (e * (mu * a).sqrt()));
    let e0 = sin_e0.atan2(cos_e0);
    let m = e0 - e * e0.sin() + n * t;
    let mut ea = m;
    for _ in 0..100 {
        let step = (ea - e * ea.sin() - m) / (1.0 - e * ea.cos());
        ea -= step;
        if step.abs() < 1e-17 * ea.abs().max(1.0) {
            break;
        }
    }
    let b = a * (1.0 - e * e).sqrt();
    let (x, y) = (a * (ea.cos() - e), b * ea.sin());
    let rr = a * (1.0 - e * ea.cos());
    let k = (mu * a).sqrt() / rr;
    let (vx, vy) = (-k * ea.sin(), k * (1.0 - e * e).sqrt() * ea.cos());
    (
        std::array::from_fn(|i| x * p_hat[i] + y * q_hat[i]),
        std::array::from_fn(|i| vx * p_hat[i] + vy * q_hat[i]),
    )
}

fn close(a: &Vec3, b: &Vec3, tol: f64, what: &str) {
    let scale = dot(b, b).sqrt();
    for i in 0..3 {
        assert!(
            (a[i] - b[i]).abs() <= tol * scale,
            "{what}: {a:?} against {b:?}"
        );
    }
}

#[test]
fn an_ellipse_follows_its_classical_elements() {
    // e ≈ 0.5 and e ≈ 0.95, over a fraction of an orbit up to several orbits
    let cases: [(f64, Vec3, Vec3); 3] = [
        (1.3, [1.0, 0.1, 0.0], [0.1, 1.2, 0.3]),
        (1.0, [0.2, -0.9, 0.4], [1.3, 0.2, 0.1]),
        (398600.4418, [7000.0, -1200.0, 300.0], [1.1, 7.4, 0.9]),
    ];
    for (mu, r0, v0) in cases {
        let period = 2.0 * std::f64::consts::PI
            / (mu.sqrt() * (2.0 / dot(&r0, &r0).sqrt() - dot(&v0, &v0) / mu).powf(1.5));
        for frac in [1e-4, 0.013, 0.37, 0.5, 0.99, 2.3, 7.7] {
            let t = frac * period;
            let (r, v) = flow(mu, &r0, &v0, t);
            let (re, ve) = ellipse_by_elements(mu, &r0, &v0, t);
            let tol = 2e-14 * (1.0 + frac);
            close(&r, &re, tol, &format!("r at {frac} periods"));
            close(&v, &ve, tol, &format!("v at {frac} periods"));
        }
    }
}

#[test]
fn a_hyperbola_keeps_its_energy_and_momentum_and_composes() {
    let (mu, r0, v0) = (1.0, [1.0, 0.2, -0.1], [0.3, 1.6, 0.4]);
    let energy = |r: &Vec3, v: &Vec3| 0.5 * dot(v, v) - mu / dot(r, r).sqrt();
    let (e0, h0) = (energy(&r0, &v0), cross(&r0, &v0));
    assert!(e0 > 0.0);
    for t in [1e-3, 0.4, 3.0, 25.0, -2.0] {
        let (r, v) = flow(mu, &r0, &v0, t);
        assert!(
            (energy(&r, &v) - e0).abs() < 1e-14 * e0.abs().max(1.0),
            "energy at {t}"
        );
        close(&cross(&r, &v), &h0, 1e-14, &format!("momentum at {t}"));
        // the group property and the time reversal
        let (r1, v1) = flow(mu, &r0, &v0, 0.3 * t);
        let (r2, v2) = flow(mu, &r1, &v1, 0.7 * t);
        close(&r2, &r, 1e-13, "r, two flows");
        close(&v2, &v, 1e-13, "v, two flows");
        let (rb, vb) = flow(mu, &r, &v, -t);
        close(&rb, &r0, 1e-13, "r back");
        close(&vb, &v0, 1e-13, "v back");
    }
}

#[test]
fn no_time_no_motion() {
    let (r0, v0) = ([1.0, 0.2, -0.1], [0.3, 1.1, 0.4]);
    assert_eq!(flow(1.0, &r0, &v0, 0.0), (r0, v0));
}

/// The dual numbers' derivatives of the flow along `μ`, `r0` and `v0` (seven directions)
/// against central differences, on an ellipse and on a hyperbola.
#[test]
fn the_flow_differentiates_exactly() {
    for (mu, r0, v0, t) in [
        (1.3, [1.0, 0.1, 0.0], [0.1, 1.2, 0.3], 2.1),
        (1.0, [1.0, 0.2, -0.1], [0.3, 1.6, 0.4], 1.7),
    ] {
        let seed = |v: f64, j: usize| {
            let mut d = [0.0; 7];
            d[j] = 1.0;
            Dual::<7>::new(v, d)
        };
        let mud = seed(mu, 0);
        let rd: [Dual<7>; 3] = std::array::from_fn(|i| seed(r0[i], 1 + i));
        let vd: [Dual<7>; 3] = std::array::from_fn(|i| seed(v0[i], 4 + i));
        let chi = universal_anomaly(mu, &r0, &v0, t);
        let (r, v) = kepler_flow(mud, &rd, &vd, t, chi);
        let plain = flow(mu, &r0, &v0, t);
        for i in 0..3 {
            assert_eq!(r[i].v.to_bits(), plain.0[i].to_bits());
            assert_eq!(v[i].v.to_bits(), plain.1[i].to_bits());
        }
        for j in 0..7 {
            let moved = |s: f64| {
                let mut x = [mu, r0[0], r0[1], r0[2], v0[0], v0[1], v0[2]];
                x[j] += s;
                let (r, v) = flow(x[0], &[x[1], x[2], x[3]], &[x[4], x[5], x[6]], t);
                [r[0], r[1], r[2], v[0], v[1], v[2]]
            };
            for i in 0..6 {
                let fd = richardson(|s| moved(s)[i], 1e-4);
                let exact = if i < 3 { r[i].d[j] } else { v[i - 3].d[j] };
                assert!(
                    (exact - fd).abs() < 1e-8 * (1.0 + fd.abs()),
                    "∂{i}/∂{j}: {exact} against {fd}"
                );
            }
        }
    }
}
