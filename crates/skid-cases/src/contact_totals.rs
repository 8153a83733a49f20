//! The resultants of every contact pair in a state, for the histories and summaries of any
//! model: forces summed over the pair's candidates, the closed and sliding ones counted, the
//! deepest penetration and the widest gap of a sliding contact.

use skid_integrator::{Model, State};

/// A contact is counted as sliding when its friction force reaches `mu N` to this relative
/// tolerance.
const SLIDING_TOLERANCE: f64 = 1e-6;

/// Resultants of one contact pair in one state.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PairTotals {
    /// Sum of the normal forces, N.
    pub normal_force: f64,
    /// Sums of the friction force components along the surface coordinates, N.
    pub tangential_force: [f64; 2],
    /// Closed contacts.
    pub active: usize,
    /// Closed contacts whose friction force is at the cone's boundary (`|t| >= mu N`).
    pub sliding: usize,
    /// Deepest penetration, m (0 if none).
    pub max_penetration: f64,
    /// Largest gap at a sliding contact, m.
    pub max_sliding_separation: f64,
}

/// Resultants of every contact pair of `model` in `state`.
pub fn pair_totals<const D: usize>(model: &Model<D>, state: &State) -> Vec<PairTotals> {
    let mut totals = vec![PairTotals::default(); model.contacts().len()];
    for c in &state.contacts {
        let t = &mut totals[c.pair];
        t.max_penetration = t.max_penetration.max(-c.gap);
        if !c.is_closed() {
            continue;
        }
        t.active += 1;
        t.normal_force += c.normal_force;
        t.tangential_force[0] += c.tangential_force[0];
        t.tangential_force[1] += c.tangential_force[1];
        let mu = model.contacts()[c.pair].mu;
        if mu > 0.0 && c.tangential_force.norm() >= mu * c.normal_force * (1.0 - SLIDING_TOLERANCE)
        {
            t.sliding += 1;
            t.max_sliding_separation = t.max_sliding_separation.max(c.gap);
        }
    }
    totals
}
