//! Observers: what a driver records of every step without storing the trajectory.
//!
//! A driver calls [`Observer::observe`] after each step of member `lane` from `(t0, y0)` to
//! `(t1, y1)` (engine states, principal frame). [`NoObserver`] compiles to nothing;
//! [`FlipObserver`] counts the flips of the tennis-racket (Dzhanibekov) motion;
//! [`crate::events::Watch`] locates the zeros of events and may end the run.

use crate::layout::OMEGA_AT;

/// What a driver records of each step.
pub trait Observer {
    fn observe(&mut self, lane: usize, t0: f64, y0: &[f64], t1: f64, y1: &[f64]);

    /// True for an observer that watches events ([`crate::events::Watch`]): the single-run
    /// drivers then call [`Observer::watch`] after every step (a constant, so that other
    /// observers pay nothing).
    const WATCHES: bool = false;

    /// After a step from `(t0, y0)` to `(t1, y1)`, with `at(t, out)` the state at any time of
    /// the step: `Some(t)` ends the run at `t` (a terminal event), where the driver leaves
    /// the state.
    fn watch(
        &mut self,
        _t0: f64,
        _y0: &[f64],
        _t1: f64,
        _y1: &[f64],
        _at: &mut dyn FnMut(f64, &mut [f64]),
    ) -> Option<f64> {
        None
    }

    /// True when watching failed (a user callback raised): the driver stops.
    fn watch_failed(&self) -> bool {
        false
    }
}

/// Records nothing.
pub struct NoObserver;

impl Observer for NoObserver {
    #[inline(always)]
    fn observe(&mut self, _: usize, _: f64, _: &[f64], _: f64, _: &[f64]) {}
}

/// Per member: `first` and `last` flip times (NaN before a flip) and `count`: the sign
/// changes of ω along the intermediate principal axis (component 1 of the principal frame,
/// moments ascending), the crossing time interpolated linearly within the step (O(h²)).
/// Lane `i` is member `i + offset`.
pub struct FlipObserver<'a> {
    pub first: &'a mut [f64],
    pub last: &'a mut [f64],
    pub count: &'a mut [f64],
    pub offset: usize,
}

impl Observer for FlipObserver<'_> {
    #[inline(always)]
    fn observe(&mut self, lane: usize, t0: f64, y0: &[f64], t1: f64, y1: &[f64]) {
        let a = y0[OMEGA_AT + 1];
        let b = y1[OMEGA_AT + 1];
        if (a < 0.0 && b >= 0.0) || (a > 0.0 && b <= 0.0) {
            let t = t0 + (t1 - t0) * a / (a - b);
            let k = lane + self.offset;
            if self.count[k] == 0.0 {
                self.first[k] = t;
            }
            self.last[k] = t;
            self.count[k] += 1.0;
        }
    }
}
