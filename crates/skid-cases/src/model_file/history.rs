//! The history of any model: one CSV row per converged increment with every rigid body's free
//! motions, every contact pair's resultants and the energy ledger.
//!
//! Columns, in order: `time`, `step`, `increment`, `load_factor` (the ramp of the loads without
//! amplitude), `dt`, `newton_iterations`, `contact_solves`; for each rigid body `B` (model order) `B.u_x`, `B.v_x` (displacement and
//! velocity of the reference node, likewise `y`, `z`) for each free translation, `B.angle`,
//! `B.omega` if it turns about one axis, and `B.rotation_x`, `_y`, `_z` (the rotation vector
//! of its orientation, rad) and `B.omega_x`, `_y`, `_z` (its angular velocity in the global
//! frame, rad/s) if it is free to turn; for each contact pair `P`:
//! `P.normal_force` (sum of the normal forces, N), `P.tangential_force_1` (and `_2` in 3D: sums
//! of the friction force components along the master surface's coordinate directions, N),
//! `P.active`, `P.sliding` (closed contacts, and those at the cone's boundary), `P.max_penetration`
//! (m); for each motion of a rigid body that the model prescribes, in model order, the reaction
//! that moves it, `B.reaction_x` (likewise `y`, `z`; N) or `B.reaction_moment` (N m), the mean
//! force of the increment; for each prescribed translation of a node set `S`, in the order of
//! the model's `boundary`, the sum of its nodes' reactions, `S.reaction_x` (likewise `y`, `z`;
//! N); for each node set `S` of the model's `output.history_nodes` and each of its nodes `n`,
//! its displacement `S.n.u_x` (likewise `y`, `z`; m); then `kinetic_energy`, `strain_energy`, `hourglass_energy`,
//! `external_work`, `friction_dissipation`, `normal_work`, `algorithmic_dissipation` and, if the
//! model prescribes motions, `reaction_work`, and if a section has stiffness damping,
//! `damping_dissipation` (J). Numbers carry 10 significant digits. The file
//! is complete or absent ([`PartialCsv`]).

use std::collections::HashMap;
use std::path::Path;

use nalgebra::Vector3;
use skid_integrator::orientation::orientation;
use skid_integrator::state::EnergyLedger;
use skid_integrator::stepper::{IncrementReport, Observer};
use skid_integrator::{BodyMotion, Model, MotionTarget, State};

use crate::append_file::FileMark;
use crate::contact_totals::{PairTotals, pair_totals};
use crate::csv_out::PartialCsv;
use crate::model_spec::ModelSpec;

/// File name of the history.
pub const HISTORY_CSV: &str = "history.csv";

/// The reaction columns of a model's history: each a name and the equations whose reactions it
/// sums (one for a motion of a rigid body, one per node for a node set's).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReactionColumns(Vec<(String, Vec<usize>)>);

impl ReactionColumns {
    /// The reaction columns of `model`, built from `spec` (see the module documentation).
    pub fn new<const D: usize>(spec: &ModelSpec, model: &Model<D>) -> Self {
        let mut columns = body_reactions(model);
        let equation: HashMap<(usize, usize), usize> = model
            .prescribed()
            .iter()
            .filter_map(|(eq, motion)| match motion.target {
                MotionTarget::Node { node, axis } => Some(((node, axis), *eq)),
                MotionTarget::Body { .. } => None,
            })
            .collect();
        for bc in spec.boundary.iter().filter(|bc| bc.is_prescribed()) {
            let Some(set) = &bc.node_set else { continue };
            let nodes = spec.part.node_sets.get(set).map_or(&[][..], Vec::as_slice);
            for axis in bc.dofs.iter().filter_map(|dof| dof.translation_axis()) {
                let eqs = nodes
                    .iter()
                    .filter_map(|&node| equation.get(&(node, axis)).copied())
                    .collect();
                columns.push((format!("{set}.reaction_{}", ["x", "y", "z"][axis]), eqs));
            }
        }
        Self(columns)
    }

