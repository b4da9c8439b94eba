//! Tests of the constrained systems ([`super`]) on pendulums: the multiplier as the rod's
//! tension, two coordinate choices moving alike, the projection, members against single runs
//! and the small oscillations' period, refused models, a singular system, a string that
//! goes slack where the energy says, and the differentiated KKT system of the sensitivities.

use std::sync::atomic::AtomicBool;

use super::*;
use crate::drivers::{run_adaptive, run_fixed, Clock, Counters, Erk, Status};
use crate::expressions::{Function, Interpreter, Program, ADD, CONST, INPUT, MUL, OUTPUT, UNARY};
use crate::steppers::{Control, Tableau};
use crate::system::VectorField;
use crate::tableaux::{RK4_A, RK4_B, RK4_C};
use crate::torque_free::tests::richardson;

/// A postfix program from a little stack language: each item an instruction.
fn program(items: &[(i64, f64)], shape: Shape) -> Program {
    let (c, v): (Vec<i64>, Vec<f64>) = items.iter().copied().unzip();
    Program::new(&c, &v, shape.n_inputs(), shape.n_outputs()).unwrap()
}

/// The planar pendulum in Cartesian coordinates (x, y): mass m = p0, length l = p1,
/// gravity g = p2 along −y. L = m/2 (ẋ² + ẏ²) − m g y, one holonomic constraint
/// g = (x² + y² − l²)/2, G = [x, y], b = 0, γ = ẋ² + ẏ², h = m/2 (ẋ² + ẏ²) + m g y.
fn cartesian_pendulum() -> Model {
    signed_pendulum(1.0)
}

/// The Cartesian pendulum with its constraint times `sign`: −1 gives a string,
/// (l² − x² − y²)/2 ≥ 0, whose multiplier λ = T/l is positive while it pulls and falls
/// through zero where it goes slack.
fn signed_pendulum(sign: f64) -> Model {
    let shape = PENDULUM_SHAPE;
    Model::new(shape, program(&pendulum_items(sign), shape), &Interpreter).unwrap()
}

/// The sizes of the Cartesian pendulum: two coordinates, one holonomic constraint, three
/// parameters.
const PENDULUM_SHAPE: Shape = Shape {
    n: 2,
    m: 1,
    nh: 1,
    np: 3,
    nu: 0,
};

/// The Cartesian pendulum's model outputs `[M, f, G, b, γ, g, h]` as a program's items.
fn pendulum_items(sign: f64) -> Vec<(i64, f64)> {
    // inputs: x0 = x, x1 = y, x2 = ẋ, x3 = ẏ, x4 = t, x5 = m, x6 = l, x7 = g
    let i = |k: usize| (INPUT, k as f64);
    let sq = |k: usize| [i(k), i(k), (MUL, 0.0)];
    let mut p: Vec<(i64, f64)> = vec![];
    // M = [[m, 0], [0, m]]
    p.extend([i(5), (OUTPUT, 0.0), (CONST, 0.0), (OUTPUT, 0.0)]);
    p.extend([(CONST, 0.0), (OUTPUT, 0.0), i(5), (OUTPUT, 0.0)]);
    // f = [0, −m g]
    p.extend([(CONST, 0.0), (OUTPUT, 0.0)]);
    p.extend([
        (CONST, -1.0),
        i(5),
        (MUL, 0.0),
        i(7),
        (MUL, 0.0),
        (OUTPUT, 0.0),
    ]);
    // G = sign · [x, y]; b = 0
    p.extend([(CONST, sign), i(0), (MUL, 0.0), (OUTPUT, 0.0)]);
    p.extend([(CONST, sign), i(1), (MUL, 0.0), (OUTPUT, 0.0)]);
    p.extend([(CONST, 0.0), (OUTPUT, 0.0)]);
    // γ = sign · (ẋ² + ẏ²)
    p.push((CONST, sign));
    p.extend(sq(2));
    p.extend(sq(3));
    p.extend([(ADD, 0.0), (MUL, 0.0), (OUTPUT, 0.0)]);
    // g = sign · (x² + y² − l²)/2
    p.push((CONST, sign));
    p.extend(sq(0));
    p.extend(sq(1));
    p.push((ADD, 0.0));
    p.extend([(CONST, -1.0)]);
    p.extend(sq(6));
    p.extend([
        (MUL, 0.0),
        (ADD, 0.0),
        (CONST, 0.5),
        (MUL, 0.0),
        (MUL, 0.0),
        (OUTPUT, 0.0),
    ]);
    // h = m/2 (ẋ² + ẏ²) + m g y
    p.extend(sq(2));
    p.extend(sq(3));
    p.extend([(ADD, 0.0), i(5), (MUL, 0.0), (CONST, 0.5), (MUL, 0.0)]);
    p.extend([
        i(5),
        i(7),
        (MUL, 0.0),
        i(1),
        (MUL, 0.0),
        (ADD, 0.0),
        (OUTPUT, 0.0),
    ]);
    p
}

