//! Parts and instances (`*PART` ... `*END PART`, `*ASSEMBLY` with `*INSTANCE` ... `*END
//! INSTANCE`, as Abaqus/CAE writes decks) flattened into the keyword blocks of one mesh, which
//! the rest of the reader takes as a deck without parts.
//!
//! Each instance copies its part's nodes, elements, sets, surfaces, sections, rigid bodies and
//! point inertias, and then those it defines itself between `*INSTANCE` and `*END INSTANCE`
//! (as Abaqus/CAE writes an analytical rigid part: an empty part whose instance holds the
//! reference node, the surface and the `*RIGID BODY`), all in the part's coordinates: node and
//! element labels are raised by the instance's offset (`k` times a stride above every label
//! of the deck, for the `k`-th instance from 1), set and surface names take the prefix
//! `<instance>.` (as do the sets and surfaces a `*RIGID BODY` names, and its `REF NODE`), and
//! nodes move by the instance's translation, then rotation. Assembly-level
//! sets with `INSTANCE=` name the instance's labels, and a field `<instance>.<label>` anywhere
//! outside the parts names that instance's node or element. A deck without `*PART` is left as it is.
//! An analytical surface in a part moves with its instance: the points that place its profile
//! are placed as the nodes are.

use std::collections::HashMap;

use nalgebra::{Rotation3, Unit, Vector3};

use super::fields::{allow_parameters, at_most, key, line_error, real};
use super::keywords::{Block, DataLine, DeckError};

/// An instance: its part, label offset and placement.
struct Instance {
    part: String,
    offset: u64,
    translation: [f64; 3],
    /// A point `a` of the rotation axis, and the rotation (after the translation).
    rotation: Option<(Vector3<f64>, Rotation3<f64>)>,
}

impl Instance {
    /// Where the part's point `x` lies in the assembly: `a + Q (x + t - a)`.
    fn place(&self, x: Vector3<f64>) -> Vector3<f64> {
        let moved = x + Vector3::from(self.translation);
        match &self.rotation {
            Some((a, q)) => a + q * (moved - a),
            None => moved,
        }
    }

    fn moves(&self) -> bool {
        self.translation != [0.0; 3] || self.rotation.is_some()
    }
}

/// Flattens the parts and instances of `blocks` (see the module documentation).
///
/// # Errors
/// [`DeckError`] at a keyword inside a part or an assembly that is not read there, an unknown
/// part, a 2D node or profile point that an instance turns out of its plane, or an unterminated
/// part, instance or assembly.
pub fn flatten(blocks: Vec<Block>) -> Result<Vec<Block>, DeckError> {
    if !blocks.iter().any(|b| b.name == "PART") {
        return Ok(blocks);
    }
    let stride = blocks
        .iter()
        .filter(|b| b.name == "NODE" || b.name == "ELEMENT")
        .flat_map(|b| &b.data)
        .filter_map(|line| line.fields.first()?.parse::<u64>().ok())
        .max()
        .unwrap_or(0)
        + 1;
    // each part's blocks in order, by key
    let mut parts: HashMap<String, Vec<Block>> = HashMap::new();
    let mut instances: HashMap<String, Instance> = HashMap::new();
    let mut out = Vec::with_capacity(blocks.len());
    let mut iter = blocks.into_iter();
    while let Some(block) = iter.next() {
        match block.name.as_str() {
            "PART" => {
                allow_parameters(&block, &["NAME"])?;
                let name = named(&block, "NAME")?;
                let mut held = Vec::new();
                loop {
                    let inner = iter
                        .next()
                        .ok_or_else(|| block.error("no *END PART closes it"))?;
                    match inner.name.as_str() {
                        "END PART" => break,
                        "PART" | "ASSEMBLY" | "END ASSEMBLY" | "STEP" => {
                            return Err(inner.error(format!(
                                "*PART {name} is not closed: expected *END PART before this \
                                 keyword"
                            )));
                        }
                        _ => in_part(&inner, "a *PART")?,
                    }
                    held.push(inner);
                }
                parts.insert(key(&name), held);
            }
            "ASSEMBLY" => {
                allow_parameters(&block, &["NAME"])?;
                loop {
                    let inner = iter
                        .next()
                        .ok_or_else(|| block.error("no *END ASSEMBLY closes it"))?;
                    match inner.name.as_str() {
                        "END ASSEMBLY" => break,
                        "INSTANCE" => {
                            // what the instance defines itself, as Abaqus/CAE writes an
                            // analytical rigid part: its reference node, surface and rigid body
                            let mut own = Vec::new();
                            loop {
                                let next = iter
                                    .next()
                                    .ok_or_else(|| inner.error("no *END INSTANCE closes it"))?;
                                if next.name == "END INSTANCE" {
                                    break;
                                }
                                in_part(&next, "an *INSTANCE")?;
                                own.push(next);
                            }
                            let k = instances.len() as u64 + 1;
                            let (name, instance) = instance(&inner, k * stride)?;
                            let part = parts.get(&key(&instance.part)).ok_or_else(|| {
                                inner.error(format!("no *PART named {}", instance.part))
                            })?;
                            for b in part.iter().chain(&own) {
                                out.push(copy(b, &name, &instance)?);
                            }
                            instances.insert(key(&name), instance);
                        }
                        "NSET" | "ELSET" if inner.parameter("INSTANCE").is_some() => {
                            out.push(assembly_set(inner, &instances)?);
                        }
                        "NODE" | "ELEMENT" | "NSET" | "ELSET" | "SURFACE" | "RIGID BODY"
                        | "MASS" | "ROTARY INERTIA" => out.push(labelled(inner, &instances)),
                        _ => {
                            return Err(inner.error(
                                "is not read inside an *ASSEMBLY (skid reads instances, nodes, \
                                 elements, sets, surfaces, rigid bodies and point inertias \
                                 there)",
                            ));
                        }
                    }
                }
            }
            "END PART" | "END ASSEMBLY" | "INSTANCE" | "END INSTANCE" => {
                return Err(block.error("outside the *PART or *ASSEMBLY it belongs to"));
            }
            _ => out.push(labelled(block, &instances)),
        }
    }
    Ok(out)
}

