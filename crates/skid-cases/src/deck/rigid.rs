//! Rigid surfaces of a deck in the body frame of their rigid body (origin at the reference
//! node): analytical surfaces (`*SURFACE, TYPE=SEGMENTS | CYLINDER | REVOLUTION`) and the facets
//! of rigid elements, each mapped onto the model file's [`RigidSurfaceSpec`] that represents it
//! exactly, or refused with the reason.
//!
//! Orientation (skid's reading of the keyword reference): a 2D profile's outward normal is its
//! direction of travel turned 90 degrees counter-clockwise, `n = e_z x t` (in the local `x-y`
//! plane of `TYPE=CYLINDER`, `e_z` its generator; in the `r-z` plane of `TYPE=REVOLUTION`, `r`
//! playing `x`). A circle contacted from outside is therefore traversed clockwise, and the
//! cylinder of revolution `r = R` from high to low `z`. The positive side (`SPOS`) of an `R2D2`
//! line is `e_z x (x_2 - x_1)`, of a quadrilateral the right-hand normal of `1-2-3-4`.

use nalgebra::{Vector2, Vector3};
use skid_contact::RigidPolyline;
use skid_contact::surface::AnalyticCylinder;
use skid_contact::triangles::CylinderChart;
use std::f64::consts::TAU;

use super::fields::{allow_parameters, at_most, field, line_error, real, real_parameter};
use super::keywords::{Block, DeckError};
use crate::model_spec::{ChartSpec, RigidSurfaceSpec, profile_polyline};

mod fillet;

/// One piece of a profile, from the end of the previous one.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Piece {
    /// Straight line to `end`.
    Line { end: Vector2<f64> },
    /// Circular arc (under 180 degrees) to `end` about `centre`.
    Arc {
        end: Vector2<f64>,
        centre: Vector2<f64>,
    },
}

impl Piece {
    /// Where the piece ends.
    fn end(&self) -> Vector2<f64> {
        match self {
            Self::Line { end } | Self::Arc { end, .. } => *end,
        }
    }
}

/// Which analytical surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnalyticalKind {
    /// 2D profile in global `x-y`.
    Segments,
    /// 3D: a local `x-y` profile swept along the local `z` (the generator).
    Cylinder,
    /// 3D: an `r-z` profile revolved about the local `z` axis.
    Revolution,
}

/// An analytical rigid surface as the deck gives it.
#[derive(Clone, Debug)]
pub struct AnalyticalSurface {
    kind: AnalyticalKind,
    origin: Vector3<f64>,
    ex: Vector3<f64>,
    ey: Vector3<f64>,
    ez: Vector3<f64>,
    start: Vector2<f64>,
    pieces: Vec<Piece>,
}

