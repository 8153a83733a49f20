//! Large-strain compression of a neo-Hookean block on rollers (the scenes
//! `cases/verification/*-compression-*.inp`, written by `scripts/compression.py`): the block
//! `[0, W] x [0, H] (x [0, D])`, its bottom held in y, its top moved down by a prescribed
//! motion, its sides free (uniaxial) or held in x (confined), is deformed homogeneously, so
//! that every element formulation must give the closed form at every increment.
//!
//! Closed form, for `U = C10 (I1bar - 3) + (J - 1)^2 / D1` (skid's polynomial material with
//! `C01 = 0`): with `F = diag(l1, l2, l3)`, `J = l1 l2 l3`, `I1 = l1^2 + l2^2 + l3^2`, the
//! Kirchhoff stress is `tau_ii = 2 C10 J^(-2/3) (li^2 - I1 / 3) + 2 J (J - 1) / D1`. `l2` is
//! the prescribed vertical stretch; a lateral stretch is 1 where the sides are held (and
//! `l3 = 1` in plane strain), and where they are free it makes its stress vanish,
//! `tau_11 = 0` (by bisection; in 3D with both sides free `l1 = l3`). The top's reaction is the
//! nominal stress times the reference area, `R = P_22 A0`, `P_22 = tau_22 / l2`, `A0 = W t`
//! (2D, thickness `t`) or `W D` (3D).
//!
//! Measured, in every increment of the history: `l2 = 1 + v / H` and the free lateral stretch
//! `l1 = 1 + u / W` from the displacements of the top corner opposite the origin (the history
//! node set holding it), and `R` from the top's reaction column; the Newton iterations of
//! every converged increment from `newton.csv`. Checks per run: the largest error of `R`
//! against the closed form over the increments within [`REACTION_TOLERANCE`] of the final
//! `|R|`, that of the lateral stretch within [`STRETCH_TOLERANCE`], the run reaches 50 %
//! compression (`1 - l2`), and at most [`MAX_NEWTON_ITERATIONS`] per increment.

use std::fmt::Write as _;
use std::path::Path;

use super::SceneRun;
use crate::ReportError;
use crate::format::{Checks, Sig};
use skid_cases::csv_out::CsvTable;
use skid_cases::model_spec::{Dof, ModelSpec, ModelStepSpec};
use skid_cases::newton::NEWTON_CSV;
use skid_cases::schema::MaterialSpec;

/// Largest error of the reaction over the increments, as a fraction of the final `|R|`: the
/// deformation is homogeneous, so the only errors are Newton's (its force tolerance is 1e-6
/// of the largest force) and the history's 10 digits.
pub const REACTION_TOLERANCE: f64 = 1e-5;
/// Largest error of the lateral stretch over the increments (absolute).
pub const STRETCH_TOLERANCE: f64 = 1e-6;
/// The compression every locking-free formulation must reach.
pub const TARGET_COMPRESSION: f64 = 0.5;
/// Most Newton iterations of a converged increment: Newton converges quadratically on the
/// exact tangent, in 2 to 4 iterations per increment in these scenes.
pub const MAX_NEWTON_ITERATIONS: usize = 10;

/// Largest distance of a node from a face of the block that still counts as on it.
const ON: f64 = 1e-9;

/// Neo-Hookean uniaxial or confined compression: the closed form of the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedForm {
    /// `C10`, Pa.
    pub c10: f64,
    /// `D1`, 1/Pa.
    pub d1: f64,
    /// Whether the stretch along x is free (the sides x = 0 and x = W unheld).
    pub free_x: bool,
    /// Whether the stretch along z is free (3D, sides unheld); `false` in plane strain.
    pub free_z: bool,
}

impl ClosedForm {
    /// `tau_ii = 2 C10 J^(-2/3) (li^2 - I1 / 3) + 2 J (J - 1) / D1` for `l = [l1, l2, l3]`.
    pub fn kirchhoff(&self, l: [f64; 3], i: usize) -> f64 {
        let j = l[0] * l[1] * l[2];
        let i1: f64 = l.iter().map(|s| s * s).sum();
        2.0 * self.c10 * j.powf(-2.0 / 3.0) * (l[i] * l[i] - i1 / 3.0)
            + 2.0 * j * (j - 1.0) / self.d1
    }

