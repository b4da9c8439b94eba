//! Tests of the ensembles ([`super`]): a member is a single-body run, members in lanes are
//! their single runs bit for bit (free, under forces, about a pivot, every method in lanes),
//! torque-free members conserve energy and momentum, flips are counted per member, a failing
//! member gets its own status, and a raised flag stops every member.

use super::blocks::{lane_systems, LaneSystems};
use super::*;
use crate::drivers::{run_fixed_native, Clock, Counters, Output, Rk4Rigid, Sampling, Status};
use crate::forces::{Force, ForceKind};
use crate::layout::{Body, BODY_SIZE, FORCE_PARAMS, OMEGA_AT};
use crate::observers::NoObserver;
use crate::rigid::{initial_state, pivot_point, state_from_principal, State};
use crate::so3::{Mat3, Vec3};
use crate::steppers::{Control, Tableau};
use crate::systems::TorqueFree;
use crate::tableaux::{RK4_A, RK4_B, RK4_C};

const CONTROL: Control = Control::with_tolerances(1e-10, 1e-12);

fn rot(a: f64, b: f64) -> Mat3 {
    let (sa, ca) = a.sin_cos();
    let (sb, cb) = b.sin_cos();
    // rotation about z by a, then about x by b
    let rz = [[ca, -sa, 0.0], [sa, ca, 0.0], [0.0, 0.0, 1.0]];
    let rx = [[1.0, 0.0, 0.0], [0.0, cb, -sb], [0.0, sb, cb]];
    crate::so3::matmul(&rz, &rx)
}

/// A body with a tilted inertia tensor, its members' initial states and bodies.
fn members(n: usize, pivot: bool) -> (Vec<State>, [f64; BODY_SIZE], Mat3, Mat3) {
    let e = rot(0.3, 0.7);
    let d = [1.0, 2.0, 3.5];
    let mut a = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            a[i][j] = (0..3).map(|k| e[i][k] * d[k] * e[j][k]).sum();
        }
    }
    let c = if pivot { [0.1, -0.2, 0.4] } else { [0.0; 3] };
    let (params, axes, _) = member_body(2.0, &a, c, pivot);
    let y0 = (0..n)
        .map(|i| {
            let s = i as f64;
            let w = [0.05 * s.sin(), 1.0 + 0.1 * s, 0.05 * s.cos()];
            initial_state(
                &rot(0.2 * s, 0.1),
                w,
                None,
                None,
                [0.5, 0.0, 0.0],
                c,
                [0.0; 3],
                pivot,
                [0.0; 3],
            )
        })
        .collect();
    (y0, params, axes, a)
}

fn schedule<'a>(method: Method<'a>, t_eval: &'a [f64]) -> Schedule<'a> {
    Schedule {
        method,
        t0: 0.0,
        t1: *t_eval.last().unwrap(),
        dt: 1e-2,
        t_eval,
        flips: true,
        max_steps: u64::MAX,
    }
}

/// A member equals the single-body run of the same system and driver, bit for bit.
#[test]
fn a_member_is_a_single_body_run() {
    let (y0, params, axes, a) = members(3, false);
    let body = Body::from_slice(&params).unwrap();
    let t_eval: Vec<f64> = (0..=20).map(|k| 0.25 * k as f64).collect();
    let s = schedule(Method::Rk4, &t_eval);
    let member = Member::new(body, axes, a, &[], y0[2]);
    let mut samples = vec![0.0; t_eval.len() * STATE_SIZE];
    let summary = run_member(&s, &member, &mut samples, &AtomicBool::new(false));
    assert_eq!(summary.status, Status::Finished);
    // the single-body route: one call of the driver, no chunks, samples converted here
    let sys = TorqueFree::new(body);
    let mut z = principal(&axes, &y0[2]);
    let mut t_out = vec![0.0; t_eval.len()];
    let mut y_out = vec![0.0; t_eval.len() * STATE_SIZE];
    let mut k = Counters::default();
    let status = run_fixed_native(
        &sys,
        &mut Rk4Rigid,
        &mut NoObserver,
        &mut Clock { t: 0.0, h: 0.0 },
        &mut z,
        1e-2,
        &Sampling {
            t_end: 5.0,
            t_eval: &t_eval,
            every: 1,
        },
        &mut Output {
            t: &mut t_out,
            y: &mut y_out,
        },
        &mut k,
        u64::MAX,
    );
    assert_eq!(status, Status::Finished);
    assert_eq!(summary.n_steps, k.n_steps);
    assert_eq!(summary.n_fev, k.n_fev);
    for (row, got) in y_out
        .chunks_exact(STATE_SIZE)
        .zip(samples.chunks_exact(STATE_SIZE))
    {
        let mut y = [0.0; STATE_SIZE];
        state_from_principal(&axes, row, &mut y);
        assert_eq!(&y[..], got);
    }
}