/// Reads the data lines of an analytical `*SURFACE` (its `NAME` and `TYPE` parameters are the
/// caller's).
///
/// - `SEGMENTS`: `START, x, y`, then `LINE, x, y` or `CIRCL, x, y, xc, yc` lines.
/// - `CYLINDER`: `a (3), b (3)` (origin and a point on the local x axis), `c (3)` (a point on
///   the generator from `a`), then the profile in local `x-y`.
/// - `REVOLUTION`: `a (3), b (3)` (two points on the symmetry axis), then the profile in
///   `r-z`.
pub fn read_analytical(
    block: &Block,
    kind: AnalyticalKind,
) -> Result<AnalyticalSurface, DeckError> {
    allow_parameters(block, &["NAME", "TYPE", "FILLET RADIUS"])?;
    let fillet_radius = real_parameter(block, "FILLET RADIUS")?.unwrap_or(0.0);
    if !(fillet_radius.is_finite() && fillet_radius >= 0.0) {
        return Err(block.error(format!(
            "FILLET RADIUS must be finite and >= 0, got {fillet_radius}"
        )));
    }
    let mut lines = block.data.iter();
    let point = |line: &super::keywords::DataLine, first: usize, what: &str| {
        Ok::<_, DeckError>(Vector3::new(
            real(block, line, first, &format!("{what} x"))?,
            real(block, line, first + 1, &format!("{what} y"))?,
            real(block, line, first + 2, &format!("{what} z"))?,
        ))
    };
    let missing = |what: &str| block.error(format!("expected a data line with {what}"));
    let (origin, ex, ey, ez) = match kind {
        AnalyticalKind::Segments => (Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()),
        AnalyticalKind::Cylinder => {
            let l1 = lines.next().ok_or_else(|| missing("points a and b"))?;
            at_most(block, l1, 6)?;
            let a = point(l1, 0, "a")?;
            let b = point(l1, 3, "b")?;
            let l2 = lines.next().ok_or_else(|| missing("point c"))?;
            at_most(block, l2, 3)?;
            let c = point(l2, 0, "c")?;
            let ex = unit(b - a).ok_or_else(|| line_error(block, l1, "points a and b coincide"))?;
            let ez = unit(c - a).ok_or_else(|| line_error(block, l2, "points a and c coincide"))?;
            if ex.dot(&ez).abs() > 1e-9 {
                return Err(line_error(
                    block,
                    l2,
                    "the generator a-c must be perpendicular to the local x axis a-b",
                ));
            }
            (a, ex, ez.cross(&ex), ez)
        }
        AnalyticalKind::Revolution => {
            let l1 = lines.next().ok_or_else(|| missing("points a and b"))?;
            at_most(block, l1, 6)?;
            let a = point(l1, 0, "a")?;
            let b = point(l1, 3, "b")?;
            let ez = unit(b - a).ok_or_else(|| line_error(block, l1, "points a and b coincide"))?;
            (a, Vector3::zeros(), Vector3::zeros(), ez)
        }
    };
    let start_line = lines.next().ok_or_else(|| missing("START, x, y"))?;
    if !field(start_line, 0).is_some_and(|w| w.eq_ignore_ascii_case("START")) {
        return Err(line_error(block, start_line, "expected START, x, y"));
    }
    at_most(block, start_line, 3)?;
    let start = Vector2::new(
        real(block, start_line, 1, "start x")?,
        real(block, start_line, 2, "start y")?,
    );
    let mut pieces = Vec::new();
    // the data line of each point of the profile: its start, then each piece's end
    let mut point_lines = vec![start_line];
    for line in lines {
        point_lines.push(line);
        let word = field(line, 0).unwrap_or_default().to_ascii_uppercase();
        let end = || {
            Ok::<_, DeckError>(Vector2::new(
                real(block, line, 1, "end x")?,
                real(block, line, 2, "end y")?,
            ))
        };
        pieces.push(match word.as_str() {
            "LINE" => {
                at_most(block, line, 3)?;
                Piece::Line { end: end()? }
            }
            "CIRCL" => {
                at_most(block, line, 5)?;
                Piece::Arc {
                    end: end()?,
                    centre: Vector2::new(
                        real(block, line, 3, "centre x")?,
                        real(block, line, 4, "centre y")?,
                    ),
                }
            }
            "PARAB" => {
                return Err(line_error(block, line, "PARAB segments are not supported"));
            }
            other => {
                return Err(line_error(
                    block,
                    line,
                    format!("expected LINE or CIRCL, got '{other}'"),
                ));
            }
        });
    }
    if pieces.is_empty() {
        return Err(block.error("the profile needs at least one LINE or CIRCL after START"));
    }
    let (start, pieces) = if fillet_radius > 0.0 {
        let size = pieces
            .iter()
            .map(|p| p.end().norm())
            .fold(start.norm(), f64::max);
        let tol = 1e-9 * size;
        let closed = pieces
            .last()
            .is_some_and(|p| (p.end() - start).norm() <= tol);
        fillet::fillet(&start, &pieces, closed, fillet_radius, tol).map_err(|(k, why)| {
            line_error(
                block,
                point_lines[k],
                format!("the corner of the profile at this point: {why}"),
            )
        })?
    } else {
        (start, pieces)
    };
    Ok(AnalyticalSurface {
        kind,
        origin,
        ex,
        ey,
        ez,
        start,
        pieces,
    })
}

