//! The keyword subset read into definitions that keep the deck's labels and names: model data
//! before the first `*STEP`, history data in each step. Every keyword and parameter outside the
//! subset is an error naming its line; [`super::assemble`] turns the definitions into a model.

use std::collections::HashMap;

use super::controls::read_section_controls;
use super::definitions::{
    BoundaryDef, Change, Definitions, FaceLabel, FieldRequest, GeneralContactDef, InitialDef,
    MaterialDef, Named, Procedure, RigidDef, SectionDef, SectionKind, StepDef, SurfaceDef,
};
use super::fields::{
    allow_parameters, at_most, field, flag, key, label, line_error, real, real_or, required, valued,
};
use super::keywords::{Block, DeckError};
use super::loads::{defined_amplitude, read_amplitude, read_load_block};
use super::rigid::{AnalyticalKind, read_analytical};
use crate::model_spec::DefaultAmplitude;
use crate::schema::MaterialSpec;

/// The sub-option context: which keyword the following material or interaction options belong
/// to.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Context {
    None,
    Material(String),
    Interaction(String),
    Contact,
}

/// Reads all blocks into [`Definitions`].
///
/// # Errors
/// [`DeckError`] at the first keyword, parameter or data line outside the subset or malformed.
pub fn read_definitions(blocks: &[Block]) -> Result<Definitions, DeckError> {
    let mut defs = Definitions::default();
    let mut context = Context::None;
    let mut step: Option<StepDef> = None;
    for block in blocks {
        if let Some(current) = step.as_mut() {
            if block.name == "END STEP" {
                allow_parameters(block, &[])?;
                defs.steps.extend(step.take());
                continue;
            }
            read_step_block(&mut defs, current, block)?;
            continue;
        }
        context = read_model_block(&mut defs, context, block)?;
        if block.name == "STEP" {
            step = Some(start_step(&defs, block)?);
        }
    }
    if let Some(open) = step {
        return Err(DeckError {
            location: open.location,
            message: format!("*STEP {}: no *END STEP closes it", open.name),
        });
    }
    Ok(defs)
}

