//! The scene the integrator solves: one deformable solid, rigid bodies, ties, loads (see
//! [`crate::loads`]) and node-to-rigid-surface contact pairs. A [`Model`] is checked once when built and is immutable
//! during a run.

use std::collections::BTreeSet;

use nalgebra::{DVector, SVector, Vector3};
use skid_contact::kinematics::RotatingFrame;
use skid_contact::surface::RigidSurface;
use skid_fem::cell::embed;
use skid_fem::element::{Formulation, SolidElement};
use skid_fem::hourglass::Hourglass;
use skid_fem::material::Hyperelastic;
use skid_fem::mesh::SolidMesh;
use skid_fem::rigid::{RigidBody, Rotation};

use crate::dof::{DofMap, EquationOwner};
use crate::error::ModelError;
use crate::loads::{DeadLoad, Loads, PressureLoad, Scene};
use crate::motion::{MotionTarget, PrescribedMotion, body_equation};
use crate::orientation::{self, Orientation};
use crate::solid_mass::{MassSource, lumped_mass, redistributed_mass};

/// A material and its mass density, shared by a group of elements.
#[derive(Debug)]
pub struct Section {
    /// Hyperelastic material.
    pub material: Box<dyn Hyperelastic>,
    /// Mass density, kg/m^3.
    pub density: f64,
    /// Stiffness-proportional (Rayleigh) damping factor `beta`, s: in a dynamic step the
    /// elements add the viscous force `beta K_T(x) v` (see [`crate::assembly::Damping`]);
    /// 0 for none.
    pub stiffness_damping: f64,
}

/// The deformable solid: mesh, materials and section data.
#[derive(Debug)]
pub struct SolidPart<const D: usize> {
    /// Name used in messages and output file names.
    pub name: String,
    /// Mesh of one-point elements (quads in 2D, hexahedra in 3D).
    pub mesh: SolidMesh<D>,
    /// Sections (at least one).
    pub sections: Vec<Section>,
    /// Section of each element, an index into `sections`; empty when every element has the
    /// first.
    pub element_sections: Vec<usize>,
    /// Out-of-plane thickness in 2D (plane strain), m; 1 in 3D.
    pub thickness: f64,
    /// Hourglass control of the one-point elements (default: the stiffness control at scale 1).
    pub hourglass: Hourglass,
    /// Formulation of each element; empty when every element is the one-point
    /// [`Formulation::Reduced`].
    pub element_formulations: Vec<Formulation>,
    /// Whether the solid is quasi-static: its nodes carry no inertia, so in a dynamic step they
    /// are in equilibrium with the mean contact forces of each increment (see
    /// [`crate::increment`]). The densities then serve only the regularisation of static
    /// Newton steps.
    pub quasi_static: bool,
    /// Node components held at zero displacement throughout, as `(node, axis)` pairs.
    pub fixed: Vec<(usize, usize)>,
}

impl<const D: usize> SolidPart<D> {
    /// The section of element `e` (the first for an element beyond `element_sections`, which
    /// [`Model::new`] refuses unless that list is empty).
    pub fn section(&self, e: usize) -> &Section {
        let k = self.element_sections.get(e).copied().unwrap_or(0);
        &self.sections[k.min(self.sections.len() - 1)]
    }

    /// The material of element `e`.
    pub fn material(&self, e: usize) -> &dyn Hyperelastic {
        self.section(e).material.as_ref()
    }

    /// The mass density of element `e`, kg/m^3.
    pub fn density(&self, e: usize) -> f64 {
        self.section(e).density
    }

    /// The formulation of element `e` ([`Formulation::Reduced`] for an element beyond
    /// `element_formulations`, which [`Model::new`] refuses unless that list is empty).
    pub fn formulation(&self, e: usize) -> Formulation {
        (self.element_formulations.get(e).copied()).unwrap_or(Formulation::Reduced)
    }
}

/// Nodes tied to a rigid body: they translate with its reference node.
#[derive(Clone, Debug)]
pub struct Tie {
    /// Index of the rigid body.
    pub body: usize,
    /// Tied nodes.
    pub nodes: Vec<usize>,
}

