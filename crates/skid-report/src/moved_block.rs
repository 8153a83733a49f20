//! A deformable block moved over a fixed rigid flat by prescribed motions in static steps (the
//! scenes `cases/verification/2d-block-dragged-on-flat*` and `2d-block-sheared-on-flat-deck`):
//! what balances its friction, from the model as run.
//!
//! The flat is the master of the scene's one frictional pair: a rigid plane on a body held in
//! every degree of freedom. Every step is static, so every increment is an equilibrium of the
//! block with whatever holds it: the flat's contact forces, the loads, and the reactions of
//! the prescribed motions. When no load pushes along the flat (every concentrated force and
//! gravity lies along its normal `n`) and nothing else holds a translation along it (no
//! boundary condition without a value on another body or a node set, none in the steps), the
//! friction alone balances the reactions there: the resultant `R` of the prescribed motions'
//! reactions has a component along the flat, `R_t = R - (R . n) n`, as large as the friction
//! resultant `|T|`, and, while every contact slides, as large as `mu N`.

use crate::block_on_flat::{along_plane, flat_pair};
use skid_cases::model_spec::{Dof, LoadSpec, ModelSpec, ModelStepSpec};

/// A block moved over a fixed flat: what the balance of its reactions needs.
#[derive(Clone, Debug, PartialEq)]
pub struct MovedBlock {
    /// Name of the frictional pair between the block and the flat.
    pub pair: String,
    /// Friction coefficient of the pair.
    pub mu: f64,
    /// Unit normal of the flat.
    pub normal: [f64; 3],
    /// The history columns of the reactions that move the block along each axis
    /// (`B.reaction_x` of a body, `S.reaction_x` of a node set, ...), by axis.
    pub reactions: Vec<(usize, String)>,
}

impl MovedBlock {
    /// The scene of `spec`, if it is one (see the module documentation).
    pub fn recognise(spec: &ModelSpec) -> Option<Self> {
        let dim = spec.dimension;
        let (pair, flat, n) = flat_pair(spec)?;
        let along_flat = |v: &[f64]| along_plane(v, &n);
        let axis_along_flat = |axis: usize| {
            let mut e = [0.0; 3];
            e[axis] = 1.0;
            along_flat(&e) > 1e-12
        };
        let flat_held = Dof::all(dim).iter().all(|dof| {
            spec.boundary.iter().any(|b| {
                b.body.as_deref() == Some(flat.name.as_str())
                    && !b.is_prescribed()
                    && b.dofs.contains(dof)
            })
        });
        let static_steps = spec.steps.iter().all(|step| match step {
            ModelStepSpec::Static { boundary, .. } => boundary.iter().all(|b| {
                b.body.as_deref() == Some(flat.name.as_str())
                    || b.dofs.as_ref().is_some_and(|dofs| {
                        dofs.iter()
                            .all(|d| d.translation_axis().is_none_or(|a| !axis_along_flat(a)))
                    })
            }),
            ModelStepSpec::Dynamic { .. } => false,
        });
        let other_supports = spec.boundary.iter().any(|b| {
            !b.is_prescribed()
                && b.body.as_deref() != Some(flat.name.as_str())
                && b.dofs
                    .iter()
                    .any(|d| d.translation_axis().is_some_and(axis_along_flat))
        });
        let loads_along = spec.loads.iter().any(|load| match load {
            LoadSpec::Concentrated { force, .. } => {
                force.as_ref().is_some_and(|f| along_flat(f) > 0.0)
            }
            LoadSpec::Gravity { acceleration, .. } => along_flat(acceleration) > 0.0,
            LoadSpec::Pressure { .. } => true,
        });
        let reactions: Vec<(usize, String)> = spec
            .boundary
            .iter()
            .filter(|b| b.is_prescribed())
            .filter_map(|b| Some((b.body.as_ref().or(b.node_set.as_ref())?, &b.dofs)))
            .flat_map(|(name, dofs)| {
                dofs.iter()
                    .filter_map(|d| d.translation_axis())
                    .map(move |axis| (axis, format!("{name}.reaction_{}", ["x", "y", "z"][axis])))
            })
            .collect();
        (pair.mu > 0.0
            && flat_held
            && static_steps
            && !other_supports
            && !loads_along
            && reactions.iter().any(|&(axis, _)| axis_along_flat(axis)))
        .then(|| Self {
            pair: pair.name.clone(),
            mu: pair.mu,
            normal: n,
            reactions,
        })
    }

    /// `|R_t|`, the size of the component along the flat of the resultant whose components
    /// along the axes are `resultant`.
    pub fn along_flat(&self, resultant: &[f64; 3]) -> f64 {
        along_plane(resultant, &self.normal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::block_on_flat::scene;

    /// The dragged block: the plate's x reaction moves it along the flat y = 0.
    #[test]
    fn the_dragged_block_is_moved_by_the_plate_along_the_flat() {
        let block = MovedBlock::recognise(&scene("2d-block-dragged-on-flat.json"))
            .expect("the dragged block");
        assert_eq!(block.pair, "block-ground");
        assert_eq!(block.reactions, [(0, "plate.reaction_x".to_string())]);
        assert_eq!(block.normal, [0.0, 1.0, 0.0]);
        assert_eq!(block.along_flat(&[3.0, -4.0, 0.0]), 3.0);
    }

    /// What else could push along the flat is not this scene: a load along it, a plate held
    /// along it, a dynamic step, a flat that may move; nor is a scene with no prescribed motion.
    #[test]
    fn scenes_with_other_forces_along_the_flat_are_not_recognised() {
        let dragged = scene("2d-block-dragged-on-flat.json");
        let mut pushed = dragged.clone();
        if let LoadSpec::Concentrated { force, .. } = &mut pushed.loads[0] {
            force.as_mut().expect("a force")[0] = 1.0;
        }
        let mut held_plate = dragged.clone();
        let mut hold = held_plate.boundary[0].clone();
        hold.body = Some("plate".into());
        hold.dofs = vec![Dof::X];
        held_plate.boundary.push(hold);
        let mut free_flat = dragged.clone();
        free_flat.boundary[0].dofs.retain(|&d| d != Dof::X);
        for (what, spec) in [
            ("a load along the flat", pushed),
            ("the plate held along the flat", held_plate),
            ("a flat free to move", free_flat),
            ("dynamic steps", scene("2d-block-pushed-on-flat.json")),
        ] {
            assert_eq!(MovedBlock::recognise(&spec), None, "{what}");
        }
    }
}