fn read_model_block(
    defs: &mut Definitions,
    context: Context,
    block: &Block,
) -> Result<Context, DeckError> {
    let sub = |owner: &str| -> Result<String, DeckError> {
        match (&context, owner) {
            (Context::Material(m), "MATERIAL") => Ok(m.clone()),
            (Context::Interaction(i), "SURFACE INTERACTION") => Ok(i.clone()),
            _ => Err(block.error(format!("must follow a *{owner} and its options"))),
        }
    };
    let mut next = Context::None;
    match block.name.as_str() {
        "HEADING" => {
            allow_parameters(block, &[])?;
            defs.heading = block
                .data
                .iter()
                .map(|l| l.fields.join(", "))
                .collect::<Vec<_>>()
                .join("\n");
        }
        "NODE" => defs.mesh.read_nodes(block)?,
        "ELEMENT" => defs.mesh.read_elements(block)?,
        "NSET" => defs.mesh.read_set(block, true)?,
        "ELSET" => defs.mesh.read_set(block, false)?,
        "SURFACE" => read_surface(defs, block)?,
        "RIGID BODY" => read_rigid_body(defs, block)?,
        "MATERIAL" => {
            allow_parameters(block, &["NAME"])?;
            let name = required(block, "NAME")?;
            no_data(block)?;
            insert_named(&mut defs.materials, block, name, MaterialDef::default())?;
            next = Context::Material(key(name));
        }
        "HYPERELASTIC" | "ELASTIC" | "DENSITY" | "DAMPING" => {
            let material = sub("MATERIAL")?;
            let value = read_material_option(block)?;
            let def = defs
                .materials
                .get_mut(&material)
                .map(|m| &mut m.value)
                .ok_or_else(|| block.error("no *MATERIAL open"))?;
            match value {
                MaterialOption::Law(law) if def.law.is_none() => def.law = Some(law),
                MaterialOption::Density(rho) if def.density.is_none() => def.density = Some(rho),
                MaterialOption::Damping(beta) if def.stiffness_damping.is_none() => {
                    def.stiffness_damping = Some(beta)
                }
                _ => return Err(block.error("given twice for this material")),
            }
            next = context.clone();
        }
        "SOLID SECTION" | "MEMBRANE SECTION" | "SHELL SECTION" => {
            defs.sections.push(read_section(block)?);
        }
        "SECTION CONTROLS" => {
            let control = read_section_controls(block)?;
            let name = required(block, "NAME")?;
            insert_named(&mut defs.section_controls, block, name, control)?;
        }
        "MASS" | "ROTARY INERTIA" => read_point_inertia(defs, block)?,
        "SURFACE INTERACTION" => {
            allow_parameters(block, &["NAME"])?;
            let name = required(block, "NAME")?;
            // an optional data line gives the out-of-plane thickness of 2D contact areas,
            // which node-to-surface forces do not use
            if block.data.len() > 1 {
                return Err(
                    block.error("expected at most one data line (the 2D out-of-plane thickness)")
                );
            }
            insert_named(&mut defs.interactions, block, name, 0.0)?;
            next = Context::Interaction(key(name));
        }
        "FRICTION" => {
            let interaction = sub("SURFACE INTERACTION")?;
            allow_parameters(block, &[])?;
            let [line] = block.data.as_slice() else {
                return Err(block.error("expected one data line: the friction coefficient"));
            };
            at_most(block, line, 1)?;
            let mu = real(block, line, 0, "friction coefficient")?;
            if let Some(i) = defs.interactions.get_mut(&interaction) {
                i.value = mu;
            }
        }
        "CONTACT PAIR" => {
            allow_parameters(block, &["INTERACTION", "TYPE"])?;
            if let Some(kind) = valued(block, "TYPE")?
                && !kind.eq_ignore_ascii_case("NODE TO SURFACE")
            {
                return Err(block.error(format!(
                    "TYPE={kind}: skid's contact is node to surface (TYPE=NODE TO SURFACE)"
                )));
            }
            let interaction = required(block, "INTERACTION")?.to_string();
            for line in &block.data {
                at_most(block, line, 2)?;
                let slave = field(line, 0)
                    .ok_or_else(|| line_error(block, line, "field 1 (slave surface) is missing"))?;
                let master = field(line, 1).ok_or_else(|| {
                    line_error(block, line, "field 2 (master surface) is missing")
                })?;
                defs.pairs.push((
                    interaction.clone(),
                    slave.to_string(),
                    master.to_string(),
                    line.location.clone(),
                ));
            }
        }
        "CONTACT" => {
            allow_parameters(block, &[])?;
            no_data(block)?;
            if defs.general.is_some() {
                return Err(block.error("general contact is defined twice"));
            }
            defs.general = Some(GeneralContactDef {
                all_exterior: false,
                interaction: None,
                location: block.location.clone(),
            });
            next = Context::Contact;
        }
        "CONTACT INCLUSIONS" | "CONTACT PROPERTY ASSIGNMENT" => {
            if context != Context::Contact {
                return Err(block.error("must follow *CONTACT"));
            }
            read_general_option(defs, block)?;
            next = Context::Contact;
        }
        "BOUNDARY" => {
            allow_parameters(block, &[])?;
            defs.boundary.extend(read_boundary(block, None)?);
        }
        "INITIAL CONDITIONS" => read_initial(defs, block)?,
        "AMPLITUDE" => {
            let amplitude = read_amplitude(block)?;
            let name = amplitude.name.clone();
            if defs.amplitudes.insert(key(&name), amplitude).is_some() {
                return Err(block.error(format!("amplitude {name} is defined twice")));
            }
        }
        "STEP" => {}
        "DSLOAD" | "DLOAD" | "CLOAD" | "STATIC" | "DYNAMIC" | "OUTPUT" | "NODE OUTPUT"
        | "CONTACT OUTPUT" | "END STEP" => {
            return Err(block.error("is history data: it belongs inside a *STEP"));
        }
        other => return Err(outside_subset(block, other)),
    }
    Ok(next)
}

fn outside_subset(block: &Block, name: &str) -> DeckError {
    block.error(format!(
        "keyword *{name} is outside the subset skid reads (see the deck module's documentation)"
    ))
}

fn no_data(block: &Block) -> Result<(), DeckError> {
    match block.data.first() {
        Some(line) => Err(line_error(block, line, "takes no data lines")),
        None => Ok(()),
    }
}

fn insert_named<T>(
    map: &mut HashMap<String, Named<T>>,
    block: &Block,
    name: &str,
    value: T,
) -> Result<(), DeckError> {
    let named = Named {
        name: name.trim().to_string(),
        value,
        location: block.location.clone(),
    };
    if let Some(previous) = map.insert(key(name), named) {
        return Err(block.error(format!(
            "{name} is already defined at {}",
            previous.location
        )));
    }
    Ok(())
}

enum MaterialOption {
    Law(MaterialSpec),
    Density(f64),
    Damping(f64),
}