/// RK4 and DOP853 members in SIMD lanes (DOP853: each lane its own step sizes, samples
/// between steps from its dense output) equal their single runs bit for bit — samples,
/// finals, counters, drifts and flips — with one shared body, with a body per member, under
/// forces about a pivot (the state projected after each step and at each sample), in a
/// partial block (padded lanes), and (RK4) with a member whose state stops being finite
/// (the block then runs member by member, each with its own status).
#[test]
fn members_in_lanes_are_their_single_runs() {
    let t_eval: Vec<f64> = (0..=8).map(|k| 0.125 * k as f64).collect();
    for method in [
        Method::Rk4,
        Method::Dop853(CONTROL),
        Method::Rkmk(crate::steppers::RK4),
        Method::Splitting,
    ] {
        lanes_are_single_runs(method, &t_eval);
    }
}

/// The exact-flow splittings in lanes ([`crate::lanes::BlockExactSplitting`]: the free flows
/// in SIMD lanes where every lane's body is the same, the kicks lane by lane) are their single
/// runs bit for bit, in every case above: torque-free members (every flow after the first goes
/// on along its motion), a body per member (the flows one by one), a member that cannot run,
/// under each force, free (Kepler's drift under central gravity) and about a pivot; with a
/// composition that starts with a kick (Strang's, Blanes & Moan's SRKN₆ᵇ) and one that starts
/// with a flow (SRKN₁₄ᵃ: the last flow of a step goes on along its motion into the next).
#[test]
fn exact_splittings_in_lanes_are_their_single_runs() {
    use crate::exact_splitting::Composition;
    use crate::tableaux::{BM4_FLOWS, BM4_KICKS, BM6_FLOWS, BM6_KICKS, STRANG_FLOWS, STRANG_KICKS};
    let t_eval: Vec<f64> = (0..=8).map(|k| 0.125 * k as f64).collect();
    for (kick_first, flows, kicks) in [
        (true, &STRANG_FLOWS[..], &STRANG_KICKS[..]),
        (true, &BM4_FLOWS[..], &BM4_KICKS[..]),
        (false, &BM6_FLOWS[..], &BM6_KICKS[..]),
    ] {
        let c = Composition::new(kick_first, flows, kicks).unwrap();
        lanes_are_single_runs(Method::ExactSplitting(c), &t_eval);
    }
}

/// A built-in force of `kind` with its first parameters `p`.
fn force(kind: ForceKind, p: &[f64]) -> Force {
    let mut params = [0.0; FORCE_PARAMS];
    params[..p.len()].copy_from_slice(p);
    Force { kind, p: params }
}

