//! Tests of the forward sensitivities: the dual right-hand side against the plain one (the
//! value bit for bit) and against central differences of it (an independent route), for
//! every built-in force, free and about a pivot.

use super::*;
use crate::forces::ForceKind;
use crate::system::RigidStructure;
use crate::systems::Rigid;

fn body(pivot: bool) -> Body {
    let moments = [1.0, 2.0, 3.5];
    let a = [[1.2, 0.0, 0.0], [0.0, 2.1, 0.0], [0.0, 0.0, 3.0]];
    Body::from_slice(&Body::vector(
        2.0,
        moments,
        if pivot { [0.1, -0.2, 0.4] } else { [0.0; 3] },
        &a,
        [0.3, 0.0, -0.1],
        pivot,
        -1,
    ))
    .unwrap()
}

fn forces() -> Vec<Force> {
    let row = |v: &[f64]| {
        let mut p = [0.0; FORCE_PARAMS];
        p[..v.len()].copy_from_slice(v);
        p
    };
    vec![
        Force {
            kind: ForceKind::Gravity,
            p: row(&[0.1, -0.2, -9.8]),
        },
        Force {
            kind: ForceKind::CentralGravity,
            p: row(&[3.0, 5.0, -4.0, 2.0, 1.0]),
        },
        Force {
            kind: ForceKind::Spring,
            p: row(&[0.1, -0.2, 0.3, 2.0, 1.0, -1.0, 7.0, 0.5, 0.3, 0.0]),
        },
        Force {
            kind: ForceKind::LinearDrag,
            p: row(&[0.2, 0.1]),
        },
        Force {
            kind: ForceKind::QuadraticDrag,
            p: row(&[0.3, 0.05]),
        },
        Force {
            kind: ForceKind::PointForce,
            p: row(&[0.2, 0.1, -0.3, 1.0, 2.0, -0.5, 1.0]),
        },
        Force {
            kind: ForceKind::Torque,
            p: row(&[0.2, -0.1, 0.3, 0.0]),
        },
    ]
}

fn state() -> State {
    let mut y = [0.0; STATE_SIZE];
    y[R_AT..R_AT + 3].copy_from_slice(&[0.4, -0.3, 0.2]);
    y[V_AT..V_AT + 3].copy_from_slice(&[0.1, 0.5, -0.2]);
    let q = exp_so3([0.3, -0.5, 0.9]);
    for i in 0..3 {
        y[Q_AT + 3 * i..Q_AT + 3 * i + 3].copy_from_slice(&q[i]);
    }
    y[OMEGA_AT..].copy_from_slice(&[0.7, -1.1, 0.4]);
    y
}

/// The directions of the test: 18 of the state, 3 moments, every parameter of every force.
fn system<'a>(body: Body, forces: &'a [Force]) -> Sensitive<'a> {
    let nf = forces.len();
    let p = STATE_SIZE + 3 + nf * FORCE_PARAMS;
    let mut moment_seeds = vec![[0.0; 3]; p];
    let mut force_seeds = vec![[0.0; FORCE_PARAMS]; p * nf];
    for k in 0..3 {
        moment_seeds[STATE_SIZE + k][k] = 1.0;
    }
    for i in 0..nf {
        for m in 0..FORCE_PARAMS {
            let j = STATE_SIZE + 3 + i * FORCE_PARAMS + m;
            force_seeds[j * nf + i][m] = 1.0;
        }
    }
    Sensitive::new(body, forces, &moment_seeds, &force_seeds, true)
}

fn rates(body: Body, forces: &[Force], y: &State) -> State {
    Rigid::<crate::systems::NoUser>::new(
        body,
        forces.to_vec(),
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        None,
    )
    .rates(0.0, y)
}

#[test]
fn the_dual_rates_are_the_rates_and_their_derivatives() {
    for pivot in [false, true] {
        let (b, f) = (body(pivot), forces());
        let sys = system(b, &f);
        let y = state();
        let mut aug = vec![0.0; sys.dim()];
        aug[..STATE_SIZE].copy_from_slice(&y);
        for i in 0..STATE_SIZE {
            aug[STATE_SIZE + sys.p * i + i] = 1.0;
        }
        let mut out = vec![0.0; sys.dim()];
        sys.rhs(0.0, &aug, &mut out);
        let plain = rates(b, &f, &y);
        for i in 0..STATE_SIZE {
            assert_eq!(out[i].to_bits(), plain[i].to_bits(), "value {i}");
        }
        // central differences of the plain rates, direction by direction
        let h = 1e-6;
        for j in 0..sys.p {
            let moved = |s: f64| {
                let (mut b2, mut f2, mut y2) = (b, f.clone(), y);
                if j < STATE_SIZE {
                    y2[j] += s;
                } else if j < STATE_SIZE + 3 {
                    let k = j - STATE_SIZE;
                    b2.moments[k] += s;
                    b2.inv_moments[k] = 1.0 / b2.moments[k];
                    b2.inertia_com[k][k] += s;
                } else {
                    let r = j - STATE_SIZE - 3;
                    f2[r / FORCE_PARAMS].p[r % FORCE_PARAMS] += s;
                }
                rates(b2, &f2, &y2)
            };
            let (up, down) = (moved(h), moved(-h));
            for i in 0..STATE_SIZE {
                let fd = (up[i] - down[i]) / (2.0 * h);
                let d = out[STATE_SIZE + sys.p * i + j];
                assert!(
                    (d - fd).abs() < 1e-7 * (1.0 + fd.abs()),
                    "pivot {pivot} dir {j} comp {i}: {d} vs {fd}"
                );
            }
        }
    }
}