/// The pendulum in its angle θ (from the downward vertical): m l² θ̈ = −m g l sin θ, as a
/// model with no constraint: M = [m l²], f = [−m g l sin θ], h = m l² θ̇²/2 − m g l cos θ.
fn angle_pendulum() -> Model {
    let shape = Shape {
        n: 1,
        m: 0,
        nh: 0,
        np: 3,
        nu: 0,
    };
    // inputs: x0 = θ, x1 = θ̇, x2 = t, x3 = m, x4 = l, x5 = g
    let i = |k: usize| (INPUT, k as f64);
    let mut p = vec![i(3), i(4), (MUL, 0.0), i(4), (MUL, 0.0), (OUTPUT, 0.0)];
    p.extend([
        (CONST, -1.0),
        i(3),
        (MUL, 0.0),
        i(5),
        (MUL, 0.0),
        i(4),
        (MUL, 0.0),
    ]);
    p.extend([i(0), (UNARY, 0.0), (MUL, 0.0), (OUTPUT, 0.0)]);
    p.extend([
        i(3),
        i(4),
        (MUL, 0.0),
        i(4),
        (MUL, 0.0),
        i(1),
        i(1),
        (MUL, 0.0),
    ]);
    p.extend([(MUL, 0.0), (CONST, 0.5), (MUL, 0.0)]);
    p.extend([
        (CONST, -1.0),
        i(3),
        (MUL, 0.0),
        i(5),
        (MUL, 0.0),
        i(4),
        (MUL, 0.0),
    ]);
    p.extend([
        i(0),
        (UNARY + 1, 0.0),
        (MUL, 0.0),
        (ADD, 0.0),
        (OUTPUT, 0.0),
    ]);
    Model::new(shape, program(&p, shape), &Interpreter).unwrap()
}

const P: [f64; 3] = [2.0, 1.5, 9.81];

/// The bob at the bottom with l ω0²/g = 7/2 (a string goes slack at cos θ = −1/2), and
/// the projection onto the constraints in play after every step.
fn slack_launch() -> ([f64; 4], Stabilization) {
    let (l, g) = (P[1], P[2]);
    let w0 = (3.5 * g / l).sqrt();
    let st = Stabilization {
        alpha: 0.0,
        beta: 0.0,
        projection: true,
    };
    ([0.0, -l, l * w0, 0.0], st)
}

/// DOP853 at rtol 1e-11, atol 1e-12 with SciPy's controller constants.
fn tight_control() -> Control {
    Control::with_tolerances(1e-11, 1e-12)
}

/// The rod's tension from Newton's law at the bob: along the rod, m v²/l + m g cos θ; the
/// multiplier of g = (x² + y² − l²)/2 is then −T/l (the generalized force Gᵀλ = λ (x, y)
/// points along the position, the tension inwards).
#[test]
fn multiplier_is_the_rod_tension_and_accelerations_are_newtons() {
    let model = cartesian_pendulum();
    let (m, l, g) = (P[0], P[1], P[2]);
    let th: f64 = 0.7;
    let w: f64 = 1.3; // θ̇
    let q = [l * th.sin(), -l * th.cos()];
    let v = [l * w * th.cos(), l * w * th.sin()];
    let sys = Lagrangian::new(
        &model,
        &P,
        Constant(&[]),
        Stabilization {
            alpha: 0.0,
            beta: 0.0,
            projection: false,
        },
        None,
    )
    .unwrap();
    let (qdd, lam) = sys.accelerations(0.0, &q, &v).unwrap();
    let tension = m * l * w * w + m * g * th.cos();
    assert!((lam[0] + tension / l).abs() < 1e-12, "{lam:?}");
    // θ̈ = −(g/l) sin θ: the tangential acceleration l θ̈ (cos θ, sin θ) plus the
    // centripetal −l θ̇² (sin θ, −cos θ)
    let thdd = -(g / l) * th.sin();
    let want = [
        l * thdd * th.cos() - l * w * w * th.sin(),
        l * thdd * th.sin() + l * w * w * th.cos(),
    ];
    for k in 0..2 {
        assert!((qdd[k] - want[k]).abs() < 1e-12, "{qdd:?} {want:?}");
    }
}

