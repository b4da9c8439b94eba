//! Tests of the closed-form torque-free motion ([`super`]): the README's flip interval, the
//! invariants conserved and Euler's equation solved along the exact ω(t), the attitude against
//! the kinematics, scale invariance, and the lanes against the single runs bit for bit.

use super::*;
use crate::elliptic::third_kind_u;
use crate::freebody::{euler_omega_dot, symmetry_code, SYMMETRY_RTOL};
use crate::invariants::principal_invariants;
use crate::isa::Isa;
use crate::real::{Real, Wide, WIDTH};
use crate::so3::{matmul, Mat3, Vec3};

const EYE: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn the_readme_flip_interval() {
    // README: FreeRigidBody((1, 2, 3)).flip_interval((1e-3, 1, 1e-3)) = 27.5308405537...
    let reg = Regime::new([1.0, 2.0, 3.0], 0, [1e-3, 1.0, 1e-3]);
    assert_eq!(reg.case, AROUND_E3);
    assert!(
        rel(reg.flip_interval(), 27.530_840_553_7) < 5e-12,
        "{}",
        reg.flip_interval()
    );
    assert!(rel(reg.period(), 2.0 * reg.flip_interval()) < 1e-16);
    // ω2 has flipped after one interval
    let w = reg.omega_at([1.0, 2.0, 3.0], [1e-3, 1.0, 1e-3], reg.flip_interval());
    assert!((w[1] + 1.0).abs() < 1e-6);
}

#[test]
fn energy_and_momentum_are_conserved_along_the_exact_omega() {
    let moments = [1.0, 2.0, 3.0];
    for w0 in [
        [0.3, 1.0, 0.2],
        [1e-3, 1.0, 1e-3],
        [0.9, -0.2, 0.4],
        [-0.1, 0.5, 1.3],
        [1e-9, 1.0, -1e-9],
    ] {
        let reg = Regime::new(moments, 0, w0);
        let (k0, a0) = principal_invariants(moments, w0);
        assert!(rel(reg.energy, k0) < 1e-15 && rel(reg.momentum, a0) < 1e-15);
        for j in 0..400 {
            let t = 0.173 * j as f64;
            let w = reg.omega_at(moments, w0, t);
            let (k, a) = principal_invariants(moments, w);
            assert!(rel(k, k0) < 1e-14 && rel(a, a0) < 1e-14, "{w0:?} t {t}");
        }
    }
}

#[test]
fn the_exact_omega_solves_eulers_equation() {
    let moments = [1.0, 2.0, 3.0];
    let h = 1e-5;
    for w0 in [[0.3, 1.0, 0.2], [0.9, -0.2, 0.4], [0.4, 0.3, -1.0]] {
        let reg = Regime::new(moments, 0, w0);
        let at0 = reg.omega_at(moments, w0, 0.0);
        for i in 0..3 {
            assert!((at0[i] - w0[i]).abs() < 1e-15);
        }
        for j in 0..50 {
            let t = 0.41 * j as f64;
            let (p, m) = (
                reg.omega_at(moments, w0, t + h),
                reg.omega_at(moments, w0, t - h),
            );
            let f = euler_omega_dot(moments, reg.omega_at(moments, w0, t));
            for i in 0..3 {
                assert!(((p[i] - m[i]) / (2.0 * h) - f[i]).abs() < 1e-8);
            }
        }
    }
    // a symmetric body precesses: the same check
    let sym = [1.0, 1.0, 2.0];
    let code = symmetry_code(sym, SYMMETRY_RTOL);
    let w0 = [0.3, -0.4, 0.8];
    let reg = Regime::new(sym, code, w0);
    assert_eq!(reg.case, PRECESSION);
    let t = 0.7;
    let (p, m) = (reg.omega_at(sym, w0, t + h), reg.omega_at(sym, w0, t - h));
    let f = euler_omega_dot(sym, reg.omega_at(sym, w0, t));
    for i in 0..3 {
        assert!(((p[i] - m[i]) / (2.0 * h) - f[i]).abs() < 1e-9);
    }
}

