//! The solid's lumped mass matrix, as its elements lump it ([`lumped_mass`]) or moved off its
//! contact nodes ([`redistributed_mass`], the mass redistribution of Khenous, Laborde and
//! Renard 2008).
//!
//! A contact node with mass is a mass point hitting a rigid constraint: every increment in
//! which it closes (or is pushed back) its normal velocity jumps by an impulse of order
//! `m v_N`, which as a mean force over the increment grows as `1/h`. A block sliding under
//! friction rings so: the normal force of its contact nodes jumps between 0 and several times
//! its mean, the more the shorter the step (scatter 0.1 % at dt 4e-5 s, 68 % at 2.5e-6 s on a
//! 4 x 4 block), and with it the friction that the Coulomb law ties to it. Without mass on the
//! contact nodes the semi-discrete problem is well posed: the contact nodes are in equilibrium
//! between the elements' forces and the contact forces at the end of every increment, so the
//! contact force is a force, not an impulse, and does not ring.
//!
//! Each element gives the lumped mass of its contact nodes in equal parts to its other nodes,
//! which keeps the total mass (and so every momentum balance of the solid) and moves the
//! centre of mass by at most the element's own size. The contact nodes' equations become
//! equations without inertia, treated as those of a quasi-static solid (see
//! [`crate::increment`]).

use std::collections::BTreeSet;

use nalgebra::DVector;
use skid_fem::element::SolidElement;

use crate::dof::DofMap;
use crate::error::ModelError;

/// The solid's elements with what their masses need: connectivity and each element's density
/// (kg/m^3).
pub struct MassSource<'a, const D: usize> {
    /// The elements.
    pub elements: &'a [SolidElement<D>],
    /// Their nodes.
    pub connectivity: &'a [Vec<usize>],
    /// Their densities.
    pub densities: &'a [f64],
}

/// The solid's lumped masses per equation: each node's share of its elements'
/// [`SolidElement::lumped_node_masses`] (tied nodes' shares on their body's equations).
pub fn lumped_mass<const D: usize>(solid: &MassSource<'_, D>, dofs: &DofMap<D>) -> DVector<f64> {
    let mut mass = DVector::zeros(dofs.len());
    let elements = solid.elements.iter().zip(solid.connectivity);
    for ((element, nodes), &density) in elements.zip(solid.densities) {
        let masses = element.lumped_node_masses(density);
        for (&n, m) in nodes.iter().zip(masses) {
            for eq in dofs.node(n).iter().flatten() {
                mass[*eq] += m;
            }
        }
    }
    mass
}

/// The solid's lumped masses per equation with the mass of the `contact` nodes moved in equal
/// parts to the other nodes of each element, and the contact nodes' equations (left without
/// mass).
///
/// # Errors
/// [`ModelError::Invalid`] for an element whose nodes are all contact nodes (its mass has
/// nowhere to go).
pub fn redistributed_mass<const D: usize>(
    solid: &MassSource<'_, D>,
    dofs: &DofMap<D>,
    contact: &BTreeSet<usize>,
) -> Result<(DVector<f64>, BTreeSet<usize>), ModelError> {
    let mut mass = DVector::zeros(dofs.len());
    let elements = solid.elements.iter().zip(solid.connectivity);
    for (e, ((element, nodes), &density)) in elements.zip(solid.densities).enumerate() {
        let masses = element.lumped_node_masses(density);
        let others = nodes.iter().filter(|n| !contact.contains(n)).count();
        if others == 0 {
            return Err(ModelError::Invalid(format!(
                "element {e}: every node is a contact node, so its mass cannot be moved off \
                 them (refine the mesh across the contact surface)"
            )));
        }
        let moved: f64 = (nodes.iter().zip(masses))
            .filter(|(n, _)| contact.contains(n))
            .map(|(_, m)| m)
            .sum();
        for (&n, m) in nodes.iter().zip(masses) {
            if contact.contains(&n) {
                continue;
            }
            for eq in dofs.node(n).iter().flatten() {
                mass[*eq] += m + moved / others as f64;
            }
        }
    }
    let contact_equations = (contact.iter())
        .flat_map(|&n| dofs.node(n).iter().flatten().copied())
        .collect();
    Ok((mass, contact_equations))
}

#[cfg(test)]
mod tests {
    use crate::test_support::block_on_drum;

    /// Moving the contact nodes' mass off them keeps the total mass, leaves the contact
    /// nodes' equations without mass (and without inertia), and gives every other node of the
    /// pad (4 x 1 elements against the drum) its own mass and an equal share of its element's
    /// contact nodes'.
    fn check<const D: usize>() {
        let lumped = block_on_drum::<D>();
        let moved = block_on_drum::<D>()
            .with_massless_contact_nodes()
            .expect("massless contact nodes");
        assert!((lumped.mass().sum() - moved.mass().sum()).abs() < 1e-12 * lumped.mass().sum());
        let front = &lumped.contacts()[0].nodes;
        for (node, eqs) in (0..lumped.part().mesh.nodes.len()).map(|n| (n, lumped.dofs().node(n))) {
            for eq in eqs.iter().flatten() {
                if front.contains(&node) {
                    assert_eq!(moved.mass()[*eq], 0.0);
                    assert!(moved.quasi_static()[*eq]);
                } else {
                    // one element through the thickness: the back node takes its own share
                    // and the front node's, which are equal on a brick
                    let expected = 2.0 * lumped.mass()[*eq];
                    assert!((moved.mass()[*eq] - expected).abs() < 1e-12 * expected);
                    assert!(!moved.quasi_static()[*eq]);
                }
            }
        }
        // the solid's rows: all but the drum's (no body is tied to the pad)
        let rows = moved.solid_rows().expect("solid rows");
        let drum = lumped.dofs().body_equations(0);
        assert!(drum.iter().all(|&eq| !rows[eq]));
        assert_eq!(rows.iter().filter(|r| **r).count(), rows.len() - drum.len());
    }

    #[test]
    fn contact_nodes_lose_their_mass_to_their_elements_other_nodes() {
        check::<2>();
        check::<3>();
    }
}