    /// The column of each reaction in `state`.
    fn values<'a>(&'a self, state: &'a State) -> impl Iterator<Item = f64> + 'a {
        self.0.iter().map(|(_, eqs)| {
            eqs.iter()
                .map(|&eq| state.reaction.get(eq).copied().unwrap_or(0.0))
                .sum()
        })
    }
}

/// The nodal displacement columns of a model's history: each a name, a node and an axis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeColumns(Vec<(String, usize, usize)>);

impl NodeColumns {
    /// The displacement columns of the nodes of `spec.output.history_nodes`, `D` components
    /// each (see the module documentation); a set the part lacks has none (the model's build
    /// refuses it).
    pub fn new<const D: usize>(spec: &ModelSpec) -> Self {
        let mut columns = Vec::new();
        for set in &spec.output.history_nodes {
            let nodes = spec.part.node_sets.get(set).map_or(&[][..], Vec::as_slice);
            for &node in nodes {
                for (axis, name) in ["x", "y", "z"].iter().enumerate().take(D) {
                    columns.push((format!("{set}.{node}.u_{name}"), node, axis));
                }
            }
        }
        Self(columns)
    }

    /// The column of each nodal displacement component in `state`, `u_i = x[eq(node, i)]`.
    fn values<'a, const D: usize>(
        &'a self,
        model: &'a Model<D>,
        state: &'a State,
    ) -> impl Iterator<Item = f64> + 'a {
        self.0
            .iter()
            .map(|&(_, node, axis)| model.dofs().node_displacement(&state.x, node)[axis])
    }
}

/// The column names of a model's history, with its reaction and nodal displacement columns.
pub fn columns<const D: usize>(
    model: &Model<D>,
    reactions: &ReactionColumns,
    nodes: &NodeColumns,
) -> Vec<String> {
    let mut names: Vec<String> = [
        "time",
        "step",
        "increment",
        "load_factor",
        "dt",
        "newton_iterations",
        "contact_solves",
    ]
    .map(String::from)
    .to_vec();
    let dofs = model.dofs();
    for (b, body) in model.bodies().iter().enumerate() {
        for (axis, eq) in dofs.body_translation(b).iter().enumerate() {
            if eq.is_some() {
                let axis = ["x", "y", "z"][axis];
                names.push(format!("{}.u_{axis}", body.name));
                names.push(format!("{}.v_{axis}", body.name));
            }
        }
        if dofs.body_rotation(b).is_some() {
            names.push(format!("{}.angle", body.name));
            names.push(format!("{}.omega", body.name));
        }
        if dofs.body_rotations(b).len() == 3 {
            for what in ["rotation", "omega"] {
                for axis in ["x", "y", "z"] {
                    names.push(format!("{}.{what}_{axis}", body.name));
                }
            }
        }
    }
    for pair in model.contacts() {
        names.push(format!("{}.normal_force", pair.name));
        for k in 1..D {
            names.push(format!("{}.tangential_force_{k}", pair.name));
        }
        for what in ["active", "sliding", "max_penetration"] {
            names.push(format!("{}.{what}", pair.name));
        }
    }
    for (name, _) in &reactions.0 {
        names.push(name.clone());
    }
    for (name, _, _) in &nodes.0 {
        names.push(name.clone());
    }
    names.extend(
        [
            "kinetic_energy",
            "strain_energy",
            "hourglass_energy",
            "external_work",
            "friction_dissipation",
            "normal_work",
            "algorithmic_dissipation",
        ]
        .map(String::from),
    );
    if !model.prescribed().is_empty() {
        names.push("reaction_work".into());
    }
    if model.has_stiffness_damping() {
        names.push("damping_dissipation".into());
    }
    names
}

/// The reaction columns of the prescribed motions of rigid bodies: each one's column name and
/// its equation.
fn body_reactions<const D: usize>(model: &Model<D>) -> Vec<(String, Vec<usize>)> {
    model
        .prescribed()
        .iter()
        .filter_map(|(eq, motion)| match motion.target {
            MotionTarget::Body { body, motion } => {
                let name = &model.bodies()[body].name;
                Some(match motion {
                    BodyMotion::Translation(axis) => (
                        format!("{name}.reaction_{}", ["x", "y", "z"][axis]),
                        vec![*eq],
                    ),
                    BodyMotion::Rotation => (format!("{name}.reaction_moment"), vec![*eq]),
                })
            }
            MotionTarget::Node { .. } => None,
        })
        .collect()
}