#[test]
fn classification() {
    let i = [1.0, 2.0, 3.0];
    assert_eq!(Regime::new(i, 0, [0.0, 1.0, 0.0]).case, FIXED);
    assert_eq!(Regime::new(i, 0, [0.0, 0.0, 0.0]).case, FIXED);
    assert_eq!(Regime::new(i, 0, [0.1, 0.2, 1.0]).case, AROUND_E3);
    assert_eq!(Regime::new(i, 0, [1.0, 0.2, 0.1]).case, AROUND_E1);
    // a² = 2k I2 exactly: I1(I2 − I1) ω1² = I3(I3 − I2) ω3² = 0.5625 for I = (1, 2, 2.25)
    let sep = Regime::new([1.0, 2.0, 2.25], 0, [0.75, 0.5, 1.0]);
    assert_eq!(sep.case, SEPARATRIX);
    assert_eq!((sep.m, sep.m1), (1.0, 0.0));
    assert!(sep.flip_interval().is_infinite() && sep.period().is_infinite());
    assert_eq!(Regime::new([2.0; 3], 3, [0.1, 0.2, 0.3]).case, SPHERICAL);
    assert!(Regime::new([2.0; 3], 3, [0.1, 0.2, 0.3]).period().is_nan());
    assert_eq!(CASE_NAMES[AROUND_E1 as usize], "around e1");
}

fn orthogonality_error(q: &Mat3) -> f64 {
    let mut e: f64 = 0.0;
    for r in 0..3 {
        for c in 0..3 {
            let d: f64 = (0..3).map(|k| q[k][r] * q[k][c]).sum();
            e = e.max((d - if r == c { 1.0 } else { 0.0 }).abs());
        }
    }
    e
}

#[test]
fn the_attitude_keeps_l_fixed_in_space_and_solves_the_kinematics() {
    // L in space, Q (I ω), is constant; Q̇ = Q hat(ω)
    let moments = [1.0, 2.0, 3.0];
    let s = EYE;
    let q0 = zxz_matrix(0.3, 1.1, -0.7);
    for (code, mom, w0) in [
        (0u8, moments, [0.3, 1.0, 0.2]),
        (0, moments, [1.0, 0.2, -0.1]),
        (2, [1.0, 1.0, 2.0], [0.3, -0.4, 0.8]),
        (1, [1.0, 2.0, 2.0], [0.3, -0.4, 0.8]),
        (0, moments, [0.0, 0.0, 1.5]),
    ] {
        let ts: Vec<f64> = (0..60).map(|j| 0.37 * j as f64).collect();
        let mut qs = vec![[[0.0; 3]; 3]; ts.len()];
        let mut ws = vec![[0.0; 3]; ts.len()];
        exact_attitudes(mom, &s, code, &[w0], &[q0], &ts, &mut qs);
        exact_omegas(mom, &s, code, &[w0], &ts, &mut ws);
        let l_of = |q: &Mat3, w: Vec3| {
            let p = [mom[0] * w[0], mom[1] * w[1], mom[2] * w[2]];
            q.map(|row| row[0] * p[0] + row[1] * p[1] + row[2] * p[2])
        };
        let l0 = l_of(&q0, w0);
        for (q, w) in qs.iter().zip(&ws) {
            assert!(orthogonality_error(q) < 1e-14);
            let l = l_of(q, *w);
            for i in 0..3 {
                assert!((l[i] - l0[i]).abs() < 1e-13, "{code} {w0:?}");
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                assert!((qs[0][i][j] - q0[i][j]).abs() < 1e-15);
            }
        }
        // Q̇ = Q hat(ω) by central differences at t = 1
        let h = 1e-5;
        let mut three = [[[0.0; 3]; 3]; 3];
        exact_attitudes(
            mom,
            &s,
            code,
            &[w0],
            &[q0],
            &[1.0 - h, 1.0, 1.0 + h],
            &mut three,
        );
        let mut w1 = [[0.0; 3]];
        exact_omegas(mom, &s, code, &[w0], &[1.0], &mut w1);
        let qw = matmul(&three[1], &crate::so3::hat(w1[0]));
        for i in 0..3 {
            for j in 0..3 {
                let d = (three[2][i][j] - three[0][i][j]) / (2.0 * h);
                assert!((d - qw[i][j]).abs() < 1e-8, "{code} {w0:?}");
            }
        }
    }
}

