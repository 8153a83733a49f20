//! The map from physical degrees of freedom to global equations.
//!
//! Unknowns are numbered node components first (node-major), then rigid-body motions. A node
//! component tied to a rigid body does not get an equation of its own: it maps to the equation
//! of the body's translation along the same axis (or to none if that translation is fixed).
//! Because the tie only involves translations, it is linear, `u_node,i = u_body,i`, and
//! assembling a node's contributions into the body's equation is exactly the condensation
//! `K' = T^T K T` with a 0/1 matrix `T`.

use nalgebra::{DVector, SVector};

/// What kind of motion an equation carries (decides its units in residual norms).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EquationKind {
    /// A translation (m; its residual is a force, N).
    Translation,
    /// A rotation angle (rad; its residual is a moment, N m).
    Rotation,
}

/// Whose motion a global equation carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EquationOwner {
    /// Component `component` (0 = x, 1 = y, 2 = z) of a mesh node's displacement.
    Node {
        /// Node index in the mesh.
        node: usize,
        /// Displacement component.
        component: usize,
    },
    /// A rigid body's translation along `component`.
    BodyTranslation {
        /// Body index in the model.
        body: usize,
        /// Translation component.
        component: usize,
    },
    /// A rigid body's rotation: its angle about its axis (component 0), or the material
    /// rotation about its x, y or z axis of a body free to turn.
    BodyRotation {
        /// Body index in the model.
        body: usize,
        /// Rotation component.
        component: usize,
    },
}

/// Global equation numbers of every node component and rigid-body motion.
#[derive(Clone, Debug)]
pub struct DofMap<const D: usize> {
    node: Vec<[Option<usize>; D]>,
    body_translation: Vec<[Option<usize>; D]>,
    body_rotation: Vec<Vec<usize>>,
    kinds: Vec<EquationKind>,
}

impl<const D: usize> DofMap<D> {
    /// Numbers the equations.
    ///
    /// - `node_count`: number of mesh nodes;
    /// - `tied_to`: for each node, the rigid body it is tied to, if any;
    /// - `fixed`: for each node, the components held at zero displacement (a shorter slice
    ///   leaves the remaining nodes free);
    /// - `free_translations`: per body, which translations are free;
    /// - `rotations`: per body, the number of rotation unknowns (0, 1 or 3; missing: 0).
    pub fn new(
        node_count: usize,
        tied_to: &[Option<usize>],
        fixed: &[[bool; D]],
        free_translations: &[[bool; D]],
        rotations: &[usize],
    ) -> Self {
        let mut kinds = Vec::new();
        let mut next = |kind| {
            kinds.push(kind);
            kinds.len() - 1
        };
        let mut node = vec![[None; D]; node_count];
        for (n, eqs) in node.iter_mut().enumerate() {
            if tied_to.get(n).copied().flatten().is_none() {
                let fixed = fixed.get(n).copied().unwrap_or([false; D]);
                for (eq, fixed) in eqs.iter_mut().zip(fixed) {
                    if !fixed {
                        *eq = Some(next(EquationKind::Translation));
                    }
                }
            }
        }
        let mut body_translation = Vec::with_capacity(free_translations.len());
        let mut body_rotation = Vec::with_capacity(rotations.len());
        for (b, free) in free_translations.iter().enumerate() {
            let mut eqs = [None; D];
            for i in 0..D {
                if free[i] {
                    eqs[i] = Some(next(EquationKind::Translation));
                }
            }
            body_translation.push(eqs);
            let count = rotations.get(b).copied().unwrap_or(0);
            body_rotation.push((0..count).map(|_| next(EquationKind::Rotation)).collect());
        }
        for (n, body) in tied_to.iter().enumerate() {
            if let Some(b) = body {
                node[n] = body_translation[*b];
            }
        }
        Self {
            node,
            body_translation,
            body_rotation,
            kinds,
        }
    }

    /// Number of global equations.
    pub fn len(&self) -> usize {
        self.kinds.len()
    }

    /// True if there are no unknowns at all.
    pub fn is_empty(&self) -> bool {
        self.kinds.is_empty()
    }

    /// Kind of each equation.
    pub fn kinds(&self) -> &[EquationKind] {
        &self.kinds
    }

    /// Equations of a node's components (`None` = fixed).
    pub fn node(&self, node: usize) -> &[Option<usize>; D] {
        &self.node[node]
    }

    /// Equations of a body's translations.
    pub fn body_translation(&self, body: usize) -> &[Option<usize>; D] {
        &self.body_translation[body]
    }

    /// Equation of the angle of a body turning about one fixed axis (`None` for a body that
    /// cannot rotate or is free to turn).
    pub fn body_rotation(&self, body: usize) -> Option<usize> {
        match self.body_rotation[body].as_slice() {
            [angle] => Some(*angle),
            _ => None,
        }
    }

    /// Equations of all a body's rotation unknowns: none, its angle, or the three material
    /// rotations of a body free to turn.
    pub fn body_rotations(&self, body: usize) -> &[usize] {
        &self.body_rotation[body]
    }

    /// All equations of one rigid body (translations, then rotations).
    pub fn body_equations(&self, body: usize) -> Vec<usize> {
        self.body_translation[body]
            .iter()
            .flatten()
            .chain(&self.body_rotation[body])
            .copied()
            .collect()
    }