    /// The stretches `[l1, l2, l3]` for the vertical stretch `l2`: the free lateral ones solve
    /// `tau_11 = 0` (or `tau_33 = 0`), the held ones are 1.
    pub fn stretches(&self, l2: f64) -> [f64; 3] {
        let with = |s: f64| {
            [
                if self.free_x { s } else { 1.0 },
                l2,
                if self.free_z { s } else { 1.0 },
            ]
        };
        if !(self.free_x || self.free_z) {
            return with(1.0);
        }
        let axis = if self.free_x { 0 } else { 2 };
        // tau rises with the free stretch, from -inf (J -> 0) to +inf: bisect in log space
        let (mut lo, mut hi) = (1e-6_f64, 1e6_f64);
        for _ in 0..200 {
            let mid = (lo * hi).sqrt();
            if self.kirchhoff(with(mid), axis) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        with((lo * hi).sqrt())
    }

    /// The nominal vertical stress `P_22 = tau_22 / l2` at the vertical stretch `l2`, Pa.
    pub fn nominal_stress(&self, l2: f64) -> f64 {
        self.kirchhoff(self.stretches(l2), 1) / l2
    }
}

/// A compression scene: its closed form and what its measurement reads.
#[derive(Clone, Debug, PartialEq)]
pub struct CompressionScene {
    /// Element type name.
    pub element: &'static str,
    /// The closed form of its material and sides.
    pub closed_form: ClosedForm,
    /// The block's width W, height H and depth D (1 in 2D), m.
    pub size: [f64; 3],
    /// Reference area of the top, `A0`, m^2.
    pub area: f64,
    /// The prescribed compression, `-v_top / H`.
    pub compression: f64,
    /// History column of the top's vertical reaction.
    pub reaction: String,
    /// History columns of the top corner's displacements, x, y and (3D) z.
    pub corner: Vec<String>,
}

impl CompressionScene {
    /// The compression scene of `spec`, if it is one: no rigid body, contact or load, one
    /// static step, one element block of a neo-Hookean material (`C01 = 0`), nodes in a box
    /// from the origin with its corner opposite the origin in a history node set, every node
    /// of the bottom y = 0 held in y, one prescribed motion, along y, of a node set that is the
    /// top y = H; the sides x = 0 and x = W either all held in x or none held but at the origin
    /// (and so z in 3D).
    pub fn recognise(spec: &ModelSpec) -> Option<Self> {
        let part = &spec.part;
        let dim = spec.dimension;
        let [block] = part.elements.as_slice() else {
            return None;
        };
        let [ModelStepSpec::Static { .. }] = spec.steps.as_slice() else {
            return None;
        };
        let MaterialSpec::PolynomialN1 { c10, c01, d1 } = part.section.material;
        if !(dim == 2 || dim == 3)
            || !spec.rigid_bodies.is_empty()
            || !spec.contact.is_empty()
            || !spec.loads.is_empty()
            || !spec.parts.is_empty()
            || !part.materials.is_empty()
            || c01 != 0.0
            || part.nodes.iter().any(|p| p.len() != dim)
        {
            return None;
        }
        let mut size = [1.0; 3];
        for (axis, s) in size.iter_mut().enumerate().take(dim) {
            let lowest = part
                .nodes
                .iter()
                .map(|p| p[axis])
                .fold(f64::INFINITY, f64::min);
            *s = part.nodes.iter().map(|p| p[axis]).fold(lowest, f64::max);
            if lowest.abs() > ON || *s <= 0.0 {
                return None;
            }
        }
        let on = |n: usize, axis: usize, at: f64| (part.nodes[n][axis] - at).abs() <= ON;
        let [prescribed] = spec
            .boundary
            .iter()
            .filter(|bc| bc.is_prescribed())
            .collect::<Vec<_>>()[..]
        else {
            return None;
        };
        let top = part.node_sets.get(prescribed.node_set.as_ref()?)?;
        let on_top: Vec<usize> = (0..part.nodes.len())
            .filter(|&n| on(n, 1, size[1]))
            .collect();
        let mut top_sorted = top.clone();
        top_sorted.sort_unstable();
        if prescribed.dofs != [Dof::Y] || top_sorted != on_top || prescribed.step_factors.is_some()
        {
            return None;
        }
        let held = spec.held_node_components();
        let is_held = |n: usize, axis: usize| held.contains(&(n, axis));
        if !(0..part.nodes.len())
            .filter(|&n| on(n, 1, 0.0))
            .all(|n| is_held(n, 1))
        {
            return None;
        }
        // the sides normal to `axis`: all held (confined), or free but at the bottom's pins
        let sides = |axis: usize| {
            let side: Vec<usize> = (0..part.nodes.len())
                .filter(|&n| on(n, axis, 0.0) || on(n, axis, size[axis]))
                .collect();
            if side.iter().all(|&n| is_held(n, axis)) {
                Some(false)
            } else if side.iter().all(|&n| !is_held(n, axis) || on(n, 1, 0.0)) {
                Some(true)
            } else {
                None
            }
        };
        let free_x = sides(0)?;
        let free_z = if dim == 3 { sides(2)? } else { false };
        let corner_node = (0..part.nodes.len()).find(|&n| (0..dim).all(|a| on(n, a, size[a])))?;
        let set = spec.output.history_nodes.iter().find(|s| {
            part.node_sets
                .get(*s)
                .is_some_and(|n| n.contains(&corner_node))
        })?;
        let value = prescribed.value?;
        Some(Self {
            element: block.kind.name(),
            closed_form: ClosedForm {
                c10,
                d1,
                free_x,
                free_z,
            },
            size,
            area: size[0]
                * if dim == 2 {
                    part.section.thickness
                } else {
                    size[2]
                },
            compression: -value / size[1],
            reaction: format!("{}.reaction_y", prescribed.node_set.as_ref()?),
            corner: ["x", "y", "z"][..dim]
                .iter()
                .map(|a| format!("{set}.{corner_node}.u_{a}"))
                .collect(),
        })
    }