#[test]
fn scale_invariance_and_rows() {
    // ω scaled by 2^k: the same motion in time scaled by 2^-k
    let moments = [1.0, 2.0, 3.0];
    let w0 = [0.3, 1.0, 0.2];
    let a = Regime::new(moments, 0, w0);
    let b = Regime::new(moments, 0, w0.map(|x| x * 2f64.powi(-500)));
    assert_eq!(a.m, b.m);
    assert_eq!(a.m1, b.m1);
    assert_eq!(a.lam * 2f64.powi(-500), b.lam);
    let r = a.to_row();
    assert_eq!(r[row::CASE], AROUND_E3 as f64);
    assert_eq!(r[row::LAM], a.lam);
    assert_eq!(r[row::QUARTER], a.quarter);
}

/// Initial ω across every regime: random directions and magnitudes, the fixed points and
/// their neighbourhoods, the separatrix and its neighbourhood (m1 from 1e-3 to 1e-12, on
/// both sides), extreme and subnormal scales, zero.
fn sample_omegas() -> Vec<Vec3> {
    let mut ws = Vec::new();
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for i in 0..3000 {
        let scale = [1.0, 1e-3, 7.5, 1e150, 1e-150][i % 5];
        ws.push([uniform(), uniform(), uniform()].map(|x| scale * x));
    }
    let r3 = 3f64.sqrt();
    for d in [1e-3, 1e-5, 1e-6, 1e-9, 1e-12, -1e-3, -1e-6, -1e-12, 0.0] {
        ws.push([r3 * (1.0 + d), 0.4, 1.0]);
        ws.push([-r3 * (1.0 + d), -0.4, 1.0]);
    }
    for special in [
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 0.0],
        [1e-150, 1.0, 1e-150],
        [1e-130, 1.0, -1e-130],
        [1e-8, 1.0, 1e-8],
        [1.0, 1e-12, 1e-12],
        [1e-12, 1e-12, 1.0],
        [1e300, 1e300, 1e300],
        [1e-310, 2e-310, -1e-310],
        [5e-324, 0.0, 5e-324],
        [1.7e308, 1.0, 1.0],
        [f64::NAN, 1.0, 0.5],
        [f64::INFINITY, 0.2, 1.0],
        [0.3, 1.0, 0.2],
    ] {
        ws.push(special);
    }
    // the specials again, each inside a block of ordinary members
    for j in 0..40 {
        let k = ws.len() - 1 - j % 30;
        ws.push(ws[k]);
        ws.push([0.3, -0.2 + 0.01 * j as f64, 0.9]);
    }
    ws
}

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || a.is_nan() && b.is_nan()
}

/// Members in SIMD lanes compute bit for bit what each member's single run (its `Regime`
/// and `omega_at`) computes, in every regime, on every instruction set the CPU offers;
/// and the lanes carry the ordinary members (not only the single runs' fallback).
#[test]
fn lanes_equal_single_runs_bit_for_bit() {
    // more times than lanes, not a multiple of them
    let mut ts = vec![0.0, 0.3, 1.0, 7.7, 100.0, -3.0, 1e4, 2.5e-10];
    ts.extend((0..WIDTH + 3).map(|j| 0.61 * j as f64 - 2.0));
    let ws = sample_omegas();
    for moments in [
        [1.0, 2.0, 3.0],
        [0.2, 1.5, 10.0],
        [1.0, 2.0, 2.25],
        [1.0, 1.0 + 1e-9, 2.0],
    ] {
        let s = zxz_matrix(0.3, 1.1, -0.7);
        let radicals = Radicals::new(moments);
        let mut want = vec![[0.0; 3]; ws.len() * ts.len()];
        for (w, o) in ws.iter().zip(want.chunks_mut(ts.len())) {
            omegas_one_by_one(moments, &s, &radicals, 0, *w, &ts, o);
        }
        let mut runs: Vec<(&str, Vec<Vec3>)> = Vec::new();
        let mut got = vec![[0.0; 3]; want.len()];
        omegas_in_lanes::<WIDTH>(moments, &s, &radicals, &ws, &ts, &mut got);
        runs.push(("dispatched", got.clone()));
        omegas_in_lanes::<8>(moments, &s, &radicals, &ws, &ts, &mut got);
        runs.push(("dispatched, 8 lanes", got.clone()));
        for isa in Isa::ALL.into_iter().filter(|isa| isa.available()) {
            omegas_in_lanes_with::<WIDTH>(isa, moments, &s, &radicals, &ws, &ts, &mut got);
            runs.push((isa.name(), got.clone()));
        }
        // the batched entry point, on rayon's threads
        exact_omegas(moments, &s, 0, &ws, &ts, &mut got);
        runs.push(("exact_omegas", got.clone()));
        // members left over (fewer than the lanes), alone: their times in the lanes
        for (w, o) in ws.iter().zip(got.chunks_mut(ts.len())) {
            exact_omegas(moments, &s, 0, &[*w], &ts, o);
        }
        runs.push(("one member, times in lanes", got.clone()));
        for (name, got) in &runs {
            for (i, (a, b)) in got.iter().zip(&want).enumerate() {
                assert!(
                    (0..3).all(|c| same(a[c], b[c])),
                    "{name} {moments:?} member {:?} t {}: {a:?} {b:?}",
                    ws[i / ts.len()],
                    ts[i % ts.len()]
                );
            }
        }
        // most members run in the lanes proper
        let mut plain = 0;
        for chunk in ws.chunks(WIDTH) {
            let mut w = [Wide::<WIDTH>::default(); 3];
            for l in 0..WIDTH {
                for c in 0..3 {
                    w[c].0[l] = chunk[l.min(chunk.len() - 1)][c];
                }
            }
            let (_, p) = LaneMotion::new(moments, &radicals, to_sorted(&s, w));
            plain += (0..chunk.len()).filter(|&l| p.get(l)).count();
        }
        assert!(
            plain * 10 > ws.len() * 9,
            "{moments:?}: {plain} of {}",
            ws.len()
        );
    }
}

