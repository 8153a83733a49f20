//! Cattaneo–Mindlin (the scenes `cases/verification/2d-cattaneo-mindlin-*.json`, written by
//! `scripts/cattaneo_mindlin.py`): the Hertz scene with friction `mu`, a rigid cylinder pressed
//! on an elastic block by `P` in a first static step and pushed along the surface by `Q < mu P`
//! in a second one, `P` held and the cylinder never turning.
//!
//! Answer, per unit length, with the normal and tangential problems uncoupled (as they are when
//! Dundurs' `beta = (1 - 2 nu) / (2 (1 - nu))` is small against `mu`): the pressure stays
//! Hertz's, `p(x) = p0 sqrt(1 - x^2 / a^2)` (see [`crate::hertz`]); the contact sticks on
//! `|x| < c`, `c = a sqrt(1 - Q / (mu P))`, where the traction along `Q` is
//! `q(x) = mu p0 [sqrt(1 - x^2 / a^2) - (c / a) sqrt(1 - x^2 / c^2)]`, and slips with
//! `q = mu p` on `c <= |x| <= a`.
//!
//! Measurement, from the run's `contact_nodes.csv` (its last state):
//! - nodal pressure `p_i` and traction `q_i`: the normal and the tangential force over the
//!   deformed tributary area, as for Hertz; `q_i` is taken along the tangential resultant;
//! - a node sticks when it carries force and `|q_i| < mu p_i (1 - 1e-6)` (the sliding test of
//!   the contact totals); `c_FE` is half the reference distance between the outermost sticking
//!   nodes, short of or beyond the discrete stick edge by up to the element there, `h_c`;
//! - profile error: the RMS of `(q_i - q(x_i)) / (mu p0)` over the nodes with `|x| <= a`;
//! - alternation ([`second_difference`]): the node-to-node (checkerboard) part of the error
//!   `e_i = q_i - q(x_i)`, `A_q = max |e_(i-1) - 2 e_i + e_(i+1)| / 4` over the nodes that stick
//!   with both neighbours, all three inside `|x| < c`, over `mu p0`. A pattern `+A, -A, +A, ...`
//!   measures `A`; a smooth error measures its second difference `h^2 e'' / 4`; the kinks of
//!   `q` at `x = +/- c` and of the discrete traction at its stick edges stay outside the
//!   stencils counted. `A_p`: the same of `p_i - p(x_i)` over the nodes in
//!   contact with both neighbours, over `p0`.
//!
//! Checks, on every run: the tangential resultant is `Q` (so the contact, not a support,
//! carries it), `c_FE` lies within `h_c` of `c`, and the profile error is at most
//! [`PROFILE_TOLERANCE`]; on the finest mesh of each element type, `A_q` and `A_p` are at most
//! [`ALTERNATION_LIMIT`]; and from one mesh to the next finer, `A_q` shrinks (an alternation
//! that the mesh does not resolve away is a defect of the discretisation, not the
//! discretisation error).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::SceneRun;
use crate::ReportError;
use crate::alternation::second_difference;
use crate::format::{Checks, Sig, percent};
use crate::hertz::{self, CandidateNode, HertzScene};
use crate::plot::{MINDLIN_SVG, plot_mindlin_traction};
use crate::read;
use skid_cases::model_file::contact_nodes::CONTACT_NODES_CSV;
use skid_cases::model_spec::{LoadSpec, ModelSpec, ModelStepSpec};

/// Largest RMS of `(q_FE - q) / (mu p0)` over the contact. Measured: 1.7-2.3 % on CPE4R,
/// CPE4H and CPE4I at 8 and 16 elements per half-width; what remains is mostly the finite
/// block's tilt under `Q` (7 % on a block of 30 a, 44 % on 10 a; see the scene's script).
pub const PROFILE_TOLERANCE: f64 = 0.05;

/// Largest alternation `A_q` (of `mu p0`) and `A_p` (of `p0`) on the finest mesh. Measured on
/// 16 elements per half-width: `A_q` 1.0 % (CPE4R), 2.1 % (CPE4H), 1.8 % (CPE4I), decaying
/// from the stick edges towards the centre, and `A_p` 0.4 %; the displacement element CPE4,
/// which locks at this `nu`, gives `A_q` 7 % on 8 and 12 % on 16 elements.
pub const ALTERNATION_LIMIT: f64 = 0.03;

