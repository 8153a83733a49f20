//! Cook's membrane (the scenes `cases/verification/2d-cook-*.inp`, written by
//! `scripts/cook.py --write`): the trapezoid with corners (0, 0), (48, 44), (48, 60), (0, 44),
//! clamped on x = 0 and sheared by a load `F` along y on x = 48, in the linear limit of its
//! neo-Hookean material (small-strain moduli `G = 2 (C10 + C01)`, `K = 2 / D1`). The measured
//! quantity is `v / F`, the vertical displacement of the loaded edge's mid-point (48, 52) per
//! unit load, read from the last row of the history (the node set that the model's
//! `output.history_nodes` names for it).
//!
//! References, for a plane-strain membrane of thickness `t` and small-strain Young's modulus
//! `E'`, Poisson's ratio `nu'`:
//! - `nu' = 1/4`: the plane-strain twin of the classic plane-stress benchmark (`nu = 1/3`,
//!   converged `v E t / F = 23.96`); a plane-stress solution with `(E, nu)` is the
//!   plane-strain one with `E' = E (1 + 2 nu) / (1 + nu)^2`, `nu' = nu / (1 + nu)`, so
//!   `v / F = 23.96 / (E t)` with `E = E' (1 + nu)^2 / (1 + 2 nu)` ([`PLANE_STRESS_COMPLIANCE`]);
//! - `nu' = 0.4999`: `v E' t / F = 18.51` ([`INCOMPRESSIBLE_COMPLIANCE`]), the extrapolation
//!   (Aitken, at the observed order) of 32 x 32, 64 x 64 and 128 x 128 meshes, on which CPE4H,
//!   CPE4R and CPE4I extrapolate to 18.508, 18.509 and 18.510 (`scripts/cook.py --meshes 32 64
//!   128`, observed orders 1.34, 1.26, 1.18).
//!
//! Checks, per scene: every locking-free element (all four at `nu' = 1/4`; CPE4R, CPE4H, CPE4I
//! at `nu' = 0.4999`, where the displacement element CPE4 locks) converges toward the
//! reference: its error shrinks with every refinement, its finest mesh is within
//! [`FINEST_TOLERANCE`] of the reference, and the extrapolation of its three finest meshes
//! within [`EXTRAPOLATION_TOLERANCE`]; and, at `nu' = 0.4999`, CPE4's finest mesh is more than
//! [`LOCKING_STIFFNESS`] too stiff.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::SceneRun;
use crate::ReportError;
use crate::format::{Checks, Sig};
use skid_cases::csv_out::CsvTable;
use skid_cases::model_spec::{LoadSpec, ModelSpec, ModelStepSpec};
use skid_cases::schema::MaterialSpec;

/// Converged `v E t / F` of the plane-stress membrane, `nu = 1/3`.
pub const PLANE_STRESS_COMPLIANCE: f64 = 23.96;
/// Converged `v E' t / F` of the plane-strain membrane, `nu' = 0.4999` (see the module
/// documentation).
pub const INCOMPRESSIBLE_COMPLIANCE: f64 = 18.51;
/// Largest relative error of a locking-free element's finest mesh. On 32 x 32 meshes the
/// errors measure 0.1-0.6 % (the elements converge from below at an observed order of about
/// 1.3, so they shrink by about 2.5 per refinement): 1 % leaves room for that and fails an
/// element that falls about one refinement behind.
pub const FINEST_TOLERANCE: f64 = 0.01;
/// Largest relative error of the extrapolation of a locking-free element's three finest
/// meshes (8, 16, 32 per edge extrapolate to within 0.15 % of the references).
pub const EXTRAPOLATION_TOLERANCE: f64 = 0.005;
/// How much too stiff the locking element's finest mesh must be at `nu' = 0.4999`:
/// `1 - (v / F) / reference` (measured: 62 % at 32 x 32, 46 % at 64 x 64, 25 % at 128 x 128).
pub const LOCKING_STIFFNESS: f64 = 0.2;

/// Largest distance of a node from a point of the geometry that still counts as on it.
const ON: f64 = 1e-9;
/// Poisson's ratios, and how close `nu'` must be to them, of the two references.
const NU_LINEAR: f64 = 0.25;
const NU_INCOMPRESSIBLE: f64 = 0.4999;
const NU_CLOSE: f64 = 1e-9;