/// The Cartesian pendulum integrated with Baumgarte's terms (DOP853) follows the angle
/// model, conserves its energy, and keeps its constraint.
#[test]
fn cartesian_and_angle_models_move_alike() {
    let cart = cartesian_pendulum();
    let l = P[1];
    let th0: f64 = 1.1;
    let t_eval: Vec<f64> = (0..=20).map(|k| k as f64 * 0.25).collect();
    let a = run_tight(&cart, &[l * th0.sin(), -l * th0.cos(), 0.0, 0.0], &t_eval);
    let b = run_tight(&angle_pendulum(), &[th0, 0.0], &t_eval);
    for k in 0..t_eval.len() {
        let th = b[2 * k];
        let (x, y) = (a[4 * k], a[4 * k + 1]);
        assert!((x - l * th.sin()).abs() < 1e-8, "t = {}", t_eval[k]);
        assert!((y + l * th.cos()).abs() < 1e-8, "t = {}", t_eval[k]);
    }
    // energy and constraint along the Cartesian run
    let s = cart.shape;
    let sn = t_eval.len();
    let (mut qdd, mut lam, mut f, mut g, mut vel, mut e) = (
        vec![0.0; sn * 2],
        vec![0.0; sn],
        vec![0.0; sn * 2],
        vec![0.0; sn],
        vec![0.0; sn],
        vec![0.0; sn],
    );
    samples(
        &cart,
        &t_eval,
        &a,
        &P,
        &vec![0.0; sn * s.nu],
        None,
        SampleOut {
            qdd: &mut qdd,
            lam: &mut lam,
            forces: &mut f,
            g: &mut g,
            velocity: &mut vel,
            energy: &mut e,
        },
    );
    for k in 0..sn {
        assert!((e[k] - e[0]).abs() < 1e-8 * e[0].abs().max(1.0));
        assert!(g[k].abs() < 1e-9 && vel[k].abs() < 1e-8);
        // Gᵀλ = λ (x, y)
        assert!((f[2 * k] - lam[k] * a[4 * k]).abs() < 1e-12);
    }
}

/// A member of `model` (parameters [`P`], no inputs) from `y0` over [0, 5], DOP853 at
/// [`tight_control`] with Baumgarte's gains 10 and 10: its samples at `t_eval`, the run
/// checked finished.
fn run_tight(model: &Model, y0: &[f64], t_eval: &[f64]) -> Vec<f64> {
    let st = Stabilization {
        alpha: 10.0,
        beta: 10.0,
        projection: false,
    };
    let mut out = vec![0.0; t_eval.len() * y0.len()];
    let stop = AtomicBool::new(false);
    let method = Method::Dop853(tight_control());
    let run = run_member(
        model,
        &P,
        &[],
        y0,
        st,
        method,
        0.0,
        5.0,
        0.0,
        t_eval,
        &mut out,
        u64::MAX,
        &stop,
    );
    assert_eq!(run.status, Status::Finished);
    out
}

/// Projection puts a state back on the constraint: |q| = l and q · q̇ = 0.
#[test]
fn projection_restores_the_constraints() {
    let model = cartesian_pendulum();
    let l = P[1];
    let mut ev = model.evaluator();
    let mut q = [1.2 * l * 0.6, -1.1 * l * 0.8];
    let mut v = [0.3, 0.9];
    assert!(ev.project(0.0, &mut q, &mut v, &P, &[], None, 1e-13, 20));
    let r = (q[0] * q[0] + q[1] * q[1]).sqrt();
    assert!((r - l).abs() < 1e-12, "{r}");
    assert!((q[0] * v[0] + q[1] * v[1]).abs() < 1e-12);
    // a released constraint is left alone
    let mut q2 = [2.0, 0.1];
    let mut v2 = [0.3, 0.9];
    assert!(ev.project(0.0, &mut q2, &mut v2, &P, &[], Some(&[false]), 1e-13, 20));
    assert_eq!((q2, v2), ([2.0, 0.1], [0.3, 0.9]));
}