/// The attitudes in lanes compute bit for bit what each member's single run
/// (`attitude_at`) computes, in every regime (the members off the plain lanes run alone),
/// on every instruction set the CPU offers, one Q0 shared or one per member; and the lanes
/// carry the ordinary members.
#[test]
fn attitude_lanes_equal_single_runs_bit_for_bit() {
    let mut ts = vec![0.0, 0.3, 1.0, 7.7, 100.0, -3.0, 1e4, 2.5e-10];
    ts.extend((0..WIDTH + 3).map(|j| 0.61 * j as f64 - 2.0));
    let ws = sample_omegas();
    let q0s: Vec<Mat3> = (0..ws.len())
        .map(|i| zxz_matrix(0.1 * i as f64, 0.3 + 0.01 * i as f64, -0.2 * i as f64))
        .collect();
    for moments in [
        [1.0, 2.0, 3.0],
        [0.2, 1.5, 10.0],
        [1.0, 2.0, 2.25],
        [1.0, 1.0 + 1e-9, 2.0],
    ] {
        let s = zxz_matrix(0.3, 1.1, -0.7);
        for q0 in [&q0s[..], &q0s[..1]] {
            let pick = |i: usize| &q0[if q0.len() > 1 { i } else { 0 }];
            let mut want = vec![[[0.0; 3]; 3]; ws.len() * ts.len()];
            for (i, (w, o)) in ws.iter().zip(want.chunks_mut(ts.len())).enumerate() {
                attitudes_one_by_one(moments, &s, 0, *w, pick(i), &ts, o);
            }
            let mut runs: Vec<(&str, Vec<Mat3>)> = Vec::new();
            let mut got = vec![[[0.0; 3]; 3]; want.len()];
            attitudes_in_lanes::<WIDTH>(moments, &s, &ws, q0, &ts, &mut got);
            runs.push(("dispatched", got.clone()));
            attitudes_in_lanes::<8>(moments, &s, &ws, q0, &ts, &mut got);
            runs.push(("dispatched, 8 lanes", got.clone()));
            for isa in Isa::ALL.into_iter().filter(|isa| isa.available()) {
                attitudes_in_lanes_with::<WIDTH>(isa, moments, &s, &ws, q0, &ts, &mut got);
                runs.push((isa.name(), got.clone()));
            }
            exact_attitudes(moments, &s, 0, &ws, q0, &ts, &mut got);
            runs.push(("exact_attitudes", got.clone()));
            for (i, (w, o)) in ws.iter().zip(got.chunks_mut(ts.len())).enumerate() {
                exact_attitudes(moments, &s, 0, &[*w], &[*pick(i)], &ts, o);
            }
            runs.push(("one member, times in lanes", got.clone()));
            for (name, got) in &runs {
                for (i, (a, b)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        (0..9).all(|k| same(a[k / 3][k % 3], b[k / 3][k % 3])),
                        "{name} {moments:?} member {:?} t {}: {a:?} {b:?}",
                        ws[i / ts.len()],
                        ts[i % ts.len()]
                    );
                }
            }
        }
        // most members run in the lanes proper
        let plain = ws
            .iter()
            .filter(|w| plain_motion(moments, &s, **w, &q0s[0]).is_some())
            .count();
        assert!(
            plain * 10 > ws.len() * 8,
            "{moments:?}: {plain} of {}",
            ws.len()
        );
    }
}

