//! The contact state of every candidate node at the end of a model-file run
//! (`contact_nodes.csv`): where each node is and what force it carries, for checks that need
//! more than the pair resultants of the history (a contact pressure distribution, a contact
//! width).
//!
//! One row per contact candidate (pairs in model order, each pair's nodes in its order), of
//! the last converged state. Columns: `pair` (its name), `node` (node number of the part),
//! `x`, `y` (and `z` in 3D: reference coordinates, m), `u_x`, `u_y` (`u_z`: displacement, m),
//! `gap` (normal gap, m, > 0 open), `normal_force` (N, >= 0), `tangential_force_1` (and `_2`
//! in 3D: the friction force along the master surface's coordinate directions, N). Numbers
//! carry 10 significant digits. Written only when the run completed, through
//! [`PartialCsv`], so the file is complete or absent.

use std::path::Path;

use skid_integrator::{Model, State};

use crate::csv_out::PartialCsv;

/// File name of the contact state.
pub const CONTACT_NODES_CSV: &str = "contact_nodes.csv";

/// The column names in dimension `D`.
pub fn columns<const D: usize>() -> Vec<String> {
    let axes = &["x", "y", "z"][..D];
    let mut names = vec!["pair".to_string(), "node".to_string()];
    names.extend(axes.iter().map(|a| (*a).to_string()));
    names.extend(axes.iter().map(|a| format!("u_{a}")));
    names.extend(["gap", "normal_force"].map(String::from));
    names.extend((1..D).map(|k| format!("tangential_force_{k}")));
    names
}

/// Writes `dir/contact_nodes.csv` of `state`, a converged state of `model`.
///
/// # Errors
/// I/O errors.
pub fn write<const D: usize>(dir: &Path, model: &Model<D>, state: &State) -> std::io::Result<()> {
    let columns = columns::<D>();
    let names: Vec<&str> = columns.iter().map(String::as_str).collect();
    let mut csv = PartialCsv::create(&dir.join(CONTACT_NODES_CSV), &names)?;
    let number = |v: f64| format!("{v:.9e}");
    let nodes = &model.part().mesh.nodes;
    for c in &state.contacts {
        let mut row = vec![model.contacts()[c.pair].name.clone(), c.node.to_string()];
        row.extend(nodes[c.node].iter().map(|&v| number(v)));
        let u = model.dofs().node_displacement(&state.x, c.node);
        row.extend(u.iter().map(|&v| number(v)));
        row.push(number(c.gap));
        row.push(number(c.normal_force));
        row.extend(c.tangential_force.iter().take(D - 1).map(|&f| number(f)));
        csv.record(row)?;
    }
    csv.finish()
}
