//! A block's time loops (`docs/ensembles.md`): the fixed-step methods through the single
//! runs' [`run_fixed`] ([`run_block`]), and adaptive Dormand–Prince 8(5,3) with each lane's
//! own step sizes ([`run_block_dop853`]: the stages and error norms across the lanes, the
//! controller, samples and checks lane by lane with the single run's functions), each compiled
//! once per instruction set and the widest the CPU offers chosen at run time; and the flips of
//! every lane ([`BlockFlips`]).

use std::sync::atomic::{AtomicBool, Ordering};

use super::{at, block_mut, gather, scatter, Block, BlockState, LaneRates, LANES};
use crate::drivers::{
    clamp_step, run_fixed, trial_step, Clock, Counters, FixedMethod, Output, Sampling, Status,
};
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

/// Write sample `i` of lane `l`: the state `y` into its block of `samples`.
#[inline(always)]
fn store(samples: &mut [f64], i: usize, y: &State, l: usize) {
    let row = STATE_SIZE * LANES;
    let r: &mut BlockState = (&mut samples[i * row..(i + 1) * row])
        .try_into()
        .expect("a sample");
    scatter(y, l, r);
}

/// The interpolant of lane `l`'s accepted step `(t, h)` from `y0` to `(y1, f1)`: the lane's
/// stages (its numbers in the block's `k`), three more, and the interpolant, by the single
/// run's [`dop853_dense`] on the lane's numbers.
#[inline(always)]
fn lane_dense<S: VectorField>(
    sys: &S,
    l: usize,
    k: &[f64],
    (t, h): (f64, f64),
    (y0, y1, f1): (&State, &State, &State),
) -> [f64; DOP853_INTERPOLATOR_POWER * STATE_SIZE] {
    let (n, row) = (STATE_SIZE, STATE_SIZE * LANES);
    let mut kl = [0.0; DOP853_STAGES_EXTENDED * STATE_SIZE];
    for s in 0..=DOP853_STAGES {
        for cc in 0..n {
            kl[s * n + cc] = k[s * row + at(cc, l)];
        }
    }
    let mut fd = [0.0; DOP853_INTERPOLATOR_POWER * STATE_SIZE];
    let mut ytmp = [0.0; STATE_SIZE];
    dop853_dense(sys, t, h, y0, y1, f1, &mut kl, &mut ytmp, &mut fd);
    fd
}

/// [`dop853_any`]'s run: what the lanes share (the block, the controller's settings, the end
/// `t1`, the sample times) and each lane's own controller, as the single run's
/// [`crate::drivers::run_adaptive`] keeps it: its status, counters and time, its step sizes
/// (the next `h_abs`, the trial's `h` to `t_new`, the smallest `min_step`), whether its last
/// trial was rejected, and whether its next trial starts a step (`fresh`).
struct LaneRun<'a, 'b, S, const SHARED: bool> {
    block: &'a Block<'b, S, SHARED>,
    control: &'a Control,
    t1: f64,
    t_eval: &'a [f64],
    status: [Status; LANES],
    counters: [Counters; LANES],
    t: [f64; LANES],
    h_abs: [f64; LANES],
    h: [f64; LANES],
    t_new: [f64; LANES],
    min_step: [f64; LANES],
    rejected: [bool; LANES],
    fresh: [bool; LANES],
}

impl<'a, 'b, S: LaneRates + VectorField, const SHARED: bool> LaneRun<'a, 'b, S, SHARED> {
    /// Every lane at `t0`, before its start ([`LaneRun::start`]).
    #[inline(always)]
    fn new(
        block: &'a Block<'b, S, SHARED>,
        control: &'a Control,
        (t0, t1): (f64, f64),
        t_eval: &'a [f64],
    ) -> Self {
        LaneRun {
            block,
            control,
            t1,
            t_eval,
            status: [Status::Running; LANES],
            counters: [Counters::default(); LANES],
            t: [t0; LANES],
            h_abs: [0.0; LANES],
            h: [0.0; LANES],
            t_new: [t0; LANES],
            min_step: [0.0; LANES],
            rejected: [false; LANES],
            fresh: [true; LANES], // the lane's next trial starts a step
        }
    }

