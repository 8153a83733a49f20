//! Hertz contact of a rigid cylinder pressed on an elastic block in plane strain (the scenes
//! `cases/verification/2d-hertz-*.json`): the analytic answer from the scene as run, and the
//! contact half-width and peak pressure measured from its `contact_nodes.csv`.
//!
//! Analytic answer (a rigid cylinder of radius `R` on an elastic half-space, frictionless,
//! load `P` per unit length): `E* = E / (1 - nu^2)`, `a = sqrt(4 P R / (pi E*))`,
//! `p0 = 2 P / (pi a)`, `p(x) = p0 sqrt(1 - x^2 / a^2)`. `E` and `nu` are the small-strain
//! moduli of the polynomial material: shear modulus `G = 2 (C10 + C01)`, bulk modulus
//! `K = 2 / D1`, `E = 9 K G / (3 K + G)`, `nu = (3 K - 2 G) / (2 (3 K + G))`.
//!
//! Measurement, from the candidates sorted along x:
//! - pressure at a node: its normal force over its tributary area `t l_i`, `t` the thickness
//!   and `l_i` half the length of the segments to its two neighbours (one at either end), in
//!   the deformed configuration (the Cauchy pressure, as the field output's
//!   `contact_pressure`). The nominal pressure takes the reference segments instead; the two
//!   differ by the surface strain along x, an effect of finite strain that linear (Hertz)
//!   theory does not see. A nodal force is the pressure weighted by the node's shape function,
//!   so at the centre either reads `p(0) (1 - h^2 / (12 a^2))` of a Hertz distribution on
//!   elements of size `h` (0.5 % low at `h = a / 4`, 0.03 % at `a / 16`);
//! - peak pressure: the pressure of the node nearest x = 0;
//! - half-width: half the reference distance between the outermost nodes that carry force on
//!   the left and on the right. The edge of the discrete contact lies between such a node and
//!   the next, open one, so this measure is short of it by up to one element at the edge
//!   (`h_edge`, the larger of the two edge segments).

use std::f64::consts::PI;
use std::path::Path;

use super::ReportError;
use skid_cases::csv_out::CsvTable;
use skid_cases::model_spec::ModelSpec;
use skid_cases::model_spec::{ContactPairSpec, LoadSpec, RigidBodySpec, RigidSurfaceSpec};
use skid_cases::schema::MaterialSpec;

/// A Hertz scene: what its analytic answer needs.
#[derive(Clone, Debug, PartialEq)]
pub struct HertzScene {
    /// Name of the contact pair between the cylinder and the block.
    pub pair: String,
    /// Cylinder radius R, m.
    pub radius: f64,
    /// Load P per unit length (the cylinder's load over the thickness), N/m.
    pub load: f64,
    /// Thickness t of the plane-strain block, m.
    pub thickness: f64,
    /// Small-strain Young's modulus E, Pa.
    pub young: f64,
    /// Small-strain Poisson's ratio nu.
    pub poisson: f64,
}

impl HertzScene {
    /// The Hertz scene of `spec`, if it is one: 2D, one frictionless contact pair whose master
    /// is a rigid cylinder, that cylinder loaded by one concentrated force and no other load,
    /// one static step, a polynomial material.
    pub fn recognise(spec: &ModelSpec) -> Option<Self> {
        let (pair, body, radius) = cylinder_pair(spec)?;
        let [
            LoadSpec::Concentrated {
                body: Some(loaded),
                force: Some(force),
                ..
            },
        ] = spec.loads.as_slice()
        else {
            return None;
        };
        let [skid_cases::model_spec::ModelStepSpec::Static { .. }] = spec.steps.as_slice() else {
            return None;
        };
        if spec.dimension != 2 || pair.mu != 0.0 || *loaded != body.name {
            return None;
        }
        let load = force.iter().map(|f| f * f).sum::<f64>().sqrt();
        Self::of_block(spec, &pair.name, radius, load)
    }