/// Frictional contact between slave nodes of the solid and a surface carried by a rigid body.
#[derive(Debug)]
pub struct ContactPair {
    /// Name used in messages.
    pub name: String,
    /// Slave nodes (every one is a permanent contact candidate).
    pub nodes: Vec<usize>,
    /// Rigid body carrying the master surface.
    pub body: usize,
    /// Master surface, described in the body frame (origin at the reference node).
    pub surface: Box<dyn RigidSurface>,
    /// Coulomb friction coefficient.
    pub mu: f64,
}

/// A checked scene with its equation numbering and lumped masses.
#[derive(Debug)]
pub struct Model<const D: usize> {
    part: SolidPart<D>,
    bodies: Vec<RigidBody<D>>,
    ties: Vec<Tie>,
    pressures: Vec<PressureLoad>,
    dead_loads: Vec<DeadLoad>,
    contacts: Vec<ContactPair>,
    elements: Vec<SolidElement<D>>,
    dofs: DofMap<D>,
    mass: DVector<f64>,
    regularization_mass: DVector<f64>,
    quasi_static: Vec<bool>,
    /// With the contact nodes' mass moved off them ([`Model::with_massless_contact_nodes`]):
    /// whether each equation is one of the solid's or of a body tied to it.
    solid_rows: Option<Vec<bool>>,
    length_scale: f64,
    /// Initial velocities of the solid's nodes, `(node, velocity)`.
    node_velocities: Vec<(usize, SVector<f64, D>)>,
    /// Prescribed motions, each with its equation.
    prescribed: Vec<(usize, PrescribedMotion)>,
}

fn invalid<T>(msg: String) -> Result<T, ModelError> {
    Err(ModelError::Invalid(msg))
}

