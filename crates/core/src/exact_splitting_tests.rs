//! The exact-flow splittings against independent routes: the closed form (torque-free, any
//! step), FRB's published trajectory (ACM TOMS Algorithm 903, example 1), and the crate's
//! DOP853 at a tight tolerance (the orders on a heavy top).

use super::*;
use crate::drivers::{Clock, Counters, Output, Sampling, Status};
use crate::forces::{Force, ForceKind};
use crate::isa::Isa;
use crate::layout::FORCE_PARAMS;
use crate::observers::NoObserver;
use crate::run::Run;
use crate::so3::Vec3;
use crate::spec::{Method, RunSpec};
use crate::steppers::Control;
use crate::systems::{NoUser, Rigid, TorqueFree};
use crate::tableaux;
use crate::torque_free::{attitude_at, AttitudeSetup, Regime};

const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn composition(name: &str) -> Composition<'static> {
    let (first, flows, kicks) = tableaux::composition(name).unwrap();
    Composition::new(first, flows, kicks).unwrap()
}

fn body(moments: Vec3, c: Vec3, pivot: bool) -> Body {
    let a = [0, 1, 2].map(|r| [0, 1, 2].map(|k| if r == k { moments[r] } else { 0.0 }));
    let rotor = crate::rigid::rotor_code(moments, SYMMETRY_RTOL);
    Body::from_slice(&Body::vector(1.0, moments, c, &a, [0.0; 3], pivot, rotor)).unwrap()
}

fn state(q: &Mat3, w: Vec3) -> [f64; STATE_SIZE] {
    let mut y = [0.0; STATE_SIZE];
    for r in 0..3 {
        y[Q_AT + 3 * r..Q_AT + 3 * r + 3].copy_from_slice(&q[r]);
    }
    y[OMEGA_AT..].copy_from_slice(&w);
    y
}

/// The final state of a run of `method` on `sys` from `y0` over `[0, t_end]` with step `dt`.
fn run_to<S: RigidStructure>(
    sys: &S,
    method: Method,
    y0: &[f64; STATE_SIZE],
    t_end: f64,
    dt: f64,
) -> [f64; STATE_SIZE] {
    let t_eval = [t_end];
    let spec = RunSpec::new(
        method,
        dt,
        Sampling {
            t_end,
            t_eval: &t_eval,
            every: 1,
        },
        u64::MAX,
    )
    .unwrap();
    let (mut clock, mut counters) = (Clock::default(), Counters::default());
    let mut z = y0.to_vec();
    let mut f = vec![0.0; STATE_SIZE];
    let (mut ts, mut ys) = (vec![0.0; 1], vec![0.0; STATE_SIZE]);
    let mut run = Run {
        spec,
        clock: &mut clock,
        z: &mut z,
        f: &mut f,
        out: Output {
            t: &mut ts,
            y: &mut ys,
        },
        counters: &mut counters,
    };
    run.enter(sys);
    assert_eq!(
        run.chunk_rigid(sys, &mut NoObserver, u64::MAX),
        Status::Finished
    );
    let mut y = [0.0; STATE_SIZE];
    y.copy_from_slice(&ys);
    y
}

fn exact(name: &str) -> Method<'static> {
    Method::ExactSplitting(composition(name))
}

/// The closed form's (ω, Q) at `t` from `(w, q0)`.
fn closed_form(moments: Vec3, w: Vec3, q0: &Mat3, t: f64) -> (Vec3, Mat3) {
    let sym = symmetry_code(moments, SYMMETRY_RTOL);
    let reg = Regime::new(moments, sym, w);
    let att = AttitudeSetup::new(moments, &reg, w, q0);
    (
        reg.omega_at(moments, w, t),
        attitude_at(moments, &reg, &att, w, q0, t),
    )
}

fn max_diff(y: &[f64; STATE_SIZE], w: Vec3, q: &Mat3) -> (f64, f64) {
    let dw = (0..3)
        .map(|k| (y[OMEGA_AT + k] - w[k]).abs())
        .fold(0.0, f64::max);
    let dq = (0..9)
        .map(|k| (y[Q_AT + k] - q[k / 3][k % 3]).abs())
        .fold(0.0, f64::max);
    (dw, dq)
}