fn unit(v: Vector3<f64>) -> Option<Vector3<f64>> {
    let n = v.norm();
    (n > 0.0 && n.is_finite()).then(|| v / n)
}

impl AnalyticalSurface {
    /// The surface in the frame of a body whose reference node is at `reference`: a closed
    /// clockwise circle about it is a [`RigidSurfaceSpec::Cylinder`] about an axis through the
    /// reference node; a straight profile (lines in one direction) through it an unbounded
    /// [`RigidSurfaceSpec::Plane`]; a revolved `r = R` line a cylinder; any other profile of
    /// lines and arcs a polyline, an extrusion or a surface of revolution of it.
    pub fn spec(&self, reference: &Vector3<f64>) -> Result<RigidSurfaceSpec, String> {
        match self.kind {
            AnalyticalKind::Revolution => self.revolution(reference),
            AnalyticalKind::Segments | AnalyticalKind::Cylinder => self.profile(reference),
        }
    }

    /// Global position of local profile point `p` (`SEGMENTS`, `CYLINDER`).
    fn global(&self, p: &Vector2<f64>) -> Vector3<f64> {
        self.origin + self.ex * p.x + self.ey * p.y
    }

    fn profile(&self, reference: &Vector3<f64>) -> Result<RigidSurfaceSpec, String> {
        let size = self.size();
        let tol = 1e-9 * size.max(reference.norm());
        let lines: Vec<Vector2<f64>> = self
            .pieces
            .iter()
            .filter_map(|p| match p {
                Piece::Line { end } => Some(*end),
                Piece::Arc { .. } => None,
            })
            .collect();
        if lines.len() == self.pieces.len() {
            // straight profile: every piece in the direction of the first
            let mut from = self.start;
            let direction = (lines[0] - self.start)
                .try_normalize(0.0)
                .ok_or("the first LINE has zero length")?;
            for end in &lines {
                let d = end - from;
                if d.norm() <= tol {
                    return Err("a LINE of the profile has zero length".into());
                }
                if (d.normalize() - direction).norm() > 1e-9 {
                    return self.polyline(reference);
                }
                from = *end;
            }
            let t = self.ex * direction.x + self.ey * direction.y;
            let normal = self.ez.cross(&t);
            let distance = normal.dot(&(self.global(&self.start) - reference));
            if distance.abs() > tol {
                // not a plane through the reference node: the segment itself
                return self.polyline(reference);
            }
            return Ok(RigidSurfaceSpec::Plane {
                normal: normal.into(),
                tangent: t.into(),
            });
        }
        match self.centred_circle(reference, tol) {
            Some(radius) => Ok(RigidSurfaceSpec::Cylinder {
                radius,
                axis: self.ez.into(),
            }),
            None => self.polyline(reference),
        }
    }

    /// The radius of the profile if it is one full circle traversed clockwise (contacted
    /// from outside) about a centre on the axis through the reference node: arcs about one
    /// centre and radius, turning once and ending where they start.
    fn centred_circle(&self, reference: &Vector3<f64>, tol: f64) -> Option<f64> {
        let mut from = self.start;
        let mut turned = 0.0;
        let mut circle: Option<(Vector2<f64>, f64)> = None;
        for piece in &self.pieces {
            let Piece::Arc { end, centre } = piece else {
                return None;
            };
            let (r0, r1) = ((from - centre).norm(), (end - centre).norm());
            if (r0 - r1).abs() > tol {
                return None;
            }
            match circle {
                None => circle = Some((*centre, r0)),
                Some((c, r)) if (c - centre).norm() > tol || (r - r0).abs() > tol => return None,
                Some(_) => {}
            }
            let (a, b) = (from - centre, end - centre);
            turned += a.perp(&b).atan2(a.dot(&b));
            from = *end;
        }
        let (centre, radius) = circle?;
        let d = self.global(&centre) - reference;
        let offset = (d - self.ez * self.ez.dot(&d)).norm();
        let closes = (from - self.start).norm() <= tol && (turned + TAU).abs() <= 1e-9;
        (closes && offset <= tol).then_some(radius)
    }