/// The lanes' cases: whether the members turn about a pivot, and their forces. In
/// lanes as [`OneForce`]: a pivot alone, uniform gravity free and about a pivot, central
/// gravity with its gradient torque free and about a pivot; as [`Rigid`]: two forces
/// (RK4 and DOP853; the other methods member by member), one force of a kind not compiled
/// in lanes.
fn forced_cases() -> Vec<(bool, Vec<Force>, LaneSystems)> {
    let gravity = force(ForceKind::Gravity, &[0.0, 0.0, -9.8]);
    let central = force(ForceKind::CentralGravity, &[40.0, -6.0, 1.0, 0.5, 1.0]);
    let drag = force(ForceKind::LinearDrag, &[0.3, 0.05]);
    // a damped tether from the body point (0.1, 0, 0) to (0, 0, 2), rest length 1
    let tether = force(
        ForceKind::Spring,
        &[0.1, 0.0, 0.0, 0.0, 0.0, 2.0, 5.0, 1.0, 0.2, 1.0],
    );
    let quadratic = force(ForceKind::QuadraticDrag, &[0.1, 0.02]);
    // a body-fixed force at the body point (0, 0.2, 0)
    let thrust = force(ForceKind::PointForce, &[0.0, 0.2, 0.0, 0.3, 0.0, 0.1, 1.0]);
    let couple = force(ForceKind::Torque, &[0.05, 0.0, 0.02, 0.0]);
    let body_couple = force(ForceKind::Torque, &[0.0, 0.1, 0.0, 1.0]);
    vec![
        (true, vec![], LaneSystems::One(0, true)),
        (false, vec![gravity], LaneSystems::One(1, false)),
        (true, vec![gravity], LaneSystems::One(1, true)),
        (false, vec![central], LaneSystems::One(2, false)),
        (true, vec![central], LaneSystems::One(2, true)),
        (true, vec![gravity, drag], LaneSystems::Forces),
        (false, vec![drag], LaneSystems::Forces),
        // every other kind, several at once: each force for the whole block at once
        (
            false,
            vec![tether, quadratic, thrust, couple],
            LaneSystems::Forces,
        ),
        (
            true,
            vec![body_couple, gravity, central],
            LaneSystems::Forces,
        ),
        // the last case: every other member has the forces in the other order, so the
        // block's kinds differ from lane to lane (each lane its own Rigid)
        (false, vec![drag, gravity], LaneSystems::Forces),
    ]
}

fn lanes_are_single_runs(method: Method, t_eval: &[f64]) {
    let dop853 = matches!(method, Method::Dop853(_));
    let s = schedule(method, t_eval);
    let stop = AtomicBool::new(false);
    let forced = forced_cases();
    let n = LANES + LANES / 2 + 3; // one full block, one partial
    for case in 0..3 + forced.len() {
        if dop853 && case == 2 {
            continue; // a state not finite from the start: the fixed-step methods' check
        }
        // 0: one shared body; 1: a body per member; 2: a member that cannot run; then
        // the forced cases
        let (pivot, forces, systems) = match case {
            0..=2 => (false, vec![], LaneSystems::Free),
            _ => forced[case - 3].clone(),
        };
        let (mut y0, params, axes, a) = members(n, pivot);
        if case == 2 {
            y0[LANES + 5][OMEGA_AT] = f64::INFINITY;
        }
        let body = Body::from_slice(&params).unwrap();
        let reversed: Vec<Force> = forces.iter().rev().copied().collect();
        let ms: Vec<Member> = (0..n)
            .map(|i| {
                let mut b = body;
                if case == 1 || case == 4 {
                    // a body per member: moments scaled
                    let f = 1.0 + 0.01 * i as f64;
                    b.moments = b.moments.map(|x| x * f);
                    b.inv_moments = b.inv_moments.map(|x| x / f);
                }
                let forces = if case == 2 + forced.len() && i % 2 == 1 {
                    &reversed
                } else {
                    &forces
                };
                Member::new(b, axes, a, forces, y0[i])
            })
            .collect();
        assert_eq!(lane_systems(&ms[..LANES]), systems, "case {case}");
        let per = t_eval.len() * STATE_SIZE;
        let mut samples = vec![0.0; n * per];
        let mut finals = vec![0.0; n * STATE_SIZE];
        let mut sums = vec![MemberSummary::default(); n];
        run_members(&s, &ms, Some(&mut samples), &mut finals, &mut sums, &stop);
        for (i, m) in ms.iter().enumerate() {
            let mut one = vec![0.0; per];
            let single = run_member(&s, m, &mut one, &stop);
            let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
            assert!(
                one.iter()
                    .zip(&samples[i * per..(i + 1) * per])
                    .all(|(a, b)| same(*a, *b)),
                "{method:?} case {case}, member {i}: samples"
            );
            let got = sums[i];
            assert_eq!(got.status, single.status, "case {case}, member {i}");
            assert_eq!(
                got.status,
                if case == 2 && i == LANES + 5 {
                    Status::NonFinite
                } else {
                    Status::Finished
                }
            );
            assert_eq!((got.n_steps, got.n_fev), (single.n_steps, single.n_fev));
            for (a, b) in [
                (got.energy, single.energy),
                (got.momentum, single.momentum),
                (got.orthogonality, single.orthogonality),
                (got.first_flip, single.first_flip),
                (got.last_flip, single.last_flip),
            ] {
                assert!(same(a, b), "case {case}, member {i}: {a} vs {b}");
            }
            assert_eq!(got.flip_count, single.flip_count);
        }
    }
}