#[test]
fn the_tables_are_consistent_compositions() {
    for (name, order_flows) in [("strang", 1), ("bm4", 6), ("bm6", 15)] {
        let c = composition(name);
        assert_eq!(c.flows.len(), order_flows, "{name}");
        // symmetric compositions: each list a palindrome (even order by symmetry)
        let rev = |x: &[f64]| x.iter().rev().copied().collect::<Vec<_>>();
        assert_eq!(rev(c.flows), c.flows.to_vec(), "{name}");
        assert_eq!(rev(c.kicks), c.kicks.to_vec(), "{name}");
    }
    assert!(Composition::new(true, &[1.0], &[1.0]).is_err());
    assert!(Composition::new(false, &[0.5, 0.5], &[1.0]).is_ok());
    let e = Composition::new(true, &[0.9], &[0.5, 0.5]).unwrap_err();
    assert!(e.contains("flows must sum to 1"), "{e}");
    assert!(Composition::new(true, &[f64::NAN], &[0.5, 0.5]).is_err());
}

/// Torque-free, every composition is the exact flow: at a large step, after many steps, the
/// state equals the closed form's at the run's time to round-off, for a triaxial body off and
/// near the separatrix, a nearly symmetric one and a symmetric one. The flows go on along one
/// motion ([`FreeFlow`]), so the error does not grow with the number of steps beyond the
/// closed form's own at that time. (The step 0.375 is a binary fraction, so that the driver's
/// clock, a running sum of the steps, is exact too.)
#[test]
fn torque_free_the_splittings_are_exact_at_any_step() {
    let q0 = crate::so3::exp_so3([0.3, -0.4, 0.5]);
    let cases: [(Vec3, Vec3); 4] = [
        ([1.0, 2.0, 3.5], [0.3, 1.0, 0.2]),
        ([1.0, 2.0, 3.0], [0.5, 1e-7, 0.5 * (1.0f64 / 3.0).sqrt()]),
        ([2.0, 2.0 + 1e-9, 3.0], [0.4, -0.2, 0.7]),
        ([2.0, 2.0, 3.0], [0.4, -0.2, 0.7]),
    ];
    for (moments, w) in cases {
        let sys = TorqueFree::new(body(moments, [0.0; 3], false));
        let y0 = state(&q0, w);
        for (name, steps) in [("strang", 1_000_000), ("bm4", 100_000), ("bm6", 40_000)] {
            let (dt, n) = (0.375, steps as f64);
            let y = run_to(&sys, exact(name), &y0, dt * n, dt);
            // from the ω the method starts from (π = Iω, then π/I: the initial state's own
            // round-off, which the motion carries over 10⁵ time units)
            let w_pi = [0, 1, 2].map(|k| (moments[k] * w[k]) * sys.body.inv_moments[k]);
            let (we, qe) = closed_form(moments, w_pi, &q0, dt * n);
            let (dw, dq) = max_diff(&y, we, &qe);
            assert!(
                dw < 1e-12 && dq < 1e-12,
                "{moments:?} {name}: {dw:e} {dq:e}"
            );
        }
    }
}

/// FRB's example 1 through poinsot's own heavy top: a pivot, the centre of mass at e3 from it
/// (M = 1), uniform gravity `g = −u0`, so that the torque is FRB's `u × e3`, `u = Qᵀ u0`.
#[allow(clippy::excessive_precision)] // FRB's inputs as printed
fn frb_top() -> (Rigid<NoUser>, [f64; STATE_SIZE]) {
    let b = body(
        [1.0, 1.0126869887825154, 3.3062374224730378],
        [0.0, 0.0, 1.0],
        true,
    );
    let u0 = [
        9.5586303547238536e-05,
        4.8777318247201465e-04,
        -8.6772148817192390e-04,
    ];
    let mut p = [0.0; FORCE_PARAMS];
    p[..3].copy_from_slice(&u0.map(|x| -x));
    let sys = Rigid::new(
        b,
        vec![Force {
            kind: ForceKind::Gravity,
            p,
        }],
        IDENTITY,
        None,
    );
    let pi0 = [
        -0.3479095708854734,
        -0.1982291459967592,
        -0.9163318919276364,
    ];
    let w0 = [0, 1, 2].map(|k| pi0[k] / b.moments[k]);
    (sys, state(&IDENTITY, w0))
}

/// FRB's published output (thinned): `(t, π, Q)` at steps 0–10 and every 40th step.
fn frb_published() -> Vec<(f64, Vec3, Mat3)> {
    include_str!("../../../tests/data/frb_example1.txt")
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let x: Vec<f64> = l.split_whitespace().map(|v| v.parse().unwrap()).collect();
            // Q column by column
            let q = [0, 1, 2].map(|r| [0, 1, 2].map(|c| x[3 + 3 * c + r]));
            (x[12], [x[0], x[1], x[2]], q)
        })
        .collect()
}