    /// Each lane's start, as the single run's first call: `f` at `(t0, z)` (into the block
    /// `f`), the samples at `t0`, the first step size; finished at once when `t0` is the end
    /// or every sample time is written.
    #[inline(always)]
    fn start(&mut self, t0: f64, z: &BlockState, f: &mut [f64], samples: &mut [f64]) {
        let (control, t1) = (self.control, self.t1);
        let (mut ytmp, mut fnew) = ([0.0; STATE_SIZE], [0.0; STATE_SIZE]);
        for l in 0..LANES {
            let sys = self.block.lane(l);
            let y = gather(z, l);
            let fl = sys.rates(t0, &y);
            scatter(&fl, l, block_mut(f));
            let c = &mut self.counters[l];
            c.n_fev = 1;
            while let Some((i, _)) = c.next_due(self.t_eval, t0) {
                store(samples, i, &y, l);
            }
            self.h_abs[l] = if control.first_step > 0.0 {
                control.first_step
            } else {
                c.n_fev += 1;
                initial_step_size(sys, t0, &y, &fl, t1, 7.0, control, &mut ytmp, &mut fnew)
            };
            if t0 >= t1 || c.next_sample >= self.t_eval.len() {
                self.status[l] = Status::Finished;
            }
        }
    }

    /// Each running lane's trial step (the single run's clamp at a step's first trial,
    /// [`clamp_step`], then [`trial_step`]); `h` is 0 on a lane not running, and a lane whose
    /// step size fell below 10 ulps of t stops there.
    #[inline(always)]
    fn trials(&mut self) {
        for l in 0..LANES {
            self.h[l] = 0.0;
            if self.status[l] != Status::Running {
                continue;
            }
            if self.fresh[l] {
                self.min_step[l] = clamp_step(self.t[l], &mut self.h_abs[l], self.control.max_step);
                self.rejected[l] = false;
                self.fresh[l] = false;
            }
            match trial_step(self.t[l], &mut self.h_abs[l], self.min_step[l], self.t1) {
                Some((t_new, h)) => (self.t_new[l], self.h[l]) = (t_new, h),
                None => self.status[l] = Status::StepTooSmall,
            }
        }
    }

    /// The single run's controller on lane `l`'s trial with error norm `err`
    /// ([`step_size_factor`]): its evaluations counted and its step size scaled; true when
    /// the step is accepted, else (a NaN norm too, as the single run's `err < 1` test) the
    /// lane retries, the rejection counted.
    #[inline(always)]
    fn accept(&mut self, l: usize, err: f64) -> bool {
        let c = &mut self.counters[l];
        c.n_fev += DOP853_STAGES as u64;
        self.h_abs[l] *= step_size_factor(err, 7.0, self.rejected[l], self.control);
        if err < 1.0 {
            self.fresh[l] = true;
            return true;
        }
        self.rejected[l] = true;
        c.n_rejected += 1;
        false
    }

