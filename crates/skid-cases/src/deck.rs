//! Abaqus-style input decks, read into the same [`crate::model_spec::ModelSpec`] as model files.
//!
//! - [`keywords`]: the keyword layer: keyword blocks with parameters and data lines, comments,
//!   continuation lines and `*INCLUDE`, each with its file and line.
//! - [`instances`]: parts and their instances flattened into the blocks of one mesh.
//! - [`read`]: the keyword subset read into the [`definitions`], which keep the deck's labels
//!   and names ([`fields`] reads typed parameters and fields, [`mesh`] nodes, elements and
//!   sets, [`rigid`] analytical and faceted rigid surfaces, [`loads`] amplitudes and loads,
//!   [`controls`] the hourglass control of `*SECTION CONTROLS`).
//! - [`assemble`]: the definitions turned into a model; [`write`]: a model written as a deck.
//!
//! The subset: `*HEADING`, `*NODE`, `*ELEMENT` (CPE4R, C3D8R; R2D2, R3D3, R3D4, M3D4R, S4R,
//! C3D4 made rigid; MASS, ROTARYI), `*NSET` / `*ELSET` (GENERATE), `*SURFACE` (ELEMENT, NODE,
//! SEGMENTS, CYLINDER, REVOLUTION with FILLET RADIUS), `*RIGID BODY` (REF NODE, ELSET, ANALYTICAL SURFACE,
//! TIE NSET), `*MATERIAL` with `*HYPERELASTIC` (POLYNOMIAL N=1, MOONEY-RIVLIN, NEO HOOKE),
//! `*ELASTIC` and `*DENSITY`, `*SOLID SECTION` (CONTROLS=), `*SECTION CONTROLS`
//! (HOURGLASS=ENHANCED|STIFFNESS, see [`controls`]), `*MEMBRANE SECTION`, `*SHELL SECTION`,
//! `*MASS`, `*ROTARY INERTIA`, `*SURFACE INTERACTION` with `*FRICTION`, `*CONTACT PAIR`,
//! `*CONTACT` with `*CONTACT INCLUSIONS, ALL EXTERIOR` and `*CONTACT PROPERTY ASSIGNMENT`,
//! `*BOUNDARY` (OP=MOD/NEW and, on rigid bodies and part nodes, magnitudes with AMPLITUDE= in
//! steps: see `assemble::motions`), `*INITIAL CONDITIONS` (VELOCITY, ROTATING VELOCITY),
//! `*AMPLITUDE` (TABULAR, step or total time), `*STEP` (NLGEOM, AMPLITUDE=RAMP|STEP), `*STATIC` (DIRECT, or automatic
//! increments without it) and `*DYNAMIC` (DIRECT, ALPHA, or automatic increments without DIRECT), `*CLOAD`, `*DSLOAD` / `*DLOAD` pressures and `*DLOAD` gravity (`GRAV`), each with
//! `AMPLITUDE=`, `*OUTPUT`, `*NODE OUTPUT`, `*CONTACT OUTPUT`,
//! `*END STEP`, `*INCLUDE`, and `*PART` / `*END PART`, `*ASSEMBLY` / `*END ASSEMBLY`,
//! `*INSTANCE` / `*END INSTANCE` (translated and rotated). Anything else is an error at its
//! line.
//!
//! How skid reads what the keywords leave open, or what it models differently:
//! - model-data boundary conditions hold throughout; in a step, zero-valued conditions on a
//!   reference node or on part nodes hold that degree of freedom for the step (at its value at
//!   the step's start; `OP=NEW` drops those of earlier steps);
//! - a load given in a step stays in force in later steps until a line at its place changes it
//!   (`OP=MOD`) or `OP=NEW` removes it; without amplitude it goes linearly over a static step
//!   from its value at the end of the previous step to the new one (from 0 in the first step;
//!   a removed load to 0), and takes the new value at once in a dynamic step (the
//!   procedures' defaults; `*STEP, AMPLITUDE=` turns either way round); with one, it is
//!   its value in the step times the amplitude at the step or total time (a static step's step
//!   time runs from 0 to the period of its `*STATIC` line). A load or motion carried into a
//!   later step with a step-time amplitude holds there the value the amplitude reached, as in
//!   Abaqus (a total-time amplitude of its own, see `assemble::carried`). The model's loads
//!   carry their factor in each step (see [`assemble`] and [`loads`] for gravity's direction
//!   and `OP=NEW`);
//! - `*DYNAMIC` without `ALPHA` takes the keyword's default `-0.05`;
//! - `*DYNAMIC` without `DIRECT` sizes its increments by their estimated local error, the
//!   model's `adaptive` steps with the tolerance [`read::AUTOMATIC_DYNAMIC_TOLERANCE`] and the
//!   data line `initial, period, min, max` with the keyword's defaults, not by the
//!   half-increment residual (`HAFTOL` is refused);
//! - `*ELASTIC` is the compressible neo-Hookean solid with the same small-strain moduli;
//! - rigid membranes and shells are contacted on their mid-surface (zero thickness), rigid
//!   elements carry no mass (give it with `*MASS` and `*ROTARY INERTIA`);
//! - lines and quadrilaterals made rigid that form a regular prism are the faceted drum, which
//!   is treated as axially unbounded, and the slave nodes are checked to lie within its ends;
//!   other lines must form one chain (a polyline; closed, it must face outwards), other
//!   quadrilaterals (split along their 1-3 diagonal: exact when flat) and triangles a triangle
//!   mesh whose surface coordinates are read on its plane if it is flat, on a cylinder about
//!   its body's one free rotation if it is curved and the body has one, else on the plane of
//!   its mean normal, its slip measured in the tangent plane (see [`rigid`]); an analytical
//!   profile of lines that
//!   runs straight through the reference node is the unbounded line or plane through it, any
//!   other a polyline (`SEGMENTS`) or its extrusion along the generator (`CYLINDER`); a
//!   revolved profile of lines at one radius is a cylinder, any other a surface of revolution
//!   (its axis through the reference node); `FILLET RADIUS` rounds every corner of the profile
//!   with a tangent arc of that radius before this reading (a square's corners rounded by half
//!   its side give the cylinder), and a fillet that does not fit its pieces is an error;
//! - a point rotary inertia counts about its body's one free rotation axis;
//! - general contact makes every node of the part's exterior faces a candidate;
//! - `*OUTPUT, FIELD` with `TIME INTERVAL=t` or `NUMBER INTERVAL=n` (the step's period over n)
//!   turns on the field output ([`crate::fields`]) with one interval for the whole run, the
//!   smallest of the dynamic steps' requests (of the static steps' if only they ask); a
//!   request without either (`FREQUENCY`) writes none, with a note;
//! - `*NODE OUTPUT, NSET=S` under `*OUTPUT, HISTORY` asking for `U` (or `U1`..`U3`) in any
//!   step writes the displacements of the nodes of `S` to `history.csv` in every increment of
//!   the run (`output.history_nodes`); other output requests are noted (skid writes the
//!   history it always writes).