/// The sliding test of the contact totals: a node slides from `|q| >= mu p (1 - 1e-6)`.
const SLIDING_TOLERANCE: f64 = 1e-6;

/// A Cattaneo–Mindlin scene: what its answer needs.
#[derive(Clone, Debug, PartialEq)]
pub struct MindlinScene {
    /// The normal problem (its load is `P` per unit length).
    pub hertz: HertzScene,
    /// Friction coefficient.
    pub mu: f64,
    /// Tangential load `Q` per unit length, N/m.
    pub tangential_load: f64,
    /// The part's element type name.
    pub element: &'static str,
}

impl MindlinScene {
    /// The scene of `spec`, if it is one: 2D, one element block, one frictional pair whose
    /// master is a rigid cylinder, two static steps, and two forces on the cylinder: one along
    /// y (the normal `P`) in both steps at full value, one along x (`Q`) only in the second,
    /// with `Q < mu P`.
    pub fn recognise(spec: &ModelSpec) -> Option<Self> {
        let (pair, body, radius) = hertz::cylinder_pair(spec)?;
        let [ModelStepSpec::Static { .. }, ModelStepSpec::Static { .. }] = spec.steps.as_slice()
        else {
            return None;
        };
        let [block] = spec.part.elements.as_slice() else {
            return None;
        };
        // The force of a load on the cylinder and its factors in the two steps.
        let on_cylinder = |load: &LoadSpec| match load {
            LoadSpec::Concentrated {
                body: Some(loaded),
                force: Some(force),
                moment: None,
                step_factors,
                ..
            } if *loaded == body.name && force.len() == 2 => {
                let factors = step_factors.clone().unwrap_or_else(|| vec![1.0, 1.0]);
                Some((force[0], force[1], factors))
            }
            _ => None,
        };
        let [first, second] = spec.loads.as_slice() else {
            return None;
        };
        let (mut normal, mut tangential) = (on_cylinder(first)?, on_cylinder(second)?);
        if normal.0 != 0.0 {
            std::mem::swap(&mut normal, &mut tangential);
        }
        let (p, q) = (normal.1.abs(), tangential.0.abs());
        let ok = spec.dimension == 2
            && pair.mu > 0.0
            && normal.0 == 0.0
            && tangential.1 == 0.0
            && normal.2 == [1.0, 1.0]
            && tangential.2 == [0.0, 1.0]
            && q > 0.0
            && q < pair.mu * p;
        if !ok {
            return None;
        }
        let hertz = HertzScene::of_block(spec, &pair.name, radius, p)?;
        let tangential_load = q / hertz.thickness;
        Some(Self {
            hertz,
            mu: pair.mu,
            tangential_load,
            element: block.kind.name(),
        })
    }

    /// `c = a sqrt(1 - Q / (mu P))`, m.
    pub fn stick_half_width(&self) -> f64 {
        self.hertz.half_width() * (1.0 - self.tangential_load / (self.mu * self.hertz.load)).sqrt()
    }

    /// Mindlin's traction `q(x)` along `Q` (see the module documentation), Pa.
    pub fn traction(&self, x: f64) -> f64 {
        let (a, c) = (self.hertz.half_width(), self.stick_half_width());
        let slip = self.mu * self.hertz.pressure(x);
        if x.abs() >= c {
            return slip;
        }
        let s = x / c;
        slip - self.mu * self.hertz.peak_pressure() * (c / a) * (1.0 - s * s).sqrt()
    }
}

/// A contact candidate's state at the end of the run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MindlinNode {
    /// Reference x, m.
    pub x: f64,
    /// Pressure, Pa.
    pub pressure: f64,
    /// Traction along the tangential resultant, Pa.
    pub traction: f64,
    /// Carries force.
    pub closed: bool,
    /// Carries force and `|q| < mu p (1 - 1e-6)`.
    pub sticks: bool,
}

