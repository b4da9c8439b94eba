//! Tests of the time loops ([`super::run_fixed`], [`super::run_adaptive`]) on problems with
//! known solutions: one step against its hand computation, the order of convergence, the step
//! budget (a run stopped by it and resumed equals one call bit for bit), sampling, a full
//! output and a blow-up; and the registry's table of steppers ([`crate::spec`]) through
//! [`crate::run::Run`].

use super::*;
use crate::exact_splitting::Composition;
use crate::layout::Body;
use crate::observers::NoObserver;
use crate::run::Run;
use crate::spec::{Method, MethodData, RunSpec, UseMethod, REGISTRY};
use crate::steppers::RK4;
use crate::systems::TorqueFree;

/// ẏ = λ y, y(0) = 1: y(t) = exp(λ t).
struct Growth(f64);

impl VectorField for Growth {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], out: &mut [f64]) {
        out[0] = self.0 * y[0];
    }
}

/// ẏ = y², y(0) = 1: y(t) = 1/(1 − t), infinite at t = 1.
struct BlowUp;

impl VectorField for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], out: &mut [f64]) {
        out[0] = y[0] * y[0];
    }
}

const CONTROL: Control = Control::with_tolerances(1e-10, 1e-12);

/// A fixed-step run of `sys` from y0 at 0 to `t_end`, samples at `t_eval`, at most
/// `max_steps` steps: (status, final state, clock, counters, sample times, samples).
fn fixed<S: VectorField, M: FixedMethod<S>>(
    sys: &S,
    m: &mut M,
    y0: &[f64],
    dt: f64,
    t_end: f64,
    t_eval: &[f64],
    max_steps: u64,
) -> (Status, Vec<f64>, Clock, Counters, Vec<f64>, Vec<f64>) {
    let n = y0.len();
    let cap = t_eval.len().max(1);
    let (mut ts, mut ys) = (vec![0.0; cap], vec![0.0; cap * n]);
    let mut clock = Clock::default();
    let mut k = Counters::default();
    let mut z = y0.to_vec();
    let sampling = Sampling {
        t_end,
        t_eval,
        every: 1,
    };
    let mut out = Output {
        t: &mut ts,
        y: &mut ys,
    };
    let s = run_fixed(
        sys,
        m,
        &mut NoObserver,
        &mut clock,
        &mut z,
        dt,
        &sampling,
        &mut out,
        &mut k,
        max_steps,
    );
    (s, z, clock, k, ts, ys)
}

/// One step of RK4 on ẏ = λy is the degree-4 Taylor polynomial of exp(λh), by hand.
#[test]
fn one_rk4_step_is_its_taylor_polynomial() {
    let (lambda, h) = (-0.7, 0.3);
    let z = lambda * h;
    let by_hand = 1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0;
    let (s, y, clock, k, ..) = fixed(
        &Growth(lambda),
        &mut Erk::new(RK4, 1),
        &[1.0],
        h,
        h,
        &[h],
        10,
    );
    assert_eq!(s, Status::Finished);
    assert!(
        (y[0] - by_hand).abs() <= 2.0 * f64::EPSILON,
        "{} {by_hand}",
        y[0]
    );
    assert_eq!((clock.t, k.n_steps, k.n_fev), (h, 1, 4));
}

/// The global error of RK4 falls as h⁴: the fitted slope over three halvings.
#[test]
fn rk4_converges_at_order_four() {
    let errors: Vec<f64> = [0.1, 0.05, 0.025, 0.0125]
        .iter()
        .map(|&dt| {
            let (_, y, ..) = fixed(
                &Growth(-1.0),
                &mut Erk::new(RK4, 1),
                &[1.0],
                dt,
                2.0,
                &[2.0],
                u64::MAX,
            );
            (y[0] - (-2.0f64).exp()).abs()
        })
        .collect();
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((3.9..4.2).contains(&order), "{order} from {errors:?}");
    }
}