    /// Any other profile, in the body frame: in 2D (`SEGMENTS`) a
    /// [`RigidSurfaceSpec::Polyline`], in 3D (`CYLINDER`) the [`RigidSurfaceSpec::Extrusion`]
    /// of the profile along the generator, closed if it ends where it starts and refused if it
    /// is then traversed inwards, its `CIRCL` pieces arcs about their centres.
    fn polyline(&self, reference: &Vector3<f64>) -> Result<RigidSurfaceSpec, String> {
        let (points, centres, closed, _) = self.profile_points(reference, |p| {
            let y = self.global(p) - reference;
            [self.ex.dot(&y), self.ey.dot(&y)]
        })?;
        Ok(match self.kind {
            AnalyticalKind::Cylinder => RigidSurfaceSpec::Extrusion {
                axis: self.ez.into(),
                reference: self.ex.into(),
                profile: points,
                centres,
                closed,
            },
            _ => RigidSurfaceSpec::Polyline {
                points,
                centres,
                closed,
            },
        })
    }

    /// The points of the profile (its start, then the ends of its pieces), closed if it ends
    /// where it starts (the last point dropped), and the centre of each piece that is an arc
    /// (none if all are lines), each placed by `place` and taken in reverse: the deck's outward
    /// normal is the travel turned counter-clockwise, a polyline's turned clockwise. A closed
    /// profile traversed inwards is refused ([`check_outward`]), as is one whose arcs do not
    /// fit their centres. Returns them with the profile they make.
    #[allow(clippy::type_complexity)] // the spec's three profile fields and their profile
    fn profile_points(
        &self,
        reference: &Vector3<f64>,
        place: impl Fn(&Vector2<f64>) -> [f64; 2],
    ) -> Result<(Vec<[f64; 2]>, Vec<Option<[f64; 2]>>, bool, RigidPolyline), String> {
        let tol = 1e-9 * self.size().max(reference.norm());
        let mut points: Vec<Vector2<f64>> = std::iter::once(self.start)
            .chain(self.pieces.iter().map(Piece::end))
            .collect();
        // the centre of piece k, from point k to k + 1
        let centres: Vec<Option<Vector2<f64>>> = self
            .pieces
            .iter()
            .map(|p| match p {
                Piece::Line { .. } => None,
                Piece::Arc { centre, .. } => Some(*centre),
            })
            .collect();
        let closed = (points[points.len() - 1] - points[0]).norm() <= tol;
        let m = centres.len();
        // reversed, piece i runs from the reversed point i to i + 1: the original piece
        // m - 1 - i of an open profile; of a closed one (its last point dropped) the original
        // m - 2 - i, and the closing piece last
        let reversed: Vec<Option<Vector2<f64>>> = if closed {
            points.pop();
            (0..m)
                .map(|i| {
                    if i + 1 < m {
                        centres[m - 2 - i]
                    } else {
                        centres[m - 1]
                    }
                })
                .collect()
        } else {
            centres.iter().rev().copied().collect()
        };
        let points: Vec<[f64; 2]> = points.iter().rev().map(&place).collect();
        let centres: Vec<Option<[f64; 2]>> = if reversed.iter().all(Option::is_none) {
            Vec::new()
        } else {
            reversed.iter().map(|c| c.as_ref().map(&place)).collect()
        };
        let profile = profile_polyline(&points, &centres, closed).map_err(|e| e.to_string())?;
        check_outward(&points, &centres, closed)?;
        Ok((points, centres, closed, profile))
    }

