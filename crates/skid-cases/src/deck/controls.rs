//! `*SECTION CONTROLS, NAME=name, HOURGLASS=ENHANCED|STIFFNESS` and the `CONTROLS=name` of a
//! `*SOLID SECTION`: the hourglass control of the one-point elements (CPE4R / C3D8R), the
//! model's `part.section.hourglass`. Abaqus/Explicit's other hourglass controls
//! (`RELAX STIFFNESS`, `VISCOUS`, `COMBINED`) are refused; so are the keyword's other
//! parameters and its data lines (scale factors: the model file's `part.section.hourglass_scale`
//! scales the stiffness control).

use std::collections::HashMap;

use skid_fem::element::Formulation;

use super::definitions::{Definitions, Named, SectionDef};
use super::fields::{allow_parameters, key, line_error, required};
use super::keywords::{Block, DeckError};
use super::mesh::ElementKind;
use crate::schema::HourglassControl;

/// The hourglass control of a `*SECTION CONTROLS` block.
///
/// # Errors
/// [`DeckError`] at the block for a parameter other than `NAME` and `HOURGLASS`, a missing
/// one, an explicit-only or unknown `HOURGLASS` value, or a data line.
pub fn read_section_controls(block: &Block) -> Result<HourglassControl, DeckError> {
    allow_parameters(block, &["NAME", "HOURGLASS"])?;
    required(block, "NAME")?;
    if let Some(line) = block.data.first() {
        return Err(line_error(
            block,
            line,
            "takes no data lines (scale factors: part.section.hourglass_scale scales the \
             stiffness control)",
        ));
    }
    let value = required(block, "HOURGLASS")?;
    match value.trim().to_ascii_uppercase().as_str() {
        "ENHANCED" => Ok(HourglassControl::Enhanced),
        "STIFFNESS" => Ok(HourglassControl::Stiffness),
        "RELAX STIFFNESS" | "VISCOUS" | "COMBINED" => Err(block.error(format!(
            "HOURGLASS={value} is an Abaqus/Explicit hourglass control: skid's implicit \
             one-point elements take HOURGLASS=ENHANCED or STIFFNESS"
        ))),
        _ => Err(block.error(format!("HOURGLASS={value}: expected ENHANCED or STIFFNESS"))),
    }
}

/// The hourglass control of the part whose solid sections are `sections`: that of its
/// sections with one-point elements (CPE4R / C3D8R), which must agree; a section without any
/// may not name the enhanced control. The default if no section has one-point elements.
///
/// # Errors
/// [`DeckError`] at the section that names undefined controls, whose control differs from
/// that of the part's first section with one-point elements, or that names the enhanced
/// control without having one-point elements.
pub fn part_control(
    defs: &Definitions,
    sections: &[&SectionDef],
) -> Result<HourglassControl, DeckError> {
    let mut part: Option<(HourglassControl, &SectionDef)> = None;
    for &section in sections {
        let control = section_control(&defs.section_controls, section)?;
        let one_point = defs
            .mesh
            .elements_named(&section.elset)
            .unwrap_or_default()
            .iter()
            .any(|e| {
                matches!(
                    defs.mesh.elements[e].kind,
                    ElementKind::Quad(Formulation::Reduced)
                        | ElementKind::Hex(Formulation::Reduced)
                )
            });
        let message = match part {
            _ if !one_point && control == HourglassControl::Enhanced => format!(
                "*SOLID SECTION, ELSET={}: HOURGLASS=ENHANCED is for one-point elements (CPE4R \
                 / C3D8R), and the set has none",
                section.elset
            ),
            Some((first, owner)) if one_point && first != control => format!(
                "*SOLID SECTION, ELSET={}: its hourglass control (CONTROLS=) differs from \
                 ELSET={}'s (one hourglass control per part)",
                section.elset, owner.elset
            ),
            None if one_point => {
                part = Some((control, section));
                continue;
            }
            _ => continue,
        };
        return Err(DeckError {
            location: section.location.clone(),
            message,
        });
    }
    Ok(part.map_or_else(HourglassControl::default, |(control, _)| control))
}

/// The hourglass control of `section`: that of the `*SECTION CONTROLS` its `CONTROLS=` names,
/// the default without one.
///
/// # Errors
/// [`DeckError`] at the section if `controls` holds no block of that name.
fn section_control(
    controls: &HashMap<String, Named<HourglassControl>>,
    section: &SectionDef,
) -> Result<HourglassControl, DeckError> {
    let Some(name) = &section.controls else {
        return Ok(HourglassControl::default());
    };
    controls
        .get(&key(name))
        .map(|c| c.value)
        .ok_or_else(|| DeckError {
            location: section.location.clone(),
            message: format!(
                "*SOLID SECTION, ELSET={}: CONTROLS={name}: no *SECTION CONTROLS named {name}",
                section.elset
            ),
        })
}