    /// The scene's kind: `uniaxial` (some side free) or `confined`.
    pub fn kind(&self) -> &'static str {
        if self.closed_form.free_x || self.closed_form.free_z {
            "uniaxial"
        } else {
            "confined"
        }
    }
}

/// What a run gives against the closed form.
#[derive(Clone, Debug, PartialEq)]
pub struct CompressionMeasure {
    /// Increments after the initial state.
    pub increments: usize,
    /// Compression of the last increment, `1 - l2`.
    pub compression: f64,
    /// Reaction of the last increment, N.
    pub reaction: f64,
    /// Closed-form reaction of the last increment, N.
    pub closed_reaction: f64,
    /// Lateral stretch of the last increment (along x, or z if x is held; 1 if confined).
    pub lateral: f64,
    /// Its closed form.
    pub closed_lateral: f64,
    /// Largest `|R - R_closed|` over the increments, over the final `|R_closed|`.
    pub reaction_error: f64,
    /// Largest `|l_lateral - l_closed|` over the increments.
    pub stretch_error: f64,
}

/// One increment: `l2`, the reaction, its closed form, the lateral stretch, its closed form.
type Sample = (f64, f64, f64, f64, f64);

/// Measures the history `text` of `scene` (see the module documentation); `path` is only used
/// in messages.
///
/// # Errors
/// [`ReportError::Parse`] if a column is absent, a field is not a number, or there is no
/// increment after the initial state.
pub fn measure(
    scene: &CompressionScene,
    text: &str,
    path: &Path,
) -> Result<CompressionMeasure, ReportError> {
    let table = CsvTable::new(text, path)?;
    let reaction = table.column(&scene.reaction)?;
    let corner = scene
        .corner
        .iter()
        .map(|c| table.column(c))
        .collect::<Result<Vec<_>, _>>()?;
    let increment = table.column("increment")?;
    let lateral_axis = if scene.closed_form.free_x || !scene.closed_form.free_z {
        0
    } else {
        2
    };
    let mut rows: Vec<Sample> = Vec::new();
    for row in table {
        let row = row?;
        if row.number::<usize>(increment)? == 0 {
            continue;
        }
        let u = corner
            .iter()
            .map(|&c| row.number::<f64>(c))
            .collect::<Result<Vec<_>, _>>()?;
        let l2 = 1.0 + u[1] / scene.size[1];
        let lateral = 1.0 + u.get(lateral_axis).copied().unwrap_or(0.0) / scene.size[lateral_axis];
        let closed = scene.closed_form.stretches(l2)[lateral_axis];
        let closed_reaction = scene.closed_form.nominal_stress(l2) * scene.area;
        rows.push((
            l2,
            row.number::<f64>(reaction)?,
            closed_reaction,
            lateral,
            closed,
        ));
    }
    let Some(&(l2, r, closed_reaction, lateral, closed_lateral)) = rows.last() else {
        return Err(ReportError::Parse {
            path: path.to_path_buf(),
            message: "no increment after the initial state".into(),
        });
    };
    let worst = |f: &dyn Fn(&Sample) -> f64| rows.iter().map(f).fold(0.0, f64::max);
    Ok(CompressionMeasure {
        increments: rows.len(),
        compression: 1.0 - l2,
        reaction: r,
        closed_reaction,
        lateral,
        closed_lateral,
        reaction_error: worst(&|x| (x.1 - x.2).abs()) / closed_reaction.abs(),
        stretch_error: worst(&|x| (x.3 - x.4).abs()),
    })
}