/// The attitude from the reduction ω(t) makes (`third_kind_excess_reduced`, `carlson_rj_above`,
/// the angles as ratios) equals the one from the angles by atan2 and `third_kind_u`
/// (libm's atan, the integral's own reduction) to round-off.
#[test]
fn the_reduced_attitude_equals_the_angle_route() {
    for moments in [[1.0, 2.0, 3.0], [0.2, 1.5, 10.0], [1.0, 2.0, 2.25]] {
        for w in [
            [0.3, 1.0, 0.2],
            [1.0, 0.2, -0.1],
            [-0.05, 1.0, 0.01],
            [0.9, -0.4, 1.3],
        ] {
            let q0 = zxz_matrix(0.4, 0.9, -1.2);
            let reg = Regime::new(moments, 0, w);
            assert!(reg.is_elliptic() && reduced_third_kind(&reg));
            let att = AttitudeSetup::new(moments, &reg, w, &q0);
            for t in [0.0, 0.7, 3.1, 25.0, -11.0, 400.0] {
                let got = attitude_at(moments, &reg, &att, w, &q0, t);
                // the angle route
                let v = reg.omega_at(moments, w, t);
                let (theta, phi) = relabelled_angles(
                    reg.pole,
                    [moments[0] * v[0], moments[1] * v[1], moments[2] * v[2]],
                );
                let u = reg.u0 + reg.lam * t;
                let u0 = reg.u0;
                let big = third_kind_u(att.n, u, reg.m, reg.m1, reg.quarter)
                    - third_kind_u(att.n, u0, reg.m, reg.m1, reg.quarter);
                let psi = reg.momentum * t / att.i_pole + att.psi_pi * big;
                let x = matmul(&att.p0, &zxz_matrix(psi, theta, phi));
                let want = if reg.pole == 2 {
                    x
                } else {
                    x.map(|row| [row[2], -row[1], row[0]])
                };
                // the two routes group ψ's terms apart (the engine joins the first-kind part
                // `λt` to `a t/I_p` exactly); where |n| ≫ 1 (I1 ≪ I2 here) both cancel by
                // the round-off of `a t (1/I_q − 1/I_p)`
                let joined = reg.momentum * t * (1.0 / att.i_other - 1.0 / att.i_pole);
                let tol = 4e-15 * (1.0 + psi.abs() + joined.abs());
                for k in 0..9 {
                    let (a, b) = (got[k / 3][k % 3], want[k / 3][k % 3]);
                    assert!((a - b).abs() <= tol, "{moments:?} {w:?} t {t}: {a} {b}");
                }
            }
            // ψ(0) = 0 exactly: Q(0) = Q0 to the round-off of the frame's products
            let q = attitude_at(moments, &reg, &att, w, &q0, 0.0);
            for k in 0..9 {
                assert!((q[k / 3][k % 3] - q0[k / 3][k % 3]).abs() < 2e-15);
            }
        }
    }
}