#[test]
fn the_initial_columns_are_the_derivatives_of_the_initial_state() {
    // ω0 in the body frame moves ω by Eᵀ e_k; a turn of Q0 by δ̂ Q0; R0, V0 their own
    let b = body(false);
    let axes = exp_so3([0.2, 0.1, -0.4]);
    let z0 = state();
    let starts: Vec<Start> = (0..3)
        .flat_map(|k| {
            [
                Start::Omega(k),
                Start::Attitude(k),
                Start::Position(k),
                Start::Velocity(k),
            ]
        })
        .chain([Start::None])
        .collect();
    let out = initial_tangents(&b, &axes, &z0, &starts, false);
    assert_eq!(&out[..STATE_SIZE], &z0);
    for (j, s) in starts.iter().enumerate() {
        let col: Vec<f64> = (0..STATE_SIZE)
            .map(|i| out[STATE_SIZE + starts.len() * i + j])
            .collect();
        let mut want = [0.0; STATE_SIZE];
        match *s {
            Start::Omega(k) => {
                want[OMEGA_AT..OMEGA_AT + 3].copy_from_slice(&axes[k]);
            }
            Start::Attitude(k) => {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                for c in 0..3 {
                    let q = [z0[Q_AT + c], z0[Q_AT + 3 + c], z0[Q_AT + 6 + c]];
                    let x = crate::so3::cross(e, q);
                    for r in 0..3 {
                        want[Q_AT + 3 * r + c] = x[r];
                    }
                }
            }
            Start::Position(k) => want[R_AT + k] = 1.0,
            Start::Velocity(k) => want[V_AT + k] = 1.0,
            Start::None => {}
        }
        for i in 0..STATE_SIZE {
            assert!((col[i] - want[i]).abs() < 1e-15, "{s:?} {i}");
        }
    }
}

/// A carrier turning and accelerating in time.
struct Turning;

impl CarrierMotion for Turning {
    fn motion(&self, t: f64) -> Option<[f64; MOTION_SIZE]> {
        Some([
            0.1 + 0.05 * t,
            0.2,
            1.0 - 0.1 * t,
            0.05,
            0.0,
            -0.1,
            0.3,
            -0.2 * t,
            9.8,
        ])
    }
}

#[test]
fn the_relative_dual_rates_are_the_relative_rates_and_their_derivatives() {
    use crate::relative::Relative;
    let (b, f) = (body(false), forces());
    let nf = f.len();
    let p = RELATIVE_STATE_SIZE + 3 + nf * FORCE_PARAMS;
    let mut ms = vec![[0.0; 3]; p];
    let mut fs = vec![[0.0; FORCE_PARAMS]; p * nf];
    for k in 0..3 {
        ms[RELATIVE_STATE_SIZE + k][k] = 1.0;
    }
    for i in 0..nf {
        for m in 0..FORCE_PARAMS {
            fs[(RELATIVE_STATE_SIZE + 3 + i * FORCE_PARAMS + m) * nf + i][m] = 1.0;
        }
    }
    let options = RelativeOptions::default();
    let sys = RelativeSensitive::new(b, &f, &Turning, options, &ms, &fs, true);
    let mut y = vec![0.0; RELATIVE_STATE_SIZE];
    y[..STATE_SIZE].copy_from_slice(&state());
    let qc = exp_so3([-0.2, 0.4, 0.1]);
    for i in 0..3 {
        y[18 + 3 * i..21 + 3 * i].copy_from_slice(&qc[i]);
    }
    y[27..33].copy_from_slice(&[1.0, 2.0, -1.0, 0.3, 0.0, 0.1]);
    let mut aug = vec![0.0; sys.dim()];
    aug[..RELATIVE_STATE_SIZE].copy_from_slice(&y);
    for i in 0..RELATIVE_STATE_SIZE {
        aug[RELATIVE_STATE_SIZE + p * i + i] = 1.0;
    }
    let t = 0.7;
    let mut out = vec![0.0; sys.dim()];
    sys.rhs(t, &aug, &mut out);
    let plain_rates = |b: Body, f: &[Force], y: &[f64]| {
        let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let rigid = Rigid::<crate::systems::NoUser>::new(b, f.to_vec(), eye, None);
        let rel = Relative::new(rigid, Turning, options);
        let mut o = vec![0.0; RELATIVE_STATE_SIZE];
        rel.rhs(t, y, &mut o);
        o
    };
    let plain = plain_rates(b, &f, &y);
    for i in 0..RELATIVE_STATE_SIZE {
        assert_eq!(out[i].to_bits(), plain[i].to_bits(), "value {i}");
    }
    let h = 1e-6;
    for j in 0..p {
        let moved = |s: f64| {
            let (mut b2, mut f2, mut y2) = (b, f.clone(), y.clone());
            if j < RELATIVE_STATE_SIZE {
                y2[j] += s;
            } else if j < RELATIVE_STATE_SIZE + 3 {
                let k = j - RELATIVE_STATE_SIZE;
                b2.moments[k] += s;
                b2.inv_moments[k] = 1.0 / b2.moments[k];
                b2.inertia_com[k][k] += s;
            } else {
                let r = j - RELATIVE_STATE_SIZE - 3;
                f2[r / FORCE_PARAMS].p[r % FORCE_PARAMS] += s;
            }
            plain_rates(b2, &f2, &y2)
        };
        let (up, down) = (moved(h), moved(-h));
        for i in 0..RELATIVE_STATE_SIZE {
            let fd = (up[i] - down[i]) / (2.0 * h);
            let d = out[RELATIVE_STATE_SIZE + p * i + j];
            assert!(
                (d - fd).abs() < 1e-7 * (1.0 + fd.abs()),
                "dir {j} comp {i}: {d} vs {fd}"
            );
        }
    }
}