/// Torque-free members keep their energy and |L| (each method to its error), Q stays
/// orthogonal (to round-off for the Lie-group methods), and the drifts computed on the fly are those of the
/// stored samples.
#[test]
fn torque_free_members_conserve_energy_and_momentum() {
    let (y0, params, axes, a) = members(16, false);
    let body = Body::from_slice(&params).unwrap();
    let ms: Vec<Member> = y0
        .iter()
        .map(|y| Member::new(body, axes, a, &[], *y))
        .collect();
    let t_eval: Vec<f64> = (0..=40).map(|k| 0.5 * k as f64).collect();
    let a_flat = RK4_A.concat();
    let tab = Tableau {
        a: &a_flat,
        b: &RK4_B,
        c: &RK4_C,
    };
    // (method, tolerance of the invariants, of QᵀQ = I: the Lie-group methods keep it)
    for (method, tol, tol_q) in [
        (Method::Rk4, 1e-6, 1e-6),
        (Method::Erk(tab), 1e-6, 1e-6),
        (Method::Rkmk(tab), 1e-6, 1e-13),
        (Method::Splitting, 1e-3, 1e-13),
        (Method::Dop853(CONTROL), 1e-8, 1e-8),
    ] {
        let s = schedule(method, &t_eval);
        let m = ms.len();
        let mut samples = vec![0.0; m * t_eval.len() * STATE_SIZE];
        let mut finals = vec![0.0; m * STATE_SIZE];
        let mut sums = vec![MemberSummary::default(); m];
        let stop = AtomicBool::new(false);
        run_members(&s, &ms, Some(&mut samples), &mut finals, &mut sums, &stop);
        for (i, sum) in sums.iter().enumerate() {
            assert_eq!(sum.status, Status::Finished, "{method:?}");
            assert!(sum.energy < tol && sum.momentum < tol, "{method:?} {sum:?}");
            assert!(sum.orthogonality < tol_q, "{method:?} {sum:?}");
            // the drifts again, from the stored samples by the invariants directly
            let w0 = [y0[i][15], y0[i][16], y0[i][17]];
            let e0 = crate::invariants::rotational_energy(&a, w0);
            let mut de: f64 = 0.0;
            for row in samples[i * t_eval.len() * STATE_SIZE..][..t_eval.len() * STATE_SIZE]
                .chunks_exact(STATE_SIZE)
            {
                let e = crate::invariants::rotational_energy(&a, [row[15], row[16], row[17]]);
                de = de.max((e - e0).abs() / e0);
            }
            assert!((de - sum.energy).abs() <= 1e-15, "{de} {}", sum.energy);
            let last = &samples[(i + 1) * t_eval.len() * STATE_SIZE - STATE_SIZE..][..STATE_SIZE];
            assert_eq!(&finals[i * STATE_SIZE..(i + 1) * STATE_SIZE], last);
        }
        // no samples stored: the same summaries and final states
        let mut finals2 = vec![0.0; m * STATE_SIZE];
        let mut sums2 = vec![MemberSummary::default(); m];
        run_members(&s, &ms, None, &mut finals2, &mut sums2, &stop);
        assert_eq!(finals, finals2, "{method:?}");
        assert_eq!(sums, sums2);
    }
}

