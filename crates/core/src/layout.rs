//! Memory layouts shared by the whole crate and the Python package: the rigid-body state, the
//! body's parameter vector and the lowered forces (`docs/theory.md` §1, eqs (07)–(09)).
//!
//! The state of one body is the flat 18-vector of the source notebook,
//! `y = [R (3), V (3), Q (9, row-major), ω (3)]`: centre of mass and its velocity (space
//! frame), attitude (body → space) and angular velocity (body frame). Inside the engine the
//! same layout is used in the body's *principal* frame, where Euler's equation takes its
//! component form (27)–(29).

use crate::real::Real;
use crate::so3::{Mat3, Vec3};

/// Length of the rigid-body state.
pub const STATE_SIZE: usize = 18;
/// Offset of the centre of mass `R` (space frame).
pub const R_AT: usize = 0;
/// Offset of its velocity `V`.
pub const V_AT: usize = 3;
/// Offset of the attitude `Q`, row-major.
pub const Q_AT: usize = 6;
/// Offset of the angular velocity ω (body or principal frame).
pub const OMEGA_AT: usize = 15;

// The body parameter vector (one float vector per body, principal frame of the inertia about
// the reference point), as the Python package builds it.
/// `M`
pub const MASS: usize = 0;
/// `1/M`
pub const INV_MASS: usize = 1;
/// Principal moments about the reference point (3), zero on a degenerate line.
pub const MOMENTS: usize = 2;
/// Their inverses (3), zero where the moment is zero (minimum-norm ω̇).
pub const INV_MOMENTS: usize = 5;
/// `c`: centre of mass − reference point (3); zero for a free body.
pub const COM_OFFSET: usize = 8;
/// Inertia about the centre of mass (9, row-major; gravity gradient).
pub const INERTIA_COM: usize = 11;
/// The fixed point in space (3), with a pivot.
pub const PIVOT: usize = 20;
/// 1.0 when the body turns about a fixed point.
pub const HAS_PIVOT: usize = 23;
/// Free-rotor flow: −1 asymmetric, k ∈ {0, 2} symmetric about axis k.
pub const ROTOR: usize = 24;
/// Length of the body parameter vector.
pub const BODY_SIZE: usize = 25;

/// Parameters per lowered force.
pub const FORCE_PARAMS: usize = 10;

/// A rigid body as the engine reads it (principal frame of the inertia about the reference
/// point: the centre of mass, or the pivot). Its numbers are `f64`, or dual numbers
/// ([`crate::dual::Dual`]) where a run differentiates with respect to them
/// ([`Body::lift`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body<T = f64> {
    pub mass: T,
    pub inv_mass: T,
    /// Ascending principal moments about the reference point.
    pub moments: [T; 3],
    /// `1/I_k`, or 0 where `I_k = 0`.
    pub inv_moments: [T; 3],
    /// Centre of mass seen from the reference point (zero for a free body).
    pub com_offset: [T; 3],
    /// Inertia about the centre of mass.
    pub inertia_com: [[T; 3]; 3],
    /// The fixed point in space.
    pub pivot: [T; 3],
    pub has_pivot: bool,
    /// Free-rotor flow: −1 asymmetric, k ∈ {0, 2} symmetric about axis k.
    pub rotor: i32,
}

impl Body {
    /// The body from its parameter vector (`BODY_SIZE` floats); `None` for another length.
    pub fn from_slice(p: &[f64]) -> Option<Body> {
        if p.len() != BODY_SIZE {
            return None;
        }
        let v3 = |k: usize| [p[k], p[k + 1], p[k + 2]];
        let a = INERTIA_COM;
        Some(Body {
            mass: p[MASS],
            inv_mass: p[INV_MASS],
            moments: v3(MOMENTS),
            inv_moments: v3(INV_MOMENTS),
            com_offset: v3(COM_OFFSET),
            inertia_com: [
                [p[a], p[a + 1], p[a + 2]],
                [p[a + 3], p[a + 4], p[a + 5]],
                [p[a + 6], p[a + 7], p[a + 8]],
            ],
            pivot: v3(PIVOT),
            has_pivot: p[HAS_PIVOT] != 0.0,
            rotor: p[ROTOR] as i32,
        })
    }