    /// The Hertz scene of the contact pair `pair` between a cylinder of radius `radius` and the
    /// part of the 2D model `spec` under the total normal load `load` (N): the small-strain
    /// moduli of the part's polynomial material; `None` for a non-positive thickness.
    pub fn of_block(spec: &ModelSpec, pair: &str, radius: f64, load: f64) -> Option<Self> {
        let MaterialSpec::PolynomialN1 { c10, c01, d1 } = spec.part.section.material;
        let thickness = spec.part.section.thickness;
        if thickness <= 0.0 {
            return None;
        }
        let shear = 2.0 * (c10 + c01);
        let bulk = 2.0 / d1;
        Some(Self {
            pair: pair.to_string(),
            radius,
            load: load / thickness,
            thickness,
            young: 9.0 * bulk * shear / (3.0 * bulk + shear),
            poisson: (3.0 * bulk - 2.0 * shear) / (2.0 * (3.0 * bulk + shear)),
        })
    }

    /// `E* = E / (1 - nu^2)`, Pa.
    pub fn plane_strain_modulus(&self) -> f64 {
        self.young / (1.0 - self.poisson * self.poisson)
    }

    /// `a = sqrt(4 P R / (pi E*))`, m.
    pub fn half_width(&self) -> f64 {
        (4.0 * self.load * self.radius / (PI * self.plane_strain_modulus())).sqrt()
    }

    /// `p0 = 2 P / (pi a)`, Pa.
    pub fn peak_pressure(&self) -> f64 {
        2.0 * self.load / (PI * self.half_width())
    }

    /// `p(x) = p0 sqrt(1 - x^2 / a^2)` inside the contact, 0 outside, Pa.
    pub fn pressure(&self, x: f64) -> f64 {
        let s = x / self.half_width();
        self.peak_pressure() * (1.0 - s * s).max(0.0).sqrt()
    }
}

/// The model's only contact pair, if its master is a rigid cylinder: the pair, the body and
/// the cylinder's radius.
pub fn cylinder_pair(spec: &ModelSpec) -> Option<(&ContactPairSpec, &RigidBodySpec, f64)> {
    let [pair] = spec.contact.as_slice() else {
        return None;
    };
    let body = spec.rigid_bodies.iter().find(|b| b.name == pair.master)?;
    let Some(RigidSurfaceSpec::Cylinder { radius, .. }) = body.surface else {
        return None;
    };
    Some((pair, body, radius))
}

/// A contact candidate at the end of the run, from `contact_nodes.csv`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CandidateNode {
    /// Current position (reference plus displacement), m.
    pub position: [f64; 2],
    /// Reference x, m.
    pub reference_x: f64,
    /// Normal force, N.
    pub normal_force: f64,
    /// Tangential force along the contact's first tangent (2D: its only one), N.
    pub tangential_force: f64,
}

/// Reads the candidates of the pair `pair` from `contact_nodes.csv` text (2D); `path` is only
/// used in messages.
///
/// # Errors
/// [`ReportError::Parse`] naming the file, line and column at fault.
pub fn read_candidates(
    text: &str,
    path: &Path,
    pair: &str,
) -> Result<Vec<CandidateNode>, ReportError> {
    let table = CsvTable::new(text, path)?;
    let [name, x, y, ux, uy, force, tangential] = [
        "pair",
        "x",
        "y",
        "u_x",
        "u_y",
        "normal_force",
        "tangential_force_1",
    ]
    .map(|c| table.column(c));
    let (name, x, y, ux, uy, force, tangential) = (name?, x?, y?, ux?, uy?, force?, tangential?);
    let mut nodes = Vec::new();
    for row in table {
        let row = row?;
        if row.text(name)? != pair {
            continue;
        }
        let (x0, y0): (f64, f64) = (row.number(x)?, row.number(y)?);
        let (dx, dy): (f64, f64) = (row.number(ux)?, row.number(uy)?);
        nodes.push(CandidateNode {
            position: [x0 + dx, y0 + dy],
            reference_x: x0,
            normal_force: row.number(force)?,
            tangential_force: row.number(tangential)?,
        });
    }
    Ok(nodes)
}

