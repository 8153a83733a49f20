//! The state at the end of a converged increment: the contact points' states and the energy
//! ledger's new entries.

use nalgebra::{DVector, Vector2};

use crate::assembly::InternalState;
use crate::contact_rows::ContactRows;
use crate::hht::IncrementEnds;
use crate::model::Model;
use crate::state::{ContactPointState, EnergyLedger, State};

use super::IncrementKind;
use super::residual::mean_rates;

/// The converged iterate: unknowns, their rates, and the forces evaluated there.
pub(super) struct Iterate {
    pub(super) x: DVector<f64>,
    pub(super) v: DVector<f64>,
    pub(super) a: DVector<f64>,
    /// `f_int - f_ext`.
    pub(super) net: DVector<f64>,
    pub(super) f_ext: DVector<f64>,
    pub(super) internal: InternalState,
    /// The residual `R_i` of each constrained equation without contact (zero elsewhere): what
    /// its constraint and the contact forces on it together balance.
    pub(super) constrained: DVector<f64>,
    /// What each constraint adds: `R_i` less the contact forces on the equation, `(H^T r)_i`
    /// over every candidate.
    pub(super) reaction: DVector<f64>,
    /// The equations that move as prescribed.
    pub(super) moving: Vec<bool>,
}

/// Builds the converged state and updates the energy ledger.
pub(super) fn finish<const D: usize>(
    model: &Model<D>,
    start: &State,
    kind: IncrementKind,
    iterate: Iterate,
    rows: &ContactRows,
    r: &DVector<f64>,
    warm_forces: DVector<f64>,
) -> State {
    let Iterate {
        x,
        v,
        a,
        net,
        f_ext,
        internal,
        constrained,
        reaction,
        moving,
    } = iterate;
    // The mean contact force over the increment and, for a dynamic increment, the velocity and
    // smooth acceleration with the contact impulse (see `crate::hht`); a prescribed
    // equation's reaction, and the contact forces on it, act as the contact forces do: an
    // impulse over the increment.
    let (r, reaction, constrained, v, a) = match kind {
        IncrementKind::Static { .. } => (r.clone(), reaction, constrained, v, a),
        IncrementKind::Dynamic { hht, h, .. } => {
            let mut impulse = rows.transpose_times(r, x.len());
            for (eq, _) in moving.iter().enumerate().filter(|(_, m)| **m) {
                impulse[eq] += constrained[eq];
            }
            let contact = model.acceleration_of(&impulse);
            let (mut v, mut a) = hht.split_impulse(h, &start.v, &start.a, &a, &contact);
            mean_rates(model.quasi_static(), h, &start.x, &x, &mut v, &mut a);
            let mean = hht.impulse_force_factor();
            (r * mean, reaction * mean, constrained * mean, v, a)
        }
    };
    let r = &r;
    let (contacts, friction, normal_work) = contact_states(start, kind, rows, r);
    let (time, load_factor) = match kind {
        IncrementKind::Static { load_factor, .. } => (start.time, load_factor),
        IncrementKind::Dynamic { h, .. } => (start.time + h, 1.0),
    };
    let dx = &x - &start.x;
    let contact_reaction = rows.transpose_times(r, x.len());
    let moved: Vec<usize> = (0..x.len()).filter(|&eq| moving[eq]).collect();
    let reaction_work = reaction_work(start, kind, (&reaction, &moved), &dx);
    let algorithmic = algorithmic_dissipation(
        (model, start, kind),
        (&dx, &net, &a, &v),
        (&contact_reaction, &constrained, &moved),
    );
    // the viscous forces' work by the trapezoidal rule, as the algorithmic dissipation takes
    // them among the smooth forces
    let damping = match start.damping_force.len() {
        0 => 0.5 * internal.damping_force.dot(&dx),
        _ => 0.5 * (&start.damping_force + &internal.damping_force).dot(&dx),
    };
    let energy = EnergyLedger {
        kinetic: 0.5 * v.component_mul(&v).dot(model.mass()),
        strain: internal.strain_energy,
        hourglass: internal.hourglass_energy,
        external_work: start.energy.external_work + 0.5 * (&start.external_force + &f_ext).dot(&dx),
        reaction_work: start.energy.reaction_work + reaction_work,
        friction_dissipation: start.energy.friction_dissipation + friction,
        normal_work: start.energy.normal_work + normal_work,
        algorithmic_dissipation: start.energy.algorithmic_dissipation + algorithmic,
        damping_dissipation: start.energy.damping_dissipation + damping,
    };
    let orientations = model.record_orientations(&start.orientations, &x);
    State {
        time,
        load_factor,
        orientations,
        contact_reaction,
        reaction,
        x,
        v,
        a,
        net_force: net,
        damping_force: internal.damping_force,
        external_force: f_ext,
        contacts,
        warm_forces,
        energy,
    }
}