/// `*HYPERELASTIC` (`POLYNOMIAL, N=1` or `MOONEY-RIVLIN`: `C10, C01, D1`; `NEO HOOKE`:
/// `C10, D1`), `*ELASTIC` (`E, nu`, read as the compressible neo-Hookean solid with the same
/// small-strain shear and bulk moduli: `C10 = E / (4 (1 + nu))`, `C01 = 0`,
/// `D1 = 6 (1 - 2 nu) / E`), `*DENSITY` (`rho`), `*DAMPING, BETA=beta` (stiffness-proportional
/// Rayleigh damping; no data line).
fn read_material_option(block: &Block) -> Result<MaterialOption, DeckError> {
    if block.name == "DAMPING" {
        allow_parameters(block, &["ALPHA", "BETA"])?;
        no_data(block)?;
        if valued(block, "ALPHA")?.is_some() {
            return Err(block.error(
                "ALPHA (mass-proportional damping, which also damps rigid motion) is not \
                 read: give BETA, the stiffness-proportional factor",
            ));
        }
        let beta = valued(block, "BETA")?
            .ok_or_else(|| block.error("give BETA, the stiffness-proportional factor (s)"))?;
        return match beta.trim().parse::<f64>() {
            Ok(b) if b.is_finite() && b >= 0.0 => Ok(MaterialOption::Damping(b)),
            _ => Err(block.error(format!("BETA={beta}: expected a number >= 0 (s)"))),
        };
    }
    let [line] = block.data.as_slice() else {
        return Err(block.error("expected one data line"));
    };
    match block.name.as_str() {
        "DENSITY" => {
            allow_parameters(block, &[])?;
            at_most(block, line, 1)?;
            Ok(MaterialOption::Density(real(block, line, 0, "density")?))
        }
        "ELASTIC" => {
            allow_parameters(block, &["TYPE"])?;
            if let Some(t) = valued(block, "TYPE")?
                && !t.eq_ignore_ascii_case("ISOTROPIC")
            {
                return Err(block.error(format!("TYPE={t}: only ISOTROPIC is read")));
            }
            at_most(block, line, 2)?;
            let e = real(block, line, 0, "Young's modulus")?;
            let nu = real(block, line, 1, "Poisson's ratio")?;
            if !(e > 0.0 && nu > -1.0 && nu < 0.5) {
                return Err(line_error(
                    block,
                    line,
                    format!("expected E > 0 and -1 < nu < 0.5, got E = {e}, nu = {nu}"),
                ));
            }
            Ok(MaterialOption::Law(MaterialSpec::PolynomialN1 {
                c10: e / (4.0 * (1.0 + nu)),
                c01: 0.0,
                d1: 6.0 * (1.0 - 2.0 * nu) / e,
            }))
        }
        _ => {
            allow_parameters(block, &["POLYNOMIAL", "N", "MOONEY-RIVLIN", "NEO HOOKE"])?;
            let neo = flag(block, "NEO HOOKE")?;
            let mooney = flag(block, "MOONEY-RIVLIN")?;
            let polynomial = flag(block, "POLYNOMIAL")?;
            if usize::from(neo) + usize::from(mooney) + usize::from(polynomial) != 1 {
                return Err(block
                    .error("give exactly one of POLYNOMIAL (with N=1), MOONEY-RIVLIN, NEO HOOKE"));
            }
            if polynomial && valued(block, "N")? != Some("1") {
                return Err(block.error("POLYNOMIAL is read with N=1 only"));
            }
            if !polynomial && block.parameter("N").is_some() {
                return Err(block.error("N= goes with POLYNOMIAL"));
            }
            let (c10, c01, d1) = if neo {
                at_most(block, line, 2)?;
                (
                    real(block, line, 0, "C10")?,
                    0.0,
                    real(block, line, 1, "D1")?,
                )
            } else {
                at_most(block, line, 3)?;
                (
                    real(block, line, 0, "C10")?,
                    real(block, line, 1, "C01")?,
                    real(block, line, 2, "D1")?,
                )
            };
            Ok(MaterialOption::Law(MaterialSpec::PolynomialN1 {
                c10,
                c01,
                d1,
            }))
        }
    }
}

fn read_section(block: &Block) -> Result<SectionDef, DeckError> {
    let kind = match block.name.as_str() {
        "SOLID SECTION" => SectionKind::Solid,
        "MEMBRANE SECTION" => SectionKind::Membrane,
        _ => SectionKind::Shell,
    };
    allow_parameters(block, &["ELSET", "MATERIAL", "OFFSET", "CONTROLS"])?;
    if let Some(offset) = valued(block, "OFFSET")?
        && super::fields::parse_real(offset) != Some(0.0)
    {
        return Err(block.error(format!(
            "OFFSET={offset}: the facets of rigid membranes and shells are contacted on their \
             mid-surface (zero-thickness surface); offsets are not supported"
        )));
    }
    if kind == SectionKind::Solid && block.parameter("OFFSET").is_some() {
        return Err(block.error("OFFSET belongs to membrane and shell sections"));
    }
    let controls = valued(block, "CONTROLS")?.map(str::to_string);
    if kind != SectionKind::Solid && controls.is_some() {
        return Err(block.error(
            "CONTROLS belongs to solid sections (the hourglass control of one-point elements)",
        ));
    }
    let thickness = match block.data.as_slice() {
        [] => None,
        [line] => {
            at_most(block, line, 1)?;
            field(line, 0)
                .map(|_| real(block, line, 0, "thickness"))
                .transpose()?
        }
        _ => return Err(block.error("expected at most one data line (the thickness)")),
    };
    Ok(SectionDef {
        kind,
        elset: required(block, "ELSET")?.to_string(),
        material: required(block, "MATERIAL")?.to_string(),
        thickness,
        controls,
        location: block.location.clone(),
    })
}