/// What a run gives of the Cattaneo–Mindlin answer.
#[derive(Clone, Debug, PartialEq)]
pub struct MindlinMeasure {
    /// The candidates in order of x.
    pub nodes: Vec<MindlinNode>,
    /// Half the reference distance between the outermost sticking nodes, m.
    pub stick_half_width: f64,
    /// The larger of the two reference segments from an outermost sticking node to the next
    /// (`h_c`), m.
    pub stick_edge_element: f64,
    /// Element size at the centre, m.
    pub centre_element: f64,
    /// Tangential resultant over the thickness, N/m.
    pub tangential_resultant: f64,
}

/// Measures the answer from `nodes` of a block of thickness `thickness` with friction `mu`.
///
/// # Errors
/// Why it cannot be measured: fewer than three candidates, or no node that sticks with a
/// neighbour on either side.
pub fn measure(nodes: &[CandidateNode], thickness: f64, mu: f64) -> Result<MindlinMeasure, String> {
    let mut nodes = nodes.to_vec();
    nodes.sort_by(|a, b| a.reference_x.total_cmp(&b.reference_x));
    let n = nodes.len();
    if n < 3 {
        return Err(format!("{n} contact candidates, expected at least 3"));
    }
    let resultant: f64 = nodes.iter().map(|c| c.tangential_force).sum();
    let along = if resultant < 0.0 { -1.0 } else { 1.0 };
    let tributary = hertz::tributary_lengths(&nodes);
    let states: Vec<MindlinNode> = nodes
        .iter()
        .zip(&tributary)
        .map(|(c, l)| {
            let (pressure, traction) = (
                c.normal_force / (thickness * l),
                along * c.tangential_force / (thickness * l),
            );
            let closed = c.normal_force > 0.0;
            MindlinNode {
                x: c.reference_x,
                pressure,
                traction,
                closed,
                sticks: closed && traction.abs() < mu * pressure * (1.0 - SLIDING_TOLERANCE),
            }
        })
        .collect();
    let sticking: Vec<usize> = (0..n).filter(|&i| states[i].sticks).collect();
    let (Some(&first), Some(&last)) = (sticking.first(), sticking.last()) else {
        return Err("no node sticks".into());
    };
    if first == 0 || last + 1 == n {
        return Err("the stick zone reaches the outermost candidate".into());
    }
    let reference = |i: usize, j: usize| (states[j].x - states[i].x).abs();
    let centre = (0..n)
        .min_by(|&i, &j| states[i].x.abs().total_cmp(&states[j].x.abs()))
        .unwrap_or(0);
    let next = if centre + 1 < n {
        centre + 1
    } else {
        centre - 1
    };
    Ok(MindlinMeasure {
        stick_half_width: 0.5 * reference(first, last),
        stick_edge_element: reference(first - 1, first).max(reference(last, last + 1)),
        centre_element: reference(centre, next),
        tangential_resultant: along * resultant / thickness,
        nodes: states,
    })
}

impl MindlinMeasure {
    /// RMS of `(q_FE - q) / (mu p0)` over the nodes with `|x| <= a`.
    pub fn profile_error(&self, scene: &MindlinScene) -> Option<f64> {
        let (a, scale) = (
            scene.hertz.half_width(),
            scene.mu * scene.hertz.peak_pressure(),
        );
        let inside: Vec<f64> = self
            .nodes
            .iter()
            .filter(|s| s.x.abs() <= a)
            .map(|s| (s.traction - scene.traction(s.x)) / scale)
            .collect();
        (!inside.is_empty())
            .then(|| (inside.iter().map(|e| e * e).sum::<f64>() / inside.len() as f64).sqrt())
    }

    /// `A_q`, of `mu p0`.
    pub fn traction_alternation(&self, scene: &MindlinScene) -> Option<f64> {
        let errors: Vec<f64> = self
            .nodes
            .iter()
            .map(|s| s.traction - scene.traction(s.x))
            .collect();
        let c = scene.stick_half_width();
        let sticks: Vec<bool> = self
            .nodes
            .iter()
            .map(|s| s.sticks && s.x.abs() < c)
            .collect();
        second_difference(&errors, &sticks).map(|v| v / (scene.mu * scene.hertz.peak_pressure()))
    }

