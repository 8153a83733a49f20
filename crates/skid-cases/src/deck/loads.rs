//! Loads of a deck: `*AMPLITUDE` tables (model data) and, in steps, `*CLOAD`, `*DLOAD`
//! (face pressures `Pk` and gravity `GRAV`) and `*DSLOAD` (surface pressures `P`), each with
//! `OP=MOD|NEW` and `AMPLITUDE=`.
//!
//! How skid reads what the keywords leave open:
//! - an amplitude is `DEFINITION=TABULAR`, read against the step time (`TIME=STEP TIME`, the
//!   default) or the total time (`TIME=TOTAL TIME`); a static step's step time runs from 0 to
//!   the time period of its `*STATIC` line, and the total time adds the time periods of the
//!   steps before;
//! - `GRAV` takes the direction components as a direction: the acceleration is the magnitude
//!   times the unit vector; without an element set it acts on the whole model (the part and
//!   every rigid body's point mass);
//! - `OP=NEW` on a keyword removes the loads of earlier steps given with the same keyword;
//!   the loads in force in each step become the model's loads with a factor per step (see
//!   `assemble::loads::model_loads`).

use super::definitions::{
    AmplitudeDef, ConcentratedDef, Definitions, GravityDef, LoadChange, LoadDef, LoadKind, Named,
    PressureDef,
};
use super::fields::{allow_parameters, at_most, field, key, label, line_error, real, valued};
use super::keywords::{Block, DeckError};
use crate::model_spec::AmplitudeTime;

/// Reads a `*AMPLITUDE` block: `t1, a1, t2, a2, ...`, up to four pairs a line, times from 0
/// and increasing.
///
/// # Errors
/// At the keyword or data line at fault.
pub fn read_amplitude(block: &Block) -> Result<Named<AmplitudeDef>, DeckError> {
    allow_parameters(block, &["NAME", "DEFINITION", "TIME"])?;
    let name = valued(block, "NAME")?
        .ok_or_else(|| block.error("parameter NAME is required"))?
        .to_string();
    if let Some(v) = valued(block, "DEFINITION")?
        && !v.eq_ignore_ascii_case("TABULAR")
    {
        return Err(block.error(format!(
            "DEFINITION={v}: skid reads DEFINITION=TABULAR only"
        )));
    }
    let time = match valued(block, "TIME")? {
        None => AmplitudeTime::Step,
        Some(v) if v.eq_ignore_ascii_case("STEP TIME") => AmplitudeTime::Step,
        Some(v) if v.eq_ignore_ascii_case("TOTAL TIME") => AmplitudeTime::Total,
        Some(v) => {
            return Err(block.error(format!("TIME={v}: expected STEP TIME or TOTAL TIME")));
        }
    };
    let mut points = Vec::new();
    for line in &block.data {
        at_most(block, line, 8)?;
        if line.fields.len() % 2 != 0 {
            return Err(line_error(block, line, "expected pairs of time and factor"));
        }
        for pair in 0..line.fields.len() / 2 {
            let t = real(block, line, 2 * pair, "time")?;
            let a = real(block, line, 2 * pair + 1, "factor")?;
            match points.last() {
                None if t < 0.0 => {
                    return Err(line_error(
                        block,
                        line,
                        format!("time {t}: the step and total times start at 0"),
                    ));
                }
                Some(&(before, _)) if t <= before => {
                    return Err(line_error(
                        block,
                        line,
                        format!("time {t} after {before}: the times must increase"),
                    ));
                }
                _ => points.push((t, a)),
            }
        }
    }
    if points.is_empty() {
        return Err(block.error("expected at least one pair of time and factor"));
    }
    Ok(Named {
        name,
        value: AmplitudeDef { points, time },
        location: block.location.clone(),
    })
}