fn read_point_inertia(defs: &mut Definitions, block: &Block) -> Result<(), DeckError> {
    allow_parameters(block, &["ELSET"])?;
    let elset = required(block, "ELSET")?.to_string();
    let [line] = block.data.as_slice() else {
        return Err(block.error("expected one data line"));
    };
    if block.name == "MASS" {
        at_most(block, line, 1)?;
        let m = real(block, line, 0, "mass")?;
        defs.masses.push((elset, m, line.location.clone()));
    } else {
        at_most(block, line, 6)?;
        let mut inertia = [0.0; 6];
        for (i, v) in inertia.iter_mut().enumerate() {
            *v = real_or(
                block,
                line,
                i,
                ["I11", "I22", "I33", "I12", "I13", "I23"][i],
                0.0,
            )?;
        }
        if line.fields.len() == 1 {
            // a single value: the planar rotary inertia about z
            inertia = [0.0, 0.0, inertia[0], 0.0, 0.0, 0.0];
        }
        defs.inertias.push((elset, inertia, line.location.clone()));
    }
    Ok(())
}

fn read_surface(defs: &mut Definitions, block: &Block) -> Result<(), DeckError> {
    let name = required(block, "NAME")?;
    let kind = valued(block, "TYPE")?
        .unwrap_or("ELEMENT")
        .to_ascii_uppercase();
    let def = match kind.as_str() {
        "ELEMENT" => {
            allow_parameters(block, &["NAME", "TYPE"])?;
            let mut faces = Vec::new();
            for line in &block.data {
                at_most(block, line, 2)?;
                let target = field(line, 0).ok_or_else(|| {
                    line_error(block, line, "field 1 (element or set) is missing")
                })?;
                let elements = defs.mesh.elements_named(target).ok_or_else(|| {
                    line_error(
                        block,
                        line,
                        format!(
                            "'{target}' is neither an element nor an element set defined above"
                        ),
                    )
                })?;
                let face = match field(line, 1).map(str::to_ascii_uppercase) {
                    None => FaceLabel::Exterior,
                    Some(f) if f == "SPOS" => FaceLabel::Positive,
                    Some(f) if f == "SNEG" => FaceLabel::Negative,
                    Some(f) => f
                        .strip_prefix('S')
                        .and_then(|k| k.parse::<usize>().ok())
                        .filter(|k| (1..=6).contains(k))
                        .map(FaceLabel::Numbered)
                        .ok_or_else(|| {
                            line_error(
                                block,
                                line,
                                format!("field 2: expected a face S1..S6, SPOS or SNEG, got '{f}'"),
                            )
                        })?,
                };
                faces.extend(elements.into_iter().map(|e| (e, face)));
            }
            SurfaceDef::Faces(faces)
        }
        "NODE" => {
            allow_parameters(block, &["NAME", "TYPE"])?;
            let mut nodes = Vec::new();
            for line in &block.data {
                at_most(block, line, 2)?;
                let target = field(line, 0)
                    .ok_or_else(|| line_error(block, line, "field 1 (node or set) is missing"))?;
                nodes.extend(defs.mesh.nodes_named(target).ok_or_else(|| {
                    line_error(
                        block,
                        line,
                        format!("'{target}' is neither a node nor a node set defined above"),
                    )
                })?);
                if field(line, 1).is_some() && real(block, line, 1, "weight")? != 1.0 {
                    return Err(line_error(
                        block,
                        line,
                        "node weights other than 1 are not supported",
                    ));
                }
            }
            SurfaceDef::Nodes(nodes)
        }
        "SEGMENTS" => SurfaceDef::Analytical(read_analytical(block, AnalyticalKind::Segments)?),
        "CYLINDER" => SurfaceDef::Analytical(read_analytical(block, AnalyticalKind::Cylinder)?),
        "REVOLUTION" => SurfaceDef::Analytical(read_analytical(block, AnalyticalKind::Revolution)?),
        other => {
            return Err(block.error(format!(
                "TYPE={other} is outside the subset (ELEMENT, NODE, SEGMENTS, CYLINDER, REVOLUTION)"
            )));
        }
    };
    let empty = match &def {
        SurfaceDef::Faces(faces) => faces.is_empty(),
        SurfaceDef::Nodes(nodes) => nodes.is_empty(),
        SurfaceDef::Analytical(_) => false,
    };
    if empty {
        return Err(block.error(format!(
            "surface {name} has no {}: give its elements or nodes on data lines",
            if kind == "NODE" { "nodes" } else { "faces" }
        )));
    }
    insert_named(&mut defs.surfaces, block, name, def)
}