    /// A revolved profile of lines: at one radius `r = R`, running from high to low `z`, the
    /// [`RigidSurfaceSpec::Cylinder`]; any other the [`RigidSurfaceSpec::Revolution`] of its
    /// points (in reverse, as a polyline's), closed if it ends where it starts, refused if it is
    /// closed and faces inwards. The axis must pass through the reference node.
    fn revolution(&self, reference: &Vector3<f64>) -> Result<RigidSurfaceSpec, String> {
        let tol = 1e-9 * self.size().max(reference.norm());
        let d = self.origin - reference;
        let offset = (d - self.ez * self.ez.dot(&d)).norm();
        if offset > tol {
            return Err(format!(
                "the axis of revolution passes {offset:e} m from the reference node; skid's \
                 surfaces of revolution turn about their reference node"
            ));
        }
        let radius = self.start.x;
        let mut from = self.start;
        let cylinder = self.pieces.iter().all(|piece| {
            let Piece::Line { end } = piece else {
                return false;
            };
            let down = (end.x - radius).abs() <= tol && end.y < from.y - tol;
            from = *end;
            down
        });
        if cylinder {
            if radius <= 0.0 {
                return Err(format!("the revolved radius must be > 0, got {radius}"));
            }
            return Ok(RigidSurfaceSpec::Cylinder {
                radius,
                axis: self.ez.into(),
            });
        }
        let shift = self.ez.dot(&d);
        let (profile, centres, closed, meridian) =
            self.profile_points(reference, |p| [p.x, p.y + shift])?;
        let (low, _) = meridian.bounds();
        if low.x < 0.0 {
            return Err(format!(
                "a revolved profile lies at r >= 0, this one reaches r = {}",
                low.x
            ));
        }
        Ok(RigidSurfaceSpec::Revolution {
            axis: self.ez.into(),
            profile,
            centres,
            closed,
            radius: None,
        })
    }

    fn size(&self) -> f64 {
        self.pieces
            .iter()
            .map(|p| p.end().norm())
            .fold(self.start.norm() + self.origin.norm(), f64::max)
    }
}