#[test]
fn families_in_lanes_equal_each_members_regime_bit_for_bit() {
    // the members of the ω lanes' test (near the axes, the separatrix, extreme scales),
    // many of them, so that the threads' blocks and a partial group of lanes run
    let base = sample_omegas();
    let ws: Vec<Vec3> = (0..PARALLEL_MIN + 77)
        .map(|i| base[i % base.len()].map(|x| x * (1.0 + (i / base.len()) as f64 * 1e-3)))
        .collect();
    for (moments, symmetry) in [
        ([1.0, 2.0, 3.0], 0),
        ([0.2, 1.5, 10.0], 0),
        ([1.0, 2.0, 2.25], 0),
        ([1.0, 2.0, 2.0], 2),
    ] {
        let s = zxz_matrix(0.3, 1.1, -0.7);
        let want: Vec<Family> = ws
            .iter()
            .map(|w| Family::of(&regime_of(moments, &s, symmetry, *w)))
            .collect();
        let mut got = vec![Family::default(); ws.len()];
        let mut runs: Vec<(&str, Vec<Family>)> = Vec::new();
        families(moments, &s, symmetry, &ws, &mut got);
        runs.push(("families", got.clone()));
        families(moments, &s, symmetry, &ws[..100], &mut got[..100]);
        runs.push(("few members, one thread", got.clone()));
        if symmetry == 0 {
            let radicals = Radicals::new(moments);
            for isa in Isa::ALL.into_iter().filter(|isa| isa.available()) {
                families_in_lanes_with::<WIDTH>(isa, moments, &s, &radicals, &ws, &mut got);
                runs.push((isa.name(), got.clone()));
            }
            families_in_lanes::<8>(moments, &s, &radicals, &ws, &mut got);
            runs.push(("8 lanes", got.clone()));
        }
        for (name, got) in &runs {
            for (i, (a, b)) in got.iter().zip(&want).enumerate() {
                assert!(
                    a.case == b.case
                        && same(a.period, b.period)
                        && same(a.flip_interval, b.flip_interval),
                    "{name} {moments:?} member {:?}: {a:?} {b:?}",
                    ws[i]
                );
            }
        }
        // every family occurs where the body has them
        if symmetry == 0 {
            for case in [AROUND_E1, AROUND_E3, FIXED] {
                assert!(want.iter().any(|f| f.case == case), "{moments:?} {case}");
            }
        }
    }
}

/// The time of 10⁶ closed forms at one time each (run with `--ignored --nocapture`).
#[test]
#[ignore]
fn time_exact_omegas() {
    let ws = random_omegas(1_000_000);
    for nt in [1usize, 10, 100] {
        let ts: Vec<f64> = (0..nt).map(|j| 1.0 + 0.3 * j as f64).collect();
        let ws = &ws[..ws.len() / nt.min(10)];
        let mut out = vec![[0.0; 3]; ws.len() * nt];
        let radicals = Radicals::new([1.0, 2.0, 3.0]);
        for name in [
            "exact_omegas",
            "one by one",
            "8 lanes",
            "16 lanes",
            "32 lanes",
            "64 lanes",
            "32 lanes, AVX2",
            "16 lanes, AVX2",
            "16 lanes, baseline",
        ] {
            let mut best = f64::INFINITY;
            for _ in 0..5 {
                let t0 = std::time::Instant::now();
                if !omegas_by(name, &radicals, ws, &ts, &mut out) {
                    break;
                }
                best = best.min(t0.elapsed().as_secs_f64());
            }
            eprintln!(
                "{nt:4} times, {name:18}: {:.3e} /s",
                (ws.len() * nt) as f64 / best
            );
        }
    }
}

/// `n` values of ω, each component uniform in [−0.5, 0.5) (xorshift64).
fn random_omegas(n: usize) -> Vec<Vec3> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    (0..n)
        .map(|_| {
            [0; 3].map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
        })
        .collect()
}

/// ω(t) of the body (1, 2, 3) from each of `ws` at the times `ts` into `out`, by the route
/// `name` ([`time_exact_omegas`]); false when this CPU lacks the route's instruction set.
fn omegas_by(name: &str, radicals: &Radicals, ws: &[Vec3], ts: &[f64], out: &mut [Vec3]) -> bool {
    let ms = [1.0, 2.0, 3.0];
    match name {
        "exact_omegas" => exact_omegas(ms, &EYE, 0, ws, ts, out),
        "one by one" => {
            for (w, o) in ws.iter().zip(out.chunks_mut(ts.len())) {
                omegas_one_by_one(ms, &EYE, radicals, 0, *w, ts, o)
            }
        }
        "8 lanes" => omegas_in_lanes::<8>(ms, &EYE, radicals, ws, ts, out),
        "16 lanes" => omegas_in_lanes::<16>(ms, &EYE, radicals, ws, ts, out),
        "64 lanes" => omegas_in_lanes::<64>(ms, &EYE, radicals, ws, ts, out),
        "16 lanes, AVX2" | "32 lanes, AVX2" if !Isa::Avx2.available() => return false,
        "16 lanes, AVX2" => omegas_in_lanes_with::<16>(Isa::Avx2, ms, &EYE, radicals, ws, ts, out),
        "32 lanes, AVX2" => omegas_in_lanes_with::<32>(Isa::Avx2, ms, &EYE, radicals, ws, ts, out),
        "16 lanes, baseline" => omegas_in_lanes_any::<16>(ms, &EYE, radicals, ws, ts, out),
        _ => omegas_in_lanes::<32>(ms, &EYE, radicals, ws, ts, out),
    }
    true
}