    /// Lane `l`'s accepted step, as the single run takes it: its end (the lane's numbers in
    /// `z_new`, its derivative the last stage in `k`) put back on the constraints with its
    /// derivative anew, the step counted, its flips observed, the end checked finite, the
    /// samples written ([`LaneRun::samples`]), and the end taken into `z` and `f`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn take(
        &mut self,
        l: usize,
        (k, z_new): (&[f64], &BlockState),
        z: &mut BlockState,
        f: &mut [f64],
        samples: &mut [f64],
        flips: Option<&mut BlockFlips>,
    ) {
        let sys = self.block.lane(l);
        let (t, t_new) = (self.t[l], self.t_new[l]);
        let y0 = gather(z, l);
        let mut y1 = gather(z_new, l);
        let mut f1: State = [0.0; STATE_SIZE];
        for (cc, x) in f1.iter_mut().enumerate() {
            *x = k[DOP853_STAGES * STATE_SIZE * LANES + at(cc, l)];
        }
        let c = &mut self.counters[l];
        if sys.project(t_new, &mut y1) {
            // about a pivot: the state put back on the constraint, its derivative anew
            sys.rhs(t_new, &y1, &mut f1);
            c.n_fev += 1;
        }
        c.n_steps += 1;
        if let Some(obs) = flips {
            let mut one = crate::observers::FlipObserver {
                first: &mut obs.first,
                last: &mut obs.last,
                count: &mut obs.count,
                offset: 0,
            };
            one.observe(l, t, &y0, t_new, &y1);
        }
        if !y1.iter().all(|x| x.is_finite()) {
            scatter(&y1, l, z);
            self.t[l] = t_new;
            self.status[l] = Status::NonFinite;
            return;
        }
        if self.samples(l, k, (&y0, &y1, &f1), samples) {
            self.status[l] = Status::Finished;
        }
        scatter(&y1, l, z);
        scatter(&f1, l, block_mut(f));
        self.t[l] = t_new;
        if self.t[l] >= self.t1 {
            self.status[l] = Status::Finished;
        }
    }

    /// Lane `l`'s samples due by the end of its accepted step from `y0` to `(y1, f1)`: the
    /// end itself, elsewhere the dense output ([`lane_dense`], made once, three more
    /// evaluations), projected. True once the last sample time is written.
    #[inline(always)]
    fn samples(
        &mut self,
        l: usize,
        k: &[f64],
        (y0, y1, f1): (&State, &State, &State),
        samples: &mut [f64],
    ) -> bool {
        let sys = self.block.lane(l);
        let (t, h, t_new) = (self.t[l], self.h[l], self.t_new[l]);
        let mut dense: Option<[f64; DOP853_INTERPOLATOR_POWER * STATE_SIZE]> = None;
        let c = &mut self.counters[l];
        while let Some((i, te)) = c.next_due(self.t_eval, t_new) {
            if te == t_new {
                store(samples, i, y1, l);
                continue;
            }
            let fd = dense.get_or_insert_with(|| lane_dense(sys, l, k, (t, h), (y0, y1, f1)));
            let mut sample = [0.0; STATE_SIZE];
            dop853_interpolate(fd, y0, (te - t) / h, &mut sample);
            sys.project(te, &mut sample);
            store(samples, i, &sample, l);
        }
        if dense.is_some() {
            c.n_fev += (DOP853_STAGES_EXTENDED - DOP853_STAGES - 1) as u64;
        }
        c.next_sample >= self.t_eval.len()
    }
}

/// The lanes' adaptive loop, inlined into each target's copy of it: the single run's
/// [`crate::drivers::run_adaptive`] lane by lane ([`LaneRun`]), the stages and error norms in
/// lanes.
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
    let row = STATE_SIZE * LANES;
    let z = block_mut(z);
    let mut k = vec![0.0; DOP853_STAGES_EXTENDED * row];
    let mut z_new = vec![0.0; row];
    let mut f = vec![0.0; row];
    let mut obs = BlockFlips::default();
    let mut run = LaneRun::new(block, control, (t0, t1), t_eval);
    run.start(t0, z, &mut f, samples);
    let mut rounds: u64 = 0;
    while run.status.contains(&Status::Running) {
        rounds += 1;
        if rounds % crate::drivers::STEPS_PER_CALL == 0 && stop.load(Ordering::Relaxed) {
            break;
        }
        run.trials();
        k[..row].copy_from_slice(&f);
        let zn: &mut BlockState = (&mut z_new[..]).try_into().expect("a block");
        dop853_stages(block, &run.t, &run.h, z, &mut k, zn);
        let err = dop853_errors(&k, &run.h, z, zn, control);
        // each lane: accept or retry; an accepted step observed, sampled and taken
        let zn: &BlockState = (&z_new[..]).try_into().expect("a block");
        for l in 0..LANES {
            if run.status[l] == Status::Running && run.accept(l, err[l]) {
                let flips = flips.then_some(&mut obs);
                run.take(l, (&k, zn), z, &mut f, samples, flips);
            }
        }
    }
    BlockAdaptiveRun {
        status: run.status,
        counters: run.counters,
        flips: flips.then_some(obs),
    }
}