/// The rigid surface of facets given outward in skid's convention, in the body frame (2D:
/// segments whose direction turned clockwise points out; 3D: quadrilaterals counter-clockwise
/// seen from outside), if they form a regular prism about an axis through the origin: `n`
/// facets inscribed in one circle, each spanning the same axial range (2D: a regular polygon),
/// which is the model file's [`RigidSurfaceSpec::FacetedCylinder`]. Returns it with the axial
/// range (3D) of the facets, or why they form none (the caller then reads them as a
/// [`chain`] of lines or a mesh of [`triangles`]).
pub fn prism(
    facets: &[Vec<Vector3<f64>>],
    dimension: usize,
) -> Result<(RigidSurfaceSpec, Option<[f64; 2]>), String> {
    let n = facets.len();
    if n < 3 {
        return Err(format!(
            "a faceted rigid surface needs at least 3 facets, got {n}"
        ));
    }
    let size = facets
        .iter()
        .flatten()
        .map(|p| p.norm())
        .fold(0.0, f64::max);
    let tol = 1e-9 * size;
    let (axis, range) = if dimension == 2 {
        (Vector3::z(), None)
    } else {
        let normal = |f: &Vec<Vector3<f64>>| (f[2] - f[0]).cross(&(f[3] - f[1]));
        let n0 = normal(&facets[0]);
        let axis = facets
            .iter()
            .map(|f| n0.cross(&normal(f)))
            .max_by(|a, b| a.norm().total_cmp(&b.norm()))
            .and_then(unit)
            .ok_or("the facets are all parallel: they do not form a prism")?;
        // the axis's largest component positive
        let i = axis.iamax();
        let axis = if axis[i] < 0.0 { -axis } else { axis };
        let heights: Vec<f64> = facets.iter().flatten().map(|p| p.dot(&axis)).collect();
        let low = heights.iter().copied().fold(f64::INFINITY, f64::min);
        let high = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if heights
            .iter()
            .any(|h| (h - low).abs() > tol && (h - high).abs() > tol)
        {
            return Err("the facets do not all span one axial range: not a single prism".into());
        }
        (axis, Some([low, high]))
    };
    // in-plane segments, oriented counter-clockwise about the axis
    let radius = facets
        .iter()
        .flatten()
        .map(|p| (p - axis * axis.dot(p)).norm())
        .fold(0.0, f64::max);
    let frame = AnalyticCylinder::new(radius, axis).map_err(|e| e.to_string())?;
    let b1 = frame.reference_direction();
    let b2 = axis.cross(&b1);
    let angle = |p: &Vector3<f64>| b2.dot(p).atan2(b1.dot(p)).rem_euclid(TAU);
    let step = TAU / n as f64;
    let mut starts = Vec::with_capacity(n);
    for (k, f) in facets.iter().enumerate() {
        let plane: Vec<Vector3<f64>> = f.iter().map(|p| p - axis * axis.dot(p)).collect();
        for p in &plane {
            if ((p.norm() - radius).abs()) > tol {
                return Err(format!(
                    "facet {k} has a corner at {} m from the axis, not on the circle of radius \
                     {radius} through the others",
                    p.norm()
                ));
            }
        }
        // the two distinct in-plane corners, in the facet's own order
        let a = plane[0];
        let b = plane
            .iter()
            .copied()
            .find(|p| (p - a).norm() > tol)
            .ok_or(format!("facet {k} is degenerate"))?;
        if plane
            .iter()
            .any(|p| (p - a).norm() > tol && (p - b).norm() > tol)
        {
            return Err(format!("facet {k} is not parallel to the prism's axis"));
        }
        // outward normal of the facet
        let outward = if dimension == 2 {
            let t = f[1] - f[0];
            Vector3::new(t.y, -t.x, 0.0)
        } else {
            (f[2] - f[0]).cross(&(f[3] - f[1]))
        };
        if outward.dot(&(a + b)) <= 0.0 {
            return Err(format!(
                "facet {k}'s normal points towards the axis: skid's faceted rigid surfaces are \
                 contacted from outside (use the other side, SPOS or SNEG)"
            ));
        }
        let (first, second) = if axis.dot(&a.cross(&b)) > 0.0 {
            (a, b)
        } else {
            (b, a)
        };
        let sweep = (angle(&second) - angle(&first)).rem_euclid(TAU);
        if (sweep - step).abs() > 1e-9 {
            return Err(format!(
                "facet {k} spans {sweep:.9} rad; a regular prism of {n} facets spans {step:.9}"
            ));
        }
        starts.push(angle(&first));
    }
    starts.sort_by(f64::total_cmp);
    for (k, pair) in starts.windows(2).enumerate() {
        if (pair[1] - pair[0] - step).abs() > 1e-9 {
            return Err(format!(
                "the facets do not close into one regular polygon (gap after the {k}-th vertex)"
            ));
        }
    }
    let phase = aligned_phase(starts[0].rem_euclid(step), n);
    let radius = shortest_decimal(radius);
    Ok((
        RigidSurfaceSpec::FacetedCylinder {
            radius,
            axis: axis.into(),
            facets: n,
            phase,
        },
        range,
    ))
}

/// The decimal with the fewest significant digits within `1e-15 |v|` of `v` (a deck's
/// coordinates are roundings of decimal dimensions: a radius recomputed from them is the
/// dimension up to a few ulps, which this removes).
fn shortest_decimal(v: f64) -> f64 {
    (1..=17)
        .filter_map(|digits| format!("{v:.*e}", digits - 1).parse::<f64>().ok())
        .find(|d| (d - v).abs() <= 1e-15 * v.abs())
        .unwrap_or(v)
}

