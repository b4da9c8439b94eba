//! The events of a constrained system's run (`docs/lagrange.md`), one per [`Source`]: an
//! output of the user's compiled expressions of `[q, q̇, t]`, a callback (the slow path), or
//! the physical multiplier of a one-sided constraint in play, whose fall through zero is its
//! release (the KKT solve of \[L\] (6.60) at the state). [`LagrangeEvents`] gives their values
//! to [`crate::events::Watch`], which locates their zeros inside the time loop.

use std::cell::RefCell;

use super::{Inputs, Lagrangian};
use crate::events::EventFunctions;
use crate::expressions::{Function, Scratch};

/// Where an event of a constrained system's run comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// Output `k` of the compiled event expressions, a [`Function`] of `[q, q̇, t]`.
    Expression(usize),
    /// The user's callback `k` (the slow path: a Python function).
    Callback(usize),
    /// The physical multiplier λ_c of constraint `c` (numbered among all the model's
    /// constraints), which must be in play: a one-sided constraint lets go where it falls
    /// through zero (its reaction would have to pull).
    Release(usize),
}

/// Event functions the engine calls out for (the user's Python functions, in the bindings).
pub trait Callbacks {
    /// Callback `k` at `(t, y)`; `None` when it failed (its error kept by the implementor).
    fn value(&self, k: usize, t: f64, y: &[f64]) -> Option<f64>;
}

/// No callbacks: a run whose events are all compiled.
pub struct NoCallbacks;

impl Callbacks for NoCallbacks {
    fn value(&self, _: usize, _: f64, _: &[f64]) -> Option<f64> {
        None
    }
}

/// The events of a constrained system's run ([`crate::events`]), one per [`Source`], in order.
pub struct LagrangeEvents<'a, 'm, I: Inputs, C: Callbacks> {
    sys: &'a Lagrangian<'m, I>,
    sources: &'a [Source],
    expressions: Option<&'a Function>,
    callbacks: C,
    /// Per source: the index of its multiplier among the constraints in play.
    rank: Vec<usize>,
    scratch: RefCell<EventScratch>,
}

/// The expressions' working memory, inputs `[q, q̇, t]` and outputs.
type EventScratch = (Option<Scratch>, Vec<f64>, Vec<f64>);

impl<'a, 'm, I: Inputs, C: Callbacks> LagrangeEvents<'a, 'm, I, C> {
    /// Check `sources` against the system and the expressions (a function of `[q, q̇, t]`).
    pub fn new(
        sys: &'a Lagrangian<'m, I>,
        sources: &'a [Source],
        expressions: Option<&'a Function>,
        callbacks: C,
    ) -> Result<Self, String> {
        let s = sys.model.shape;
        let outputs = match expressions {
            Some(f) => {
                let p = f.program();
                if p.n_inputs != 2 * s.n + 1 {
                    return Err(format!(
                        "the events' expressions take {} values; [q, qd, t] ({}) are needed",
                        p.n_inputs,
                        2 * s.n + 1
                    ));
                }
                p.n_outputs
            }
            None => 0,
        };
        let in_play = |c: usize| sys.active.as_ref().map_or(true, |a| a[c]);
        let mut rank = vec![0; sources.len()];
        for (i, source) in sources.iter().enumerate() {
            match *source {
                Source::Expression(k) if k >= outputs => {
                    return Err(format!(
                        "event {i} is expression {k}, and the events' expressions have {outputs}"
                    ))
                }
                Source::Release(c) if c >= s.m || !in_play(c) => {
                    return Err(format!(
                        "event {i} watches the multiplier of constraint {c}, which is not in play"
                    ))
                }
                Source::Release(c) => rank[i] = (0..c).filter(|&j| in_play(j)).count(),
                _ => {}
            }
        }
        let scratch = (
            expressions.map(|f| f.scratch()),
            vec![0.0; 2 * s.n + 1],
            vec![0.0; outputs],
        );
        Ok(LagrangeEvents {
            sys,
            sources,
            expressions,
            callbacks,
            rank,
            scratch: RefCell::new(scratch),
        })
    }

    /// The compiled expressions at `(t, y)`, into the scratch's outputs.
    fn expressions_at(&self, t: f64, y: &[f64]) -> std::cell::RefMut<'_, EventScratch> {
        let mut sc = self.scratch.borrow_mut();
        if let Some(f) = self.expressions {
            let (mem, x, out) = &mut *sc;
            let dim = y.len();
            x[..dim].copy_from_slice(y);
            x[dim] = t;
            f.eval_in(mem.as_mut().expect("made with the function"), x, out);
        }
        sc
    }

    /// The physical multipliers of the constraints in play at `(t, y)` (NaN where the system
    /// is singular, or an input failed).
    fn multipliers(&self, t: f64, y: &[f64]) -> Option<Vec<f64>> {
        let n = self.sys.model.shape.n;
        self.sys
            .accelerations(t, &y[..n], &y[n..])
            .map(|(_, lam)| lam)
    }
}

impl<I: Inputs, C: Callbacks> EventFunctions for LagrangeEvents<'_, '_, I, C> {
    fn count(&self) -> usize {
        self.sources.len()
    }

    fn value(&self, k: usize, t: f64, y: &[f64]) -> Option<f64> {
        Some(match self.sources[k] {
            Source::Expression(j) => self.expressions_at(t, y).2[j],
            Source::Callback(j) => return self.callbacks.value(j, t, y),
            Source::Release(_) => self
                .multipliers(t, y)
                .map_or(f64::NAN, |lam| lam[self.rank[k]]),
        })
    }

    fn values(&self, t: f64, y: &[f64], out: &mut [f64]) -> bool {
        let has = |f: fn(&Source) -> bool| self.sources.iter().any(f);
        let lam = if has(|s| matches!(s, Source::Release(_))) {
            self.multipliers(t, y)
        } else {
            None
        };
        let sc = has(|s| matches!(s, Source::Expression(_))).then(|| self.expressions_at(t, y));
        for (k, o) in out.iter_mut().enumerate() {
            *o = match self.sources[k] {
                Source::Expression(j) => sc.as_ref().expect("evaluated above").2[j],
                Source::Callback(j) => match self.callbacks.value(j, t, y) {
                    Some(v) => v,
                    None => return false,
                },
                Source::Release(_) => lam.as_ref().map_or(f64::NAN, |l| l[self.rank[k]]),
            };
        }
        true
    }
}
