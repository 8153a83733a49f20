//! The mesh part of a deck: `*NODE`, `*ELEMENT`, `*NSET`, `*ELSET` (with `GENERATE`) and the
//! element faces of `*SURFACE, TYPE=ELEMENT`, kept with the deck's own labels.

use std::collections::{BTreeMap, HashMap};

use skid_fem::element::Formulation;

use super::fields::{allow_parameters, at_most, field, flag, key, label, line_error, real, valued};
use super::keywords::{Block, DeckError, Location};

/// Element types of the keyword subset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementKind {
    /// Plane-strain quadrilateral of a formulation (the deformable part in 2D: CPE4R, CPE4,
    /// CPE4H, CPE4I).
    Quad(Formulation),
    /// Hexahedron of a formulation (the deformable part in 3D: C3D8R, C3D8, C3D8H, C3D8I).
    Hex(Formulation),
    /// Two-node rigid line (2D).
    R2d2,
    /// Three-node rigid triangle (3D).
    R3d3,
    /// Four-node rigid quadrilateral (3D).
    R3d4,
    /// Four-node membrane (3D), read as a facet of a rigid body.
    M3d4r,
    /// Four-node shell (3D), read as a facet of a rigid body.
    S4r,
    /// Four-node tetrahedron, read as a cell of a rigid body.
    C3d4,
    /// Point mass.
    Mass,
    /// Point rotary inertia.
    RotaryI,
}

impl ElementKind {
    /// The kind named by `*ELEMENT, TYPE=`, or why it is not read.
    fn parse(name: &str) -> Result<Self, String> {
        Ok(match name.to_ascii_uppercase().as_str() {
            "CPE4R" => Self::Quad(Formulation::Reduced),
            "CPE4" => Self::Quad(Formulation::Full),
            "CPE4H" => Self::Quad(Formulation::Hybrid),
            "CPE4I" => Self::Quad(Formulation::Incompatible),
            "C3D8R" => Self::Hex(Formulation::Reduced),
            "C3D8" => Self::Hex(Formulation::Full),
            "C3D8H" => Self::Hex(Formulation::Hybrid),
            "C3D8I" => Self::Hex(Formulation::Incompatible),
            "R2D2" => Self::R2d2,
            "R3D3" => Self::R3d3,
            "R3D4" => Self::R3d4,
            "M3D4R" => Self::M3d4r,
            "S4R" => Self::S4r,
            "C3D4" => Self::C3d4,
            "MASS" => Self::Mass,
            "ROTARYI" => Self::RotaryI,
            other => {
                return Err(format!(
                    "TYPE={other} is outside the element subset (CPE4R, CPE4, CPE4H, CPE4I, \
                     C3D8R, C3D8, C3D8H, C3D8I, R2D2, R3D3, R3D4, M3D4R, S4R, C3D4, MASS, \
                     ROTARYI)"
                ));
            }
        })
    }

    /// Number of nodes of one element.
    pub fn node_count(self) -> usize {
        match self {
            Self::Quad(_) | Self::R3d4 | Self::M3d4r | Self::S4r | Self::C3d4 => 4,
            Self::R3d3 => 3,
            Self::Hex(_) => 8,
            Self::R2d2 => 2,
            Self::Mass | Self::RotaryI => 1,
        }
    }

    /// Whether the element belongs to the deformable part.
    pub fn is_solid(self) -> bool {
        matches!(self, Self::Quad(_) | Self::Hex(_))
    }