/// A Cook's membrane run: what its measurement and reference need.
#[derive(Clone, Debug, PartialEq)]
pub struct CookScene {
    /// Element type name (CPE4R, CPE4, CPE4H, CPE4I).
    pub element: &'static str,
    /// Elements of the mesh.
    pub elements: usize,
    /// History column of the vertical displacement of the node at (48, 52).
    pub column: String,
    /// Total shear load `F`, N.
    pub load: f64,
    /// Thickness `t`, m.
    pub thickness: f64,
    /// Small-strain Young's modulus `E'`, Pa.
    pub young: f64,
    /// Small-strain Poisson's ratio `nu'`.
    pub poisson: f64,
}

impl CookScene {
    /// The Cook's membrane of `spec`, if it is one: 2D, no rigid body and no contact, one
    /// static step, one element block, one material, nodes at the trapezoid's four corners and
    /// none outside 0 <= x <= 48, every node on x = 0 held in x and y, every load a
    /// concentrated force along y on nodes of x = 48, and a history node set holding the node
    /// at (48, 52).
    pub fn recognise(spec: &ModelSpec) -> Option<Self> {
        let part = &spec.part;
        let [block] = part.elements.as_slice() else {
            return None;
        };
        let [ModelStepSpec::Static { .. }] = spec.steps.as_slice() else {
            return None;
        };
        if spec.dimension != 2
            || !spec.rigid_bodies.is_empty()
            || !spec.contact.is_empty()
            || !spec.parts.is_empty()
            || !part.materials.is_empty()
            || part.section.thickness <= 0.0
        {
            return None;
        }
        let at = |node: usize, x: f64, y: f64| {
            let p = &part.nodes[node];
            (p[0] - x).abs() <= ON && (p[1] - y).abs() <= ON
        };
        let corners = [(0.0, 0.0), (48.0, 44.0), (48.0, 60.0), (0.0, 44.0)];
        if !corners
            .iter()
            .all(|&(x, y)| (0..part.nodes.len()).any(|n| at(n, x, y)))
            || part
                .nodes
                .iter()
                .any(|p| p.len() != 2 || p[0] < -ON || p[0] > 48.0 + ON)
        {
            return None;
        }
        let held = spec.held_node_components();
        let clamped = (0..part.nodes.len())
            .filter(|&n| part.nodes[n][0].abs() <= ON)
            .all(|n| held.contains(&(n, 0)) && held.contains(&(n, 1)));
        let mut load = 0.0;
        for l in &spec.loads {
            let LoadSpec::Concentrated {
                node_set: Some(set),
                body: None,
                force: Some(force),
                moment: None,
                ..
            } = l
            else {
                return None;
            };
            let nodes = part.node_sets.get(set)?;
            if force.len() != 2
                || force[0] != 0.0
                || nodes.iter().any(|&n| (part.nodes[n][0] - 48.0).abs() > ON)
            {
                return None;
            }
            load += force[1] * nodes.len() as f64;
        }
        let column = spec.output.history_nodes.iter().find_map(|set| {
            let node = part
                .node_sets
                .get(set)?
                .iter()
                .find(|&&n| at(n, 48.0, 52.0))?;
            Some(format!("{set}.{node}.u_y"))
        })?;
        let MaterialSpec::PolynomialN1 { c10, c01, d1 } = part.section.material;
        let (shear, bulk) = (2.0 * (c10 + c01), 2.0 / d1);
        (clamped && load != 0.0).then(|| Self {
            element: block.kind.name(),
            elements: block.connectivity.len(),
            column,
            load,
            thickness: part.section.thickness,
            young: 9.0 * bulk * shear / (3.0 * bulk + shear),
            poisson: (3.0 * bulk - 2.0 * shear) / (2.0 * (3.0 * bulk + shear)),
        })
    }

    /// Elements per edge, `sqrt(elements)` rounded.
    pub fn per_edge(&self) -> usize {
        (self.elements as f64).sqrt().round() as usize
    }

    /// The reference `v / F`, m/N, with what it is; `None` for a Poisson's ratio without one.
    pub fn reference(&self) -> Option<(f64, &'static str)> {
        let (e, nu, t) = (self.young, self.poisson, self.thickness);
        if (nu - NU_LINEAR).abs() <= NU_CLOSE {
            let nu_stress = nu / (1.0 - nu);
            let e_stress = e * (1.0 + nu_stress).powi(2) / (1.0 + 2.0 * nu_stress);
            Some((
                PLANE_STRESS_COMPLIANCE / (e_stress * t),
                "the plane-stress benchmark's v E t / F = 23.96 at nu = 1/3",
            ))
        } else if (nu - NU_INCOMPRESSIBLE).abs() <= NU_CLOSE {
            Some((
                INCOMPRESSIBLE_COMPLIANCE / (e * t),
                "v E t / F = 18.51, extrapolated from 32 x 32, 64 x 64 and 128 x 128 meshes",
            ))
        } else {
            None
        }
    }