fn read_rigid_body(defs: &mut Definitions, block: &Block) -> Result<(), DeckError> {
    allow_parameters(
        block,
        &["REF NODE", "ELSET", "ANALYTICAL SURFACE", "TIE NSET"],
    )?;
    no_data(block)?;
    let reference_text = required(block, "REF NODE")?;
    let (reference, name) = match super::fields::parse_label(reference_text) {
        Some(id) => (id, format!("body-{id}")),
        None => {
            let set = defs
                .mesh
                .node_sets
                .get(&key(reference_text))
                .ok_or_else(|| {
                    block.error(format!(
                        "REF NODE={reference_text}: no node or node set of that name"
                    ))
                })?;
            let [id] = set.labels.as_slice() else {
                return Err(block.error(format!(
                    "REF NODE={reference_text}: the node set must hold exactly one node, it holds {}",
                    set.labels.len()
                )));
            };
            (*id, set.name.clone())
        }
    };
    if !defs.mesh.nodes.contains_key(&reference) {
        return Err(block.error(format!("REF NODE: node {reference} is not defined")));
    }
    if defs.rigid_bodies.iter().any(|b| b.reference == reference) {
        return Err(block.error(format!(
            "node {reference} is already the reference node of another rigid body"
        )));
    }
    defs.rigid_bodies.push(RigidDef {
        reference,
        name,
        elset: valued(block, "ELSET")?.map(str::to_string),
        analytical: valued(block, "ANALYTICAL SURFACE")?.map(str::to_string),
        tie: valued(block, "TIE NSET")?.map(str::to_string),
        location: block.location.clone(),
    });
    Ok(())
}

fn read_general_option(defs: &mut Definitions, block: &Block) -> Result<(), DeckError> {
    let Some(general) = defs.general.as_mut() else {
        return Err(block.error("must follow *CONTACT"));
    };
    if block.name == "CONTACT INCLUSIONS" {
        allow_parameters(block, &["ALL EXTERIOR"])?;
        if !flag(block, "ALL EXTERIOR")? || !block.data.is_empty() {
            return Err(block.error(
                "only ALL EXTERIOR (no data lines) is read: general contact between every \
                 exterior face of the part and every rigid surface",
            ));
        }
        general.all_exterior = true;
    } else {
        allow_parameters(block, &[])?;
        let [line] = block.data.as_slice() else {
            return Err(block.error("expected one data line: ', , interaction'"));
        };
        at_most(block, line, 3)?;
        if field(line, 0).is_some() || field(line, 1).is_some() {
            return Err(line_error(
                block,
                line,
                "only the global assignment ', , interaction' (blank surfaces) is read",
            ));
        }
        let interaction = field(line, 2)
            .ok_or_else(|| line_error(block, line, "field 3 (interaction) is missing"))?;
        general.interaction = Some(interaction.to_string());
    }
    Ok(())
}

/// Data lines `node or set, first dof[, last dof[, magnitude]]` or `node or set, TYPE` with
/// `ENCASTRE` (1-6), `PINNED` (1-3), `XSYMM` (1, 5, 6), `YSYMM` (2, 4, 6), `ZSYMM` (3, 4, 5).
/// In a step, `step` gives the keyword's amplitude; a nonzero magnitude (a prescribed motion)
/// is read in a step only.
fn read_boundary(
    block: &Block,
    step: Option<Option<String>>,
) -> Result<Vec<BoundaryDef>, DeckError> {
    let in_step = step.is_some();
    let amplitude = step.flatten();
    let mut out = Vec::new();
    for line in &block.data {
        at_most(block, line, 4)?;
        let mut magnitude = 0.0;
        let target = field(line, 0)
            .ok_or_else(|| line_error(block, line, "field 1 (node or node set) is missing"))?;
        let second = field(line, 1)
            .ok_or_else(|| line_error(block, line, "field 2 (degree of freedom) is missing"))?;
        let dofs: Vec<usize> = match second.to_ascii_uppercase().as_str() {
            "ENCASTRE" => (1..=6).collect(),
            "PINNED" => vec![1, 2, 3],
            "XSYMM" => vec![1, 5, 6],
            "YSYMM" => vec![2, 4, 6],
            "ZSYMM" => vec![3, 4, 5],
            _ => {
                let first = label(block, line, 1, "first degree of freedom")? as usize;
                let last = if field(line, 2).is_some() {
                    label(block, line, 2, "last degree of freedom")? as usize
                } else {
                    first
                };
                if !(first <= last && last <= 6) {
                    return Err(line_error(
                        block,
                        line,
                        format!(
                            "degrees of freedom {first} to {last}: expected 1 <= first <= last <= 6"
                        ),
                    ));
                }
                magnitude = real_or(block, line, 3, "magnitude", 0.0)?;
                if magnitude != 0.0 && !in_step {
                    return Err(line_error(
                        block,
                        line,
                        format!(
                            "magnitude {magnitude}: model data holds degrees of freedom at zero; \
                             prescribe a motion inside a step"
                        ),
                    ));
                }
                (first..=last).collect()
            }
        };
        out.push(BoundaryDef {
            target: target.to_string(),
            dofs,
            magnitude,
            amplitude: amplitude.clone(),
            location: line.location.clone(),
        });
    }
    Ok(out)
}