    /// Corners of face `S<k>` (k from 1), listed outward (2D: the edge direction turned
    /// clockwise points out; 3D: counter-clockwise seen from outside), as positions in the
    /// element's node list; `None` for an element without numbered faces.
    pub fn face(self, k: usize) -> Option<&'static [usize]> {
        const QUAD: [&[usize]; 4] = [&[0, 1], &[1, 2], &[2, 3], &[3, 0]];
        const HEX: [&[usize]; 6] = [
            &[0, 3, 2, 1],
            &[4, 5, 6, 7],
            &[0, 1, 5, 4],
            &[1, 2, 6, 5],
            &[2, 3, 7, 6],
            &[3, 0, 4, 7],
        ];
        const C3D4: [&[usize]; 4] = [&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[2, 0, 3]];
        let table: &[&[usize]] = match self {
            Self::Quad(_) => &QUAD,
            Self::Hex(_) => &HEX,
            Self::C3d4 => &C3D4,
            _ => return None,
        };
        k.checked_sub(1).and_then(|i| table.get(i)).copied()
    }

    /// Number of numbered faces.
    pub fn face_count(self) -> usize {
        match self {
            Self::Quad(_) | Self::C3d4 => 4,
            Self::Hex(_) => 6,
            _ => 0,
        }
    }
}

/// One element: its kind and node labels.
#[derive(Clone, Debug)]
pub struct Element {
    /// Element type.
    pub kind: ElementKind,
    /// Node labels in the element's order.
    pub nodes: Vec<u64>,
    /// Where it is defined.
    pub location: Location,
}

/// A named set of labels, with the name as first written.
#[derive(Clone, Debug, Default)]
pub struct LabelSet {
    /// Name as written.
    pub name: String,
    /// Labels in the order given, without repeats.
    pub labels: Vec<u64>,
}

impl LabelSet {
    fn add(&mut self, label: u64) {
        if !self.labels.contains(&label) {
            self.labels.push(label);
        }
    }
}

/// Nodes, elements and sets of a deck.
#[derive(Debug, Default)]
pub struct Mesh {
    /// Node coordinates by label (missing coordinates are 0).
    pub nodes: BTreeMap<u64, [f64; 3]>,
    /// Node labels in the order they are defined.
    pub node_order: Vec<u64>,
    /// Elements by label.
    pub elements: BTreeMap<u64, Element>,
    /// Element labels in the order they are defined.
    pub element_order: Vec<u64>,
    /// Node sets by [`key`].
    pub node_sets: HashMap<String, LabelSet>,
    /// Element sets by [`key`].
    pub element_sets: HashMap<String, LabelSet>,
}

impl Mesh {
    /// Reads a `*NODE` block.
    pub fn read_nodes(&mut self, block: &Block) -> Result<(), DeckError> {
        allow_parameters(block, &["NSET"])?;
        let set = valued(block, "NSET")?;
        for line in &block.data {
            at_most(block, line, 4)?;
            let id = label(block, line, 0, "node label")?;
            let mut x = [0.0; 3];
            for (k, xk) in x.iter_mut().enumerate() {
                if field(line, k + 1).is_some() {
                    *xk = real(block, line, k + 1, ["x", "y", "z"][k])?;
                }
            }
            if self.nodes.insert(id, x).is_some() {
                return Err(line_error(
                    block,
                    line,
                    format!("node {id} is defined twice"),
                ));
            }
            self.node_order.push(id);
            if let Some(set) = set {
                set_entry(&mut self.node_sets, set).add(id);
            }
        }
        Ok(())
    }

    /// Reads an `*ELEMENT` block.
    pub fn read_elements(&mut self, block: &Block) -> Result<(), DeckError> {
        allow_parameters(block, &["TYPE", "ELSET"])?;
        let type_name =
            valued(block, "TYPE")?.ok_or_else(|| block.error("parameter TYPE= is required"))?;
        let kind = ElementKind::parse(type_name).map_err(|m| block.error(m))?;
        let set = valued(block, "ELSET")?;
        for line in &block.data {
            let n = kind.node_count();
            at_most(block, line, n + 1)?;
            let id = label(block, line, 0, "element label")?;
            let nodes = (1..=n)
                .map(|i| label(block, line, i, "node label"))
                .collect::<Result<Vec<_>, _>>()?;
            let element = Element {
                kind,
                nodes,
                location: line.location.clone(),
            };
            if self.elements.insert(id, element).is_some() {
                return Err(line_error(
                    block,
                    line,
                    format!("element {id} is defined twice"),
                ));
            }
            self.element_order.push(id);
            if let Some(set) = set {
                set_entry(&mut self.element_sets, set).add(id);
            }
        }
        Ok(())
    }