/// DOP853 meets its tolerance on exp(−t), and its error falls with the tolerance.
#[test]
fn dop853_meets_its_tolerance() {
    let mut last = f64::INFINITY;
    for rtol in [1e-6, 1e-9, 1e-12] {
        let control = Control {
            rtol,
            atol: rtol * 1e-2,
            ..CONTROL
        };
        let (mut ts, mut ys) = ([0.0; 2], [0.0; 2]);
        let mut out = Output {
            t: &mut ts,
            y: &mut ys,
        };
        let (mut clock, mut k) = (Clock::default(), Counters::default());
        let (mut z, mut f) = ([1.0], [0.0]);
        let sampling = Sampling {
            t_end: 3.0,
            t_eval: &[1.5, 3.0],
            every: 1,
        };
        let s = run_adaptive(
            &Growth(-1.0),
            &mut NoObserver,
            &mut clock,
            &mut z,
            &mut f,
            &control,
            &sampling,
            &mut out,
            &mut k,
            u64::MAX,
        );
        assert_eq!(s, Status::Finished);
        let err = (ys[0] - (-1.5f64).exp())
            .abs()
            .max((ys[1] - (-3.0f64).exp()).abs());
        assert!(err < 10.0 * rtol, "rtol {rtol}: error {err}");
        assert!(err < last, "rtol {rtol}: error {err} not below {last}");
        last = err;
    }
}

/// A run stopped by its step budget says so (`Running`), holds exactly the steps it took,
/// and resumed to the end equals a run in one call bit for bit.
#[test]
fn the_step_budget_stops_a_run_that_resumes_exactly() {
    let sys = Growth(0.4);
    let t_eval: Vec<f64> = (0..=10).map(|k| k as f64 * 0.25).collect();
    let whole = fixed(
        &sys,
        &mut Erk::new(RK4, 1),
        &[1.0],
        0.01,
        2.5,
        &t_eval,
        u64::MAX,
    );
    assert_eq!(whole.0, Status::Finished);
    let (mut ts, mut ys) = (vec![0.0; 11], vec![0.0; 11]);
    let mut clock = Clock::default();
    let mut k = Counters::default();
    let mut z = vec![1.0];
    let sampling = Sampling {
        t_end: 2.5,
        t_eval: &t_eval,
        every: 1,
    };
    let mut m = Erk::new(RK4, 1);
    let mut calls = 0;
    loop {
        let mut out = Output {
            t: &mut ts,
            y: &mut ys,
        };
        let before = k.n_steps;
        let s = run_fixed(
            &sys,
            &mut m,
            &mut NoObserver,
            &mut clock,
            &mut z,
            0.01,
            &sampling,
            &mut out,
            &mut k,
            7,
        );
        calls += 1;
        if s == Status::Finished {
            break;
        }
        assert_eq!(s, Status::Running);
        assert_eq!(k.n_steps - before, 7, "a call takes its whole budget");
    }
    assert!(calls > 30);
    assert_eq!(z, whole.1);
    assert_eq!((clock.t, k.n_steps), (whole.2.t, whole.3.n_steps));
    assert_eq!((ts, ys), (whole.4, whole.5));
}

/// Steps shorten to land on every sample time: the samples are at the times asked, and
/// each is the exact solution to the method's accuracy.
#[test]
fn samples_land_on_their_times() {
    let t_eval = [0.0, 0.013, 0.5, 0.5, 1.0 / 3.0 + 0.5, 2.0];
    let (s, _, _, k, ts, ys) = fixed(
        &Growth(-2.0),
        &mut Erk::new(RK4, 1),
        &[1.0],
        1e-3,
        2.0,
        &t_eval,
        u64::MAX,
    );
    assert_eq!(s, Status::Finished);
    assert_eq!(k.n_out, t_eval.len());
    assert_eq!(ts, t_eval);
    for (t, y) in ts.iter().zip(&ys) {
        assert!((y - (-2.0 * t).exp()).abs() < 1e-12, "{t}: {y}");
    }
}