fn read_initial(defs: &mut Definitions, block: &Block) -> Result<(), DeckError> {
    allow_parameters(block, &["TYPE", "DEFINITION"])?;
    let kind = required(block, "TYPE")?.to_ascii_uppercase();
    if let Some(d) = valued(block, "DEFINITION")?
        && !d.eq_ignore_ascii_case("COORDINATES")
    {
        return Err(block.error(format!("DEFINITION={d}: only COORDINATES is read")));
    }
    match kind.as_str() {
        "VELOCITY" => {
            for line in &block.data {
                at_most(block, line, 3)?;
                let target = field(line, 0)
                    .ok_or_else(|| line_error(block, line, "field 1 (node or set) is missing"))?;
                let dof = label(block, line, 1, "degree of freedom")? as usize;
                if dof > 6 {
                    return Err(line_error(
                        block,
                        line,
                        format!("degree of freedom {dof}: expected 1 to 6"),
                    ));
                }
                defs.initial.push(InitialDef::Velocity {
                    target: target.to_string(),
                    dof,
                    value: real(block, line, 2, "velocity")?,
                    location: line.location.clone(),
                });
            }
        }
        "ROTATING VELOCITY" => {
            if !block.data.len().is_multiple_of(2) {
                return Err(block.error(
                    "expected pairs of data lines: 'node or set, omega, vx, vy, vz' then the \
                     axis points 'ax, ay, az, bx, by, bz'",
                ));
            }
            for pair in block.data.chunks(2) {
                let (first, second) = (&pair[0], &pair[1]);
                at_most(block, first, 5)?;
                at_most(block, second, 6)?;
                let target = field(first, 0)
                    .ok_or_else(|| line_error(block, first, "field 1 (node or set) is missing"))?;
                let omega = real(block, first, 1, "angular velocity")?;
                let mut velocity = [0.0; 3];
                for (i, v) in velocity.iter_mut().enumerate() {
                    *v = real_or(block, first, 2 + i, ["vx", "vy", "vz"][i], 0.0)?;
                }
                let mut axis = [0.0; 6];
                for (i, v) in axis.iter_mut().enumerate() {
                    *v = real_or(
                        block,
                        second,
                        i,
                        ["ax", "ay", "az", "bx", "by", "bz"][i],
                        0.0,
                    )?;
                }
                defs.initial.push(InitialDef::Rotating {
                    target: target.to_string(),
                    omega,
                    velocity,
                    a: [axis[0], axis[1], axis[2]],
                    b: [axis[3], axis[4], axis[5]],
                    location: first.location.clone(),
                });
            }
        }
        other => {
            return Err(block.error(format!(
                "TYPE={other} is outside the subset (VELOCITY, ROTATING VELOCITY)"
            )));
        }
    }
    Ok(())
}

fn start_step(defs: &Definitions, block: &Block) -> Result<StepDef, DeckError> {
    allow_parameters(block, &["NAME", "NLGEOM", "INC", "AMPLITUDE"])?;
    let default_amplitude = match valued(block, "AMPLITUDE")? {
        None => None,
        Some(a) if a.eq_ignore_ascii_case("RAMP") => Some(DefaultAmplitude::Ramp),
        Some(a) if a.eq_ignore_ascii_case("STEP") => Some(DefaultAmplitude::Step),
        Some(a) => {
            return Err(block.error(format!("AMPLITUDE={a}: expected RAMP or STEP")));
        }
    };
    if let Some(inc) = valued(block, "INC")?
        && super::fields::parse_label(inc).is_none()
    {
        return Err(block.error(format!("INC={inc}: expected a positive integer")));
    }
    let nlgeom = block
        .parameter("NLGEOM")
        .map(|_| flag(block, "NLGEOM"))
        .transpose()?;
    let name = valued(block, "NAME")?
        .map_or_else(|| format!("Step-{}", defs.steps.len() + 1), str::to_string);
    Ok(StepDef {
        name,
        location: block.location.clone(),
        procedure: None,
        boundary: Vec::new(),
        loads: Vec::new(),
        nlgeom,
        default_amplitude,
        field_output: Vec::new(),
        history_output: false,
        history_nodes: Vec::new(),
    })
}