    /// Whether the element locks volumetrically in this scene: the displacement element CPE4
    /// in the nearly incompressible one.
    pub fn locks(&self) -> bool {
        self.element == "CPE4" && (self.poisson - NU_INCOMPRESSIBLE).abs() <= NU_CLOSE
    }
}

/// The vertical displacement of the history column `column` in the last row of the history
/// `text`, m; `path` is only used in messages.
///
/// # Errors
/// [`ReportError::Parse`] if the column is absent, a field is not a number, or there is no
/// row.
pub fn tip_displacement(text: &str, path: &Path, column: &str) -> Result<f64, ReportError> {
    let table = CsvTable::new(text, path)?;
    let c = table.column(column)?;
    let mut last = None;
    for row in table {
        last = Some(row?.number::<f64>(c)?);
    }
    last.ok_or_else(|| ReportError::Parse {
        path: path.to_path_buf(),
        message: "no increment in the history".into(),
    })
}

/// The extrapolation of three values on meshes refined by a constant factor, at their observed
/// order (Aitken's delta-squared): `v3 - (v3 - v2)^2 / ((v3 - v2) - (v2 - v1))`; `None` if the
/// changes do not shrink (no order to extrapolate at).
pub fn extrapolate([v1, v2, v3]: [f64; 3]) -> Option<f64> {
    let (d1, d2) = (v2 - v1, v3 - v2);
    (d2.abs() < d1.abs() && d1 * d2 > 0.0).then(|| v3 - d2 * d2 / (d2 - d1))
}

/// One element's ladder in one scene: `(elements per edge, v / F)`, coarsest first.
type Ladder = Vec<(usize, f64)>;

/// The tables and checks of the Cook runs `runs` (see the module documentation).
///
/// # Errors
/// [`ReportError`] if a completed run's history is absent or lacks its column.
pub fn section(
    runs: &[(&SceneRun, CookScene)],
    checks: &mut Checks,
) -> Result<String, ReportError> {
    // scenes by their moduli, then elements in the order first seen
    let mut scenes: BTreeMap<(u64, u64), Vec<(CookScene, Ladder)>> = BTreeMap::new();
    for (run, scene) in runs {
        if !run.completed_or_recorded(checks) {
            continue;
        }
        let path = run.dir.join("history.csv");
        let v = tip_displacement(&crate::read(&path)?, &path, &scene.column)?;
        let key = (scene.poisson.to_bits(), scene.young.to_bits());
        let elements = scenes.entry(key).or_default();
        let ladder = match elements
            .iter_mut()
            .find(|(e, _)| e.element == scene.element)
        {
            Some((_, ladder)) => ladder,
            None => {
                elements.push((scene.clone(), Vec::new()));
                &mut elements.last_mut().expect("just pushed").1
            }
        };
        ladder.push((scene.per_edge(), v / scene.load));
    }
    let mut out = String::from(
        "\n### Cook's membrane: locking and its cure\n\n\
         The trapezoid (0, 0), (48, 44), (48, 60), (0, 44) clamped on x = 0 and sheared \
         along y on x = 48 (plane strain, linear limit): `v / F`, the vertical displacement \
         of the loaded edge's mid-point (48, 52) per unit load, from the history, against the \
         reference (in brackets: the error). `extrapolated`: Aitken's extrapolation of the \
         three finest meshes.\n",
    );
    for elements in scenes.values_mut() {
        for (_, ladder) in elements.iter_mut() {
            ladder.sort_by_key(|&(n, _)| n);
        }
        let first = &elements[0].0;
        let reference = first.reference();
        let meshes: Vec<usize> = {
            let mut m: Vec<usize> = elements
                .iter()
                .flat_map(|(_, l)| l.iter().map(|&(n, _)| n))
                .collect();
            m.sort_unstable();
            m.dedup();
            m
        };
        let _ = write!(
            out,
            "\n#### E = {} Pa, nu = {}: reference v / F = {}\n\n| element | {} | extrapolated |\n|---|{}---|\n",
            Sig(first.young),
            first.poisson,
            reference.map_or_else(
                || "none known".to_string(),
                |(r, what)| format!("{} m/N ({what})", Sig(r))
            ),
            meshes
                .iter()
                .map(|n| format!("{n} x {n}"))
                .collect::<Vec<_>>()
                .join(" | "),
            "---|".repeat(meshes.len()),
        );
        let cell = |v: f64| match reference {
            Some((r, _)) => format!("{} ({:+.2} %)", Sig(v), 100.0 * (v / r - 1.0)),
            None => Sig(v).to_string(),
        };
        for (scene, ladder) in elements.iter() {
            let cells: Vec<String> = meshes
                .iter()
                .map(|n| {
                    ladder
                        .iter()
                        .find(|(m, _)| m == n)
                        .map_or_else(|| "-".to_string(), |&(_, v)| cell(v))
                })
                .collect();
            let _ = writeln!(
                out,
                "| {} | {} | {} |",
                scene.element,
                cells.join(" | "),
                finest_three(ladder)
                    .and_then(extrapolate)
                    .map_or_else(|| "-".to_string(), cell)
            );
        }
        for (scene, ladder) in elements.iter() {
            scene_checks(scene, ladder, checks);
        }
    }
    out.push('\n');
    Ok(out)
}