/// Saving every step with room for one sample: the driver keeps the start, then stops with
/// `OutputFull` before its first step (the caller grows the output and calls again).
#[test]
fn a_full_output_stops_the_run() {
    let (s, _, clock, k, ..) = fixed(
        &Growth(1.0),
        &mut Erk::new(RK4, 1),
        &[1.0],
        0.1,
        1.0,
        &[],
        u64::MAX,
    );
    // `fixed` gives room for one sample without t_eval: the start
    assert_eq!(s, Status::OutputFull);
    assert_eq!((k.n_out, k.n_steps, clock.t), (1, 0, 0.0));
}

/// A solution that blows up ends with `NonFinite` near its pole, the state left for the
/// diagnosis.
#[test]
fn a_blow_up_is_reported_at_its_step() {
    let (s, y, clock, ..) = fixed(
        &BlowUp,
        &mut Erk::new(RK4, 1),
        &[1.0],
        1e-3,
        2.0,
        &[2.0],
        u64::MAX,
    );
    assert_eq!(s, Status::NonFinite);
    assert!(!y[0].is_finite());
    assert!((0.99..1.01).contains(&clock.t), "{}", clock.t);
}

fn body() -> TorqueFree {
    let moments = [1.0, 2.0, 3.5];
    let a = [0, 1, 2].map(|r| [0, 1, 2].map(|c| if r == c { moments[r] } else { 0.0 }));
    let body = Body::from_slice(&Body::vector(
        2.0, moments, [0.0; 3], &a, [0.0; 3], false, -1,
    ))
    .unwrap();
    TorqueFree::new(body)
}

/// Which stepper the table builds: (adaptive, evaluations per step).
struct Which;

impl<S: VectorField + ?Sized> UseMethod<S> for Which {
    type Output = (bool, u64);
    fn fixed<M: FixedMethod<S> + Send>(self, m: M) -> (bool, u64) {
        (false, m.evals_per_step())
    }
    fn adaptive(self, _control: Control) -> (bool, u64) {
        (true, 0)
    }
}

/// What each kind may need: RK4's tableau, Strang's composition, the test's controller.
fn method_data(tableau: crate::steppers::Tableau<'static>) -> MethodData<'static> {
    let (kick_first, flows, kicks) = crate::tableaux::composition("strang").unwrap();
    MethodData {
        tableau,
        composition: Some(Composition::new(kick_first, flows, kicks).unwrap()),
        control: CONTROL,
    }
}

/// Every kind builds its stepper from the one table; the kinds of any vector field are
/// exactly those the table builds for one, and the adaptive kinds those it hands a
/// controller.
#[test]
fn the_table_builds_every_kind() {
    let sys = body();
    for kind in Method::NAMES {
        let m = Method::parse(kind, method_data(RK4)).unwrap();
        let (adaptive, evals) = m.on_rigid(&sys, Which);
        assert_eq!(adaptive, m.is_adaptive(), "{kind}");
        assert_eq!(adaptive, Method::ADAPTIVE_KINDS.contains(&kind), "{kind}");
        let expected = match kind {
            "dop853" => 0,
            "splitting" | "exact-splitting" => 2,
            _ => 4,
        };
        assert_eq!(evals, expected, "{kind}");
        let field = m.on_field(&Growth(1.0), Which);
        assert_eq!(field.is_ok(), Method::FIELD_KINDS.contains(&kind), "{kind}");
        assert_eq!(field.is_ok(), !m.needs_rigid_body(), "{kind}");
    }
    for e in REGISTRY {
        assert!(Method::NAMES.contains(&e.kind), "{}", e.name);
    }
}

/// A torque-free body through [`Run`] with each kind: every one finishes, the methods that
/// declare the invariants keep |L| to round-off, and all agree with DOP853 at its tolerance.
#[test]
fn a_run_with_each_kind_through_the_table() {
    let reference = run_kind("dop853");
    let momentum = |y: &[f64]| {
        let w = &y[crate::layout::OMEGA_AT..crate::layout::OMEGA_AT + 3];
        ((1.0 * w[0]).powi(2) + (2.0 * w[1]).powi(2) + (3.5 * w[2]).powi(2)).sqrt()
    };
    for kind in ["rk4", "erk", "rkmk", "splitting"] {
        let ys = run_kind(kind);
        let last = &ys[2 * STATE_SIZE..];
        let tol = if kind == "splitting" { 1e-5 } else { 1e-9 };
        let err = last
            .iter()
            .zip(&reference[2 * STATE_SIZE..])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < tol, "{kind}: {err}");
        if kind == "splitting" {
            let drift = (momentum(last) - momentum(&ys[..STATE_SIZE])).abs();
            assert!(drift < 1e-14, "{kind}: |L| drifts by {drift}");
        }
    }
}