pub mod assemble;
pub mod controls;
pub mod definitions;
pub mod fields;
pub mod instances;
pub mod keywords;
pub mod loads;
pub mod mesh;
pub mod read;
pub mod rigid;
pub mod write;

use std::path::Path;

use keywords::{DeckError, Location, read_deck};

use crate::model_spec::ModelSpec;

/// A deck read into a model, with what skid reads differently from the deck's requests.
#[derive(Clone, Debug)]
pub struct DeckModel {
    /// The model.
    pub model: ModelSpec,
    /// One note per request skid handles its own way (e.g. output requests), with its line.
    pub notes: Vec<String>,
}

/// Whether `path` names a deck (extension `.inp`, any case).
pub fn is_deck(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("inp"))
}

/// Reads the deck at `path` (with its includes) into a model named after the file.
///
/// # Errors
/// [`DeckError`] naming the file and line of the first problem.
pub fn read_model(path: &Path) -> Result<DeckModel, DeckError> {
    let blocks = instances::flatten(read_deck(path)?)?;
    let defs = read::read_definitions(&blocks)?;
    let name = path
        .file_stem()
        .map_or_else(|| "deck".to_string(), |s| s.to_string_lossy().into_owned());
    let deck = Location {
        file: path.into(),
        line: 0,
    };
    let model = assemble::assemble(&defs, &name, &deck)?;
    Ok(DeckModel {
        model,
        notes: defs.notes,
    })
}