/// The value of the required parameter `name`.
fn named(block: &Block, name: &str) -> Result<String, DeckError> {
    block
        .parameter(name)
        .flatten()
        .map(str::to_string)
        .ok_or_else(|| block.error(format!("expected {name}=")))
}

/// Refuses a keyword that a part, or an instance's own definitions (`holder`), do not hold.
fn in_part(block: &Block, holder: &str) -> Result<(), DeckError> {
    match block.name.as_str() {
        "NODE" | "ELEMENT" | "NSET" | "ELSET" | "SURFACE" | "SOLID SECTION"
        | "MEMBRANE SECTION" | "SHELL SECTION" | "RIGID BODY" | "MASS" | "ROTARY INERTIA" => Ok(()),
        _ => Err(block.error(format!(
            "is not read inside {holder} (skid reads nodes, elements, sets, surfaces, sections, \
             rigid bodies and point inertias there; give the rest in the assembly or the model \
             data)"
        ))),
    }
}

/// `*INSTANCE, NAME, PART` with its optional placement: a translation line `x, y, z`, then a
/// rotation line `a (3), b (3), angle` (about the axis from `a` to `b`, in degrees, after the
/// translation).
fn instance(block: &Block, offset: u64) -> Result<(String, Instance), DeckError> {
    allow_parameters(block, &["NAME", "PART"])?;
    let name = named(block, "NAME")?;
    let part = named(block, "PART")?;
    let numbers = |line: &DataLine, count: usize, what: &str| -> Result<Vec<f64>, DeckError> {
        at_most(block, line, count)?;
        (0..count)
            .map(|k| match line.fields.get(k).filter(|f| !f.is_empty()) {
                Some(_) => real(block, line, k, what),
                None => Ok(0.0),
            })
            .collect()
    };
    let mut translation = [0.0; 3];
    let mut rotation = None;
    let lines = block.data.as_slice();
    if let Some(line) = lines.first() {
        let t = numbers(line, 3, "translation")?;
        translation.copy_from_slice(&t);
    }
    if let Some(line) = lines.get(1) {
        let r = numbers(line, 7, "rotation")?;
        let a = Vector3::new(r[0], r[1], r[2]);
        let axis = Unit::try_new(Vector3::new(r[3], r[4], r[5]) - a, 0.0)
            .ok_or_else(|| line_error(block, line, "the rotation axis' two points coincide"))?;
        rotation = Some((a, Rotation3::from_axis_angle(&axis, r[6].to_radians())));
    }
    if let Some(line) = lines.get(2) {
        return Err(line_error(
            block,
            line,
            "expected at most a translation line and a rotation line",
        ));
    }
    Ok((
        name,
        Instance {
            part,
            offset,
            translation,
            rotation,
        },
    ))
}

/// The block `b` of a part copied into instance `name`.
fn copy(b: &Block, name: &str, instance: &Instance) -> Result<Block, DeckError> {
    let mut out = b.clone();
    let prefix = |v: &str| format!("{name}.{v}");
    let raise = |field: &mut String| {
        if let Ok(label) = field.parse::<u64>() {
            *field = (label + instance.offset).to_string();
        }
    };
    for (parameter, value) in &mut out.parameters {
        let renamed = matches!(
            parameter.as_str(),
            "NSET" | "ELSET" | "ANALYTICAL SURFACE" | "TIE NSET"
        ) || (parameter == "NAME" && b.name == "SURFACE");
        if let Some(v) = value.as_mut() {
            if renamed {
                *v = prefix(v);
            } else if parameter == "REF NODE" {
                if v.parse::<u64>().is_ok() {
                    raise(v);
                } else {
                    *v = prefix(v);
                }
            }
        }
    }
    let moved = instance.moves();
    match b.name.as_str() {
        "NODE" => {
            for line in &mut out.data {
                if let Some(label) = line.fields.first_mut() {
                    raise(label);
                }
                if moved {
                    place(b, line, instance)?;
                }
            }
        }
        "ELEMENT" => {
            for line in &mut out.data {
                line.fields.iter_mut().for_each(raise);
            }
        }
        "NSET" | "ELSET" => {
            let generate = b.parameter("GENERATE").is_some();
            for line in &mut out.data {
                for (k, field) in line.fields.iter_mut().enumerate() {
                    if generate {
                        // first, last, increment
                        if k < 2 {
                            raise(field);
                        }
                    } else if field.parse::<u64>().is_ok() {
                        raise(field);
                    } else if !field.is_empty() {
                        *field = prefix(field);
                    }
                }
            }
        }
        "SURFACE" => {
            let on_elements = b.parameter("TYPE").flatten().is_none_or(|t| {
                t.eq_ignore_ascii_case("ELEMENT") || t.eq_ignore_ascii_case("NODE")
            });
            if !on_elements && moved {
                place_analytical(b, &mut out, instance)?;
            }
            if on_elements {
                for line in &mut out.data {
                    if let Some(first) = line.fields.first_mut() {
                        if first.parse::<u64>().is_ok() {
                            raise(first);
                        } else if !first.is_empty() {
                            *first = prefix(first);
                        }
                    }
                }
            }
        }
        _ => {}
    }
    Ok(out)
}