/// A fixed point's attitude at a huge angle (a slow spin at t = 10¹⁰, which double precision
/// still resolves): the true rotation, against the plane rotation by `cos θ`, `sin θ` of the
/// standard library (issue 43's fuzz case was 1.3e-7 off), and the same as `exp_so3` below
/// the wide-angle limit.
#[test]
fn fixed_point_attitude_at_a_huge_angle_is_the_true_rotation() {
    let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for &t in &[1.7e6, 1e10, 3.3e12, 4e15] {
        let q = fixed_point_attitude(&eye, [1.0, 0.0, 0.0], t);
        let (s, c) = t.sin_cos();
        let want = [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]];
        for i in 0..3 {
            for j in 0..3 {
                assert!((q[i][j] - want[i][j]).abs() < 1e-15, "{t}: {i}{j}");
            }
        }
    }
    let q = fixed_point_attitude(&eye, [0.0, 2.0, 0.0], 0.3);
    assert_eq!(q, crate::so3::exp_so3([0.0, 0.6, 0.0]));
}

/// `f'(0)` by central differences at `h` and `h/2`, Richardson-extrapolated (the closed
/// forms' derivative tests, here, in [`crate::heavy_top`], [`crate::kepler`] and the constrained
/// sensitivities).
pub(crate) fn richardson(f: impl Fn(f64) -> f64, h: f64) -> f64 {
    let d1 = (f(h) - f(-h)) / (2.0 * h);
    let d2 = (f(h / 2.0) - f(-h / 2.0)) / h;
    (4.0 * d2 - d1) / 3.0
}

#[test]
fn the_closed_forms_derivatives_equal_differences_of_the_closed_form() {
    // ∂ω(t), ∂T and ∂(flip interval) along the moments and ω0 against Richardson differences
    // of the f64 regime itself (the same closed form, an independent route to its derivative)
    for (moments, w, t) in [
        ([1.0, 2.0, 3.0], [0.3, -0.4, 1.1], 2.7),
        ([1.0, 2.0, 3.0], [1.2, 0.5, -0.2], 5.3),
        ([0.7, 1.3, 1.9], [-0.5, -0.8, 0.6], 11.0),
    ] {
        let tangent = ExactTangent::new(moments, w).expect("an elliptic motion");
        let (value, d) = tangent.omega_at(t);
        let (period, flip) = (tangent.period(), tangent.flip_interval());
        let moved = |j: usize, h: f64| {
            let (mut m, mut x) = (moments, w);
            if j < 3 {
                m[j] += h;
            } else {
                x[j - 3] += h;
            }
            let reg = Regime::new(m, 0, x);
            let o = reg.omega_at(m, x, t);
            [o[0], o[1], o[2], reg.period(), reg.flip_interval()]
        };
        assert_eq!(value, Regime::new(moments, 0, w).omega_at(moments, w, t));
        for j in 0..DIRECTIONS {
            for (k, want) in [d[0][j], d[1][j], d[2][j], period.d[j], flip.d[j]]
                .into_iter()
                .enumerate()
            {
                let fd = richardson(|h| moved(j, h)[k], 1e-4);
                let scale = fd.abs().max(1.0);
                assert!(
                    (want - fd).abs() <= 1e-8 * scale,
                    "{moments:?} {w:?}: output {k}, direction {j}: {want} against {fd}"
                );
            }
        }
    }
}