    /// `A_p`, of `p0`.
    pub fn pressure_alternation(&self, scene: &MindlinScene) -> Option<f64> {
        let errors: Vec<f64> = self
            .nodes
            .iter()
            .map(|s| s.pressure - scene.hertz.pressure(s.x))
            .collect();
        let closed: Vec<bool> = self.nodes.iter().map(|s| s.closed).collect();
        second_difference(&errors, &closed).map(|v| v / scene.hertz.peak_pressure())
    }
}

/// A completed run and what it measured.
struct Level<'a> {
    run: &'a SceneRun,
    scene: &'a MindlinScene,
    measure: MindlinMeasure,
}

/// The Cattaneo–Mindlin part of the verification section: table, plot (written into `plots`)
/// and checks (see the module documentation).
///
/// # Errors
/// [`ReportError`] if a completed run's `contact_nodes.csv` is absent or malformed, or the
/// plot cannot be written.
pub fn section(
    runs: &[(&SceneRun, MindlinScene)],
    plots: &Path,
    checks: &mut Checks,
) -> Result<(String, Option<std::path::PathBuf>), ReportError> {
    let mut by_element: BTreeMap<&str, Vec<Level>> = BTreeMap::new();
    for (run, scene) in runs {
        if !run.completed_or_recorded(checks) {
            continue;
        }
        let path = run.dir.join(CONTACT_NODES_CSV);
        let nodes = hertz::read_candidates(&read(&path)?, &path, &scene.hertz.pair)?;
        match measure(&nodes, scene.hertz.thickness, scene.mu) {
            Ok(measure) => by_element.entry(scene.element).or_default().push(Level {
                run,
                scene,
                measure,
            }),
            Err(why) => checks.record(
                &format!("{}: Cattaneo–Mindlin measures", run.name),
                false,
                why,
            ),
        }
    }
    let mut out = String::from(
        "### Cattaneo–Mindlin: a cylinder pressed, then pushed sideways (plane strain)\n\n\
         Stick on `|x| < c = a sqrt(1 - Q / (mu P))` with \
         `q(x) = mu p0 [sqrt(1 - x^2 / a^2) - (c / a) sqrt(1 - x^2 / c^2)]`, slip with \
         `q = mu p` outside; `a`, `p0` and `p(x)` are Hertz's. Nodal `p` and `q`: force over \
         the deformed tributary area. `c_FE`: half the reference distance between the \
         outermost sticking nodes (`|q| < mu p`), `h_c` the element at its edge. RMS: of \
         `(q_FE - q) / (mu p0)` over `|x| <= a`. Alternation `A_q`: the largest \
         `|e_(i-1) - 2 e_i + e_(i+1)| / 4` of the traction error `e = q_FE - q` over the nodes \
         that stick with both neighbours, all three inside `|x| < c`, of `mu p0` (an \
         alternating `+A, -A, ...` measures `A`, a smooth error about nothing); `A_p` the same \
         of the pressure over the nodes in contact, of `p0`.\n\n\
         | run | element | a / h | c / a | c_FE / a | (c_FE - c) / h_c | RMS [% of mu p0] \
         | A_q [% of mu p0] | A_p [% of p0] | Q_FE vs Q [%] | wall time [s] |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for levels in by_element.values_mut() {
        // Coarsest first.
        levels.sort_by(|a, b| {
            b.measure
                .centre_element
                .total_cmp(&a.measure.centre_element)
        });
        for l in levels.iter() {
            let (s, m) = (l.scene, &l.measure);
            let a = s.hertz.half_width();
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} |",
                l.run.name,
                s.element,
                Sig(a / m.centre_element),
                Sig(s.stick_half_width() / a),
                Sig(m.stick_half_width / a),
                Sig((m.stick_half_width - s.stick_half_width()) / m.stick_edge_element),
                percent(m.profile_error(s)),
                percent(m.traction_alternation(s)),
                percent(m.pressure_alternation(s)),
                Sig(100.0 * (m.tangential_resultant / s.tangential_load - 1.0)),
                l.run.summary.wall_time_s,
            );
        }
    }
    for levels in by_element.values() {
        for l in levels {
            level_checks(l, checks);
        }
        let Some(finest) = levels.last() else {
            continue;
        };
        let (s, m) = (finest.scene, &finest.measure);
        let name = &finest.run.name;
        let limit = 100.0 * ALTERNATION_LIMIT;
        checks.check_fraction(
            &format!("{name} (finest): traction alternation A_q within {limit} % of mu p0"),
            m.traction_alternation(s),
            ALTERNATION_LIMIT,
            "no node sticks with both neighbours",
        );
        checks.check_fraction(
            &format!("{name} (finest): pressure alternation A_p within {limit} % of p0"),
            m.pressure_alternation(s),
            ALTERNATION_LIMIT,
            "no node is in contact with both neighbours",
        );
        for pair in levels.windows(2) {
            let (coarse, fine) = (&pair[0], &pair[1]);
            let (before, after) = (
                coarse.measure.traction_alternation(coarse.scene),
                fine.measure.traction_alternation(fine.scene),
            );
            checks.record(
                &format!(
                    "{} -> {}: the traction alternation shrinks",
                    coarse.run.name, fine.run.name
                ),
                matches!((before, after), (Some(b), Some(f)) if f < b),
                format!("{} % -> {} % of mu p0", percent(before), percent(after)),
            );
        }
    }
    // The plot: the finest mesh of the one-point element, or else of the first element type.
    let plotted = by_element
        .get("CPE4R")
        .or_else(|| by_element.values().next());
    let Some(finest) = plotted.and_then(|levels| levels.last()) else {
        return Ok((out, None));
    };
    let (s, name) = (finest.scene, &finest.run.name);
    let (a, scale) = (s.hertz.half_width(), s.mu * s.hertz.peak_pressure());
    let fe: Vec<(f64, f64)> = finest
        .measure
        .nodes
        .iter()
        .filter(|n| n.x.abs() <= 1.2 * a)
        .map(|n| (n.x / a, n.traction / scale))
        .collect();
    let curve = |f: &dyn Fn(f64) -> f64| -> Vec<(f64, f64)> {
        (-120..=120)
            .map(|k| {
                let x = f64::from(k) / 100.0 * a;
                (x / a, f(x) / scale)
            })
            .collect()
    };
    let plot = plots.join(MINDLIN_SVG);
    plot_mindlin_traction(
        &format!("Cattaneo–Mindlin traction, {name}"),
        fe,
        curve(&|x| s.traction(x)),
        curve(&|x| s.mu * s.hertz.pressure(x)),
        &plot,
    )?;
    let _ = write!(
        out,
        "\n![q(x) / (mu p0) of {name} against Mindlin]({MINDLIN_SVG})\n\n"
    );
    Ok((out, Some(plot)))
}