/// Members of an ensemble equal single runs, bit for bit; small oscillations of the angle
/// pendulum have the period 2π √(l/g).
#[test]
fn members_equal_single_runs_and_small_oscillations_have_their_period() {
    let model = angle_pendulum();
    let tab = Tableau {
        a: &RK4_A.concat(),
        b: &RK4_B,
        c: &RK4_C,
    };
    let ls = [0.5, 1.0, 2.0];
    let params: Vec<f64> = ls.iter().flat_map(|&l| [1.0, l, 9.81]).collect();
    let y0: Vec<f64> = ls.iter().flat_map(|_| [1e-4, 0.0]).collect();
    let st = Stabilization {
        alpha: 0.0,
        beta: 0.0,
        projection: false,
    };
    let t_eval: Vec<f64> = (0..=400).map(|k| k as f64 * 0.01).collect();
    let mut all = vec![0.0; 3 * t_eval.len() * 2];
    let stop = AtomicBool::new(false);
    let runs = run_members(
        &model,
        &params,
        &[],
        &y0,
        st,
        Method::Erk(tab),
        0.0,
        4.0,
        1e-3,
        &t_eval,
        &mut all,
        u64::MAX,
        &stop,
    );
    assert!(runs.iter().all(|r| r.status == Status::Finished));
    // a budget below the run's 4000 steps stops every member there
    let mut cut = vec![0.0; all.len()];
    let runs = run_members(
        &model,
        &params,
        &[],
        &y0,
        st,
        Method::Erk(tab),
        0.0,
        4.0,
        1e-3,
        &t_eval,
        &mut cut,
        1000,
        &stop,
    );
    assert!(runs
        .iter()
        .all(|r| r.status == Status::Running && r.n_steps == 1000));
    assert!(cut.iter().all(|x| x.is_nan()));
    for (i, &l) in ls.iter().enumerate() {
        let mut one = vec![0.0; t_eval.len() * 2];
        run_member(
            &model,
            &params[3 * i..3 * i + 3],
            &[],
            &y0[2 * i..2 * i + 2],
            st,
            Method::Erk(tab),
            0.0,
            4.0,
            1e-3,
            &t_eval,
            &mut one,
            u64::MAX,
            &stop,
        );
        assert_eq!(&all[i * one.len()..(i + 1) * one.len()], &one[..]);
        // θ(t) = θ0 cos(√(g/l) t) to second order in θ0
        let w = (9.81 / l).sqrt();
        for (k, &t) in t_eval.iter().enumerate() {
            assert!((one[2 * k] - 1e-4 * (w * t).cos()).abs() < 1e-10);
        }
    }
}

#[test]
fn bad_models_are_refused() {
    let shape = Shape {
        n: 1,
        m: 0,
        nh: 0,
        np: 0,
        nu: 0,
    };
    let p = Program::new(&[INPUT, OUTPUT], &[0.0, 0.0], 3, 1).unwrap();
    assert!(Model::new(shape, p, &Interpreter).is_err()); // 1 output, 3 needed
    let bad = Shape { nh: 2, ..shape };
    let p = Program::new(&[INPUT, OUTPUT], &[0.0, 0.0], 3, 1).unwrap();
    assert!(Model::new(bad, p, &Interpreter).is_err());
    let m = angle_pendulum();
    assert!(Lagrangian::new(
        &m,
        &[1.0],
        Constant(&[]),
        Stabilization {
            alpha: 0.0,
            beta: 0.0,
            projection: false
        },
        None
    )
    .is_err());
}

/// A singular system (zero mass) makes NaN rates, not a panic.
#[test]
fn a_singular_system_gives_nan() {
    let m = angle_pendulum();
    let sys = Lagrangian::new(
        &m,
        &[0.0, 1.0, 9.81],
        Constant(&[]),
        Stabilization {
            alpha: 0.0,
            beta: 0.0,
            projection: false,
        },
        None,
    )
    .unwrap();
    let mut out = [0.0; 2];
    sys.rhs(0.0, &[0.3, 0.0], &mut out);
    assert!(out[1].is_nan());
}