impl<const D: usize> Model<D> {
    /// Checks the scene and numbers its equations.
    ///
    /// # Errors
    /// [`ModelError`] naming the entity at fault: a bad mesh or element geometry, non-physical
    /// density or thickness, an out-of-range node or body, a node tied twice, a tie to a body
    /// that can rotate, a negative friction coefficient, an equation without inertia, or a
    /// load that does not fit (see [`crate::loads::ConcentratedLoad`]).
    pub fn new(
        part: SolidPart<D>,
        bodies: Vec<RigidBody<D>>,
        ties: Vec<Tie>,
        loads: Loads<D>,
        contacts: Vec<ContactPair>,
    ) -> Result<Self, ModelError> {
        let Loads {
            pressures,
            concentrated,
            gravity,
        } = loads;
        if D != 2 && D != 3 {
            return invalid(format!("dimension must be 2 or 3, got {D}"));
        }
        part.mesh.validate()?;
        if part.sections.is_empty() {
            return invalid("the solid needs at least one section".into());
        }
        for (k, section) in part.sections.iter().enumerate() {
            if !(section.density.is_finite() && section.density > 0.0) {
                return invalid(format!(
                    "section {k}: density must be > 0, got {}",
                    section.density
                ));
            }
        }
        let n_elements = part.mesh.elements.len();
        if !part.element_sections.is_empty() && part.element_sections.len() != n_elements {
            return invalid(format!(
                "{} element sections for {n_elements} elements",
                part.element_sections.len()
            ));
        }
        if let Some((e, k)) = part
            .element_sections
            .iter()
            .enumerate()
            .find(|&(_, &k)| k >= part.sections.len())
        {
            return invalid(format!(
                "element {e}: section {k} does not exist ({} sections)",
                part.sections.len()
            ));
        }
        let formulations = part.element_formulations.len();
        if formulations != 0 && formulations != part.mesh.elements.len() {
            return invalid(format!(
                "{formulations} element formulations for {} elements",
                part.mesh.elements.len()
            ));
        }
        if let Some((k, section)) = part
            .sections
            .iter()
            .enumerate()
            .find(|(_, s)| !(s.stiffness_damping.is_finite() && s.stiffness_damping >= 0.0))
        {
            return invalid(format!(
                "section {k}: stiffness damping must be >= 0, got {}",
                section.stiffness_damping
            ));
        }
        if !(part.thickness.is_finite() && part.thickness > 0.0) {
            return invalid(format!("thickness must be > 0, got {}", part.thickness));
        }
        if let Hourglass::Stiffness { scale } = part.hourglass
            && !(scale.is_finite() && scale > 0.0)
        {
            return invalid(format!("hourglass scale must be > 0, got {scale}"));
        }
        for body in &bodies {
            body.validate()?;
        }
        let n_nodes = part.mesh.nodes.len();
        let check_node = |n: usize, what: &str| {
            if n >= n_nodes {
                invalid(format!("{what}: node {n} does not exist ({n_nodes} nodes)"))
            } else {
                Ok(())
            }
        };
        let check_body = |b: usize, what: &str| {
            if b >= bodies.len() {
                invalid(format!("{what}: rigid body {b} does not exist"))
            } else {
                Ok(())
            }
        };

        let mut tied_to = vec![None; n_nodes];
        for tie in &ties {
            check_body(tie.body, "tie")?;
            if bodies[tie.body].rotation != Rotation::None {
                return invalid(format!(
                    "tie to rigid body '{}': ties to rotating bodies are not supported",
                    bodies[tie.body].name
                ));
            }
            for &n in &tie.nodes {
                check_node(n, "tie")?;
                if tied_to[n].replace(tie.body).is_some() {
                    return invalid(format!("node {n} is tied twice"));
                }
            }
        }
        let mut fixed = vec![[false; D]; n_nodes];
        for &(n, axis) in &part.fixed {
            check_node(n, "fixed node")?;
            if axis >= D {
                return invalid(format!(
                    "fixed node {n}: axis {axis} does not exist in {D}D"
                ));
            }
            if let Some(b) = tied_to[n] {
                return invalid(format!(
                    "node {n} is both fixed and tied to rigid body '{}': a tied node moves \
                     with the body; fix the body's motion instead",
                    bodies[b].name
                ));
            }
            fixed[n][axis] = true;
        }
        let face_nodes = 1 << (D - 1);
        for load in &pressures {
            if !load.pressure.is_finite() {
                return invalid(format!("pressure must be finite, got {}", load.pressure));
            }
            for face in &load.faces {
                if face.len() != face_nodes {
                    return invalid(format!(
                        "pressure face {face:?} must have {face_nodes} nodes"
                    ));
                }
                for &n in face {
                    check_node(n, "pressure face")?;
                }
            }
        }
        for pair in &contacts {
            check_body(pair.body, &format!("contact pair '{}'", pair.name))?;
            if !(pair.mu.is_finite() && pair.mu >= 0.0) {
                return invalid(format!(
                    "contact pair '{}': friction coefficient must be >= 0, got {}",
                    pair.name, pair.mu
                ));
            }
            for &n in &pair.nodes {
                check_node(n, &format!("contact pair '{}'", pair.name))?;
            }
        }

        let mut elements = Vec::with_capacity(part.mesh.elements.len());
        for (e, conn) in part.mesh.elements.iter().enumerate() {
            let x: Vec<SVector<f64, D>> = conn.iter().map(|&n| part.mesh.nodes[n]).collect();
            let formulation = part.formulation(e);
            let material = part.material(e);
            let element =
                SolidElement::new(formulation, &x, part.thickness, material, part.hourglass)
                    .map_err(|err| ModelError::Invalid(format!("element {e}: {err}")))?;
            elements.push(element);
        }

        let free_translations: Vec<[bool; D]> =
            bodies.iter().map(|b| b.free_translations).collect();
        let rotations: Vec<usize> = bodies.iter().map(|b| b.rotation.unknowns()).collect();
        let dofs = DofMap::new(n_nodes, &tied_to, &fixed, &free_translations, &rotations);

        let densities: Vec<f64> = (0..elements.len()).map(|e| part.density(e)).collect();
        let solid = MassSource {
            elements: &elements,
            connectivity: &part.mesh.elements,
            densities: &densities,
        };
        let solid_mass = lumped_mass(&solid, &dofs);
        let mut body_mass = DVector::zeros(dofs.len());
        for (b, body) in bodies.iter().enumerate() {
            for eq in dofs.body_translation(b).iter().flatten() {
                body_mass[*eq] += body.mass;
            }
            let inertia = match body.rotation {
                Rotation::Free {
                    principal_inertia, ..
                } => principal_inertia,
                _ => Vector3::repeat(body.rotary_inertia),
            };
            for (i, &eq) in dofs.body_rotations(b).iter().enumerate() {
                body_mass[eq] += inertia[i];
            }
        }
        let regularization_mass = &solid_mass + &body_mass;
        for (b, body) in bodies.iter().enumerate() {
            for eq in dofs.body_equations(b) {
                if regularization_mass[eq] <= 0.0 {
                    return invalid(format!(
                        "rigid body '{}' has a free motion without inertia (give it mass, \
                         rotary inertia, or tie nodes to it)",
                        body.name
                    ));
                }
            }
        }
        // A quasi-static solid's equations (its nodes and the bodies tied to it) have no
        // inertia. They may not carry a body's own mass: an equation with inertia coupled by
        // stiffness to one without would need rows of the tangent scaled differently (see
        // `crate::increment`), which breaks its symmetry.
        let (mass, quasi_static) = if part.quasi_static {
            for tie in &ties {
                let body = &bodies[tie.body];
                if body.mass > 0.0 {
                    return invalid(format!(
                        "rigid body '{}' is tied to the quasi-static solid and must be massless \
                         too (its mass is {} kg)",
                        body.name, body.mass
                    ));
                }
            }
            let quasi_static: Vec<bool> = solid_mass.iter().map(|&m| m > 0.0).collect();
            (body_mass, quasi_static)
        } else {
            (regularization_mass.clone(), vec![false; dofs.len()])
        };

        let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
        let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
        for p in part
            .mesh
            .nodes
            .iter()
            .chain(bodies.iter().map(|b| &b.reference_point))
        {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let length_scale = (hi - lo).norm().max(f64::MIN_POSITIVE);

        let scene = Scene {
            dofs: &dofs,
            bodies: &bodies,
            elements: &elements,
            connectivity: &part.mesh.elements,
            densities: &densities,
            nodes: n_nodes,
        };
        let mut dead_loads = Vec::with_capacity(concentrated.len() + gravity.len());
        for (i, load) in concentrated.iter().enumerate() {
            dead_loads.push(load.dead(&scene, i)?);
        }
        for (i, load) in gravity.iter().enumerate() {
            dead_loads.push(load.dead(&scene, i)?);
        }

        Ok(Self {
            part,
            bodies,
            ties,
            pressures,
            dead_loads,
            contacts,
            elements,
            dofs,
            mass,
            regularization_mass,
            quasi_static,
            solid_rows: None,
            length_scale,
            node_velocities: Vec::new(),
            prescribed: Vec::new(),
        })
    }

    /// The model with the lumped mass of the solid's contact nodes moved to the other nodes of
    /// their elements (see [`crate::solid_mass`]): the contact nodes' equations are then
    /// without inertia, in equilibrium at the end of each dynamic increment, so that their
    /// contact forces do not ring as the time step shrinks. Nothing changes for a quasi-static
    /// solid or a model without contact.
    ///
    /// # Errors
    /// [`ModelError::Invalid`] for a contact node tied to a rigid body, an element whose nodes
    /// are all contact nodes, or a contact surface carried by a body tied to the solid (its
    /// equations would mix the solid's rows, scaled in a dynamic increment, with contact
    /// impulses).
    pub fn with_massless_contact_nodes(mut self) -> Result<Self, ModelError> {
        if self.part.quasi_static || self.contacts.is_empty() {
            return Ok(self);
        }
        if let Some(pair) =
            (self.contacts.iter()).find(|p| self.ties.iter().any(|t| t.body == p.body))
        {
            return invalid(format!(
                "contact pair '{}': its surface's body '{}' is tied to the solid, so the \
                 contact nodes' mass cannot be moved off them",
                pair.name, self.bodies[pair.body].name
            ));
        }
        let contact: BTreeSet<usize> = (self.contacts.iter())
            .flat_map(|p| p.nodes.iter().copied())
            .collect();
        if let Some((node, tie)) = (self.ties.iter())
            .find_map(|t| t.nodes.iter().find(|n| contact.contains(n)).map(|n| (n, t)))
        {
            return invalid(format!(
                "contact node {node} is tied to rigid body '{}': its mass cannot be moved off it",
                self.bodies[tie.body].name
            ));
        }
        let densities: Vec<f64> = (0..self.elements.len())
            .map(|e| self.part.density(e))
            .collect();
        let solid = MassSource {
            elements: &self.elements,
            connectivity: &self.part.mesh.elements,
            densities: &densities,
        };
        let (redistributed, contact_equations) = redistributed_mass(&solid, &self.dofs, &contact)?;
        let lumped = lumped_mass(&solid, &self.dofs);
        self.mass += redistributed - lumped;
        for &eq in &contact_equations {
            self.mass[eq] = 0.0;
            self.quasi_static[eq] = true;
        }
        let mut rows = vec![false; self.dofs.len()];
        for node in 0..self.part.mesh.nodes.len() {
            for eq in self.dofs.node(node).iter().flatten() {
                rows[*eq] = true;
            }
        }
        for tie in &self.ties {
            for eq in self.dofs.body_equations(tie.body) {
                rows[eq] = true;
            }
        }
        self.solid_rows = Some(rows);
        Ok(self)
    }

    /// With the contact nodes' mass moved off them: whether each equation is one of the
    /// solid's or of a body tied to it (the rows a dynamic increment scales, see
    /// [`crate::increment`]); `None` otherwise.
    pub fn solid_rows(&self) -> Option<&[bool]> {
        self.solid_rows.as_deref()
    }

    /// The model with these initial velocities of the solid's nodes, `(node, velocity)`, added
    /// to those it has (a node given twice takes its last velocity).
    ///
    /// # Errors
    /// [`ModelError::Invalid`] for a node that does not exist, a velocity that is not finite, a
    /// node tied to a rigid body (it moves with the body: give the body the velocity), a
    /// velocity along a fixed component, or a quasi-static solid (its nodes have no inertia).
    pub fn with_node_velocities(
        mut self,
        velocities: Vec<(usize, SVector<f64, D>)>,
    ) -> Result<Self, ModelError> {
        if self.part.quasi_static && !velocities.is_empty() {
            return invalid(
                "initial velocities of a quasi-static solid's nodes: its nodes have no inertia"
                    .into(),
            );
        }
        let n_nodes = self.part.mesh.nodes.len();
        for &(node, v) in &velocities {
            if node >= n_nodes {
                return invalid(format!(
                    "initial velocity: node {node} does not exist ({n_nodes} nodes)"
                ));
            }
            if !v.iter().all(|c| c.is_finite()) {
                return invalid(format!(
                    "initial velocity of node {node}: expected finite components, got {:?}",
                    v.as_slice()
                ));
            }
            if let Some(tie) = self.ties.iter().find(|t| t.nodes.contains(&node)) {
                return invalid(format!(
                    "initial velocity of node {node}: it is tied to rigid body '{}' and moves \
                     with it; give the body the velocity",
                    self.bodies[tie.body].name
                ));
            }
            for (axis, eq) in self.dofs.node(node).iter().enumerate() {
                if eq.is_none() && v[axis] != 0.0 {
                    return invalid(format!(
                        "initial velocity of node {node}: component {axis} is fixed, expected 0 \
                         there, got {}",
                        v[axis]
                    ));
                }
            }
        }
        self.node_velocities.extend(velocities);
        Ok(self)
    }

    /// The model with these prescribed motions added (see [`crate::motion`]).
    ///
    /// # Errors
    /// [`ModelError::Invalid`] for a body or node that does not exist, an axis beyond the
    /// dimension, a value that is not finite, a degree of freedom the model fixes (or a body
    /// does not have), a node tied to a rigid body (prescribe the body's motion), or a degree
    /// of freedom prescribed twice.
    pub fn with_prescribed_motions(
        mut self,
        motions: Vec<PrescribedMotion>,
    ) -> Result<Self, ModelError> {
        for motion in motions {
            let what = match motion.target {
                MotionTarget::Body { body, motion } => format!("body {body} {motion:?}"),
                MotionTarget::Node { node, axis } => format!("node {node} along axis {axis}"),
            };
            let what = format!("prescribed motion of {what}");
            if !motion.value.is_finite() {
                return invalid(format!(
                    "{what}: expected a finite value, got {}",
                    motion.value
                ));
            }
            let equation = match motion.target {
                MotionTarget::Body { body, motion } => {
                    if body >= self.bodies.len() {
                        return invalid(format!(
                            "{what}: the body does not exist ({} bodies)",
                            self.bodies.len()
                        ));
                    }
                    body_equation(&self.dofs, body, motion)
                }
                MotionTarget::Node { node, axis } => {
                    let n_nodes = self.part.mesh.nodes.len();
                    if node >= n_nodes || axis >= D {
                        return invalid(format!(
                            "{what}: expected a node below {n_nodes} and an axis below {D}"
                        ));
                    }
                    if let Some(tie) = self.ties.iter().find(|t| t.nodes.contains(&node)) {
                        return invalid(format!(
                            "{what}: the node is tied to rigid body '{}' and moves with it; \
                             prescribe the body's motion",
                            self.bodies[tie.body].name
                        ));
                    }
                    self.dofs.node(node)[axis]
                }
            };
            let Some(equation) = equation else {
                return invalid(format!(
                    "{what}: the model fixes this degree of freedom (or has none such): \
                     a boundary condition holds it at 0"
                ));
            };
            if self.prescribed.iter().any(|(eq, _)| *eq == equation) {
                return invalid(format!(
                    "{what}: this degree of freedom is prescribed twice"
                ));
            }
            self.prescribed.push((equation, motion));
        }
        Ok(self)
    }

    /// The prescribed motions, each with its equation.
    pub fn prescribed(&self) -> &[(usize, PrescribedMotion)] {
        &self.prescribed
    }

    /// Linear momentum `sum_eq m_eq v_eq` along each axis over the translation equations of
    /// nodes and rigid bodies (an equation of a body carries the masses of the nodes tied to
    /// it), for the velocities `v`.
    pub fn linear_momentum(&self, v: &DVector<f64>) -> SVector<f64, D> {
        let mut p = SVector::zeros();
        for eq in 0..self.dofs.len() {
            if let Some(
                EquationOwner::Node { component, .. }
                | EquationOwner::BodyTranslation { component, .. },
            ) = self.dofs.owner(eq)
            {
                p[component] += self.mass[eq] * v[eq];
            }
        }
        p
    }

    /// Whether a section of the solid has stiffness damping ([`Section::stiffness_damping`]).
    pub fn has_stiffness_damping(&self) -> bool {
        self.part.sections.iter().any(|s| s.stiffness_damping > 0.0)
    }

    /// The deformable solid.
    pub fn part(&self) -> &SolidPart<D> {
        &self.part
    }
    /// Rigid bodies.
    pub fn bodies(&self) -> &[RigidBody<D>] {
        &self.bodies
    }
    /// Ties.
    pub fn ties(&self) -> &[Tie] {
        &self.ties
    }
    /// Pressure loads.
    pub fn pressures(&self) -> &[PressureLoad] {
        &self.pressures
    }
    /// Concentrated and gravity loads, as nodal forces per equation at factor 1.
    pub fn dead_loads(&self) -> &[DeadLoad] {
        &self.dead_loads
    }
    /// Contact pairs.
    pub fn contacts(&self) -> &[ContactPair] {
        &self.contacts
    }
    /// Precomputed elements (same order as the mesh's elements).
    pub fn elements(&self) -> &[SolidElement<D>] {
        &self.elements
    }
    /// Equation numbering.
    pub fn dofs(&self) -> &DofMap<D> {
        &self.dofs
    }
    /// Lumped mass (or rotary inertia) of each equation: its inertia, zero for the equations
    /// of a quasi-static solid.
    pub fn mass(&self) -> &DVector<f64> {
        &self.mass
    }
    /// Lumped mass of each equation counting the solid's density even where it is
    /// quasi-static: the mass term `M/h_s^2` by which Newton steps are regularised, never an
    /// inertia.
    pub fn regularization_mass(&self) -> &DVector<f64> {
        &self.regularization_mass
    }
    /// Whether each equation is without inertia: one of a quasi-static solid's (see
    /// [`SolidPart::quasi_static`]) or of a contact node whose mass was moved off it (see
    /// [`Self::with_massless_contact_nodes`]).
    pub fn quasi_static(&self) -> &[bool] {
        &self.quasi_static
    }
    /// `M^{-1} f` for the lumped mass matrix; equations without mass (which carry no force)
    /// get 0.
    pub fn acceleration_of(&self, f: &DVector<f64>) -> DVector<f64> {
        f.zip_map(&self.mass, |f, m| if m > 0.0 { f / m } else { 0.0 })
    }
    /// Size of the scene (diagonal of the bounding box of nodes and body reference points), m.
    pub fn length_scale(&self) -> f64 {
        self.length_scale
    }
    /// Index of the rigid body with this name.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// The frame of rigid body `body` at `x`: its current reference point `c` (the reference
    /// point plus its displacement) and its orientation `Q`, so that a body-frame point `y` is at
    /// `c + Q y`. `Q` turns by the angle about the axis of a body turning about one axis (`+z`
    /// for a body that cannot rotate), and is the orientation from the records `orientations`
    /// for a body free to turn (see [`crate::orientation`]).
    pub fn body_frame(
        &self,
        x: &DVector<f64>,
        body: usize,
        orientations: &[Orientation],
    ) -> RotatingFrame {
        let b = &self.bodies[body];
        let center = embed(&(b.reference_point + self.dofs.body_displacement(x, body)));
        match b.rotation {
            Rotation::Free { principal_axes, .. } => RotatingFrame::free(
                center,
                &orientation::orientation(&self.dofs, &self.bodies, orientations, x, body),
                &principal_axes,
            ),
            Rotation::Axis(axis) => {
                RotatingFrame::about(center, axis, self.dofs.body_angle(x, body))
            }
            Rotation::None => RotatingFrame::about(center, Vector3::z(), 0.0),
        }
    }

    /// The orientations of the bodies free to turn at `x`, recorded there (see
    /// [`crate::orientation::record`]).
    pub fn record_orientations(
        &self,
        orientations: &[Orientation],
        x: &DVector<f64>,
    ) -> Vec<Orientation> {
        orientation::record(&self.dofs, &self.bodies, orientations, x)
    }

    /// The gyroscopic moments of the bodies free to turn at the body-frame angular velocities
    /// in `v` (see [`crate::orientation::gyroscopic_moments`]).
    pub fn gyroscopic_moments(&self, v: &DVector<f64>) -> Option<DVector<f64>> {
        orientation::gyroscopic_moments(&self.dofs, &self.bodies, v)
    }

    /// Current position of a node embedded in 3D (z = 0 in 2D).
    pub fn node_position(&self, x: &DVector<f64>, node: usize) -> Vector3<f64> {
        embed(&(self.part.mesh.nodes[node] + self.dofs.node_displacement(x, node)))
    }

    /// Initial velocity vector: rigid-body initial velocities, and those given to the solid's
    /// nodes (zero elsewhere).
    pub fn initial_velocity(&self) -> DVector<f64> {
        let mut v = DVector::zeros(self.dofs.len());
        for (node, velocity) in &self.node_velocities {
            for (eq, c) in self.dofs.node(*node).iter().zip(velocity.iter()) {
                if let Some(eq) = eq {
                    v[*eq] = *c;
                }
            }
        }
        for (b, body) in self.bodies.iter().enumerate() {
            for (i, eq) in self.dofs.body_translation(b).iter().enumerate() {
                if let Some(eq) = eq {
                    v[*eq] = body.initial_velocity[i];
                }
            }
            // a body free to turn: in its principal axes
            let w = match body.rotation {
                Rotation::Free {
                    initial_angular_velocity,
                    principal_axes,
                    ..
                } => principal_axes.inverse() * initial_angular_velocity,
                _ => Vector3::repeat(body.initial_angular_velocity),
            };
            for (i, &eq) in self.dofs.body_rotations(b).iter().enumerate() {
                v[eq] = w[i];
            }
        }
        v
    }
}