/// A rigid body's motion in one state.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BodyState {
    /// Body name.
    pub name: String,
    /// Displacement of the reference node, m.
    pub displacement: Vec<f64>,
    /// Velocity of the reference node, m/s.
    pub velocity: Vec<f64>,
    /// Rotation angle about the free axis, rad (0 if it cannot rotate or is free to turn about
    /// all three axes, whose orientation the history gives).
    pub angle: f64,
    /// Angular velocity about the free axis, rad/s (0 as for `angle`).
    pub omega: f64,
}

/// The motions of every rigid body of `model` in `state`.
pub fn body_states<const D: usize>(model: &Model<D>, state: &State) -> Vec<BodyState> {
    let dofs = model.dofs();
    model
        .bodies()
        .iter()
        .enumerate()
        .map(|(b, body)| BodyState {
            name: body.name.clone(),
            displacement: dofs
                .body_displacement(&state.x, b)
                .iter()
                .copied()
                .collect(),
            velocity: dofs
                .body_displacement(&state.v, b)
                .iter()
                .copied()
                .collect(),
            angle: dofs.body_angle(&state.x, b),
            omega: dofs.body_angle(&state.v, b),
        })
        .collect()
}

/// What a run's summary needs of its history.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct RunRecord {
    /// Time of the last converged state, s.
    pub final_time: f64,
    /// Motions of every rigid body in the last converged state.
    pub final_bodies: Vec<BodyState>,
    /// Pair resultants of the last converged state.
    pub final_pairs: Vec<PairTotals>,
    /// Energy ledger of the first recorded state (the initial one).
    pub first_energy: Option<EnergyLedger>,
    /// Energy ledger of the state the first dynamic step started from, once it has started.
    pub dynamic_start_energy: Option<EnergyLedger>,
    /// Energy ledger of the last converged state.
    pub last_energy: Option<EnergyLedger>,
    /// Largest of the kinetic + strain + hourglass energy, |external work|, |normal work| and
    /// the frictional dissipation over the run, J: the scale of the energy balance.
    pub energy_scale: f64,
    /// Deepest penetration over the run, m.
    pub max_penetration: f64,
    /// Largest gap at a sliding contact over the run, m.
    pub max_sliding_separation: f64,
}

/// Observer writing a model's `history.csv` and keeping its [`RunRecord`].
pub struct ModelRecorder {
    csv: PartialCsv,
    reactions: ReactionColumns,
    nodes: NodeColumns,
    record: RunRecord,
}

impl ModelRecorder {
    /// Creates `dir/history.csv.partial` with the header for `model` and its reaction and
    /// nodal displacement columns.
    ///
    /// # Errors
    /// I/O errors.
    pub fn create<const D: usize>(
        dir: &Path,
        model: &Model<D>,
        reactions: ReactionColumns,
        nodes: NodeColumns,
    ) -> std::io::Result<Self> {
        let columns = columns(model, &reactions, &nodes);
        let names: Vec<&str> = columns.iter().map(String::as_str).collect();
        Ok(Self {
            csv: PartialCsv::create(&dir.join(HISTORY_CSV), &names)?,
            reactions,
            nodes,
            record: RunRecord::default(),
        })
    }

    /// Continues the history of an interrupted run: `dir/history.csv.partial` reopened at
    /// `mark` ([`PartialCsv::reopen`]), with the record up to that point and the reaction and
    /// nodal displacement columns the history was created with.
    ///
    /// # Errors
    /// As [`PartialCsv::reopen`].
    pub fn reopen(
        dir: &Path,
        mark: &FileMark,
        record: RunRecord,
        reactions: ReactionColumns,
        nodes: NodeColumns,
    ) -> std::io::Result<Self> {
        Ok(Self {
            csv: PartialCsv::reopen(&dir.join(HISTORY_CSV), mark)?,
            reactions,
            nodes,
            record,
        })
    }