/// A pendulum on a string (the Cartesian pendulum) launched from the bottom with
/// l ω0²/g = 7/2: the string goes slack where the tension m l ω² + m g cos θ vanishes, at
/// cos θ = (2 − l ω0²/g)/3 = −1/2 by the energy (the multiplier λ = −T/l rises through
/// zero there). The watch locates it inside the driver's loop, with both fixed-step RK4
/// and DOP853; an expression event (y rising through 0: the bob at the pivot's height)
/// is logged on the way, and the terminal release ends the run there.
#[test]
fn a_string_goes_slack_where_the_energy_says() {
    use crate::events::Watch;
    let model = cartesian_pendulum();
    let l = P[1];
    let (y0, st) = slack_launch();
    let sys = Lagrangian::new(&model, &P, Constant(&[]), st, None).unwrap();
    // the expression y (input 1 of [x, y, ẋ, ẏ, t])
    let height = Function::compile(
        Program::new(&[INPUT, OUTPUT], &[1.0, 0.0], 5, 1).unwrap(),
        &Interpreter,
    );
    let sources = [Source::Expression(0), Source::Release(0)];
    let events = LagrangeEvents::new(&sys, &sources, Some(&height), NoCallbacks).unwrap();
    let (terminal, direction) = ([false, true], [1.0, 1.0]);
    let t_eval: Vec<f64> = (0..=40).map(|k| k as f64 * 0.05).collect();
    for adaptive in [false, true] {
        let mut watch = Watch::new(&events, &terminal, &direction, 0.01, 4);
        let (status, clock, z, k) = watched_run(&sys, &mut watch, &y0, &t_eval, adaptive);
        assert_eq!(status, Status::Terminated, "adaptive: {adaptive}");
        let log = &watch.log;
        assert_eq!(log.len(), 2, "{log:?}");
        let (up, slack) = (&log[0], &log[1]);
        assert_eq!((up.event, slack.event), (0, 1));
        assert!(up.y[1].abs() < 1e-12 && up.t < slack.t);
        // cos θ = −y/l = −1/2 at the release, the run's end
        let tol = if adaptive { 1e-9 } else { 1e-8 };
        assert!((-slack.y[1] / l + 0.5).abs() < tol, "{:?}", slack.y);
        assert_eq!((clock.t, &z[..]), (slack.t, &slack.y[..]));
        let lam = sys.accelerations(slack.t, &z[..2], &z[2..]).unwrap().1[0];
        assert!(lam.abs() < 1e-8, "{lam}");
        // samples up to the release only
        assert!(k.n_out < t_eval.len() && t_eval[k.n_out - 1] <= slack.t);
    }
}

/// A run of `sys` from `y0` over [0, 2], sampled at `t_eval` and watched by `observer`:
/// DOP853 at [`tight_control`] (`adaptive`), else RK4 (its tableau) in steps of 10⁻³. Its
/// status, clock, final state and counters.
fn watched_run<I: Inputs, O: crate::observers::Observer>(
    sys: &Lagrangian<'_, I>,
    observer: &mut O,
    y0: &[f64],
    t_eval: &[f64],
    adaptive: bool,
) -> (Status, Clock, Vec<f64>, Counters) {
    use crate::drivers::{Output, Sampling};
    let (mut ts, mut ys) = (vec![0.0; t_eval.len()], vec![0.0; t_eval.len() * 4]);
    let mut out = Output {
        t: &mut ts,
        y: &mut ys,
    };
    let sampling = Sampling {
        t_end: 2.0,
        t_eval,
        every: 1,
    };
    let mut clock = Clock { t: 0.0, h: 0.0 };
    let mut k = Counters::default();
    let mut z = y0.to_vec();
    let (c, s) = (&mut clock, &sampling);
    let status = if adaptive {
        let mut f = vec![0.0; 4];
        let control = tight_control();
        run_adaptive(
            sys,
            observer,
            c,
            &mut z,
            &mut f,
            &control,
            s,
            &mut out,
            &mut k,
            u64::MAX,
        )
    } else {
        let flat = RK4_A.concat();
        let tab = Tableau {
            a: &flat,
            b: &RK4_B,
            c: &RK4_C,
        };
        let mut m = Erk::new(tab, 4);
        run_fixed(
            sys,
            &mut m,
            observer,
            c,
            &mut z,
            1e-3,
            s,
            &mut out,
            &mut k,
            u64::MAX,
        )
    };
    (status, clock, z, k)
}

