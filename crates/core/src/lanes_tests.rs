//! Tests of the lanes ([`super`]): every instruction set's copy of a block's loop and the
//! single runs give the same numbers, lane for member, with RK4, RKMK4 and the splitting
//! method.

use std::sync::atomic::AtomicBool;

use super::*;
use crate::drivers::{
    run_fixed, run_fixed_native, Clock, Counters, FixedMethod, Output, Rk4Rigid, Sampling, Status,
};
use crate::isa::Isa;
use crate::layout::{Body, OMEGA_AT, Q_AT};
use crate::observers::NoObserver;
use crate::systems::TorqueFree;

/// The torque-free RK4 step's fused multiply-adds round once on every instruction set:
/// the block's AVX-512, AVX2 + FMA and baseline copies (fma in software) give the same
/// numbers, and so do the single runs' baseline and native loops, lane for member.
#[test]
fn every_instruction_set_gives_the_same_numbers() {
    same_numbers_everywhere(BlockRk4, || Rk4Rigid);
}

/// RKMK4 and the splitting method in lanes (sines and cosines by polynomials, no fused
/// operations): every copy and every single run gives the same numbers, lane for member
/// (the splitting method's samples leave its momentum state).
#[test]
fn rkmk4_and_splitting_lanes_are_their_single_runs() {
    use crate::drivers::{RkmkRigid, Splitting};
    same_numbers_everywhere(BlockRkmk4, || RkmkRigid::new(crate::steppers::RK4));
    same_numbers_everywhere(BlockSplitting, || Splitting);
}

fn same_numbers_everywhere<M, N>(method: M, single: impl Fn() -> N)
where
    M: for<'a> FixedMethod<Block<'a, TorqueFree, true>> + Copy,
    N: FixedMethod<TorqueFree>,
{
    let moments = [1.0, 2.0, 3.5];
    let a = [0, 1, 2].map(|r| [0, 1, 2].map(|c| if r == c { moments[r] } else { 0.0 }));
    let body = Body::from_slice(&Body::vector(
        2.0, moments, [0.0; 3], &a, [0.0; 3], false, -1,
    ))
    .unwrap();
    let sys = [TorqueFree::new(body)];
    let block = Block::<_, true> { systems: &sys };
    let states = lane_states();
    let t_eval = [0.0, 0.37, 2.0];
    let span = (0.0, 2.0, 1e-2);
    let want = every_copy_alike(&block, method, &states, span, &t_eval);
    // each lane is its member's single run, with the baseline loop and the native one
    for l in [0, 1, LANES / 2 + 13, LANES - 1] {
        for native in [false, true] {
            let y_out = single_run(&sys[0], single(), &states[l], span, &t_eval, native);
            let mut lane = vec![0.0; t_eval.len() * STATE_SIZE];
            lane_samples(&want, l, &mut lane);
            assert!(
                lane.iter()
                    .zip(&y_out)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "lane {l}, native {native}"
            );
        }
    }
}

/// A state per lane: the identity attitude, ω near the intermediate axis and a position, each
/// a little different.
fn lane_states() -> Vec<State> {
    (0..LANES)
        .map(|l| {
            let s = l as f64;
            let mut y = [0.0; STATE_SIZE];
            y[Q_AT] = 1.0;
            y[Q_AT + 4] = 1.0;
            y[Q_AT + 8] = 1.0;
            y[OMEGA_AT..].copy_from_slice(&[0.05 * s.sin(), 1.0 + 0.01 * s, 0.05 * s.cos()]);
            y[3] = 0.1 * s;
            y
        })
        .collect()
}

/// The block's samples from `states` over `(t0, t1, dt)` with the dispatched copy, checked
/// finite and equal bit for bit to every available instruction set's copy.
fn every_copy_alike<M>(
    block: &Block<'_, TorqueFree, true>,
    method: M,
    states: &[State],
    (t0, t1, dt): (f64, f64, f64),
    t_eval: &[f64],
) -> Vec<f64>
where
    M: for<'a> FixedMethod<Block<'a, TorqueFree, true>> + Copy,
{
    let stop = AtomicBool::new(false);
    let run = |f: &dyn Fn(&mut [f64], &mut [f64])| {
        let mut z = block_state(states);
        let mut samples = vec![0.0; t_eval.len() * STATE_SIZE * LANES];
        f(&mut z, &mut samples);
        samples
    };
    let mut copies: Vec<(&str, Vec<f64>)> = vec![(
        "dispatched",
        run(&|z, y| {
            run_block(block, method, t0, t1, dt, t_eval, true, z, y, &stop);
        }),
    )];
    for isa in Isa::ALL.into_iter().filter(|isa| isa.available()) {
        let got = run(&|z, y| {
            run_block_with(isa, block, method, t0, t1, dt, t_eval, true, z, y, &stop);
        });
        copies.push((isa.name(), got));
    }
    let want = &copies[0].1;
    assert!(want.iter().all(|x| x.is_finite()));
    for (name, got) in &copies {
        assert!(
            got.iter()
                .zip(want)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{name}"
        );
    }
    copies.swap_remove(0).1
}

/// The samples of the single run of `sys` from `y0` over `(t0, t1, dt)` with `method`,
/// through the baseline loop ([`run_fixed`]) or the native one ([`run_fixed_native`]).
fn single_run<N: FixedMethod<TorqueFree>>(
    sys: &TorqueFree,
    mut method: N,
    y0: &State,
    (t0, t1, dt): (f64, f64, f64),
    t_eval: &[f64],
    native: bool,
) -> Vec<f64> {
    let mut z = [0.0; STATE_SIZE];
    method.init(sys, y0, &mut z);
    let mut t_out = vec![0.0; t_eval.len()];
    let mut y_out = vec![0.0; t_eval.len() * STATE_SIZE];
    let sampling = Sampling {
        t_end: t1,
        t_eval,
        every: 1,
    };
    let mut out = Output {
        t: &mut t_out,
        y: &mut y_out,
    };
    let run = if native { run_fixed_native } else { run_fixed };
    let status = run(
        sys,
        &mut method,
        &mut NoObserver,
        &mut Clock { t: t0, h: 0.0 },
        &mut z,
        dt,
        &sampling,
        &mut out,
        &mut Counters::default(),
        u64::MAX,
    );
    assert_eq!(status, Status::Finished);
    y_out
}
