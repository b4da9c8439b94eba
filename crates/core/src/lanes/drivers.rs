//! A block's time loops (`docs/ensembles.md`): the fixed-step methods through the single
//! runs' [`run_fixed`] ([`run_block`]), and adaptive Dormand–Prince 8(5,3) with each lane's
//! own step sizes ([`run_block_dop853`]: the stages and error norms across the lanes, the
//! controller, samples and checks lane by lane with the single run's functions), each compiled
//! once per instruction set and the widest the CPU offers chosen at run time; and the flips of
//! every lane ([`BlockFlips`]).

use std::sync::atomic::{AtomicBool, Ordering};

use super::{at, block_mut, gather, scatter, Block, BlockState, LaneRates, LANES};
use crate::drivers::{next_up, run_fixed, Clock, Counters, FixedMethod, Output, Sampling, Status};
use crate::layout::{OMEGA_AT, STATE_SIZE};
use crate::observers::Observer;
use crate::rigid::State;
use crate::steppers::{
    dop853_dense, dop853_interpolate, initial_step_size, step_size_factor, Control,
};
use crate::system::{RigidStructure, VectorField};
use crate::tableaux::{
    DOP853_A, DOP853_C, DOP853_E3, DOP853_E5, DOP853_INTERPOLATOR_POWER, DOP853_STAGES,
    DOP853_STAGES_EXTENDED,
};

/// The flips of every lane ([`crate::observers::FlipObserver`]'s rule, lane by lane): the
/// sign test runs on all lanes at once; the rare step with a flip records it lane by lane.
pub struct BlockFlips {
    pub first: [f64; LANES],
    pub last: [f64; LANES],
    pub count: [f64; LANES],
}

impl Default for BlockFlips {
    fn default() -> Self {
        BlockFlips {
            first: [f64::NAN; LANES],
            last: [f64::NAN; LANES],
            count: [0.0; LANES],
        }
    }
}

impl Observer for BlockFlips {
    #[inline(always)]
    fn observe(&mut self, _: usize, t0: f64, y0: &[f64], t1: f64, y1: &[f64]) {
        let (a, b) = (
            &y0[at(OMEGA_AT + 1, 0)..at(OMEGA_AT + 2, 0)],
            &y1[at(OMEGA_AT + 1, 0)..at(OMEGA_AT + 2, 0)],
        );
        // a flip has a · b ≤ 0, which one product and one compare per vector tell (the exact
        // rule below, four compares, runs for the rare step where some lane may have flipped:
        // a product of zero, an underflow, a flip)
        let mut any = false;
        for l in 0..LANES {
            any |= a[l] * b[l] <= 0.0;
        }
        if !any {
            return;
        }
        // the lanes that flipped take the new time, the others keep theirs: written without
        // branches, so that the whole block is a few vector instructions
        for l in 0..LANES {
            let (a, b) = (a[l], b[l]);
            let flip = (a < 0.0 && b >= 0.0) | (a > 0.0 && b <= 0.0);
            let t = t0 + (t1 - t0) * a / (a - b);
            let fresh = flip & (self.count[l] == 0.0);
            self.first[l] = if fresh { t } else { self.first[l] };
            self.last[l] = if flip { t } else { self.last[l] };
            self.count[l] += if flip { 1.0 } else { 0.0 };
        }
    }
}

/// Records nothing (a block without flips).
pub struct NoFlips;

impl Observer for NoFlips {
    #[inline(always)]
    fn observe(&mut self, _: usize, _: f64, _: &[f64], _: f64, _: &[f64]) {}
}

/// What a block's run leaves: its status, counters and (when watched) flips.
pub struct BlockRun {
    pub status: Status,
    pub counters: Counters,
    pub flips: Option<BlockFlips>,
}

crate::multiversion! {
    /// Integrate a block with a fixed-step `method` ([`BlockRk4`](super::BlockRk4),
    /// [`BlockRkmk4`](super::BlockRkmk4)) from `t0` to `t1` in steps of `dt`, landing on every
    /// time of
    /// `t_eval`: `z` (18 · LANES) the initial states, advanced in place; `samples`
    /// (len(t_eval) · 18 · LANES) the block's states at the sample times. The driver is the
    /// single runs' [`run_fixed`], resumed [`crate::drivers::STEPS_PER_CALL`] steps at a time
    /// until it ends or `stop` is raised.
    pub fn run_block, run_block_with [
        'a,
        S: RigidStructure + Sync,
        M: FixedMethod<Block<'a, S, SHARED>> + Copy,
        const SHARED: bool,
    ] (
        block: &Block<'a, S, SHARED>,
        method: M,
        t0: f64,
        t1: f64,
        dt: f64,
        t_eval: &[f64],
        flips: bool,
        z: &mut [f64],
        samples: &mut [f64],
        stop: &AtomicBool,
    ) -> BlockRun where [] => run_block_any, up to Avx512;
}

