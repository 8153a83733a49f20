//! The elimination order of the global contact system (see [`crate::global_contact`]).
//!
//! The system's unknowns are the model's equations followed by `components` contact rows per
//! candidate. Its order follows the nested dissection of the mesh's nodes
//! ([`skid_fem::ordering`]): each node's own equations, then the rows of the candidates at that
//! node (a constraint row eliminated after its node's equations leaves a pivot of the order of
//! the node's compliance, not the row's small regularisation, see [`crate::quasi_definite`]),
//! and last the rigid bodies' equations, which couple whole surfaces and would fill the factor
//! wherever else they stood.

use skid_fem::ordering::nested_dissection;

use crate::model::Model;

/// `order[k]`: the unknown of the global system eliminated `k`-th (see the module
/// documentation), for `components` contact rows per candidate.
pub fn global_system_order<const D: usize>(model: &Model<D>, components: usize) -> Vec<usize> {
    let dofs = model.dofs();
    let n = dofs.len();
    let mut is_body = vec![false; n];
    for b in 0..model.bodies().len() {
        for eq in dofs.body_equations(b) {
            is_body[eq] = true;
        }
    }
    let mesh = &model.part().mesh;
    let mut candidates_at: Vec<Vec<usize>> = vec![Vec::new(); mesh.nodes.len()];
    let candidates = model.contacts().iter().flat_map(|pair| pair.nodes.iter());
    for (c, &node) in candidates.enumerate() {
        candidates_at[node].push(c);
    }
    let rows = candidates_at.iter().map(Vec::len).sum::<usize>() * components;
    let mut placed = vec![false; n + rows];
    let mut order = Vec::with_capacity(n + rows);
    let mut place = |unknown: usize, order: &mut Vec<usize>| {
        if !placed[unknown] {
            placed[unknown] = true;
            order.push(unknown);
        }
    };
    for node in nested_dissection(mesh) {
        for &eq in dofs.node(node).iter().flatten() {
            if !is_body[eq] {
                place(eq, &mut order);
            }
        }
        for &c in &candidates_at[node] {
            for row in n + c * components..n + (c + 1) * components {
                place(row, &mut order);
            }
        }
    }
    for unknown in 0..n + rows {
        place(unknown, &mut order);
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::block_on_drum;

    /// Every unknown appears once; each candidate's rows follow its node's equations; the
    /// rigid bodies' equations come last.
    fn order_places_rows_after_their_nodes_and_bodies_last<const D: usize>() {
        let model = block_on_drum::<D>();
        let n = model.dofs().len();
        let candidates: Vec<usize> = model
            .contacts()
            .iter()
            .flat_map(|pair| pair.nodes.iter().copied())
            .collect();
        let order = global_system_order(&model, D);
        let total = n + candidates.len() * D;
        let mut position = vec![usize::MAX; total];
        for (k, &unknown) in order.iter().enumerate() {
            assert_eq!(position[unknown], usize::MAX, "{D}D: {unknown} twice");
            position[unknown] = k;
        }
        assert_eq!(order.len(), total);
        let bodies: Vec<usize> = (0..model.bodies().len())
            .flat_map(|b| model.dofs().body_equations(b))
            .collect();
        let first_body = bodies.iter().map(|&eq| position[eq]).min().expect("bodies");
        assert_eq!(first_body, total - bodies.len(), "{D}D: bodies last");
        for (c, &node) in candidates.iter().enumerate() {
            for &eq in model.dofs().node(node).iter().flatten() {
                if !bodies.contains(&eq) {
                    assert!(position[eq] < position[n + c * D], "{D}D: candidate {c}");
                }
            }
        }
    }

    #[test]
    fn order_places_rows_after_their_nodes_and_bodies_last_2d() {
        order_places_rows_after_their_nodes_and_bodies_last::<2>();
    }

    #[test]
    fn order_places_rows_after_their_nodes_and_bodies_last_3d() {
        order_places_rows_after_their_nodes_and_bodies_last::<3>();
    }
}