/// The torque-free [`body`] from ω = (0.1, 1, 0.2) through [`Run`] with the method of `kind`
/// (dt 10⁻³), checked finished with the system's state left: its samples at t = 0, 1, 2.
fn run_kind(kind: &str) -> [f64; 3 * STATE_SIZE] {
    let sys = body();
    let mut y0 = [0.0; STATE_SIZE];
    y0[crate::layout::Q_AT] = 1.0;
    y0[crate::layout::Q_AT + 4] = 1.0;
    y0[crate::layout::Q_AT + 8] = 1.0;
    y0[crate::layout::OMEGA_AT..].copy_from_slice(&[0.1, 1.0, 0.2]);
    let t_eval = [0.0, 1.0, 2.0];
    let spec = RunSpec::new(
        Method::parse(kind, method_data(RK4)).unwrap(),
        1e-3,
        Sampling {
            t_end: 2.0,
            t_eval: &t_eval,
            every: 1,
        },
        u64::MAX,
    )
    .unwrap();
    let (mut clock, mut k) = (Clock::default(), Counters::default());
    let (mut z, mut f) = (y0, [0.0; STATE_SIZE]);
    let (mut ts, mut ys) = ([0.0; 3], [0.0; 3 * STATE_SIZE]);
    let mut r = Run {
        spec,
        clock: &mut clock,
        z: &mut z,
        f: &mut f,
        out: Output {
            t: &mut ts,
            y: &mut ys,
        },
        counters: &mut k,
    };
    r.enter(&sys);
    let s = r.chunk_rigid(&sys, &mut NoObserver, u64::MAX);
    r.leave(&sys);
    assert_eq!(s, Status::Finished, "{kind}");
    assert_eq!(
        z[crate::layout::OMEGA_AT..],
        ys[2 * STATE_SIZE + crate::layout::OMEGA_AT..],
        "{kind}: the state left is the system's"
    );
    ys
}

/// A method that needs a rigid body, on a field: the call fails (refused when built).
#[test]
fn a_rigid_body_method_on_a_field_fails() {
    let spec = RunSpec::new(
        Method::Splitting,
        0.1,
        Sampling {
            t_end: 1.0,
            t_eval: &[1.0],
            every: 1,
        },
        10,
    )
    .unwrap();
    let (mut clock, mut k) = (Clock::default(), Counters::default());
    let (mut z, mut f, mut ts, mut ys) = ([1.0], [0.0], [0.0], [0.0]);
    let mut r = Run {
        spec,
        clock: &mut clock,
        z: &mut z,
        f: &mut f,
        out: Output {
            t: &mut ts,
            y: &mut ys,
        },
        counters: &mut k,
    };
    assert_eq!(
        r.chunk(&Growth(1.0), &mut NoObserver, 10),
        Status::CallbackFailed
    );
}