/// The block's time loop, inlined into each target's copy of it.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn run_block_any<
    'a,
    S: RigidStructure + Sync,
    M: FixedMethod<Block<'a, S, SHARED>> + Copy,
    const SHARED: bool,
>(
    block: &Block<'a, S, SHARED>,
    method: M,
    t0: f64,
    t1: f64,
    dt: f64,
    t_eval: &[f64],
    flips: bool,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> BlockRun {
    let mut times = vec![0.0; t_eval.len()];
    let mut out = Output {
        t: &mut times,
        y: samples,
    };
    let sampling = Sampling {
        t_end: t1,
        t_eval,
        every: u64::MAX,
    };
    let mut clock = Clock { t: t0, h: 0.0 };
    let mut k = Counters::default();
    let mut obs = BlockFlips::default();
    let mut method = method;
    // the method's own state (the splitting method's momenta), once per run
    let y0 = z.to_vec();
    method.init(block, &y0, z);
    let status = loop {
        let s = if flips {
            run_fixed(
                block,
                &mut method,
                &mut obs,
                &mut clock,
                z,
                dt,
                &sampling,
                &mut out,
                &mut k,
                crate::drivers::STEPS_PER_CALL,
            )
        } else {
            run_fixed(
                block,
                &mut method,
                &mut NoFlips,
                &mut clock,
                z,
                dt,
                &sampling,
                &mut out,
                &mut k,
                crate::drivers::STEPS_PER_CALL,
            )
        };
        if s != Status::Running || stop.load(Ordering::Relaxed) {
            break s;
        }
    };
    BlockRun {
        status,
        counters: k,
        flips: flips.then_some(obs),
    }
}

/// What a block's adaptive run leaves: each lane's status and counters (every lane its own
/// steps), and (when watched) the flips.
pub struct BlockAdaptiveRun {
    pub status: [Status; LANES],
    pub counters: [Counters; LANES],
    pub flips: Option<BlockFlips>,
}

crate::multiversion! {
    /// Adaptive Dormand–Prince 8(5,3) on every lane (free bodies, or built-in forces and a pivot),
    /// each lane with its own step sizes, bit for bit its single run ([`crate::drivers::run_adaptive`]): the lanes step in lock
    /// step, one trial step (accepted or rejected) per lane per round. The twelve stages and the
    /// error norms run for all lanes at once (structure of arrays, each lane's step size its own);
    /// the controller, the flips, the samples (dense output where a sample falls inside a step)
    /// and the checks run lane by lane, with the single run's own functions. `z` (18 · LANES) the
    /// initial states, advanced in place; `samples` (len(t_eval) · 18 · LANES). The instruction
    /// set is chosen at run time, as [`run_block`].
    pub fn run_block_dop853, run_block_dop853_with [
        S: LaneRates + VectorField,
        const SHARED: bool,
    ] (
        block: &Block<'_, S, SHARED>,
        control: &Control,
        t0: f64,
        t1: f64,
        t_eval: &[f64],
        flips: bool,
        z: &mut [f64],
        samples: &mut [f64],
        stop: &AtomicBool,
    ) -> BlockAdaptiveRun where [] => dop853_any, up to Avx512;
}

/// The stages of one DOP853 trial step on every lane, as [`dop853_step`] computes them for
/// one: `k` (16 · 18 · LANES) holds the stages (row 0 the lanes' `f`), `z_new` the 8th-order
/// solutions; then each lane's error norm ([`dop853_error_norm`]'s sums, in its order).
#[inline(always)]
fn dop853_stages<S: LaneRates + VectorField, const SHARED: bool>(
    block: &Block<'_, S, SHARED>,
    t: &[f64; LANES],
    h: &[f64; LANES],
    z: &BlockState,
    k: &mut [f64],
    z_new: &mut BlockState,
) {
    let row = STATE_SIZE * LANES;
    let mut ytmp = [0.0; STATE_SIZE * LANES];
    for st in 1..=DOP853_STAGES {
        for c in 0..STATE_SIZE {
            // the sum over the stages in their order, each lane's own
            let mut acc = [0.0; LANES];
            for (m, a) in DOP853_A[st][..st].iter().enumerate() {
                let km = &k[m * row + at(c, 0)..m * row + at(c, 0) + LANES];
                for l in 0..LANES {
                    acc[l] += a * km[l];
                }
            }
            for l in 0..LANES {
                ytmp[at(c, l)] = z[at(c, l)] + h[l] * acc[l];
            }
        }
        if st == DOP853_STAGES {
            z_new.copy_from_slice(&ytmp);
        }
        let kr: &mut BlockState = (&mut k[st * row..(st + 1) * row])
            .try_into()
            .expect("a stage");
        let mut ts = [0.0; LANES];
        for l in 0..LANES {
            ts[l] = t[l] + DOP853_C[st] * h[l];
        }
        S::rates_in_lanes(block, 0, &ts, &ytmp, kr);
    }
}

/// Each lane's error norm of the last trial step ([`dop853_error_norm`], its sums in its
/// order).
#[inline(always)]
fn dop853_errors(
    k: &[f64],
    h: &[f64; LANES],
    z: &BlockState,
    z_new: &BlockState,
    control: &Control,
) -> [f64; LANES] {
    let row = STATE_SIZE * LANES;
    let (rtol, atol) = (control.rtol, control.atol);
    let mut e5 = [0.0; LANES];
    let mut e3 = [0.0; LANES];
    for c in 0..STATE_SIZE {
        let mut a5 = [0.0; LANES];
        let mut a3 = [0.0; LANES];
        for s in 0..=DOP853_STAGES {
            let ks = &k[s * row + at(c, 0)..s * row + at(c, 0) + LANES];
            for l in 0..LANES {
                a5[l] += DOP853_E5[s] * ks[l];
                a3[l] += DOP853_E3[s] * ks[l];
            }
        }
        for l in 0..LANES {
            let i = at(c, l);
            let scale = atol + z[i].abs().max(z_new[i].abs()) * rtol;
            let (b5, b3) = (a5[l] / scale, a3[l] / scale);
            e5[l] += b5 * b5;
            e3[l] += b3 * b3;
        }
    }
    let mut err = [0.0; LANES];
    for l in 0..LANES {
        err[l] = if e5[l] == 0.0 && e3[l] == 0.0 {
            0.0
        } else {
            h[l].abs() * e5[l] / ((e5[l] + 0.01 * e3[l]) * STATE_SIZE as f64).sqrt()
        };
    }
    err
}

/// The lanes' adaptive loop, inlined into each target's copy of it: the single run's
/// [`crate::drivers::run_adaptive`] lane by lane, the stages and error norms in lanes.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn dop853_any<S: LaneRates + VectorField, const SHARED: bool>(
    block: &Block<'_, S, SHARED>,
    control: &Control,
    t0: f64,
    t1: f64,
    t_eval: &[f64],
    flips: bool,
    z: &mut [f64],
    samples: &mut [f64],
    stop: &AtomicBool,
) -> BlockAdaptiveRun {
    let n = STATE_SIZE;
    let row = STATE_SIZE * LANES;
    let n_eval = t_eval.len();
    let z = block_mut(z);
    let mut k = vec![0.0; DOP853_STAGES_EXTENDED * row];
    let mut z_new = vec![0.0; row];
    let mut f = vec![0.0; row];
    let mut obs = BlockFlips::default();
    let mut status = [Status::Running; LANES];
    let mut counters = [Counters::default(); LANES];
    let mut t = [t0; LANES];
    let mut h_abs = [0.0; LANES];
    let mut h = [0.0; LANES];
    let mut t_new = [t0; LANES];
    let mut min_step = [0.0; LANES];
    let mut rejected = [false; LANES];
    let mut fresh = [true; LANES]; // the lane's next trial starts a step
    let (mut ytmp, mut fnew) = ([0.0; STATE_SIZE], [0.0; STATE_SIZE]);
    let store = |samples: &mut [f64], i: usize, y: &State, l: usize| {
        let r: &mut BlockState = (&mut samples[i * row..(i + 1) * row])
            .try_into()
            .expect("a sample");
        scatter(y, l, r);
    };
    // each lane's start: f, the samples at t0, the first step
    for l in 0..LANES {
        let sys = block.lane(l);
        let y = gather(z, l);
        let fl = sys.rates(t0, &y);
        scatter(&fl, l, block_mut(&mut f));
        let c = &mut counters[l];
        c.n_fev = 1;
        while c.next_sample < n_eval && t_eval[c.next_sample] <= t0 {
            store(samples, c.n_out, &y, l);
            c.n_out += 1;
            c.next_sample += 1;
        }
        h_abs[l] = if control.first_step > 0.0 {
            control.first_step
        } else {
            c.n_fev += 1;
            initial_step_size(sys, t0, &y, &fl, t1, 7.0, control, &mut ytmp, &mut fnew)
        };
        if t0 >= t1 || c.next_sample >= n_eval {
            status[l] = Status::Finished;
        }
    }
    let mut rounds: u64 = 0;
    while status.contains(&Status::Running) {
        rounds += 1;
        if rounds % crate::drivers::STEPS_PER_CALL == 0 && stop.load(Ordering::Relaxed) {
            break;
        }
        // each running lane's trial step size (the single run's clamps and checks)
        for l in 0..LANES {
            h[l] = 0.0;
            if status[l] != Status::Running {
                continue;
            }
            if fresh[l] {
                min_step[l] = 10.0 * (next_up(t[l]) - t[l]).abs();
                if h_abs[l] > control.max_step {
                    h_abs[l] = control.max_step;
                } else if h_abs[l] < min_step[l] {
                    h_abs[l] = min_step[l];
                }
                rejected[l] = false;
                fresh[l] = false;
            }
            if h_abs[l] < min_step[l] {
                status[l] = Status::StepTooSmall;
                continue;
            }
            t_new[l] = t[l] + h_abs[l];
            if t_new[l] > t1 {
                t_new[l] = t1;
            }
            h[l] = t_new[l] - t[l];
            h_abs[l] = h[l].abs();
        }
        k[..row].copy_from_slice(&f);
        let zn: &mut BlockState = (&mut z_new[..]).try_into().expect("a block");
        dop853_stages(block, &t, &h, z, &mut k, zn);
        let err = dop853_errors(&k, &h, z, zn, control);
        // each lane: accept or retry; an accepted step observed, sampled and taken
        let zn: &BlockState = (&z_new[..]).try_into().expect("a block");
        for l in 0..LANES {
            if status[l] != Status::Running {
                continue;
            }
            let c = &mut counters[l];
            c.n_fev += DOP853_STAGES as u64;
            h_abs[l] *= step_size_factor(err[l], 7.0, rejected[l], control);
            let accepted = err[l] < 1.0;
            if !accepted {
                // rejected (a NaN norm too, as the single run's `err < 1` test)
                rejected[l] = true;
                c.n_rejected += 1;
                continue;
            }
            fresh[l] = true;
            let sys = block.lane(l);
            let y0 = gather(z, l);
            let mut y1 = gather(zn, l);
            let mut f1: State = [0.0; STATE_SIZE];
            for cc in 0..n {
                f1[cc] = k[DOP853_STAGES * row + at(cc, l)];
            }
            if sys.project(t_new[l], &mut y1) {
                // about a pivot: the state put back on the constraint, its derivative anew
                sys.rhs(t_new[l], &y1, &mut f1);
                c.n_fev += 1;
            }
            c.n_steps += 1;
            if flips {
                let mut one = crate::observers::FlipObserver {
                    first: &mut obs.first,
                    last: &mut obs.last,
                    count: &mut obs.count,
                    offset: 0,
                };
                one.observe(l, t[l], &y0, t_new[l], &y1);
            }
            let y1_finite = y1.iter().all(|x| x.is_finite());
            if !y1_finite {
                scatter(&y1, l, z);
                t[l] = t_new[l];
                status[l] = Status::NonFinite;
                continue;
            }
            let mut dense: Option<[f64; DOP853_INTERPOLATOR_POWER * STATE_SIZE]> = None;
            while c.next_sample < n_eval && t_eval[c.next_sample] <= t_new[l] {
                let te = t_eval[c.next_sample];
                if te == t_new[l] {
                    store(samples, c.n_out, &y1, l);
                } else {
                    let fd = dense.get_or_insert_with(|| {
                        // the lane's stages, three more, and the interpolant (the single
                        // run's dop853_dense on the lane's numbers)
                        let mut kl = [0.0; DOP853_STAGES_EXTENDED * STATE_SIZE];
                        for s in 0..=DOP853_STAGES {
                            for cc in 0..n {
                                kl[s * n + cc] = k[s * row + at(cc, l)];
                            }
                        }
                        let mut fd = [0.0; DOP853_INTERPOLATOR_POWER * STATE_SIZE];
                        dop853_dense(sys, t[l], h[l], &y0, &y1, &f1, &mut kl, &mut ytmp, &mut fd);
                        c.n_fev += (DOP853_STAGES_EXTENDED - DOP853_STAGES - 1) as u64;
                        fd
                    });
                    let mut sample = [0.0; STATE_SIZE];
                    dop853_interpolate(fd, &y0, (te - t[l]) / h[l], &mut sample);
                    sys.project(te, &mut sample);
                    store(samples, c.n_out, &sample, l);
                }
                c.n_out += 1;
                c.next_sample += 1;
            }
            if c.next_sample >= n_eval {
                status[l] = Status::Finished;
            }
            scatter(&y1, l, z);
            scatter(&f1, l, block_mut(&mut f));
            t[l] = t_new[l];
            if t[l] >= t1 {
                status[l] = Status::Finished;
            }
        }
    }
    BlockAdaptiveRun {
        status,
        counters,
        flips: flips.then_some(obs),
    }
}