/// The Newton iterations of every converged increment in `newton.csv` text (the rows of status
/// `converged`: the largest `iteration` of each step and increment), in order; `path` is only
/// used in messages.
///
/// # Errors
/// [`ReportError::Parse`] if a column is absent or a field is malformed.
pub fn newton_iterations(text: &str, path: &Path) -> Result<Vec<usize>, ReportError> {
    let table = CsvTable::new(text, path)?;
    let [step, increment, iteration, status] =
        ["step", "increment", "iteration", "status"].map(|c| table.column(c));
    let (step, increment, iteration, status) = (step?, increment?, iteration?, status?);
    let mut counts: Vec<((String, usize), usize)> = Vec::new();
    for row in table {
        let row = row?;
        if row.text(status)? != "converged" {
            continue;
        }
        let key = (row.text(step)?.to_string(), row.number::<usize>(increment)?);
        let k = row.number::<usize>(iteration)?;
        match counts.last_mut() {
            Some((last, n)) if *last == key => *n = (*n).max(k),
            _ => counts.push((key, k)),
        }
    }
    Ok(counts.into_iter().map(|(_, n)| n).collect())
}

/// The table and checks of the compression runs `runs` (see the module documentation).
///
/// # Errors
/// [`ReportError`] if a completed run's history or `newton.csv` is absent or malformed.
pub fn section(
    runs: &[(&SceneRun, CompressionScene)],
    checks: &mut Checks,
) -> Result<String, ReportError> {
    let mut out = String::from(
        "\n### Large-strain compression of a neo-Hookean block on rollers\n\n\
         Homogeneous compression, the top moved down, the sides free (uniaxial: one element) \
         or held (confined: 4 x 4): the closed form `tau_ii = 2 C10 J^(-2/3) (li^2 - I1 / 3) \
         + 2 J (J - 1) / D1`, the free lateral stretch from `tau_11 = 0`, the top's reaction \
         `R = A0 tau_22 / l2`. Errors: the largest over the increments, the reaction's over \
         the final `|R|`. Newton: iterations per converged increment (mean, largest); cutbacks: \
         failed attempts whose increment was cut back.\n\n\
         | run | element | kind | compression | R [N] | closed-form R [N] | reaction error \
         | lateral stretch | closed form | stretch error | increments | cutbacks | Newton mean \
         | Newton max |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (run, scene) in runs {
        if !run.completed_or_recorded(checks) {
            continue;
        }
        let path = run.dir.join("history.csv");
        let m = measure(scene, &crate::read(&path)?, &path)?;
        let path = run.dir.join(NEWTON_CSV);
        let newton = newton_iterations(&crate::read(&path)?, &path)?;
        let most = newton.iter().copied().max();
        let mean = newton.iter().sum::<usize>() as f64 / newton.len().max(1) as f64;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.1} % | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {} |",
            run.name,
            scene.element,
            scene.kind(),
            100.0 * m.compression,
            Sig(m.reaction),
            Sig(m.closed_reaction),
            Sig(m.reaction_error),
            Sig(m.lateral),
            Sig(m.closed_lateral),
            Sig(m.stretch_error),
            m.increments,
            run.summary.cutbacks,
            mean,
            most.map_or_else(|| "-".to_string(), |n| n.to_string()),
        );
        let label = format!("{} ({} {})", run.name, scene.element, scene.kind());
        checks.check(
            &format!(
                "{label}: the reaction is the closed form's within {} of |R|",
                Sig(REACTION_TOLERANCE)
            ),
            Some(m.reaction_error),
            REACTION_TOLERANCE,
            "",
        );
        if scene.kind() == "uniaxial" {
            checks.check(
                &format!(
                    "{label}: the lateral stretch is the closed form's within {}",
                    Sig(STRETCH_TOLERANCE)
                ),
                Some(m.stretch_error),
                STRETCH_TOLERANCE,
                "",
            );
        }
        checks.record(
            &format!("{label}: at most {MAX_NEWTON_ITERATIONS} Newton iterations per increment"),
            most.is_some_and(|n| n <= MAX_NEWTON_ITERATIONS),
            format!("mean {mean:.2}, largest {}", most.unwrap_or(0)),
        );
        checks.record(
            &format!(
                "{label}: reaches {} % compression",
                100.0 * TARGET_COMPRESSION
            ),
            m.compression + ON >= TARGET_COMPRESSION,
            format!("{:.1} %", 100.0 * m.compression),
        );
    }
    out.push('\n');
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f64 = 1e6;
    const K: f64 = 50e6;

    fn form(free_x: bool, free_z: bool) -> ClosedForm {
        ClosedForm {
            c10: G / 2.0,
            d1: 2.0 / K,
            free_x,
            free_z,
        }
    }

    #[test]
    fn at_small_strain_the_closed_form_is_linear_elasticity() {
        let (e, nu) = (
            9.0 * K * G / (3.0 * K + G),
            (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G)),
        );
        let eps = -1e-6;
        let l2 = 1.0 + eps;
        let rel = |a: f64, b: f64| (a / b - 1.0).abs();
        // plane strain, sides free: lateral strain -nu / (1 - nu) eps, stress E / (1 - nu^2) eps
        let f = form(true, false);
        let l = f.stretches(l2);
        assert!(rel(l[0] - 1.0, -nu / (1.0 - nu) * eps) < 1e-4, "{l:?}");
        assert_eq!(l[2], 1.0);
        assert!(rel(f.nominal_stress(l2), e / (1.0 - nu * nu) * eps) < 1e-4);
        // 3D, sides free: lateral -nu eps, stress E eps
        let f = form(true, true);
        let l = f.stretches(l2);
        assert!(rel(l[0] - 1.0, -nu * eps) < 1e-4 && l[0] == l[2], "{l:?}");
        assert!(rel(f.nominal_stress(l2), e * eps) < 1e-4);
        // confined: the P-wave modulus K + 4 G / 3
        let f = form(false, false);
        assert_eq!(f.stretches(l2), [1.0, l2, 1.0]);
        assert!(rel(f.nominal_stress(l2), (K + 4.0 * G / 3.0) * eps) < 1e-4);
    }

    #[test]
    fn the_free_stretch_unloads_its_sides_at_large_strain() {
        let f = form(true, false);
        let l = f.stretches(0.5);
        assert!(f.kirchhoff(l, 0).abs() < 1e-6 * G, "{l:?}");
        // nearly incompressible: J close to 1, so l1 close to 1 / l2
        assert!((l[0] * l[1] - 1.0).abs() < 0.05, "{l:?}");
        // confined: tau_22 = 2 C10 J^(-2/3) (l^2 - (l^2 + 2) / 3) + 2 J (J - 1) / D1 at J = l
        let c = form(false, false);
        let expected = (G * 0.5_f64.powf(-2.0 / 3.0) * (0.25 - 0.75) + K * 0.5 * -0.5) / 0.5;
        assert!((c.nominal_stress(0.5) / expected - 1.0).abs() < 1e-12);
    }

    fn scene() -> CompressionScene {
        CompressionScene {
            element: "CPE4R",
            closed_form: form(true, false),
            size: [1.0, 2.0, 1.0],
            area: 1.0,
            compression: 0.5,
            reaction: "top.reaction_y".into(),
            corner: vec!["corner.3.u_x".into(), "corner.3.u_y".into()],
        }
    }

    /// A history of `scene` at the compressions `c`, its lateral stretch off the closed form
    /// by `off`.
    fn history(s: &CompressionScene, c: &[f64], off: f64) -> String {
        let mut text =
            String::from("increment,top.reaction_y,corner.3.u_x,corner.3.u_y\n0,0,0,0\n");
        for (k, c) in c.iter().enumerate() {
            let l2 = 1.0 - c;
            let l1 = s.closed_form.stretches(l2)[0] + off;
            let r = s.closed_form.nominal_stress(l2) * s.area;
            let _ = writeln!(text, "{},{r:e},{:e},{:e}", k + 1, l1 - 1.0, -c * s.size[1]);
        }
        text
    }

    #[test]
    fn a_history_on_the_closed_form_measures_to_it() {
        let s = scene();
        let path = Path::new("history.csv");
        let m = measure(&s, &history(&s, &[0.1, 0.3, 0.5], 0.0), path).expect("measures");
        assert_eq!(m.increments, 3);
        assert!((m.compression - 0.5).abs() < 1e-12);
        assert!(m.reaction_error < 1e-12 && m.stretch_error < 1e-12, "{m:?}");
        assert!(m.reaction < 0.0);
        let m = measure(&s, &history(&s, &[0.1, 0.5], 1e-3), path).expect("measures");
        assert!((m.stretch_error - 1e-3).abs() < 1e-9, "{m:?}");
        let e = measure(&s, "increment,top.reaction_y\n", path).expect_err("columns");
        assert!(e.to_string().contains("corner.3.u_x"), "{e}");
    }

    fn shipped(name: &str) -> ModelSpec {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../cases/verification")
            .join(name);
        skid_cases::deck::read_model(&path).expect("deck").model
    }

    #[test]
    fn the_shipped_scenes_are_recognised_with_their_sides() {
        let s = CompressionScene::recognise(&shipped("3d-compression-uniaxial-c3d8h.inp"))
            .expect("a compression scene");
        assert_eq!(s.element, "C3D8H");
        assert!(s.closed_form.free_x && s.closed_form.free_z);
        assert_eq!((s.size, s.area, s.compression), ([1.0; 3], 1.0, 0.5));
        assert_eq!(s.reaction, "top.reaction_y");
        assert_eq!(s.corner.len(), 3);
        let mut confined = shipped("2d-compression-confined-cpe4r.inp");
        let c = CompressionScene::recognise(&confined).expect("a compression scene");
        assert_eq!(c.kind(), "confined");
        assert!(!c.closed_form.free_z);
        // a model with a load, or without the corner in its history, is something else
        confined.output.history_nodes.clear();
        assert_eq!(CompressionScene::recognise(&confined), None);
        let cook = shipped("2d-cook-linear-cpe4r-n4.inp");
        assert_eq!(CompressionScene::recognise(&cook), None);
    }

    #[test]
    fn newton_iterations_count_the_converged_checks_of_each_increment() {
        let text = "step,increment,time,size,iteration,force_residual,contact_residual,status\n\
                    s,1,0,0.1,1,1e-2,0,converged\n\
                    s,1,0,0.1,2,1e-9,0,converged\n\
                    s,2,0,0.2,1,1e-1,0,rejected: newton not converged\n\
                    s,2,0,0.1,1,1e-2,0,converged\n\
                    s,2,0,0.1,2,1e-5,0,converged\n\
                    s,2,0,0.1,3,1e-11,0,converged\n";
        let n = newton_iterations(text, Path::new("newton.csv")).expect("reads");
        assert_eq!(n, [2, 3]);
    }
}