/// A member whose string goes slack ([`run_member_with`], the constraint one-sided): the
/// release where the energy puts it (cos θ = −1/2 for l ω0²/g = 7/2, as
/// `a_string_goes_slack_where_the_energy_says`), and after it a free fall: every later
/// sample on the parabola from the release state. A two-sided rod keeps the bob on its
/// circle instead.
#[test]
fn a_slack_string_lets_the_bob_fall_freely() {
    let model = signed_pendulum(-1.0);
    let (l, g) = (P[1], P[2]);
    let (y0, st) = slack_launch();
    let t_eval: Vec<f64> = (0..=30).map(|k| k as f64 * 0.05).collect();
    let stop = AtomicBool::new(false);
    let mut samples = vec![0.0; t_eval.len() * 4];
    let mut released = [0.0];
    let one_sided = OneSided {
        constraints: &[0],
        resolution: 2001,
    };
    let run = run_member_with(
        &model,
        &P,
        &[],
        &y0,
        st,
        Method::Dop853(tight_control()),
        (0.0, 1.5, 0.0),
        &t_eval,
        &mut samples,
        u64::MAX,
        &stop,
        one_sided,
        &mut released,
    );
    assert_eq!(run.status, Status::Finished);
    let tr = released[0];
    assert!(tr > 0.0 && tr < 1.5, "{tr}");
    // a run with the rod (the constraint two-sided) from the same start
    let rod_run = |t1: f64, t_eval: &[f64], out: &mut [f64]| {
        let control = Method::Dop853(tight_control());
        run_member(
            &model,
            &P,
            &[],
            &y0,
            st,
            control,
            0.0,
            t1,
            0.0,
            t_eval,
            out,
            u64::MAX,
            &stop,
        )
    };
    // the state at the release (the rod pulls until then)
    let mut rod = [0.0; 4];
    rod_run(tr, &[tr], &mut rod);
    let cos = -rod[1] / l;
    assert!((cos + 0.5).abs() < 1e-9, "cos θ at the release: {cos}");
    for (k, &t) in t_eval.iter().enumerate() {
        let s = &samples[4 * k..4 * k + 4];
        let r = (s[0] * s[0] + s[1] * s[1]).sqrt();
        if t < tr {
            assert!((r - l).abs() < 1e-9, "taut at t = {t}: r = {r}");
        } else {
            let d = t - tr;
            let x = rod[0] + rod[2] * d;
            let y = rod[1] + rod[3] * d - g * d * d / 2.0;
            let off = (s[0] - x).abs().max((s[1] - y).abs());
            assert!(off < 1e-8, "t = {t}: {off} off the parabola");
            assert!(r < l, "slack at t = {t}: r = {r}");
        }
    }
    // without the one-sided constraint the rod holds the bob on its circle
    rod_run(1.5, &t_eval, &mut samples);
    let last = &samples[samples.len() - 4..];
    assert!(((last[0] * last[0] + last[1] * last[1]).sqrt() - l).abs() < 1e-9);
}