/// Members near the intermediate axis flip (the tennis-racket effect); a steady spin
/// about the largest axis never does.
#[test]
fn flips_are_counted_per_member() {
    let d = [1.0, 2.0, 3.0];
    let a = [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]];
    let (params, axes, _) = member_body(1.0, &a, [0.0; 3], false);
    let body = Body::from_slice(&params).unwrap();
    let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let y = |w: Vec3| {
        initial_state(
            &eye, w, None, None, [0.0; 3], [0.0; 3], [0.0; 3], false, [0.0; 3],
        )
    };
    let ms = [
        Member::new(body, axes, a, &[], y([1e-3, 1.0, 1e-3])),
        Member::new(body, axes, a, &[], y([0.0, 0.0, 1.0])),
    ];
    let t_eval = [60.0];
    let s = schedule(Method::Dop853(CONTROL), &t_eval);
    let mut finals = vec![0.0; 2 * STATE_SIZE];
    let mut sums = vec![MemberSummary::default(); 2];
    run_members(
        &s,
        &ms,
        None,
        &mut finals,
        &mut sums,
        &AtomicBool::new(false),
    );
    assert!(sums[0].flip_count >= 2, "{:?}", sums[0]);
    assert!(sums[0].first_flip > 0.0 && sums[0].last_flip > sums[0].first_flip);
    assert_eq!(sums[1].flip_count, 0);
    assert!(sums[1].first_flip.is_nan());
}

/// A member that overflows fails alone; its neighbours are unchanged, bit for bit.
#[test]
fn a_failing_member_gets_its_own_status() {
    let (mut y0, params, axes, a) = members(5, true);
    let body = Body::from_slice(&params).unwrap();
    let gravity = Force {
        kind: ForceKind::Gravity,
        p: {
            let mut p = [0.0; FORCE_PARAMS];
            p[2] = -9.8;
            p
        },
    };
    let forces = [gravity];
    let t_eval = [0.5, 1.0];
    let s = schedule(Method::Rk4, &t_eval);
    let run = |y0: &[State]| {
        let ms: Vec<Member> = y0
            .iter()
            .map(|y| Member::new(body, axes, a, &forces, *y))
            .collect();
        let mut finals = vec![0.0; y0.len() * STATE_SIZE];
        let mut sums = vec![MemberSummary::default(); y0.len()];
        run_members(
            &s,
            &ms,
            None,
            &mut finals,
            &mut sums,
            &AtomicBool::new(false),
        );
        (finals, sums)
    };
    let (good, good_sums) = run(&y0);
    y0[2][16] = 1e200;
    let (bad, bad_sums) = run(&y0);
    assert_eq!(bad_sums[2].status, Status::NonFinite);
    assert!(bad_sums[2].energy.is_nan());
    assert!(bad[2 * STATE_SIZE..3 * STATE_SIZE]
        .iter()
        .all(|x| x.is_nan()));
    for i in [0, 1, 3, 4] {
        assert_eq!(good_sums[i], bad_sums[i]);
        assert_eq!(
            good[i * STATE_SIZE..(i + 1) * STATE_SIZE],
            bad[i * STATE_SIZE..(i + 1) * STATE_SIZE]
        );
    }
    // about a pivot the pivot stays where the initial state put it
    let m = Member::new(body, axes, a, &forces, y0[0]);
    let z0 = principal(&axes, &y0[0]);
    assert_eq!(pivot_point(&m.body, &z0), m.body.pivot);
}

/// A raised stop flag: no member runs.
#[test]
fn a_raised_flag_stops_every_member() {
    let (y0, params, axes, a) = members(8, false);
    let body = Body::from_slice(&params).unwrap();
    let ms: Vec<Member> = y0
        .iter()
        .map(|y| Member::new(body, axes, a, &[], *y))
        .collect();
    let t_eval = [1e6];
    let s = schedule(Method::Rk4, &t_eval);
    let mut finals = vec![0.0; 8 * STATE_SIZE];
    let mut sums = vec![MemberSummary::default(); 8];
    run_members(
        &s,
        &ms,
        None,
        &mut finals,
        &mut sums,
        &AtomicBool::new(true),
    );
    assert!(sums.iter().all(|s| s.status == Status::Running));
}