/// What a run gives of the Hertz answer (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct HertzMeasure {
    /// Element size at the centre: reference distance from the node nearest x = 0 to the next
    /// one, m.
    pub centre_element: f64,
    /// Nodes carrying force.
    pub closed: usize,
    /// Pressure at the node nearest x = 0, Pa.
    pub peak_pressure: f64,
    /// Nominal pressure (reference tributary length) at the node nearest x = 0, Pa.
    pub nominal_peak_pressure: f64,
    /// Half the reference distance between the outermost nodes carrying force, m.
    pub half_width: f64,
    /// The larger of the two reference segments from an outermost node carrying force to the
    /// next, m.
    pub edge_element: f64,
    /// Sum of the normal forces over the thickness, N/m.
    pub resultant: f64,
    /// Every candidate's reference x and pressure, Pa, in order of x.
    pub profile: Vec<(f64, f64)>,
}

/// Measures the Hertz answer from `nodes` of a block of thickness `thickness`.
///
/// # Errors
/// Why it cannot be measured: fewer than three candidates, no contact, or contact that
/// reaches the outermost candidate on a side (the edge is then not seen).
pub fn measure(nodes: &[CandidateNode], thickness: f64) -> Result<HertzMeasure, String> {
    let mut nodes = nodes.to_vec();
    nodes.sort_by(|a, b| a.reference_x.total_cmp(&b.reference_x));
    let n = nodes.len();
    if n < 3 {
        return Err(format!("{n} contact candidates, expected at least 3"));
    }
    let reference = |i: usize, j: usize| (nodes[j].reference_x - nodes[i].reference_x).abs();
    // The nominal pressure of node i: over its reference tributary area.
    let nominal = |i: usize| {
        let left = if i > 0 { reference(i - 1, i) } else { 0.0 };
        let right = if i + 1 < n { reference(i, i + 1) } else { 0.0 };
        nodes[i].normal_force / (thickness * 0.5 * (left + right))
    };
    let tributary = tributary_lengths(&nodes);
    let profile: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let p = nodes[i].normal_force / (thickness * tributary[i]);
            (nodes[i].reference_x, p)
        })
        .collect();
    let closed: Vec<usize> = (0..n).filter(|&i| nodes[i].normal_force > 0.0).collect();
    let (Some(&first), Some(&last)) = (closed.first(), closed.last()) else {
        return Err("no node carries a contact force".into());
    };
    if first == 0 || last + 1 == n {
        return Err("the contact reaches the outermost candidate, so its edge is not seen".into());
    }
    let centre = (0..n)
        .min_by(|&i, &j| {
            nodes[i]
                .reference_x
                .abs()
                .total_cmp(&nodes[j].reference_x.abs())
        })
        .unwrap_or(0);
    let next = if centre + 1 < n {
        centre + 1
    } else {
        centre - 1
    };
    Ok(HertzMeasure {
        centre_element: reference(centre, next),
        closed: closed.len(),
        peak_pressure: profile[centre].1,
        nominal_peak_pressure: nominal(centre),
        half_width: 0.5 * reference(first, last),
        edge_element: reference(first - 1, first).max(reference(last, last + 1)),
        resultant: nodes.iter().map(|c| c.normal_force).sum::<f64>() / thickness,
        profile,
    })
}

/// The tributary length of each of `nodes` (sorted along x): half the deformed segments to its
/// two neighbours (one at either end), m.
pub fn tributary_lengths(nodes: &[CandidateNode]) -> Vec<f64> {
    let segment = |i: usize| {
        let (p, q) = (nodes[i].position, nodes[i + 1].position);
        (p[0] - q[0]).hypot(p[1] - q[1])
    };
    let n = nodes.len();
    (0..n)
        .map(|i| {
            let left = if i > 0 { segment(i - 1) } else { 0.0 };
            let right = if i + 1 < n { segment(i) } else { 0.0 };
            0.5 * (left + right)
        })
        .collect()
}