/// `*STATIC` without `DIRECT`: automatic incrementation, from the optional data line
/// `initial, period, min, max` with the keyword's defaults: period 1, initial the period, min
/// the smaller of initial and `1e-5` of the period, max the period.
/// Local error tolerance of the increments of `*DYNAMIC` without `DIRECT` (see
/// `skid_integrator::Adaptive`: the estimated local error of an increment, relative to the
/// model size). Abaqus/Standard controls these increments by the half-increment residual
/// (`HAFTOL`, a force), which skid does not compute; a deck cannot give this tolerance, so it
/// is the one that keeps the drum's spin-down as accurate as fixed 0.1 ms increments with
/// fewer of them (`cases/inp/2d-analytic.inp` with automatic increments: 727 increments
/// against 1505, deceleration within 0.001 %, omega within 0.19 % of omega0 of the fixed run;
/// 1e-5 takes 2483 increments, 1e-6 7060, no more accurate than that).
pub const AUTOMATIC_DYNAMIC_TOLERANCE: f64 = 1e-4;

/// The data line `initial, period, min, max` of automatic incrementation, with the keyword's
/// defaults where absent: period 1, initial the period, min the smaller of initial and 1e-5
/// of the period, max the period. Returns `(initial, period, [min, max])`.
fn automatic_increments(block: &Block) -> Result<(f64, f64, [f64; 2]), DeckError> {
    let line = match block.data.as_slice() {
        [] => None,
        [line] => Some(line),
        _ => return Err(block.error("expected one data line: 'initial, period, min, max'")),
    };
    let value = |i: usize, what: &str| -> Result<Option<f64>, DeckError> {
        match line {
            Some(line) if field(line, i).is_some() => real(block, line, i, what).map(Some),
            _ => Ok(None),
        }
    };
    if let Some(line) = line {
        at_most(block, line, 4)?;
    }
    let period = value(1, "time period")?.unwrap_or(1.0);
    let initial = value(0, "initial increment")?.unwrap_or(period);
    let min = value(2, "minimum increment")?.unwrap_or(initial.min(1e-5 * period));
    let max = value(3, "maximum increment")?.unwrap_or(period);
    if !(period > 0.0 && min > 0.0 && min <= initial && initial <= max && max <= period) {
        return Err(block.error(format!(
            "automatic increments need 0 < min <= initial <= max <= period, got initial \
             {initial}, period {period}, min {min}, max {max}"
        )));
    }
    Ok((initial, period, [min, max]))
}

fn read_step_block(
    defs: &mut Definitions,
    step: &mut StepDef,
    block: &Block,
) -> Result<(), DeckError> {
    let op_new = |block: &Block| -> Result<bool, DeckError> {
        match valued(block, "OP")? {
            None => Ok(false),
            Some(op) if op.eq_ignore_ascii_case("MOD") => Ok(false),
            Some(op) if op.eq_ignore_ascii_case("NEW") => Ok(true),
            Some(op) => Err(block.error(format!("OP={op}: expected MOD or NEW"))),
        }
    };
    match block.name.as_str() {
        "STATIC" | "DYNAMIC" => {
            if step.procedure.is_some() {
                return Err(block.error("a step has one procedure"));
            }
            let dynamic = block.name == "DYNAMIC";
            if dynamic && valued(block, "HAFTOL")?.is_some() {
                return Err(block.error(
                    "HAFTOL is not read: skid sizes the increments of *DYNAMIC without DIRECT by \
                     their estimated local error, not by the half-increment residual",
                ));
            }
            allow_parameters(
                block,
                if dynamic {
                    &["DIRECT", "ALPHA"]
                } else {
                    &["DIRECT"]
                },
            )?;
            let alpha = || -> Result<f64, DeckError> {
                Ok(super::fields::real_parameter(block, "ALPHA")?.unwrap_or(-0.05))
            };
            let procedure = if flag(block, "DIRECT")? {
                let [line] = block.data.as_slice() else {
                    return Err(block.error("expected one data line: 'increment, period'"));
                };
                at_most(block, line, 4)?;
                let increment = real(block, line, 0, "time increment")?;
                let period = real(block, line, 1, "time period")?;
                if dynamic {
                    Procedure::Dynamic {
                        dt: increment,
                        period,
                        alpha: alpha()?,
                        automatic: None,
                    }
                } else {
                    Procedure::Static {
                        initial: increment,
                        period,
                        automatic: None,
                    }
                }
            } else {
                let (initial, period, automatic) = automatic_increments(block)?;
                if dynamic {
                    defs.notes.push(format!(
                        "{}: *DYNAMIC without DIRECT: increments sized by their estimated local \
                         error, tolerance {AUTOMATIC_DYNAMIC_TOLERANCE:e} of the model size",
                        block.location
                    ));
                    Procedure::Dynamic {
                        dt: initial,
                        period,
                        alpha: alpha()?,
                        automatic: Some(automatic),
                    }
                } else {
                    Procedure::Static {
                        initial,
                        period,
                        automatic: Some(automatic),
                    }
                }
            };
            step.procedure = Some((procedure, block.location.clone()));
        }
        "BOUNDARY" => {
            allow_parameters(block, &["OP", "AMPLITUDE"])?;
            let amplitude = defined_amplitude(defs, block)?;
            step.boundary.push(Change {
                replace: op_new(block)?,
                items: read_boundary(block, Some(amplitude))?,
            });
        }
        "CLOAD" | "DLOAD" | "DSLOAD" => {
            let change = read_load_block(defs, block, op_new(block)?)?;
            step.loads.push(change);
        }
        "OUTPUT" => {
            allow_parameters(
                block,
                &[
                    "FIELD",
                    "HISTORY",
                    "FREQUENCY",
                    "NUMBER INTERVAL",
                    "TIME INTERVAL",
                    "VARIABLE",
                ],
            )?;
            no_data(block)?;
            step.history_output = flag(block, "HISTORY")?;
            if flag(block, "FIELD")? {
                match field_request(block)? {
                    Some(request) => step.field_output.push(request),
                    None => defs.notes.push(format!(
                        "{}: *OUTPUT, FIELD without TIME INTERVAL or NUMBER INTERVAL: skid \
                         writes field frames at a time interval, so none are written for it \
                         (give TIME INTERVAL= or NUMBER INTERVAL=)",
                        block.location
                    )),
                }
            }
        }
        "NODE OUTPUT" | "CONTACT OUTPUT" | "ENERGY OUTPUT" => {
            allow_parameters(block, &["NSET", "SURFACE", "MASTER", "SLAVE", "VARIABLE"])?;
            for line in &block.data {
                if let Some(bad) = line
                    .fields
                    .iter()
                    .find(|f| !f.chars().all(|c| c.is_ascii_alphanumeric()))
                {
                    return Err(line_error(
                        block,
                        line,
                        format!("'{bad}' is not an output variable name"),
                    ));
                }
            }
            let displacement = block.data.iter().flat_map(|line| &line.fields).any(|f| {
                ["U", "U1", "U2", "U3"]
                    .iter()
                    .any(|u| f.eq_ignore_ascii_case(u))
            });
            match valued(block, "NSET")? {
                Some(set) if block.name == "NODE OUTPUT" && step.history_output && displacement => {
                    step.history_nodes
                        .push((set.to_string(), block.location.clone()));
                }
                _ => defs.notes.push(format!(
                    "{}: *{}: skid writes every body's motion, every contact pair's resultants \
                     and the energies to history.csv in every increment, whatever is \
                     requested, and the displacements of the nodes of the sets that a *NODE \
                     OUTPUT, NSET= under *OUTPUT, HISTORY asks U of",
                    block.location, block.name
                )),
            }
        }
        "STEP" => return Err(block.error("a step cannot start inside another (missing *END STEP)")),
        other if is_model_keyword(other) => {
            return Err(block.error("is model data: it belongs before the first *STEP"));
        }
        other => return Err(outside_subset(block, other)),
    }
    Ok(())
}