/// The checks of one run: its tangential resultant, stick half-width and profile error.
fn level_checks(l: &Level, checks: &mut Checks) {
    let (s, m, name) = (l.scene, &l.measure, &l.run.name);
    checks.check_fraction(
        &format!("{name}: the contact carries Q (tangential resultant within 0.1 %)"),
        Some((m.tangential_resultant / s.tangential_load - 1.0).abs()),
        1e-3,
        "",
    );
    let width_error = m.stick_half_width - s.stick_half_width();
    checks.record(
        &format!("{name}: stick half-width within one element (h_c) of Mindlin's"),
        width_error.abs() <= m.stick_edge_element,
        format!(
            "c_FE - c = {} mm, h_c = {} mm",
            Sig(1e3 * width_error),
            Sig(1e3 * m.stick_edge_element)
        ),
    );
    checks.check_fraction(
        &format!(
            "{name}: traction profile within {} % (RMS) of mu p0",
            100.0 * PROFILE_TOLERANCE
        ),
        m.profile_error(s),
        PROFILE_TOLERANCE,
        "no node within the contact",
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> MindlinScene {
        MindlinScene {
            hertz: HertzScene {
                pair: "p".into(),
                radius: 0.05,
                load: 1000.0,
                thickness: 0.5,
                young: 10e6,
                poisson: 0.49,
            },
            mu: 0.3,
            tangential_load: 150.0,
            element: "CPE4R",
        }
    }

    #[test]
    fn mindlin_traction_balances_q_and_slips_at_mu_p() {
        let s = scene();
        let (a, c) = (s.hertz.half_width(), s.stick_half_width());
        assert!((c / a - 0.5_f64.sqrt()).abs() < 1e-12);
        // The integral of q over the contact is Q (midpoint rule on 2e5 strips).
        let n = 200_000;
        let h = 2.0 * a / f64::from(n);
        let total: f64 = (0..n)
            .map(|k| s.traction(-a + (f64::from(k) + 0.5) * h) * h)
            .sum();
        assert!((total / s.tangential_load - 1.0).abs() < 1e-6, "{total}");
        // Continuous at c, mu p in the slip zone, below it in the stick zone.
        let x = 0.9 * a;
        assert_eq!(s.traction(x), s.mu * s.hertz.pressure(x));
        let scale = s.mu * s.hertz.peak_pressure();
        assert!((s.traction(c * (1.0 - 1e-12)) - s.traction(c)).abs() < 1e-5 * scale);
        assert!(s.traction(0.0) < s.mu * s.hertz.pressure(0.0));
    }

    /// Candidates every `h` from -2a to 2a carrying Mindlin's tractions plus `wiggle` times an
    /// alternating pattern (of `mu p0`) in the stick zone.
    fn nodes(s: &MindlinScene, h: f64, wiggle: f64) -> Vec<CandidateNode> {
        let a = s.hertz.half_width();
        let n = (2.0 * a / h).round() as i64;
        let scale = s.mu * s.hertz.peak_pressure();
        (-n..=n)
            .map(|i| {
                let x = i as f64 * h;
                let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                let extra = if x.abs() < 0.6 * a {
                    sign * wiggle * scale
                } else {
                    0.0
                };
                let area = s.hertz.thickness * h;
                CandidateNode {
                    position: [x, 0.0],
                    reference_x: x,
                    normal_force: s.hertz.pressure(x) * area,
                    tangential_force: (s.traction(x) + extra) * area,
                }
            })
            .collect()
    }

    #[test]
    fn the_analytic_tractions_measure_to_mindlin_without_alternation() {
        let s = scene();
        let a = s.hertz.half_width();
        let h = a / 16.5;
        let m = measure(&nodes(&s, h, 0.0), s.hertz.thickness, s.mu).expect("measurable");
        assert!((m.stick_half_width - s.stick_half_width()).abs() <= m.stick_edge_element);
        assert!(m.profile_error(&s).expect("inside") < 1e-12);
        assert!(m.traction_alternation(&s).expect("sticks") < 1e-12);
        assert!(m.pressure_alternation(&s).expect("closed") < 1e-12);
        assert!((m.centre_element - h).abs() < 1e-15);
        // Q as a sum of nodal forces on a node-centred grid: the rule's error only.
        assert!((m.tangential_resultant / s.tangential_load - 1.0).abs() < 2e-2);
    }

    #[test]
    fn an_alternating_traction_measures_its_amplitude() {
        let s = scene();
        let h = s.hertz.half_width() / 16.5;
        let m = measure(&nodes(&s, h, 0.04), s.hertz.thickness, s.mu).expect("measurable");
        let alternation = m.traction_alternation(&s).expect("sticks");
        assert!((alternation - 0.04).abs() < 1e-9, "{alternation}");
        assert!(m.pressure_alternation(&s).expect("closed") < 1e-12);
        // Reversed: the traction is taken along the resultant.
        let flipped: Vec<CandidateNode> = nodes(&s, h, 0.04)
            .into_iter()
            .map(|c| CandidateNode {
                tangential_force: -c.tangential_force,
                ..c
            })
            .collect();
        let m = measure(&flipped, s.hertz.thickness, s.mu).expect("measurable");
        assert!((m.traction_alternation(&s).expect("sticks") - 0.04).abs() < 1e-9);
    }

    #[test]
    fn a_sliding_contact_is_not_measured() {
        let s = scene();
        let sliding: Vec<CandidateNode> = nodes(&s, s.hertz.half_width() / 8.5, 0.0)
            .into_iter()
            .map(|c| CandidateNode {
                tangential_force: s.mu * c.normal_force,
                ..c
            })
            .collect();
        let e = measure(&sliding, s.hertz.thickness, s.mu).expect_err("no stick");
        assert!(e.contains("no node sticks"), "{e}");
    }
}