    /// Whose motion equation `eq` carries: a rigid body's (also for the nodes tied to it) or a
    /// node's; `None` beyond the last equation.
    pub fn owner(&self, eq: usize) -> Option<EquationOwner> {
        let bodies = self.body_translation.iter().zip(&self.body_rotation);
        for (body, (translation, rotation)) in bodies.enumerate() {
            if let Some(component) = translation.iter().position(|e| *e == Some(eq)) {
                return Some(EquationOwner::BodyTranslation { body, component });
            }
            if let Some(component) = rotation.iter().position(|e| *e == eq) {
                return Some(EquationOwner::BodyRotation { body, component });
            }
        }
        self.node.iter().enumerate().find_map(|(node, eqs)| {
            let component = eqs.iter().position(|e| *e == Some(eq))?;
            Some(EquationOwner::Node { node, component })
        })
    }

    /// Displacement of a node, `u_i = x[eq(node, i)]` (0 for fixed components).
    pub fn node_displacement(&self, x: &DVector<f64>, node: usize) -> SVector<f64, D> {
        gather(&self.node[node], x)
    }

    /// Translation of a rigid body's reference node.
    pub fn body_displacement(&self, x: &DVector<f64>, body: usize) -> SVector<f64, D> {
        gather(&self.body_translation[body], x)
    }

    /// Rotation angle of a rigid body turning about one fixed axis (0 for any other body).
    pub fn body_angle(&self, x: &DVector<f64>, body: usize) -> f64 {
        self.body_rotation(body).map_or(0.0, |eq| x[eq])
    }
}

fn gather<const D: usize>(eqs: &[Option<usize>; D], x: &DVector<f64>) -> SVector<f64, D> {
    SVector::<f64, D>::from_fn(|i, _| eqs[i].map_or(0.0, |eq| x[eq]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tied_nodes_share_the_body_translation_equation() {
        // 4 nodes; nodes 2 and 3 tied to body 0 which may only translate along y;
        // body 1 may only rotate.
        let map = DofMap::<2>::new(
            4,
            &[None, None, Some(0), Some(0)],
            &[],
            &[[false, true], [false, false]],
            &[0, 1],
        );
        assert_eq!(map.len(), 4 + 1 + 1);
        assert_eq!(map.node(0), &[Some(0), Some(1)]);
        assert_eq!(map.node(1), &[Some(2), Some(3)]);
        assert_eq!(map.node(2), &[None, Some(4)]);
        assert_eq!(map.node(3), map.node(2));
        assert_eq!(map.body_rotation(1), Some(5));
        assert_eq!(map.kinds()[5], EquationKind::Rotation);
        let x = DVector::from_vec(vec![0.0, 0.0, 0.0, 0.0, -0.004, 1.5]);
        assert_eq!(map.node_displacement(&x, 3)[1], -0.004);
        assert_eq!(map.body_angle(&x, 1), 1.5);
        assert_eq!(map.body_equations(0), vec![4]);
        let translation = Some(EquationOwner::BodyTranslation {
            body: 0,
            component: 1,
        });
        assert_eq!(map.owner(4), translation);
        let rotation = EquationOwner::BodyRotation {
            body: 1,
            component: 0,
        };
        assert_eq!(map.owner(5), Some(rotation));
        let node = Some(EquationOwner::Node {
            node: 1,
            component: 1,
        });
        assert_eq!(map.owner(3), node);
        assert_eq!(map.owner(6), None);
    }

    #[test]
    fn a_body_free_to_turn_has_three_rotation_equations() {
        // body 0 translates along x and turns freely; body 1 turns about one axis
        let map = DofMap::<3>::new(
            1,
            &[None],
            &[],
            &[[true, false, false], [false; 3]],
            &[3, 1],
        );
        assert_eq!(map.len(), 3 + 1 + 3 + 1);
        assert_eq!(map.body_rotations(0), &[4, 5, 6]);
        assert_eq!(map.body_rotation(0), None, "no single angle");
        assert_eq!(map.body_rotation(1), Some(7));
        assert_eq!(map.body_equations(0), vec![3, 4, 5, 6]);
        let x = DVector::from_fn(8, |i, _| i as f64);
        assert_eq!(map.body_angle(&x, 0), 0.0);
        assert_eq!(map.body_angle(&x, 1), 7.0);
        let owner = EquationOwner::BodyRotation {
            body: 0,
            component: 2,
        };
        assert_eq!(map.owner(6), Some(owner));
        assert!(
            map.kinds()[4..]
                .iter()
                .all(|k| *k == EquationKind::Rotation)
        );
    }

    #[test]
    fn fixed_node_components_get_no_equation() {
        // node 0 fixed along x, node 1 along both axes
        let map = DofMap::<2>::new(3, &[None; 3], &[[true, false], [true, true]], &[], &[]);
        assert_eq!(map.len(), 1 + 2);
        assert_eq!(map.node(0), &[None, Some(0)]);
        assert_eq!(map.node(1), &[None, None]);
        assert_eq!(map.node(2), &[Some(1), Some(2)]);
        let x = DVector::from_vec(vec![0.5, 1.0, 2.0]);
        assert_eq!(
            map.node_displacement(&x, 0),
            SVector::<f64, 2>::new(0.0, 0.5)
        );
    }
}