/// `exact-splitting6` with FRB's coefficients and step reproduces FRB's published trajectory,
/// at the start of the run and at its end (t = 5000, 10⁴ steps of fifteen flows).
#[test]
fn frb_example_1_is_reproduced() {
    let (sys, y0) = frb_top();
    let published = frb_published();
    let mut worst: f64 = 0.0;
    for &(t, pi, q) in published.iter().filter(|r| r.0 <= 5.0 || r.0 >= 4999.0) {
        if t == 0.0 {
            continue;
        }
        let y = run_to(&sys, exact("bm6"), &y0, t, 0.5);
        let w = [0, 1, 2].map(|k| pi[k] / sys.body.moments[k]);
        let (dw, dq) = max_diff(&y, w, &q);
        worst = worst.max(dw).max(dq);
        let bound = if t <= 5.0 { 1e-13 } else { 1e-9 };
        assert!(dw < bound && dq < bound, "t = {t}: {dw:e} {dq:e}");
    }
    assert!(worst > 0.0);
}

/// The orders on FRB's heavy top, against the crate's DOP853 at rtol 1e-13: halving the step
/// divides the error by 2ᵖ (p = 2, 4, 6).
#[test]
fn the_orders_are_2_4_6_on_a_heavy_top() {
    let (sys, y0) = frb_top();
    let t_end = 20.0;
    let control = Control::with_tolerances(1e-14, 1e-16);
    let reference = run_to(&sys, Method::Dop853(control), &y0, t_end, 0.0);
    let error = |name: &str, dt: f64| {
        let y = run_to(&sys, exact(name), &y0, t_end, dt);
        (Q_AT..STATE_SIZE)
            .map(|k| (y[k] - reference[k]).abs())
            .fold(0.0, f64::max)
    };
    for (name, order, dt) in [("strang", 2.0, 0.1), ("bm4", 4.0, 0.5), ("bm6", 6.0, 1.0)] {
        let (e1, e2) = (error(name, dt), error(name, dt / 2.0));
        let p = (e1 / e2).log2();
        assert!((p - order).abs() < 0.3, "{name}: {e1:e} {e2:e} p = {p}");
    }
}

/// The free flow's copies for each instruction set ([`evaluate_with`]: the AVX2 copy a single
/// run takes on this CPU, and the baseline's) give the same ω and Q bit for bit, over motions
/// about either pole, near the middle axis, beyond a half period (`Π(n|m)` needed) and from a
/// turned attitude; each copy against the closed form's own route as well.
#[test]
fn the_free_flow_is_the_same_in_every_instruction_set() {
    let c = (0.3f64, 0.4f64);
    let turned: Mat3 = [
        [c.0.cos(), -c.0.sin(), 0.0],
        [c.0.sin() * c.1.cos(), c.0.cos() * c.1.cos(), -c.1.sin()],
        [c.0.sin() * c.1.sin(), c.0.cos() * c.1.sin(), c.1.cos()],
    ];
    let cases: [(Vec3, Vec3, Mat3, f64); 5] = [
        ([1.0, 2.0, 3.0], [0.3, 1.0, 0.8], IDENTITY, 0.7),
        ([1.0, 2.0, 3.0], [0.9, 0.5, 0.1], turned, 13.0),
        (
            [1.0, 1.0126869887825154, 3.3062374224730378],
            [-0.3, -0.2, -0.3],
            IDENTITY,
            0.5,
        ),
        ([2.0, 3.0, 4.5], [1e-4, 1.0, 1e-4], turned, 40.0),
        ([0.3, 0.5, 0.9], [-2.0, 0.1, 1.5], turned, -3.0),
    ];
    for (moments, w0, q0, t) in cases {
        let radicals = Radicals::new(moments);
        let symmetry = symmetry_code(moments, SYMMETRY_RTOL);
        let reference = {
            let mut m = Motion::at(w0, q0, 0.0);
            evaluate_with(Isa::Baseline, moments, &radicals, symmetry, &mut m, t)
        };
        for isa in Isa::ALL {
            let mut m = Motion::at(w0, q0, 0.0);
            let (w, q) = evaluate_with(isa, moments, &radicals, symmetry, &mut m, t);
            assert_eq!(
                w.map(f64::to_bits),
                reference.0.map(f64::to_bits),
                "{isa:?} {w0:?}"
            );
            assert_eq!(
                q.map(|r| r.map(f64::to_bits)),
                reference.1.map(|r| r.map(f64::to_bits))
            );
        }
        let (w, q) = closed_form(moments, w0, &q0, t);
        let scale = w0.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for k in 0..3 {
            assert!(
                (w[k] - reference.0[k]).abs() <= 1e-13 * scale,
                "{w:?} {:?}",
                reference.0
            );
            for j in 0..3 {
                assert!((q[k][j] - reference.1[k][j]).abs() <= 1e-12, "{q:?}");
            }
        }
    }
}