/// Places the coordinates of a `*NODE` line (2 or 3 of them) as the instance does; a 2D node
/// that the placement takes out of its plane is refused.
fn place(b: &Block, line: &mut DataLine, instance: &Instance) -> Result<(), DeckError> {
    let count = line.fields.len().saturating_sub(1).min(3);
    place_point(b, line, 1, count, instance)
}

/// Places the points of an analytical surface (`out`, a copy of `b`) as the instance does:
/// the points `a`, `b` (and `c`) of `TYPE=CYLINDER` and `TYPE=REVOLUTION`, which carry the
/// local profile with them, and every point of a `TYPE=SEGMENTS` profile, which is given in
/// the part's `x-y` plane (the end point of `START` and `LINE`, the end point and the centre
/// of `CIRCL`).
fn place_analytical(b: &Block, out: &mut Block, instance: &Instance) -> Result<(), DeckError> {
    let kind = b
        .parameter("TYPE")
        .flatten()
        .unwrap_or_default()
        .to_ascii_uppercase();
    for (k, line) in out.data.iter_mut().enumerate() {
        match kind.as_str() {
            "CYLINDER" | "REVOLUTION" => {
                let axis_lines = if kind == "CYLINDER" { 2 } else { 1 };
                if k < axis_lines {
                    for first in (0..line.fields.len().min(6)).step_by(3) {
                        place_point(b, line, first, 3, instance)?;
                    }
                }
            }
            _ => {
                let word = line.fields.first().map(|w| w.to_ascii_uppercase());
                let points: &[usize] = match word.as_deref() {
                    Some("START" | "LINE") => &[1],
                    Some("CIRCL") => &[1, 3],
                    _ => &[],
                };
                for &first in points {
                    place_point(b, line, first, 2, instance)?;
                }
            }
        }
    }
    Ok(())
}

/// Places the point of `count` coordinates (2 or 3) from field `first` of `line` as the
/// instance does; a 2D point that the placement takes out of its plane is refused.
fn place_point(
    b: &Block,
    line: &mut DataLine,
    first: usize,
    count: usize,
    instance: &Instance,
) -> Result<(), DeckError> {
    let mut x = Vector3::zeros();
    for k in 0..count {
        x[k] = real(b, line, first + k, "coordinate")?;
    }
    let placed = instance.place(x);
    if count < 3 && placed.z.abs() > 1e-12 * (1.0 + placed.norm()) {
        return Err(line_error(
            b,
            line,
            "the instance's placement takes this 2D point out of its plane",
        ));
    }
    for k in 0..count {
        line.fields[first + k] = format!("{:?}", placed[k]);
    }
    Ok(())
}

/// An assembly-level `*NSET`/`*ELSET` with `INSTANCE=`: its labels are the instance's.
fn assembly_set(mut b: Block, instances: &HashMap<String, Instance>) -> Result<Block, DeckError> {
    let name = named(&b, "INSTANCE")?;
    let instance = instances
        .get(&key(&name))
        .ok_or_else(|| b.error(format!("no *INSTANCE named {name} before it")))?;
    let generate = b.parameter("GENERATE").is_some();
    for line in &mut b.data {
        for (k, field) in line.fields.iter_mut().enumerate() {
            if (!generate || k < 2)
                && let Ok(label) = field.parse::<u64>()
            {
                *field = (label + instance.offset).to_string();
            }
        }
    }
    b.parameters.retain(|(p, _)| p != "INSTANCE");
    Ok(b)
}

/// `b` with every field `<instance>.<label>` replaced by the instance's label.
fn labelled(mut b: Block, instances: &HashMap<String, Instance>) -> Block {
    if instances.is_empty() {
        return b;
    }
    for line in &mut b.data {
        for field in &mut line.fields {
            if let Some((name, label)) = field.rsplit_once('.')
                && let (Some(instance), Ok(label)) =
                    (instances.get(&key(name)), label.parse::<u64>())
            {
                *field = (label + instance.offset).to_string();
            }
        }
    }
    b
}
