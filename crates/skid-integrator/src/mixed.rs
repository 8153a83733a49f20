//! Element pressures of the condensed mixed (u-p) tangent, carried from one Newton iterate to
//! the next.
//!
//! With one-point elements the mixed formulation (Simo, Taylor and Pister 1985: an independent
//! pressure `p` constant per element, `J - 1` and `p` related by `U'`) condenses to the
//! displacement formulation with two changes in the tangent only. Linearising the constraint
//! `p = U'(J)` at the iterate `u_k` gives the pressure of the next iterate
//!
//! `p_{k+1} = U'(J_k) + U''(J_k) dJ/du (u_k) . du_k`,
//!
//! and the tangent at `u_{k+1}` takes that pressure in its stress-dependent terms
//! (`J p (I (x) I - 2 II)` and the geometric stiffness) instead of `U'(J_{k+1})`. At convergence
//! the two agree, so the converged state, the residual and the quadratic rate are those of the
//! displacement formulation. What changes is the Newton path of a nearly incompressible solid:
//! a step that is exact to first order leaves `J_{k+1} - 1` wrong by O(du^2), and with
//! `U'' = K = 1e7 mu` that error makes `U'(J_{k+1})` exceed the shear modulus by orders of
//! magnitude, so that `-2 J p II` turns the tangent indefinite at iterates far from the solution.
//! The mixed pressure stays of the order of the applied stresses.

use nalgebra::DVector;
use skid_fem::solid::{ElementResponse, MAX_COMPONENTS, Tangent};

use crate::model::Model;

/// The volumetric linearisation of one element at the last evaluated configuration.
#[derive(Clone, Copy, Debug)]
struct Linearisation {
    /// `U'(J)`.
    pressure: f64,
    /// `U''(J)`.
    stiffness: f64,
    /// `dJ/du`, element ordering, in the element's first `D 2^D` entries.
    volume_gradient: [f64; MAX_COMPONENTS],
}

/// Per element: the last linearisation and the mixed pressure predicted for the next iterate.
#[derive(Clone, Debug, Default)]
pub struct MixedPressures {
    /// The configuration (per equation) of the recorded linearisations.
    recorded_at: Option<DVector<f64>>,
    at: Vec<Option<Linearisation>>,
    next: Vec<Option<f64>>,
}

impl MixedPressures {
    /// No predictions for `elements` elements: every tangent is the consistent one until
    /// [`Self::advance`] is called.
    pub fn new(elements: usize) -> Self {
        Self {
            recorded_at: None,
            at: vec![None; elements],
            next: vec![None; elements],
        }
    }

    /// True if the recorded linearisations are those at configuration `x`.
    pub fn recorded_at(&self, x: &DVector<f64>) -> bool {
        self.recorded_at.as_ref() == Some(x)
    }

    /// The tangent to request from element `e`: mixed at the predicted pressure, or
    /// consistent without a prediction.
    pub fn tangent(&self, e: usize) -> Tangent {
        match self.next.get(e).copied().flatten() {
            Some(pressure) => Tangent::Mixed { pressure },
            None => Tangent::Consistent,
        }
    }

    /// Records each element's volumetric linearisation at the configuration `x` just evaluated
    /// (`responses` in element order), overwriting the storage of the last one.
    pub fn record<const D: usize>(
        &mut self,
        model: &Model<D>,
        x: &DVector<f64>,
        responses: &[ElementResponse],
    ) {
        let part = model.part();
        match &mut self.recorded_at {
            Some(recorded) if recorded.len() == x.len() => recorded.copy_from(x),
            recorded => *recorded = Some(x.clone()),
        }
        self.at.clear();
        self.at.extend(responses.iter().enumerate().map(|(e, r)| {
            let material = part.material(e);
            let mut volume_gradient = [0.0; MAX_COMPONENTS];
            volume_gradient[..r.volume_ratio_gradient().len()]
                .copy_from_slice(r.volume_ratio_gradient());
            Some(Linearisation {
                pressure: material.volumetric_pressure(r.volume_ratio),
                stiffness: material.volumetric_stiffness(r.volume_ratio),
                volume_gradient,
            })
        }));
    }

    /// Predicts the recorded pressures `U'(J)` unchanged for the next tangent.
    pub fn hold(&mut self) {
        self.next.clear();
        self.next
            .extend(self.at.iter().map(|at| at.as_ref().map(|lin| lin.pressure)));
    }

    /// Predicts each element's pressure after the step `dx` (per equation) from the recorded
    /// linearisation: `p = U'(J) + U''(J) dJ/du . du_e`.
    pub fn advance<const D: usize>(&mut self, model: &Model<D>, dx: &DVector<f64>) {
        let elements = &model.part().mesh.elements;
        self.next.clear();
        self.next
            .extend(self.at.iter().zip(elements).map(|(at, nodes)| {
                at.as_ref().map(|lin| {
                    let dj: f64 = nodes
                        .iter()
                        .enumerate()
                        .map(|(k, &n)| {
                            let du = model.dofs().node_displacement(dx, n);
                            (lin.volume_gradient[D * k..D * (k + 1)].iter())
                                .zip(du.iter())
                                .map(|(dj_du, du)| dj_du * du)
                                .sum::<f64>()
                        })
                        .sum();
                    lin.pressure + lin.stiffness * dj
                })
            }));
    }
}