/// Root mean square of `(p_FE - p) / p0` over the nodes with `|x| <= a`.
pub fn profile_error(scene: &HertzScene, profile: &[(f64, f64)]) -> Option<f64> {
    let (a, p0) = (scene.half_width(), scene.peak_pressure());
    let inside: Vec<f64> = profile
        .iter()
        .filter(|(x, _)| x.abs() <= a)
        .map(|&(x, p)| (p - scene.pressure(x)) / p0)
        .collect();
    (!inside.is_empty())
        .then(|| (inside.iter().map(|e| e * e).sum::<f64>() / inside.len() as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> HertzScene {
        HertzScene {
            pair: "p".into(),
            radius: 0.05,
            load: 1000.0,
            thickness: 0.5,
            young: 10e6,
            poisson: 0.3,
        }
    }

    #[test]
    fn the_analytic_answer_balances_the_load() {
        let s = scene();
        let a = s.half_width();
        // p0 pi a / 2 = P, and a^2 = 4 P R / (pi E*).
        assert!((s.peak_pressure() * PI * a / 2.0 - s.load).abs() < 1e-9 * s.load);
        assert!((a * a * PI * s.plane_strain_modulus() / (4.0 * s.radius) - s.load).abs() < 1e-6);
        assert_eq!(s.pressure(a * 1.01), 0.0);
        assert!((s.pressure(0.0) - s.peak_pressure()).abs() < 1e-9);
    }

    /// Candidates every `h` from -3a to 3a carrying the Hertz pressure scaled by `scale` at
    /// their position times their tributary area, `scale p(x_i) t h`.
    fn hertz_nodes(s: &HertzScene, h: f64, scale: f64) -> Vec<CandidateNode> {
        let a = s.half_width();
        let n = (3.0 * a / h).round() as i64;
        (-n..=n)
            .map(|i| {
                let x = i as f64 * h;
                CandidateNode {
                    position: [x, 0.0],
                    reference_x: x,
                    normal_force: scale * s.pressure(x) * s.thickness * h,
                    tangential_force: 0.0,
                }
            })
            .collect()
    }

    #[test]
    fn a_hertz_distribution_measures_to_its_peak_and_width() {
        let s = scene();
        let a = s.half_width();
        let h = a / 7.5;
        let m = measure(&hertz_nodes(&s, h, 1.0), s.thickness).expect("measurable");
        assert!((m.peak_pressure - s.peak_pressure()).abs() < 1e-9 * s.peak_pressure());
        // Nodes at 7 h = 0.933 a carry force; the next one, at 8 h, is outside.
        assert!((m.half_width - 7.0 * h).abs() < 1e-12, "{}", m.half_width);
        assert!((m.edge_element - h).abs() < 1e-12);
        assert_eq!(m.closed, 15);
        assert!((m.centre_element - h).abs() < 1e-12);
        assert!(profile_error(&s, &m.profile).expect("inside") < 1e-12);
        let m = measure(&hertz_nodes(&s, h, 1.1), s.thickness).expect("measurable");
        assert!((m.peak_pressure / s.peak_pressure() - 1.1).abs() < 1e-9);
    }

    #[test]
    fn contact_without_a_visible_edge_is_not_measured() {
        let s = scene();
        let mut nodes = hertz_nodes(&s, s.half_width() / 4.0, 1.0);
        let last = nodes.len() - 1;
        nodes[last].normal_force = 1.0;
        let e = measure(&nodes, s.thickness).expect_err("edge not seen");
        assert!(e.contains("outermost candidate"), "{e}");
        for n in &mut nodes {
            n.normal_force = 0.0;
        }
        assert!(measure(&nodes, 1.0).is_err());
    }

    #[test]
    fn candidates_are_read_by_column_name() {
        let text = "pair,node,x,y,u_x,u_y,gap,normal_force,tangential_force_1\n\
                    p,3,0.001,0,1e-6,-2e-5,0,5.5,0\n\
                    q,4,0.002,0,0,0,1e-3,0,0\n";
        let nodes = read_candidates(text, Path::new("c.csv"), "p").expect("reads");
        assert_eq!(nodes.len(), 1);
        assert_eq!(nodes[0].position, [0.001 + 1e-6, -2e-5]);
        assert_eq!(nodes[0].normal_force, 5.5);
        assert_eq!(nodes[0].tangential_force, 0.0);
        let e = read_candidates("pair,x\np,1\n", Path::new("c.csv"), "p").expect_err("columns");
        assert!(e.to_string().contains("no column 'y'"), "{e}");
    }
}