/// The values of the three finest meshes of `ladder` if they refine by a constant factor.
fn finest_three(ladder: &Ladder) -> Option<[f64; 3]> {
    let [.., (n1, v1), (n2, v2), (n3, v3)] = ladder.as_slice() else {
        return None;
    };
    (n2 * n2 == n1 * n3).then_some([*v1, *v2, *v3])
}

/// The checks of one element's ladder in one scene (see the module documentation).
fn scene_checks(scene: &CookScene, ladder: &Ladder, checks: &mut Checks) {
    let label = format!("Cook nu = {} {}", scene.poisson, scene.element);
    let Some((reference, _)) = scene.reference() else {
        checks.skip(
            &format!("{label}: against the reference"),
            "no reference known for this Poisson's ratio",
        );
        return;
    };
    let Some(&(finest, v)) = ladder.last() else {
        return;
    };
    let error = |v: f64| v / reference - 1.0;
    if scene.locks() {
        checks.record(
            &format!(
                "{label} {finest} x {finest}: locks (more than {} % too stiff)",
                100.0 * LOCKING_STIFFNESS
            ),
            -error(v) > LOCKING_STIFFNESS,
            format!("v / F {} % off the reference", Sig(100.0 * error(v))),
        );
        return;
    }
    checks.check_fraction(
        &format!(
            "{label} {finest} x {finest}: within {} % of the reference",
            100.0 * FINEST_TOLERANCE
        ),
        Some(error(v).abs()),
        FINEST_TOLERANCE,
        "",
    );
    if ladder.len() < 3 {
        checks.skip(&format!("{label}: convergence"), "fewer than three meshes");
        return;
    }
    let errors: Vec<f64> = ladder.iter().map(|&(_, v)| error(v).abs()).collect();
    checks.record(
        &format!("{label}: the error shrinks with every refinement"),
        errors.windows(2).all(|w| w[1] < w[0]),
        errors
            .iter()
            .map(|e| format!("{} %", Sig(100.0 * e)))
            .collect::<Vec<_>>()
            .join(" -> "),
    );
    let extrapolated = finest_three(ladder).and_then(extrapolate);
    checks.check_fraction(
        &format!(
            "{label}: the extrapolation of its three finest meshes within {} % of the reference",
            100.0 * EXTRAPOLATION_TOLERANCE
        ),
        extrapolated.map(|x| error(x).abs()),
        EXTRAPOLATION_TOLERANCE,
        "the three finest meshes do not refine by one factor, or their changes do not shrink",
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(poisson: f64, element: &'static str) -> CookScene {
        CookScene {
            element,
            elements: 64,
            column: "tip.40.u_y".into(),
            load: 2.0,
            thickness: 1.0,
            young: 15.0 / 16.0,
            poisson,
        }
    }

    #[test]
    fn the_plane_strain_twin_has_the_plane_stress_reference() {
        let s = scene(0.25, "CPE4R");
        // E' = 15/16, nu' = 1/4 is E = 1, nu = 1/3 in plane stress: v / F = 23.96
        let (r, _) = s.reference().expect("a reference");
        assert!((r - 23.96).abs() < 1e-12, "{r}");
        assert_eq!(s.per_edge(), 8);
        let mut thick = scene(0.25, "CPE4R");
        thick.thickness = 2.0;
        thick.young = 30.0 / 16.0;
        assert!((thick.reference().expect("a reference").0 - 23.96 / 4.0).abs() < 1e-12);
        let incompressible = CookScene {
            young: 250.0,
            ..scene(0.4999, "CPE4")
        };
        assert!((incompressible.reference().expect("one").0 - 18.51 / 250.0).abs() < 1e-15);
        assert!(incompressible.locks() && !s.locks());
        assert_eq!(scene(0.3, "CPE4H").reference(), None);
    }

    #[test]
    fn aitken_extrapolates_a_geometric_sequence_exactly() {
        // v = 10 - 3 q^k for q = 0.4: the limit is 10
        let v = [0.0, 1.0, 2.0].map(|k: f64| 10.0 - 3.0 * 0.4_f64.powf(k));
        assert!((extrapolate(v).expect("converges") - 10.0).abs() < 1e-12);
        assert_eq!(extrapolate([1.0, 2.0, 4.0]), None);
        assert_eq!(extrapolate([1.0, 2.0, 1.5]), None);
    }

    fn checked(scene: &CookScene, ladder: &[(usize, f64)]) -> Checks {
        let mut checks = Checks::default();
        scene_checks(scene, &ladder.to_vec(), &mut checks);
        checks
    }

    #[test]
    fn a_converging_element_passes_and_a_lagging_or_locking_one_fails() {
        let s = scene(0.25, "CPE4I");
        let r = s.reference().expect("one").0;
        // errors 8 %, 3.2 %, 1.28 %, 0.512 %: converging at a constant ratio
        let converging: Vec<(usize, f64)> = (0..4)
            .map(|k| (4 << k, r * (1.0 - 0.08 * 0.4_f64.powi(k))))
            .collect();
        let c = checked(&s, &converging);
        assert_eq!((c.counts.passed, c.counts.failed), (3, 0), "{}", c.text);
        // one refinement behind: 1.28 % at the finest mesh
        let c = checked(&s, &converging[..3]);
        assert_eq!(c.counts.failed, 1, "{}", c.text);
        assert!(
            c.text
                .contains("FAIL** Cook nu = 0.25 CPE4I 16 x 16: within"),
            "{}",
            c.text
        );
        // an error that grows again
        let mut wobbly = converging.clone();
        wobbly[2].1 = r * 0.95;
        let c = checked(&s, &wobbly);
        assert!(
            c.text
                .contains("FAIL** Cook nu = 0.25 CPE4I: the error shrinks"),
            "{}",
            c.text
        );
        // the locking element must lock
        let locking = CookScene {
            young: 250.0,
            ..scene(0.4999, "CPE4")
        };
        let r = locking.reference().expect("one").0;
        let c = checked(&locking, &[(16, 0.3 * r), (32, 0.4 * r)]);
        assert_eq!((c.counts.passed, c.counts.failed), (1, 0), "{}", c.text);
        let c = checked(&locking, &[(32, 0.9 * r)]);
        assert_eq!(c.counts.failed, 1, "{}", c.text);
        let c = checked(&scene(0.3, "CPE4R"), &converging);
        assert_eq!(c.counts.skipped, 1);
    }

    #[test]
    fn the_shipped_scenes_are_recognised_with_their_tip() {
        let read = |name: &str| {
            let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../cases/verification")
                .join(name);
            skid_cases::deck::read_model(&path).expect("deck").model
        };
        let mut spec = read("2d-cook-incompressible-cpe4h-n8.inp");
        let s = CookScene::recognise(&spec).expect("a Cook scene");
        assert_eq!((s.element, s.elements, s.per_edge()), ("CPE4H", 64, 8));
        // the tip (48, 52) is node (8, 4): 4 (8 + 1) + 8
        assert_eq!(s.column, "tip.44.u_y");
        assert!((s.load - 250.0 * 1e-4).abs() < 1e-12, "{}", s.load);
        assert!((s.young / 250.0 - 1.0).abs() < 1e-9 && (s.poisson - 0.4999).abs() < 1e-9);
        spec.output.history_nodes.clear();
        assert_eq!(CookScene::recognise(&spec), None);
        assert_eq!(
            CookScene::recognise(&read("2d-compression-uniaxial-cpe4.inp")),
            None
        );
    }

    #[test]
    fn the_tip_displacement_is_the_last_rows() {
        let text = "time,step,tip.40.u_x,tip.40.u_y\n0,s,0,0\n1,s,1e-3,2.5e-3\n";
        let path = Path::new("history.csv");
        assert_eq!(
            tip_displacement(text, path, "tip.40.u_y").expect("reads"),
            2.5e-3
        );
        let e = tip_displacement(text, path, "tip.41.u_y").expect_err("no such column");
        assert!(e.to_string().contains("tip.41.u_y"), "{e}");
        assert!(tip_displacement("time,tip.40.u_y\n", path, "tip.40.u_y").is_err());
    }
}