    /// Flushes the rows so far to disk and returns the file's mark, for a restart point.
    ///
    /// # Errors
    /// I/O errors.
    pub fn mark(&mut self) -> std::io::Result<FileMark> {
        self.csv.mark()
    }

    /// The record so far, for a restart point.
    pub fn record(&self) -> &RunRecord {
        &self.record
    }

    /// Flushes and renames the file to `history.csv`.
    ///
    /// # Errors
    /// I/O errors.
    pub fn finish(self) -> std::io::Result<RunRecord> {
        self.csv.finish()?;
        Ok(self.record)
    }
}

impl<const D: usize> Observer<D> for ModelRecorder {
    fn on_increment(
        &mut self,
        model: &Model<D>,
        report: &IncrementReport<'_>,
    ) -> std::io::Result<()> {
        let s = report.state;
        let number = |v: f64| format!("{v:.9e}");
        let mut row = vec![
            number(s.time),
            report.step.to_string(),
            report.increment.to_string(),
            format!("{:.6}", s.load_factor),
            format!("{:.6e}", report.size),
            report.counters.newton_iterations.to_string(),
            report.counters.contact_solves.to_string(),
        ];
        let dofs = model.dofs();
        for b in 0..model.bodies().len() {
            for &eq in dofs.body_translation(b).iter().flatten() {
                row.push(number(s.x[eq]));
                row.push(number(s.v[eq]));
            }
            if let Some(eq) = dofs.body_rotation(b) {
                row.push(number(s.x[eq]));
                row.push(number(s.v[eq]));
            }
            if let [e0, e1, e2] = *dofs.body_rotations(b) {
                // the rotation vector of the turn from the start and the spatial angular
                // velocity, `Q_p W` with `Q_p` the principal axes' orientation
                let turned = model.body_frame(&s.x, b, &s.orientations).orientation;
                let principal = orientation(dofs, model.bodies(), &s.orientations, &s.x, b);
                let omega = principal * Vector3::new(s.v[e0], s.v[e1], s.v[e2]);
                row.extend(
                    turned
                        .scaled_axis()
                        .iter()
                        .chain(omega.iter())
                        .map(|&c| number(c)),
                );
            }
        }
        let totals = pair_totals(model, s);
        let record = &mut self.record;
        for t in &totals {
            row.push(number(t.normal_force));
            row.extend(t.tangential_force[..D - 1].iter().map(|&f| number(f)));
            row.push(t.active.to_string());
            row.push(t.sliding.to_string());
            row.push(format!("{:.3e}", t.max_penetration.max(0.0)));
            record.max_penetration = record.max_penetration.max(t.max_penetration);
            record.max_sliding_separation =
                record.max_sliding_separation.max(t.max_sliding_separation);
        }
        row.extend(self.reactions.values(s).map(number));
        row.extend(self.nodes.values(model, s).map(number));
        let e = &s.energy;
        row.extend(
            [
                e.kinetic,
                e.strain,
                e.hourglass,
                e.external_work,
                e.friction_dissipation,
                e.normal_work,
                e.algorithmic_dissipation,
            ]
            .map(number),
        );
        if !model.prescribed().is_empty() {
            row.push(number(e.reaction_work));
        }
        if model.has_stiffness_damping() {
            row.push(number(e.damping_dissipation));
        }
        self.csv.record(row)?;
        record.energy_scale = [
            e.kinetic + e.strain + e.hourglass,
            e.external_work.abs(),
            e.normal_work.abs(),
            e.friction_dissipation,
            e.algorithmic_dissipation.abs(),
            e.reaction_work.abs(),
            e.damping_dissipation,
        ]
        .into_iter()
        .fold(record.energy_scale, f64::max);
        record.first_energy.get_or_insert_with(|| e.clone());
        if report.dynamic && record.dynamic_start_energy.is_none() {
            record.dynamic_start_energy = record.last_energy.clone();
        }
        record.last_energy = Some(e.clone());
        record.final_pairs = totals;
        record.final_bodies = body_states(model, s);
        record.final_time = s.time;
        Ok(())
    }
}