    /// Reads an `*NSET` or `*ELSET` block: labels and names of sets already defined, or
    /// `first, last, increment` triples with `GENERATE`.
    pub fn read_set(&mut self, block: &Block, nodes: bool) -> Result<(), DeckError> {
        let name_parameter = if nodes { "NSET" } else { "ELSET" };
        allow_parameters(block, &[name_parameter, "GENERATE"])?;
        let name = valued(block, name_parameter)?
            .ok_or_else(|| block.error(format!("parameter {name_parameter}= is required")))?;
        let generate = flag(block, "GENERATE")?;
        let mut labels = Vec::new();
        for line in &block.data {
            if generate {
                at_most(block, line, 3)?;
                let first = label(block, line, 0, "first label")?;
                let last = label(block, line, 1, "last label")?;
                let step = if field(line, 2).is_some() {
                    label(block, line, 2, "increment")?
                } else {
                    1
                };
                if last < first || (last - first) / step > 10_000_000 {
                    return Err(line_error(
                        block,
                        line,
                        format!(
                            "GENERATE {first}, {last}, {step}: expected first <= last and at most 1e7 labels"
                        ),
                    ));
                }
                labels.extend((first..=last).step_by(step as usize));
            } else {
                for (i, text) in line.fields.iter().enumerate() {
                    if text.is_empty() {
                        continue;
                    }
                    if let Some(id) = super::fields::parse_label(text) {
                        labels.push(id);
                    } else {
                        let sets = if nodes {
                            &self.node_sets
                        } else {
                            &self.element_sets
                        };
                        let set = sets.get(&key(text)).ok_or_else(|| {
                            line_error(
                                block,
                                line,
                                format!(
                                    "field {}: '{text}' is neither a label nor a {} set defined above",
                                    i + 1,
                                    if nodes { "node" } else { "element" }
                                ),
                            )
                        })?;
                        labels.extend(set.labels.iter().copied());
                    }
                }
            }
        }
        let sets = if nodes {
            &mut self.node_sets
        } else {
            &mut self.element_sets
        };
        let set = set_entry(sets, name);
        for id in labels {
            set.add(id);
        }
        Ok(())
    }

    /// The node labels named by a data-line field: a node label or a node set name.
    pub fn nodes_named(&self, name: &str) -> Option<Vec<u64>> {
        match super::fields::parse_label(name) {
            Some(id) => self.nodes.contains_key(&id).then(|| vec![id]),
            None => self.node_sets.get(&key(name)).map(|s| s.labels.clone()),
        }
    }

    /// The element labels named by a data-line field: an element label or an element set name.
    pub fn elements_named(&self, name: &str) -> Option<Vec<u64>> {
        match super::fields::parse_label(name) {
            Some(id) => self.elements.contains_key(&id).then(|| vec![id]),
            None => self.element_sets.get(&key(name)).map(|s| s.labels.clone()),
        }
    }

    /// Checks that every element's nodes are defined and every set's labels exist.
    pub fn check_references(&self) -> Result<(), DeckError> {
        for (id, e) in &self.elements {
            if let Some(n) = e.nodes.iter().find(|n| !self.nodes.contains_key(n)) {
                return Err(DeckError {
                    location: e.location.clone(),
                    message: format!(
                        "*ELEMENT: element {id} uses node {n}, which no *NODE defines"
                    ),
                });
            }
        }
        Ok(())
    }
}

/// The set named `name`, created empty (with that spelling) if new.
fn set_entry<'a>(sets: &'a mut HashMap<String, LabelSet>, name: &str) -> &'a mut LabelSet {
    sets.entry(key(name)).or_insert_with(|| LabelSet {
        name: name.trim().to_string(),
        labels: Vec::new(),
    })
}