/// The Cartesian pendulum's tangent: its model outputs, then the Jacobian of
/// `[M, f, G, b, γ, g]` along `[x, y, ẋ, ẏ, m, l, g]`, written by hand (11 rows of 7).
fn pendulum_tangent(sign: f64) -> Tangent {
    let shape = PENDULUM_SHAPE;
    let mut items = pendulum_items(sign);
    let i = |k: usize| (INPUT, k as f64);
    // the nonzero entries: (output row, direction) → items computing it
    let entry = |row: usize, dir: usize| -> Vec<(i64, f64)> {
        match (row, dir) {
            (0, 4) | (3, 4) => vec![(CONST, 1.0)],                 // ∂M/∂m
            (5, 4) => vec![(CONST, -1.0), i(7), (MUL, 0.0)],       // ∂(−m g)/∂m
            (5, 6) => vec![(CONST, -1.0), i(5), (MUL, 0.0)],       // ∂(−m g)/∂g
            (6, 0) | (7, 1) => vec![(CONST, sign)],                // ∂G/∂q
            (9, 2) => vec![(CONST, 2.0 * sign), i(2), (MUL, 0.0)], // ∂γ/∂ẋ
            (9, 3) => vec![(CONST, 2.0 * sign), i(3), (MUL, 0.0)], // ∂γ/∂ẏ
            (10, 0) => vec![(CONST, sign), i(0), (MUL, 0.0)],      // ∂g/∂x
            (10, 1) => vec![(CONST, sign), i(1), (MUL, 0.0)],      // ∂g/∂y
            (10, 5) => vec![(CONST, -sign), i(6), (MUL, 0.0)],     // ∂g/∂l
            _ => vec![(CONST, 0.0)],
        }
    };
    for row in 0..shape.n_outputs() - 1 {
        for dir in 0..shape.n_directions() {
            items.extend(entry(row, dir));
            items.push((OUTPUT, 0.0));
        }
    }
    let (c, v): (Vec<i64>, Vec<f64>) = items.iter().copied().unzip();
    let program = Program::new(&c, &v, shape.n_inputs(), shape.n_tangent_outputs()).unwrap();
    Tangent::new(shape, program, &Interpreter).unwrap()
}

/// The differentiated KKT system ([`LagrangeSensitive`]): each column's rate against central
/// differences of the plain system's rates along the same direction (its state part and its
/// parameters' seed), Richardson-extrapolated, for the rod and for the string (the
/// constraint's sign flipped), with and without Baumgarte's terms; the state's own rates bit
/// for bit the plain system's.
#[test]
fn the_sensitive_rates_are_the_derivatives_of_the_rates() {
    for (sign, alpha, beta) in [(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (1.0, 3.0, 4.0)] {
        let model = signed_pendulum(sign);
        let tangent = pendulum_tangent(sign);
        let st = Stabilization {
            alpha,
            beta,
            projection: false,
        };
        // seven directions: four of the state (mixed columns), then m, l, g one at a time
        let dirs = 7;
        let mut seeds = vec![0.0; dirs * 3];
        for k in 0..3 {
            seeds[(4 + k) * 3 + k] = 1.0;
        }
        let sens = LagrangeSensitive::new(&tangent, &P, &[], st, &seeds, dirs, true).unwrap();
        // off the constraint on purpose (Baumgarte's terms see it), moving
        let y = [0.9, -1.1, 0.7, 0.4];
        let mut aug = vec![0.0; 4 * (1 + dirs)];
        aug[..4].copy_from_slice(&y);
        for k in 0..4 {
            for j in 0..dirs {
                aug[4 + k * dirs + j] = if j < 4 {
                    (0.3 + k as f64 - 0.7 * j as f64).sin()
                } else {
                    0.0
                };
            }
        }
        let mut out = vec![0.0; aug.len()];
        sens.rhs(0.2, &aug, &mut out);
        let rates = |y: &[f64], p: &[f64; 3]| {
            let sys = Lagrangian::new(&model, p, Constant(&[]), st, None).unwrap();
            let mut r = [0.0; 4];
            sys.rhs(0.2, y, &mut r);
            r
        };
        let plain = rates(&y, &P);
        for k in 0..4 {
            assert_eq!(out[k].to_bits(), plain[k].to_bits(), "rate {k}");
        }
        for j in 0..dirs {
            let moved = |h: f64| {
                let yj: Vec<f64> = (0..4).map(|k| y[k] + h * aug[4 + k * dirs + j]).collect();
                let pj: [f64; 3] = std::array::from_fn(|k| P[k] + h * seeds[j * 3 + k]);
                rates(&yj, &pj)
            };
            for k in 0..4 {
                let fd = richardson(|h| moved(h)[k], 1e-4);
                let exact = out[4 + k * dirs + j];
                assert!(
                    (exact - fd).abs() <= 1e-8 * (1.0 + fd.abs()),
                    "sign {sign}, α {alpha}: ∂rate {k}/∂direction {j}: {exact} against {fd}"
                );
            }
        }
    }
}