/// The keyword's `AMPLITUDE=` parameter, if given.
///
/// # Errors
/// At the keyword, if the deck defines no `*AMPLITUDE` of that name (amplitudes are model data,
/// so they come before the steps).
pub fn defined_amplitude(defs: &Definitions, block: &Block) -> Result<Option<String>, DeckError> {
    let amplitude = valued(block, "AMPLITUDE")?.map(str::to_string);
    if let Some(name) = &amplitude
        && !defs.amplitudes.contains_key(&key(name))
    {
        return Err(block.error(format!("AMPLITUDE={name}: no *AMPLITUDE named {name}")));
    }
    Ok(amplitude)
}

/// Reads a load keyword of a step (`CLOAD`, `DLOAD`, `DSLOAD`) with its `OP` and `AMPLITUDE`.
///
/// # Errors
/// At the keyword or data line at fault; an amplitude the deck does not define.
pub fn read_load_block(
    defs: &Definitions,
    block: &Block,
    replace: bool,
) -> Result<LoadChange, DeckError> {
    allow_parameters(block, &["OP", "AMPLITUDE"])?;
    let amplitude = defined_amplitude(defs, block)?;
    let keyword = match block.name.as_str() {
        "CLOAD" => "CLOAD",
        "DLOAD" => "DLOAD",
        _ => "DSLOAD",
    };
    let mut items = Vec::new();
    for line in &block.data {
        let kind = match keyword {
            "CLOAD" => {
                at_most(block, line, 3)?;
                let target =
                    field(line, 0).ok_or_else(|| line_error(block, line, "field 1 is missing"))?;
                let dof = label(block, line, 1, "degree of freedom")?;
                if !(1..=6).contains(&dof) {
                    return Err(line_error(
                        block,
                        line,
                        format!("degree of freedom {dof}: expected 1 to 6"),
                    ));
                }
                LoadKind::Concentrated(ConcentratedDef {
                    target: target.to_string(),
                    dof: dof as usize,
                    magnitude: real(block, line, 2, "magnitude")?,
                    location: line.location.clone(),
                })
            }
            _ => distributed(block, line, keyword)?,
        };
        items.push(LoadDef {
            kind,
            amplitude: amplitude.clone(),
        });
    }
    Ok(LoadChange {
        keyword,
        replace,
        items,
    })
}

/// A `*DLOAD` or `*DSLOAD` data line.
fn distributed(
    block: &Block,
    line: &super::keywords::DataLine,
    keyword: &str,
) -> Result<LoadKind, DeckError> {
    let load = field(line, 1).unwrap_or_default().to_ascii_uppercase();
    if keyword == "DLOAD" && load == "GRAV" {
        at_most(block, line, 6)?;
        let g = real(block, line, 2, "magnitude")?;
        let direction: Vec<f64> = (3..6)
            .map(|i| match field(line, i) {
                Some(_) => real(block, line, i, "direction component"),
                None => Ok(0.0),
            })
            .collect::<Result<_, _>>()?;
        let norm = direction.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return Err(line_error(
                block,
                line,
                "GRAV: the direction (fields 4 to 6) must not be zero",
            ));
        }
        return Ok(LoadKind::Gravity(GravityDef {
            target: field(line, 0).map(str::to_string),
            acceleration: std::array::from_fn(|i| direction[i] * (g / norm)),
            location: line.location.clone(),
        }));
    }
    at_most(block, line, 3)?;
    let target = field(line, 0).ok_or_else(|| line_error(block, line, "field 1 is missing"))?;
    let face = if keyword == "DSLOAD" {
        if load != "P" {
            return Err(line_error(
                block,
                line,
                format!("load type '{load}': only P (pressure) is read"),
            ));
        }
        None
    } else {
        Some(
            load.strip_prefix('P')
                .and_then(|k| k.parse::<usize>().ok())
                .filter(|k| (1..=6).contains(k))
                .ok_or_else(|| {
                    line_error(
                        block,
                        line,
                        format!("load type '{load}': expected P1..P6 (face pressure) or GRAV"),
                    )
                })?,
        )
    };
    Ok(LoadKind::Pressure(PressureDef {
        target: target.to_string(),
        face,
        magnitude: real(block, line, 2, "magnitude")?,
        location: line.location.clone(),
    }))
}