/// The interval an `*OUTPUT, FIELD` block asks for: `TIME INTERVAL` (a time > 0) or `NUMBER
/// INTERVAL` (a positive integer), which exclude each other and `FREQUENCY`; `None` without
/// either (`FREQUENCY` counts increments, which skid's field output does not).
fn field_request(block: &Block) -> Result<Option<FieldRequest>, DeckError> {
    let given: Vec<&str> = ["FREQUENCY", "NUMBER INTERVAL", "TIME INTERVAL"]
        .into_iter()
        .filter(|p| block.parameter(p).is_some())
        .collect();
    if given.len() > 1 {
        return Err(block.error(format!("{} exclude each other", given.join(" and "))));
    }
    if let Some(t) = super::fields::real_parameter(block, "TIME INTERVAL")? {
        if !(t.is_finite() && t > 0.0) {
            return Err(block.error(format!("TIME INTERVAL={t}: expected a time > 0")));
        }
        return Ok(Some(FieldRequest::Time(t)));
    }
    match valued(block, "NUMBER INTERVAL")? {
        Some(n) => super::fields::parse_label(n)
            .map(|n| Some(FieldRequest::Number(n)))
            .ok_or_else(|| {
                block.error(format!("NUMBER INTERVAL={n}: expected a positive integer"))
            }),
        None => Ok(None),
    }
}

fn is_model_keyword(name: &str) -> bool {
    matches!(
        name,
        "HEADING"
            | "NODE"
            | "ELEMENT"
            | "NSET"
            | "ELSET"
            | "SURFACE"
            | "RIGID BODY"
            | "MATERIAL"
            | "HYPERELASTIC"
            | "ELASTIC"
            | "DENSITY"
            | "DAMPING"
            | "SOLID SECTION"
            | "MEMBRANE SECTION"
            | "SHELL SECTION"
            | "SECTION CONTROLS"
            | "MASS"
            | "ROTARY INERTIA"
            | "SURFACE INTERACTION"
            | "FRICTION"
            | "CONTACT PAIR"
            | "CONTACT"
            | "CONTACT INCLUSIONS"
            | "CONTACT PROPERTY ASSIGNMENT"
            | "INITIAL CONDITIONS"
            | "AMPLITUDE"
    )
}