/// A polygon's first-vertex angle, snapped to the nearest multiple `m pi / (2 n)` (vertex or
/// facet midpoint on a quarter-facet grid, e.g. the benchmark's `pi / n`) when within
/// `1e-14` rad: the angle recomputed from rounded vertices is that multiple up to an ulp, and a
/// faceted drum's spin-down moves by 1e-4 of its stop time for a 1-ulp change of angle or
/// radius.
fn aligned_phase(phase: f64, n: usize) -> f64 {
    let grid = std::f64::consts::PI / (2 * n) as f64;
    let m = (phase / grid).round();
    let snapped = m * std::f64::consts::PI / (2 * n) as f64;
    if (snapped - phase).abs() <= 1e-14 {
        snapped
    } else {
        phase
    }
}

/// The rigid surface of triangles given outward (counter-clockwise seen from outside), in the
/// body frame, with its chart: a flat mesh (every triangle's normal within 1e-9 of their
/// area-weighted mean `n`) the plane chart of `n`, whose first direction is the coordinate axis
/// least along `n` made perpendicular to it, so that its coordinates are lengths on the mesh;
/// a drum, a curved mesh on a body with one free rotation `axis` (through the origin) whose
/// faces lie on cylinders about it or across it (its ends, see
/// [`CylinderChart::first_triangle_off`]), the cylinder about the axis whose radius reaches the
/// farthest vertex (its slip is counted in that cylinder's arc length); any other curved mesh
/// the plane chart of its mean
/// normal (`z` where that vanishes, on a closed mesh), whose coordinates label its points while
/// its slip is measured in lengths in the tangent plane.
pub fn triangles(
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    axis: Option<Vector3<f64>>,
) -> Result<RigidSurfaceSpec, String> {
    let corners = |t: &[usize; 3]| t.map(|i| Vector3::from(vertices[i]));
    let areas: Vec<Vector3<f64>> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = corners(t);
            (b - a).cross(&(c - a))
        })
        .collect();
    let mean = areas.iter().sum::<Vector3<f64>>();
    let flat = unit(mean).filter(|n| {
        areas
            .iter()
            .all(|a| unit(*a).is_some_and(|m| (m - n).norm() <= 1e-9))
    });
    let drum = axis.and_then(|axis| {
        let radius = vertices
            .iter()
            .map(|v| {
                let v = Vector3::from(*v);
                (v - axis * axis.dot(&v)).norm()
            })
            .fold(0.0, f64::max);
        let cylinder = CylinderChart {
            radius: shortest_decimal(radius),
            axis,
        };
        let points: Vec<Vector3<f64>> = vertices.iter().map(|v| Vector3::from(*v)).collect();
        cylinder
            .first_triangle_off(&points, &triangles)
            .is_none()
            .then_some(cylinder)
    });
    let chart = match (flat, drum) {
        (Some(normal), _) => plane_chart(normal)?,
        (None, Some(drum)) => ChartSpec::Cylinder {
            radius: drum.radius,
            axis: drum.axis.into(),
        },
        (None, None) => {
            let total: f64 = areas.iter().map(|a| a.norm()).sum();
            let normal = unit(mean)
                .filter(|_| mean.norm() > 1e-6 * total)
                .unwrap_or_else(Vector3::z);
            plane_chart(normal)?
        }
    };
    Ok(RigidSurfaceSpec::Triangles {
        vertices,
        triangles,
        chart,
    })
}

/// The plane chart of unit `normal` whose first direction is the coordinate axis least along it,
/// made perpendicular to it.
fn plane_chart(normal: Vector3<f64>) -> Result<ChartSpec, String> {
    let least = normal.iamin();
    let tangent = unit(Vector3::ith(least, 1.0) - normal * normal[least])
        .ok_or("the mesh's normal has no perpendicular")?;
    Ok(ChartSpec::Plane {
        normal: normal.into(),
        tangent: tangent.into(),
    })
}