    /// The parameter vector of a body from its parts (principal frame of the inertia about
    /// the reference point): inverse moments are 0 where a moment is 0.
    pub fn vector(
        mass: f64,
        moments: Vec3,
        com_offset: Vec3,
        inertia_com: &Mat3,
        pivot: Vec3,
        has_pivot: bool,
        rotor: i32,
    ) -> [f64; BODY_SIZE] {
        let mut out = [0.0; BODY_SIZE];
        out[MASS] = mass;
        out[INV_MASS] = 1.0 / mass;
        for k in 0..3 {
            out[MOMENTS + k] = moments[k];
            out[INV_MOMENTS + k] = if moments[k] != 0.0 {
                1.0 / moments[k]
            } else {
                0.0
            };
            out[COM_OFFSET + k] = com_offset[k];
            out[PIVOT + k] = pivot[k];
            for j in 0..3 {
                out[INERTIA_COM + 3 * k + j] = inertia_com[k][j];
            }
        }
        out[HAS_PIVOT] = if has_pivot { 1.0 } else { 0.0 };
        out[ROTOR] = rotor as f64;
        out
    }
}

impl Body {
    /// The body in numbers of type `T` (dual numbers: their derivatives zero), its principal
    /// moments `I_k` moved by `dm[k]` (the derivative seeds of the moments): the inverse
    /// moments `1/I_k` then carry `−dm[k]/I_k²`, and the inertia about the centre of mass,
    /// `A_G = A_P − M (|c|² 1 − c cᵀ)` in the same principal axes, its diagonal `dm[k]`.
    pub fn lift<T: Real>(&self, dm: [T; 3]) -> Body<T> {
        let s = T::splat;
        let moments = [0, 1, 2].map(|k| s(self.moments[k]) + dm[k]);
        Body {
            mass: s(self.mass),
            inv_mass: s(self.inv_mass),
            inv_moments: [0, 1, 2].map(|k| {
                if self.moments[k] != 0.0 {
                    s(1.0) / moments[k]
                } else {
                    s(0.0)
                }
            }),
            moments,
            com_offset: self.com_offset.map(s),
            inertia_com: [0, 1, 2].map(|i| {
                [0, 1, 2].map(|j| {
                    let a = s(self.inertia_com[i][j]);
                    if i == j {
                        a + dm[i]
                    } else {
                        a
                    }
                })
            }),
            pivot: self.pivot.map(s),
            has_pivot: self.has_pivot,
            rotor: self.rotor,
        }
    }
}

/// The 18-state as a fixed array (a copy of the first 18 entries of `y`).
#[inline(always)]
pub fn load(y: &[f64]) -> [f64; STATE_SIZE] {
    let mut s = [0.0; STATE_SIZE];
    s.copy_from_slice(&y[..STATE_SIZE]);
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn body_vector_round_trips() {
        let a = [[1.0, 0.1, 0.0], [0.1, 2.0, 0.0], [0.0, 0.0, 3.0]];
        let v = Body::vector(
            2.0,
            [0.0, 2.0, 4.0],
            [0.1, 0.2, 0.3],
            &a,
            [1.0, 2.0, 3.0],
            true,
            -1,
        );
        let b = Body::from_slice(&v).unwrap();
        assert_eq!(b.inv_moments, [0.0, 0.5, 0.25]);
        assert_eq!(b.inertia_com, a);
        assert!(b.has_pivot && b.rotor == -1 && b.inv_mass == 0.5);
        assert!(Body::from_slice(&v[..24]).is_none());
    }
}