/// The contact points' states at the end of the increment, from the contact rows at the
/// converged iterate and their forces `r` (the mean force of a dynamic increment's impulse),
/// with the friction's dissipation `-t . slip` and the normal forces' work `p_N dg` over the
/// increment.
fn contact_states(
    start: &State,
    kind: IncrementKind,
    rows: &ContactRows,
    r: &DVector<f64>,
) -> (Vec<ContactPointState>, f64, f64) {
    let d = rows.components;
    let mut contacts = Vec::with_capacity(rows.len());
    let mut friction = 0.0;
    let mut normal_work = 0.0;
    for (k, old) in start.contacts.iter().enumerate() {
        let force = |c: usize| r.get(k * d + c).copied().unwrap_or(0.0);
        let slip = Vector2::from_fn(|c, _| {
            if c + 1 < d {
                rows.u[k * d + c + 1]
            } else {
                0.0
            }
        });
        let tangential = Vector2::from_fn(|c, _| if c + 1 < d { force(c + 1) } else { 0.0 });
        let gap = rows.u[k * d];
        // The work of the contact forces over the increment: in a dynamic increment `r` is the
        // mean force of the impulse; a static increment ramps the forces from `old` to `r`
        // along with the load, so the trapezoidal rule (as for the external work) keeps the
        // ledger's error of order 1/increments^2 rather than 1/increments.
        let (mean_tangential, mean_normal) = match kind {
            IncrementKind::Static { .. } => (
                0.5 * (tangential + old.tangential_force),
                0.5 * (force(0) + old.normal_force),
            ),
            IncrementKind::Dynamic { .. } => (tangential, force(0)),
        };
        friction -= mean_tangential.dot(&slip);
        normal_work += mean_normal * (gap - old.gap);
        contacts.push(ContactPointState {
            pair: old.pair,
            node: old.node,
            closest: rows.closest[k],
            gap,
            slip,
            normal_force: force(0),
            tangential_force: tangential,
        });
    }
    (contacts, friction, normal_work)
}

/// The work of the prescribed (`moved`) equations' reactions over the step `dx`: by the
/// trapezoidal rule in a static increment, as the mean force of the impulse in a dynamic one.
fn reaction_work(
    start: &State,
    kind: IncrementKind,
    (reaction, moved): (&DVector<f64>, &[usize]),
    dx: &DVector<f64>,
) -> f64 {
    moved
        .iter()
        .map(|&eq| {
            let mean = match kind {
                IncrementKind::Static { .. } => {
                    0.5 * (reaction[eq] + start.reaction.get(eq).copied().unwrap_or(0.0))
                }
                IncrementKind::Dynamic { .. } => reaction[eq],
            };
            mean * dx[eq]
        })
        .sum()
}

/// The energy HHT's integration removed over a dynamic increment (none in a static one; see
/// [`crate::hht::Hht::algorithmic_dissipation`]), the contact forces and all that the
/// constraint of a prescribed equation balances acting as impulses.
fn algorithmic_dissipation<const D: usize>(
    (model, start, kind): (&Model<D>, &State, IncrementKind),
    (dx, net, a, v): (&DVector<f64>, &DVector<f64>, &DVector<f64>, &DVector<f64>),
    (contact_reaction, constrained, moved): (&DVector<f64>, &DVector<f64>, &[usize]),
) -> f64 {
    match kind {
        IncrementKind::Static { .. } => 0.0,
        IncrementKind::Dynamic { hht, h, .. } => {
            // the forces that act as impulses: the contacts', and all that the constraint of
            // a prescribed equation balances (its reaction and the contact forces on it)
            let mut impulse_forces = contact_reaction.clone();
            for &eq in moved {
                impulse_forces[eq] += constrained[eq];
            }
            // the gyroscopic moments enter HHT's equations as the forces do (see the
            // `increment` module's documentation), so they are part of the smooth forces here
            let (f0, f1) = match (
                model.gyroscopic_moments(&start.v),
                model.gyroscopic_moments(v),
            ) {
                (Some(g0), Some(g1)) => (&start.net_force + g0, net + g1),
                _ => (start.net_force.clone(), net.clone()),
            };
            hht.algorithmic_dissipation(
                h,
                &IncrementEnds {
                    mass: model.mass(),
                    quasi_static: model.quasi_static(),
                    dx,
                    f0: &f0,
                    f1: &f1,
                    a0: &start.a,
                    a1: a,
                    contact: &impulse_forces,
                },
            )
        }
    }
}