/// The rigid surface of segments given outward in skid's convention (each segment's direction
/// turned clockwise points out), in the body frame, that [`prism`] does not take for a regular
/// polygon: one chain of segments, each starting where the one before ends, as a
/// [`RigidSurfaceSpec::Polyline`] (closed if the chain returns to its first point; a closed
/// chain must face outwards, as a deck's closed rigid surfaces are contacted from outside).
pub fn chain(segments: &[[Vector3<f64>; 2]]) -> Result<RigidSurfaceSpec, String> {
    let key = |p: &Vector3<f64>| [p.x.to_bits(), p.y.to_bits()];
    let mut leaving: std::collections::HashMap<[u64; 2], usize> = Default::default();
    for (k, [a, _]) in segments.iter().enumerate() {
        if leaving.insert(key(a), k).is_some() {
            return Err(format!(
                "two rigid lines start at ({}, {}) in the body frame: the lines of a surface \
                 form one chain, each line's second node the next line's first (reverse the \
                 lines that run against it, or use the other side, SPOS or SNEG)",
                a.x, a.y
            ));
        }
    }
    let ends: std::collections::HashSet<[u64; 2]> = segments.iter().map(|[_, b]| key(b)).collect();
    let first = (0..segments.len())
        .find(|&k| !ends.contains(&key(&segments[k][0])))
        .unwrap_or(0);
    let mut points = vec![segments[first][0]];
    let mut visited = vec![false; segments.len()];
    let mut k = first;
    let closed = loop {
        visited[k] = true;
        let end = segments[k][1];
        match leaving.get(&key(&end)) {
            Some(&next) if next == first => break true,
            Some(&next) if visited[next] => {
                return Err(format!(
                    "the rigid lines meet at ({}, {}) in the body frame from two sides: a \
                     surface of lines is one chain without branches",
                    end.x, end.y
                ));
            }
            Some(&next) => {
                points.push(end);
                k = next;
            }
            None => {
                points.push(end);
                break false;
            }
        }
    };
    let walked = visited.iter().filter(|v| **v).count();
    if walked != segments.len() {
        return Err(format!(
            "the rigid lines form more than one chain ({walked} of {} lines joined from the \
             first): a surface of lines is one chain, each line's second node the next line's \
             first",
            segments.len()
        ));
    }
    outward_polyline(points.iter().map(|p| [p.x, p.y]).collect(), closed)
}

/// The polyline through `points` (body frame), refused if it is closed and faces inwards
/// (see [`check_outward`]).
fn outward_polyline(points: Vec<[f64; 2]>, closed: bool) -> Result<RigidSurfaceSpec, String> {
    check_outward(&points, &[], closed)?;
    Ok(RigidSurfaceSpec::Polyline {
        points,
        centres: Vec::new(),
        closed,
    })
}

/// Refuses a closed chain of `points` (piece `k` an arc about `centres[k]` where given) that
/// faces inwards (clockwise, negative area, with the outside on the right of the travel): a
/// deck's closed rigid surfaces are contacted from outside. The area is the polygon's
/// `sum (a_x b_y - b_x a_y) / 2` plus, for each arc of radius `R` turning by the signed angle
/// `theta`, the circular segment `R^2 (theta - sin theta) / 2` between it and its chord.
fn check_outward(
    points: &[[f64; 2]],
    centres: &[Option<[f64; 2]>],
    closed: bool,
) -> Result<(), String> {
    let area: f64 = (0..points.len())
        .map(|k| {
            let (a, b) = (points[k], points[(k + 1) % points.len()]);
            let chord = (a[0] * b[1] - b[0] * a[1]) / 2.0;
            let segment = centres.get(k).copied().flatten().map_or(0.0, |c| {
                let (u, v) = (
                    Vector2::new(a[0] - c[0], a[1] - c[1]),
                    Vector2::new(b[0] - c[0], b[1] - c[1]),
                );
                let theta = u.perp(&v).atan2(u.dot(&v));
                u.norm_squared() * (theta - theta.sin()) / 2.0
            });
            chord + segment
        })
        .sum();
    if closed && area < 0.0 {
        return Err(
            "the closed chain of rigid lines faces inwards: skid's closed rigid surfaces are \
             contacted from outside (traverse it the other way, or use the other side, SPOS or \
             SNEG)"
                .into(),
        );
    }
    Ok(())
}