#[test]
fn the_closed_forms_attitude_derivatives_equal_differences_of_the_attitude() {
    // ∂Q(t) along the moments and ω0 against Richardson differences of the f64 attitude, for
    // both poles, mixed signs, a start with cn u0 = 0 (ω1 = 0 about e3, ω3 = 0 about e1:
    // the point where Carlson's first argument is zero) and several half periods of Π
    let q0 = crate::so3::exp_so3([0.3, -0.5, 0.2]);
    for (moments, w, t) in [
        ([1.0, 2.0, 3.0], [0.3, -0.4, 1.1], 2.7),
        ([1.0, 2.0, 3.0], [1.2, 0.5, -0.2], 5.3),
        ([0.7, 1.3, 1.9], [-0.5, -0.8, 0.6], 11.0),
        ([1.0, 2.0, 3.0], [0.0, 0.5, 1.1], 4.1),
        ([1.0, 2.0, 3.0], [1.2, -0.5, 0.0], 3.2),
    ] {
        let tangent = ExactTangent::new(moments, w).expect("an elliptic motion");
        let attitude = |m: Vec3, x: Vec3| {
            let reg = Regime::new(m, 0, x);
            let att = AttitudeSetup::new(m, &reg, x, &q0);
            attitude_at(m, &reg, &att, x, &q0, t)
        };
        let (value, d) = tangent.attitude_at(&q0, t);
        let plain = attitude(moments, w);
        let (_, d0) = tangent.attitude_at(&q0, 0.0);
        for r in 0..3 {
            for c in 0..3 {
                assert!((value[r][c] - plain[r][c]).abs() < 1e-14, "{w:?}: Q {r}{c}");
                for j in 0..DIRECTIONS {
                    assert!(d0[r][c][j].abs() < 1e-14, "{w:?}: ∂Q(0) {r}{c} {j}");
                    let fd = richardson(
                        |h| {
                            let (mut m, mut x) = (moments, w);
                            if j < 3 {
                                m[j] += h;
                            } else {
                                x[j - 3] += h;
                            }
                            attitude(m, x)[r][c]
                        },
                        1e-4,
                    );
                    let want = d[r][c][j];
                    assert!(
                        (want - fd).abs() <= 1e-8 * fd.abs().max(1.0),
                        "{moments:?} {w:?}: Q {r}{c}, direction {j}: {want} against {fd}"
                    );
                }
            }
        }
    }
}

/// The free flows in lanes ([`free_flows_in_lanes`]) are, in every plain lane, bit for bit
/// what one flow's scalar route computes ([`Regime::with`], [`AttitudeSetup::frame`],
/// [`ThirdKindStart::new`], [`motion_from_start`]): in every regime and scale of
/// `sample_omegas` (the others cleared from `plain`), over flows within a half period and
/// across many (the complete `Π(n|m)` lane by lane); and the lanes carry the ordinary members.
/// (The ensembles' blocks run them on every instruction set the CPU offers:
/// `ensemble_tests.rs`, `exact_splittings_in_lanes_are_their_single_runs`.)
#[test]
fn free_flows_in_lanes_equal_the_single_flow_bit_for_bit() {
    let ws = sample_omegas();
    for moments in [
        [1.0, 2.0, 3.0],
        [0.2, 1.5, 10.0],
        [1.0, 1.0126869887825154, 3.3062374224730378],
    ] {
        let radicals = Radicals::new(moments);
        let mut plain_lanes = 0;
        for (g, chunk) in ws.chunks(WIDTH).enumerate() {
            let t = [0.0, 0.37, 5.0, -2.0, 60.0][g % 5];
            let q0s: Vec<Mat3> = (0..chunk.len())
                .map(|i| zxz_matrix(0.1 * i as f64, 0.3 + 0.01 * i as f64, -0.2 * i as f64))
                .collect();
            let lane = |f: &dyn Fn(usize) -> f64| {
                Wide::<WIDTH>(std::array::from_fn(|l| f(l.min(chunk.len() - 1))))
            };
            let w = [0, 1, 2].map(|k| lane(&|l| chunk[l][k]));
            let q = [0, 1, 2].map(|r| [0, 1, 2].map(|c| lane(&|l| q0s[l][r][c])));
            let (wt, qt, plain) = free_flows_in_lanes(moments, &radicals, w, &q, Wide::splat(t));
            for (l, w0) in chunk.iter().enumerate() {
                if !plain.get(l) {
                    continue;
                }
                plain_lanes += 1;
                let reg = Regime::with(moments, &radicals, 0, *w0);
                let att = AttitudeSetup::frame(moments, &reg, *w0, &q0s[l]);
                let mut start = ThirdKindStart::new(&reg, &att, *w0).expect("an elliptic lane");
                let (we, qe) = motion_from_start(moments, &reg, &att, &mut start, t);
                for k in 0..3 {
                    assert!(same(wt[k].0[l], we[k]), "{moments:?} {w0:?} t {t}: ω{k}");
                    for c in 0..3 {
                        assert!(same(qt[k][c].0[l], qe[k][c]), "{moments:?} {w0:?} t {t}: Q");
                    }
                }
            }
        }
        assert!(
            plain_lanes > ws.len() / 2,
            "{moments:?}: {plain_lanes} plain lanes"
        );
    }
}
