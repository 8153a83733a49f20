//! Rigid polyline in the plane (2D): a chain of straight segments and circular arcs, open or
//! closed, such as a floor, a ramp, a punch profile meshed with rigid line elements or the
//! `LINE` and `CIRCL` profile of an analytical surface.

use std::f64::consts::PI;

use nalgebra::{Matrix2, Matrix2x3, Matrix3, Vector2, Vector3};
use rstar::{AABB, RTree, RTreeObject};

use crate::error::ContactError;
use crate::search::nearest_chain;
use crate::surface::{Projection, RigidSurface, SurfaceShape};

/// The circle an arc piece follows.
#[derive(Clone, Copy, Debug)]
struct Bend {
    centre: Vector2<f64>,
    radius: f64,
    /// Signed angle from the start to the end about the centre (counter-clockwise positive),
    /// `0 < |sweep| < pi`.
    sweep: f64,
    /// Unit direction from the centre to the start.
    from: Vector2<f64>,
}

impl Bend {
    /// `+1` for a counter-clockwise arc (contacted from outside its circle), `-1` otherwise.
    fn turn(&self) -> f64 {
        self.sweep.signum()
    }
}

/// One piece `P_k -> P_{k+1}` in the plane: a straight segment, or an arc if `bend`.
#[derive(Clone, Debug)]
struct Segment {
    start: Vector2<f64>,
    end: Vector2<f64>,
    /// Unit tangent `t_k = (P_{k+1} - P_k) / L_k` of a straight segment.
    tangent: Vector2<f64>,
    /// Outward unit normal `n_k` of a straight segment: the tangent turned clockwise,
    /// `(t_y, -t_x)`.
    normal: Vector2<f64>,
    /// Length `L_k` (`R |sweep|` for an arc).
    length: f64,
    /// Arc length `s_k` of `P_k` from the first vertex.
    arc: f64,
    bend: Option<Bend>,
}

impl Segment {
    /// The outward unit normal at the start (`at_end`: at the end).
    fn normal_at(&self, at_end: bool) -> Vector2<f64> {
        match &self.bend {
            None => self.normal,
            Some(b) => {
                let point = if at_end { self.end } else { self.start };
                (point - b.centre) / b.radius * b.turn()
            }
        }
    }

    /// Where the piece's closest point to `q` lies, the point and its distance: within `tiny`
    /// (a length along the piece) of an end, that end, unless the end is `smooth` (the next
    /// piece goes on with the same normal there): then only beyond `tiny` past it, so that a
    /// point on the common normal of two smoothly joined pieces takes their curvature, not a
    /// vertex's.
    fn closest(
        &self,
        q: &Vector2<f64>,
        tiny: f64,
        smooth: [bool; 2],
    ) -> (Place, Vector2<f64>, f64) {
        let end = |place: Place, point: Vector2<f64>| (place, point, (q - point).norm());
        let low = if smooth[0] { -tiny } else { tiny };
        let high = self.length - if smooth[1] { -tiny } else { tiny };
        let Some(bend) = &self.bend else {
            let u = (q - self.start).dot(&self.tangent);
            return if u <= low {
                end(Place::Start, self.start)
            } else if u >= high {
                end(Place::End, self.end)
            } else {
                end(Place::Interior(u), self.start + self.tangent * u)
            };
        };
        let d = q - bend.centre;
        let rho = d.norm();
        // the angle from the start about the centre, in the direction of travel
        let angle = bend.from.perp(&d).atan2(bend.from.dot(&d)) * bend.turn();
        let u = angle * bend.radius;
        if rho > tiny && u > low && u < high {
            return (
                Place::Interior(u),
                bend.centre + d * (bend.radius / rho),
                (rho - bend.radius).abs(),
            );
        }
        let (first, last) = (end(Place::Start, self.start), end(Place::End, self.end));
        if first.2 <= last.2 { first } else { last }
    }

    /// The axis-aligned box holding the piece.
    fn bounds(&self) -> (Vector2<f64>, Vector2<f64>) {
        let (mut low, mut high) = (self.start.inf(&self.end), self.start.sup(&self.end));
        if let Some(bend) = &self.bend {
            // the circle's extreme points the arc passes
            for k in 0..4 {
                let direction = Vector2::new([1.0, 0.0, -1.0, 0.0][k], [0.0, 1.0, 0.0, -1.0][k]);
                let angle =
                    bend.from.perp(&direction).atan2(bend.from.dot(&direction)) * bend.turn();
                if angle > 0.0 && angle < bend.sweep.abs() {
                    let point = bend.centre + direction * bend.radius;
                    low = low.inf(&point);
                    high = high.sup(&point);
                }
            }
        }
        (low, high)
    }
}

/// Where on one piece, taken by itself, a point's closest point lies.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Place {
    Start,
    End,
    /// The interior, at arc length `u` from the piece's start.
    Interior(f64),
}

/// Where on a piece a point's closest point lies.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Feature {
    /// The interior, at arc length `u` from the piece's start.
    Interior(f64),
    /// Vertex `j` of the polyline.
    Vertex(usize),
}

/// A piece's closest point to a point, with its distance.
#[derive(Clone, Copy, Debug)]
struct Closest {
    segment: usize,
    feature: Feature,
    point: Vector2<f64>,
    distance: f64,
}

/// A piece in the search tree.
#[derive(Clone, Debug)]
struct Located {
    index: usize,
    segment: Segment,
}

impl RTreeObject for Located {
    type Envelope = AABB<[f64; 2]>;

    fn envelope(&self) -> Self::Envelope {
        let (low, high) = self.segment.bounds();
        AABB::from_corners([low.x, low.y], [high.x, high.y])
    }
}

/// A polyline of vertices `P_0 .. P_m` in the body frame's plane `z = 0` (a closed one also has
/// the piece `P_m -> P_0`), each piece a straight segment or a circular arc under 180 degrees
/// about a given centre, contacted on the side of its outward normals: each piece's direction
/// turned clockwise (the right-hand side walking along it; for a closed polyline
/// counter-clockwise about its inside, the outside; a counter-clockwise arc is contacted from
/// outside its circle, a clockwise one from inside).
///
/// With `q` the in-plane point and `p` its closest point on the polyline (exact, over all
/// pieces):
/// * on the interior of segment `k` (`p = P_k + u t_k`, `0 < u < L_k`): `g = n_k.(q - P_k)`,
///   `dg/dy = n_k`, `xi_0 = s_k + u` (arc length), `d xi_0/dy = t_k`; second derivatives vanish;
/// * on the interior of arc `k` (centre `c`, radius `R`, `d = q - c`, `rho = |d|`,
///   `e_r = d/rho`, `e_phi = e_z x e_r`, `sigma = +1` counter-clockwise, `-1` clockwise):
///   `g = sigma (rho - R)`, `dg/dy = sigma e_r`, `d^2g/dy^2 = sigma (I - e_z e_z^T - e_r e_r^T)/rho`;
///   `xi_0 = s_k + sigma R (phi - phi_k)` with `phi` the angle of `d`,
///   `d xi_0/dy = sigma R e_phi/rho` and `d^2 xi_0/dy^2 = sigma R d^2 phi/dy^2`,
///   `d^2 phi/dy^2 = [[2 d_x d_y, d_y^2 - d_x^2], [d_y^2 - d_x^2, -2 d_x d_y]]/rho^4`;
/// * at vertex `P_j`: with `N_j` the sum of the outward normals of the pieces meeting there
///   (the pseudo-normal) and `s = sign((q - P_j).N_j)` (`+` on ties), `g = s |q - P_j|`,
///   `dg/dy = s (q - P_j)/|q - P_j|` (`N_j/|N_j|` when `|q - P_j| ~ 0`),
///   `d^2g/dy^2 = s (I - e_z e_z^T - dg/dy dg/dy^T)/|q - P_j|` (zero when `|q - P_j| ~ 0`),
///   `xi_0 = s_j`, `d xi_0/dy = 0`. An open polyline's end vertex is the surface's edge: a point
///   whose closest point it is lies beyond the surface, off it whichever side of the end piece's
///   line it stands, so there `s = +1` (a node sliding past the end leaves the surface instead of
///   being caught on it), unless the surface goes on beyond that end (see
///   [`RigidPolyline::continued_at`]).
///
/// Always `xi_1 = y_z`, `d xi_1/dy = e_z`; a closed polyline's `xi_0` has the period of its
/// length. The gap is the signed distance, C1 across the pieces' ends on the outside. Equally
/// distant features (to round-off) resolve to a piece's interior before a vertex, then to the
/// lowest piece. Pieces are found through an R*-tree of their bounding boxes, so that a
/// projection visits the few pieces near the point rather than all.
#[derive(Clone, Debug)]
pub struct RigidPolyline {
    vertices: Vec<Vector2<f64>>,
    closed: bool,
    segments: Vec<Segment>,
    /// Pseudo-normal `N_j` of each vertex.
    vertex_normals: Vec<Vector2<f64>>,
    /// Whether the two pieces at each vertex meet with one normal (to 1e-9).
    smooth: Vec<bool>,
    tree: RTree<Located>,
    /// Total length (the period of a closed polyline's arc length).
    length: f64,
    /// Largest vertex norm, the length scale of round-off tolerances.
    scale: f64,
    /// Whether the first and the last vertex are edges of the surface (an open polyline's
    /// ends, unless continued).
    edges: [bool; 2],
}

impl RigidPolyline {
    /// The polyline of straight segments through `vertices` (at least 2; at least 3 if
    /// `closed`).
    ///
    /// # Errors
    /// As [`RigidPolyline::with_arcs`].
    pub fn new(vertices: Vec<Vector2<f64>>, closed: bool) -> Result<Self, ContactError> {
        Self::with_arcs(vertices, Vec::new(), closed)
    }

    /// The polyline through `vertices` whose piece `k` (from vertex `k` to the next) is the
    /// arc about `centres[k]` where that is given, and straight otherwise (`centres` empty:
    /// all straight).
    ///
    /// # Errors
    /// [`ContactError::InvalidSurface`] for too few or non-finite vertices, centres given for
    /// another number of pieces, a piece shorter than `1e-12` of the largest vertex distance
    /// from the origin, an arc whose ends lie at different distances from its centre (by more
    /// than `1e-9` of the radius), or an arc of 180 degrees or more.
    pub fn with_arcs(
        vertices: Vec<Vector2<f64>>,
        centres: Vec<Option<Vector2<f64>>>,
        closed: bool,
    ) -> Result<Self, ContactError> {
        let invalid = |message: String| Err(ContactError::InvalidSurface(message));
        let least = if closed { 3 } else { 2 };
        if vertices.len() < least {
            return invalid(format!(
                "a{} polyline needs at least {least} vertices, got {}",
                if closed { " closed" } else { "n open" },
                vertices.len()
            ));
        }
        if let Some(v) = vertices
            .iter()
            .chain(centres.iter().flatten())
            .find(|v| !v.iter().all(|c| c.is_finite()))
        {
            return invalid(format!("non-finite polyline vertex or centre {v:?}"));
        }
        let scale = vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let count = if closed {
            vertices.len()
        } else {
            vertices.len() - 1
        };
        if !centres.is_empty() && centres.len() != count {
            return invalid(format!(
                "{} arc centres given for {count} pieces",
                centres.len()
            ));
        }
        let mut segments = Vec::with_capacity(count);
        let mut arc = 0.0;
        for k in 0..count {
            let (a, b) = (vertices[k], vertices[(k + 1) % vertices.len()]);
            let chord = (b - a).norm();
            if chord <= 1e-12 * scale.max(f64::MIN_POSITIVE) {
                return invalid(format!(
                    "polyline piece {k} from {a:?} to {b:?} has no length"
                ));
            }
            let tangent = (b - a) / chord;
            let bend = match centres.get(k).copied().flatten() {
                None => None,
                Some(centre) => {
                    let (r0, r1) = ((a - centre).norm(), (b - centre).norm());
                    if (r0 - r1).abs() > 1e-9 * r0.max(r1) {
                        return invalid(format!(
                            "arc {k} from {a:?} to {b:?} about {centre:?}: its ends lie at \
                             {r0} and {r1} from the centre"
                        ));
                    }
                    let (from, to) = ((a - centre) / r0, (b - centre) / r1);
                    let sweep = from.perp(&to).atan2(from.dot(&to));
                    if sweep.abs() >= PI * (1.0 - 1e-12) {
                        return invalid(format!(
                            "arc {k} from {a:?} to {b:?} about {centre:?} turns 180 degrees or \
                             more: its direction is ambiguous, split it"
                        ));
                    }
                    Some(Bend {
                        centre,
                        radius: r0,
                        sweep,
                        from,
                    })
                }
            };
            let length = bend.map_or(chord, |b| b.radius * b.sweep.abs());
            segments.push(Segment {
                start: a,
                end: b,
                tangent,
                normal: Vector2::new(tangent.y, -tangent.x),
                length,
                arc,
                bend,
            });
            arc += length;
        }
        let mut vertex_normals = vec![Vector2::zeros(); vertices.len()];
        for (k, segment) in segments.iter().enumerate() {
            vertex_normals[k] += segment.normal_at(false);
            vertex_normals[(k + 1) % vertices.len()] += segment.normal_at(true);
        }
        let smooth = (0..vertices.len())
            .map(|j| {
                let before = if j > 0 { j - 1 } else { count.wrapping_sub(1) };
                match (
                    segments.get(before).filter(|_| j > 0 || closed),
                    segments.get(j),
                ) {
                    (Some(a), Some(b)) => (a.normal_at(true) - b.normal_at(false)).norm() <= 1e-9,
                    _ => false,
                }
            })
            .collect();
        let tree = RTree::bulk_load(
            segments
                .iter()
                .enumerate()
                .map(|(index, segment)| Located {
                    index,
                    segment: segment.clone(),
                })
                .collect(),
        );
        Ok(Self {
            vertices,
            closed,
            segments,
            vertex_normals,
            smooth,
            tree,
            length: arc,
            scale,
            edges: [!closed; 2],
        })
    }

    /// The polyline with its first (`end` 0) or last (`end` 1) vertex no edge: the surface it
    /// stands for goes on beyond that end (as a profile of revolution does where it meets the
    /// axis), so a point there is signed by the end's pseudo-normal like any vertex's.
    pub(crate) fn continued_at(mut self, end: usize) -> Self {
        if let Some(edge) = self.edges.get_mut(end) {
            *edge = false;
        }
        self
    }

    /// The first and the last vertex.
    pub(crate) fn ends(&self) -> [Vector2<f64>; 2] {
        let last = self.vertices.len() - 1;
        [self.vertices[0], self.vertices[last]]
    }

    /// Whether vertex `j` is an edge of the surface (see [`RigidPolyline::continued_at`]).
    fn is_edge(&self, j: usize) -> bool {
        (j == 0 && self.edges[0]) || (j + 1 == self.vertices.len() && self.edges[1])
    }

    /// The axis-aligned box `(low, high)` holding every piece.
    pub fn bounds(&self) -> (Vector2<f64>, Vector2<f64>) {
        self.segments.iter().map(Segment::bounds).fold(
            (
                Vector2::repeat(f64::INFINITY),
                Vector2::repeat(f64::NEG_INFINITY),
            ),
            |(low, high), (l, h)| (low.inf(&l), high.sup(&h)),
        )
    }

    /// Whether the last vertex joins the first.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Points along the polyline for drawing it: the vertices, with arcs drawn through points
    /// at most 5 degrees apart (a closed polyline's first point not repeated).
    pub fn drawn_points(&self) -> Vec<Vector2<f64>> {
        let mut points = Vec::new();
        for segment in &self.segments {
            points.push(segment.start);
            if let Some(bend) = &segment.bend {
                let steps = (bend.sweep.abs() / 5f64.to_radians()).ceil() as usize;
                for i in 1..steps {
                    let angle = bend.sweep * i as f64 / steps as f64;
                    let (sin, cos) = angle.sin_cos();
                    let direction = Vector2::new(
                        bend.from.x * cos - bend.from.y * sin,
                        bend.from.x * sin + bend.from.y * cos,
                    );
                    points.push(bend.centre + direction * bend.radius);
                }
            }
        }
        if !self.closed {
            points.push(self.vertices[self.vertices.len() - 1]);
        }
        points
    }

    /// Index of the vertex at the end of segment `k`.
    fn end_vertex(&self, k: usize) -> usize {
        (k + 1) % self.vertices.len()
    }

    /// The closest point of piece `k` to `q`; within `tiny` of an end, that end's vertex.
    fn closest_on(&self, k: usize, q: &Vector2<f64>, tiny: f64) -> Closest {
        let smooth = [self.smooth[k], self.smooth[self.end_vertex(k)]];
        let (place, point, distance) = self.segments[k].closest(q, tiny, smooth);
        let feature = match place {
            Place::Start => Feature::Vertex(k),
            Place::End => Feature::Vertex(self.end_vertex(k)),
            Place::Interior(u) => Feature::Interior(u),
        };
        Closest {
            segment: k,
            feature,
            point,
            distance,
        }
    }

    /// The closest feature over all segments, as a scan in segment order finds it: a later
    /// segment replaces the best so far if nearer by more than `tolerance`, or no more than
    /// `tolerance` farther with its interior against a vertex. Only the segments in the chain of
    /// ties from the nearest are scanned ([`crate::search::nearest_chain`]; one left out could
    /// never replace a candidate).
    fn nearest(&self, q: &Vector2<f64>, tolerance: f64) -> Option<Closest> {
        let mut candidates = nearest_chain(&self.tree, [q.x, q.y], tolerance, |located| {
            let closest = self.closest_on(located.index, q, tolerance);
            (closest, closest.distance)
        });
        candidates.sort_unstable_by_key(|c| c.segment);
        let interior = |c: &Closest| matches!(c.feature, Feature::Interior(_));
        candidates.into_iter().reduce(|best, c| {
            let replaces = c.distance < best.distance - tolerance
                || (c.distance <= best.distance + tolerance && interior(&c) && !interior(&best));
            if replaces { c } else { best }
        })
    }
}

impl RigidPolyline {
    /// The point at arc length `s` from the first vertex and the unit tangent there, towards
    /// growing arc length (at a vertex, the tangent of the piece that starts there): `s` clamped
    /// to the ends of an open polyline, taken modulo the length of a closed one; `None` for a
    /// non-finite `s`. On a straight piece from `P_k` (arc length `s_k`) the point is
    /// `P_k + (s - s_k) t_k`; on an arc it is the start turned about the centre by
    /// `sweep (s - s_k) / L_k`.
    pub(crate) fn point_at(&self, s: f64) -> Option<(Vector2<f64>, Vector2<f64>)> {
        if !s.is_finite() {
            return None;
        }
        let s = if self.closed {
            s.rem_euclid(self.length)
        } else {
            s.clamp(0.0, self.length)
        };
        let k = self
            .segments
            .partition_point(|segment| segment.arc <= s)
            .saturating_sub(1);
        let segment = &self.segments[k];
        let along = (s - segment.arc).clamp(0.0, segment.length);
        Some(match &segment.bend {
            None => (segment.start + segment.tangent * along, segment.tangent),
            Some(bend) => {
                let (sin, cos) = (bend.sweep * along / segment.length).sin_cos();
                let direction = Vector2::new(
                    bend.from.x * cos - bend.from.y * sin,
                    bend.from.x * sin + bend.from.y * cos,
                );
                let tangent = Vector2::new(-direction.y, direction.x) * bend.turn();
                (bend.centre + direction * bend.radius, tangent)
            }
        })
    }

    /// The straight segment whose interior holds the closest point to `q`, with its outward
    /// normal; `None` where the closest point is a vertex or on an arc (or `q` is not finite).
    pub(crate) fn interior_segment(&self, q: &Vector2<f64>) -> Option<(usize, Vector2<f64>)> {
        if !q.iter().all(|c| c.is_finite()) {
            return None;
        }
        let tiny = 64.0 * f64::EPSILON * (self.scale + q.norm());
        let closest = self.nearest(q, tiny)?;
        let segment = &self.segments[closest.segment];
        (matches!(closest.feature, Feature::Interior(_)) && segment.bend.is_none())
            .then_some((closest.segment, segment.normal))
    }
}

/// The body-frame gradient and Hessian `(F^T g, F^T H F)` of a profile function `f(q)` whose
/// plane gradient `g` and Hessian `H` a [`RigidPolyline`] projection gives (in the `x-y`
/// block), for `q = F y` with the rows of `frame` `F` the plane's two directions.
pub(crate) fn lift_from_plane(
    frame: &Matrix2x3<f64>,
    gradient: &Vector3<f64>,
    hessian: &Matrix3<f64>,
) -> (Vector3<f64>, Matrix3<f64>) {
    let h2 = hessian.fixed_view::<2, 2>(0, 0).into_owned();
    (
        frame.transpose() * gradient.xy(),
        frame.transpose() * h2 * frame,
    )
}

/// `(v_x, v_y, 0)`.
fn lift(v: &Vector2<f64>) -> Vector3<f64> {
    Vector3::new(v.x, v.y, 0.0)
}

impl RigidSurface for RigidPolyline {
    fn shape(&self) -> SurfaceShape {
        SurfaceShape::Polyline {
            vertices: self.drawn_points().iter().map(lift).collect(),
            closed: self.closed,
        }
    }

    fn project(&self, y: &Vector3<f64>) -> Option<Projection> {
        if !y.iter().all(|c| c.is_finite()) {
            return None;
        }
        let q = y.xy();
        let tiny = 64.0 * f64::EPSILON * (self.scale + q.norm());
        let closest = self.nearest(&q, tiny)?;
        let segment = &self.segments[closest.segment];
        let (gap, gap_gradient, gap_hessian, arc, arc_gradient, arc_hessian) = match closest.feature
        {
            Feature::Interior(u) => match &segment.bend {
                None => (
                    segment.normal.dot(&(q - segment.start)),
                    lift(&segment.normal),
                    Matrix3::zeros(),
                    segment.arc + u,
                    lift(&segment.tangent),
                    Matrix3::zeros(),
                ),
                Some(bend) => {
                    let sigma = bend.turn();
                    let d = q - bend.centre;
                    let rho = d.norm();
                    let radial = d / rho;
                    let across = Vector2::new(-radial.y, radial.x);
                    let phi_hessian = Matrix2::new(
                        2.0 * d.x * d.y,
                        d.y * d.y - d.x * d.x,
                        d.y * d.y - d.x * d.x,
                        -2.0 * d.x * d.y,
                    ) / rho.powi(4);
                    let plane = |m: Matrix2<f64>| {
                        let mut out = Matrix3::zeros();
                        out.fixed_view_mut::<2, 2>(0, 0).copy_from(&m);
                        out
                    };
                    (
                        sigma * (rho - bend.radius),
                        lift(&(radial * sigma)),
                        plane((Matrix2::identity() - radial * radial.transpose()) * (sigma / rho)),
                        segment.arc + u,
                        lift(&(across * (sigma * bend.radius / rho))),
                        plane(phi_hessian * (sigma * bend.radius)),
                    )
                }
            },
            Feature::Vertex(j) => {
                let offset = q - closest.point;
                let pseudo = self.vertex_normals[j];
                let sign = if self.is_edge(j) || offset.dot(&pseudo) >= 0.0 {
                    1.0
                } else {
                    -1.0
                };
                let (gradient, curvature) = if closest.distance > tiny {
                    let direction = lift(&(offset / closest.distance));
                    let across = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 0.0))
                        - direction * direction.transpose();
                    (direction * sign, across * (sign / closest.distance))
                } else {
                    let normal = pseudo
                        .try_normalize(0.0)
                        .unwrap_or_else(|| segment.normal_at(false));
                    (lift(&normal), Matrix3::zeros())
                };
                // the arc length of vertex j: the start of the segment leaving it, or the
                // whole length at an open polyline's last vertex
                let arc = self.segments.get(j).map_or(self.length, |s| s.arc);
                (
                    sign * closest.distance,
                    gradient,
                    curvature,
                    arc,
                    Vector3::zeros(),
                    Matrix3::zeros(),
                )
            }
        };
        Some(Projection {
            gap,
            gap_gradient,
            coords: Vector2::new(arc, y.z),
            coords_gradient: [arc_gradient, Vector3::z()],
            gap_hessian,
            coords_hessian: [arc_hessian, Matrix3::zeros()],
        })
    }

    fn coords_period(&self) -> [Option<f64>; 2] {
        [self.closed.then_some(self.length), None]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facets::tests::check_gradients;
    use crate::plane::RigidPlane;
    use crate::surface::unwrapped_increment;

    fn project(surface: &dyn RigidSurface, y: &Vector3<f64>) -> Projection {
        surface.project(y).expect("projection defined")
    }

    /// A floor with a ramp up: (2, 0.2) -> (0.5, 0.2) -> (0, 0) -> (-1, 0), walked in -x so
    /// that the outward normals point up; (0.5, 0.2) is a convex corner, (0, 0) a concave one.
    fn step_floor() -> RigidPolyline {
        RigidPolyline::new(
            vec![
                Vector2::new(2.0, 0.2),
                Vector2::new(0.5, 0.2),
                Vector2::new(0.0, 0.0),
                Vector2::new(-1.0, 0.0),
            ],
            false,
        )
        .expect("floor")
    }

    #[test]
    fn rejects_invalid_data() {
        let invalid = |r: Result<RigidPolyline, ContactError>| {
            matches!(r, Err(ContactError::InvalidSurface(_)))
        };
        let (a, b, c) = (Vector2::zeros(), Vector2::x(), Vector2::y());
        assert!(invalid(RigidPolyline::new(vec![a], false)));
        assert!(invalid(RigidPolyline::new(vec![a, b], true)));
        assert!(invalid(RigidPolyline::new(vec![a, a, b], false)));
        assert!(invalid(RigidPolyline::new(
            vec![a, Vector2::new(f64::NAN, 0.0)],
            false
        )));
        assert!(RigidPolyline::new(vec![a, b, c], true).is_ok());
    }

    /// A straight polyline is the plane: same gap and normal, and the arc length from its
    /// first vertex, walked in -x.
    #[test]
    fn a_straight_polyline_projects_as_its_plane() -> Result<(), ContactError> {
        let line = RigidPolyline::new(
            vec![
                Vector2::new(1.0, 0.0),
                Vector2::new(0.3, 0.0),
                Vector2::new(-1.0, 0.0),
            ],
            false,
        )?;
        let plane = RigidPlane::new(Vector3::y(), Vector3::x())?;
        for y in [
            Vector3::new(0.1, 0.02, 0.0),
            Vector3::new(0.3, -0.01, 0.0),
            Vector3::new(-0.7, 0.5, 0.0),
        ] {
            let (p, q) = (project(&line, &y), project(&plane, &y));
            assert!((p.gap - q.gap).abs() < 1e-15, "{y:?}");
            assert!((p.gap_gradient - q.gap_gradient).norm() < 1e-15);
            assert!((p.coords[0] - (1.0 - q.coords[0])).abs() < 1e-15);
        }
        Ok(())
    }

    /// Gap and arc length against finite differences on segments, in the convex corner's
    /// wedge (outside), and below the surface.
    #[test]
    fn gradients_match_finite_differences() {
        let floor = step_floor();
        for y in [
            Vector3::new(-0.5, 0.03, 0.0),
            Vector3::new(1.2, 0.25, 0.1),
            Vector3::new(0.3, 0.05, 0.0),
            // the convex corner at (0.5, 0.2): above and right of its wedge
            Vector3::new(0.55, 0.3, 0.0),
            // the open end beyond (2, 0.2)
            Vector3::new(2.3, 0.4, 0.0),
            Vector3::new(-0.4, -0.01, 0.0),
        ] {
            check_gradients(&floor, &y, 1e-6);
        }
    }

    /// Beyond an open end the point is off the surface: its gap is its distance to the end
    /// vertex, positive on either side of the end piece's line (below it, the end piece's
    /// normal alone would sign it as a penetration and catch a node sliding past the end),
    /// with the derivatives of that distance; under the surface within its extent the gap is
    /// still negative. An end the surface continues beyond is signed by its normal.
    #[test]
    fn an_open_end_is_the_surface_edge() -> Result<(), ContactError> {
        let floor = step_floor();
        for (y, end) in [
            // beyond the first vertex (2, 0.2), below the level of its piece
            (Vector3::new(2.3, 0.1, 0.0), Vector2::new(2.0, 0.2)),
            // beyond the last vertex (-1, 0), below the floor
            (Vector3::new(-1.2, -0.05, 0.1), Vector2::new(-1.0, 0.0)),
        ] {
            let p = project(&floor, &y);
            let offset = y.xy() - end;
            assert!((p.gap - offset.norm()).abs() < 1e-15, "{y:?}: {}", p.gap);
            assert!((p.gap_gradient - lift(&offset.normalize())).norm() < 1e-15);
            check_gradients(&floor, &y, 1e-6);
        }
        let under = project(&floor, &Vector3::new(1.9, 0.1, 0.0));
        assert!((under.gap + 0.1).abs() < 1e-15);
        let continued = step_floor().continued_at(0);
        let caught = project(&continued, &Vector3::new(2.3, 0.1, 0.0));
        assert!((caught.gap + (0.3_f64.hypot(0.1))).abs() < 1e-15);
        Ok(())
    }

    /// At a convex corner the gap is the distance to the vertex and the arc length stays at
    /// the vertex's; under the surface the gap is negative.
    #[test]
    fn corner_wedges_and_penetration() {
        let floor = step_floor();
        let corner = Vector2::new(0.5, 0.2);
        let y = Vector3::new(0.45, 0.35, 0.0);
        let p = project(&floor, &y);
        // the wedge of (0.5, 0.2) between the normals of its two segments
        let expected = (y.xy() - corner).norm();
        assert!((p.gap - expected).abs() < 1e-15);
        assert!((p.coords[0] - 1.5).abs() < 1e-15);
        assert_eq!(p.coords_gradient[0], Vector3::zeros());
        let below = project(&floor, &Vector3::new(-0.5, -0.01, 0.0));
        assert!((below.gap + 0.01).abs() < 1e-15);
        // a node resting on the corner gets the pseudo-normal's direction
        let on = project(&floor, &lift(&corner));
        assert!(on.gap.abs() < 1e-15);
        let n1 = Vector2::new(-0.2, 0.5).normalize();
        let bisector = lift(&(n1 + Vector2::y()).normalize());
        assert!((on.gap_gradient - bisector).norm() < 1e-12);
    }

    /// The closed square of side 2 about the origin, counter-clockwise from (-1, -1).
    fn square() -> Result<RigidPolyline, ContactError> {
        RigidPolyline::new(
            vec![
                Vector2::new(-1.0, -1.0),
                Vector2::new(1.0, -1.0),
                Vector2::new(1.0, 1.0),
                Vector2::new(-1.0, 1.0),
            ],
            true,
        )
    }

    /// A closed square, counter-clockwise: outside positive, inside negative, and the arc
    /// length wraps with the period of its perimeter.
    #[test]
    fn a_closed_polyline_wraps_its_arc_length() -> Result<(), ContactError> {
        let square = square()?;
        assert_eq!(square.coords_period(), [Some(8.0), None]);
        assert!((project(&square, &Vector3::new(1.5, 0.0, 0.0)).gap - 0.5).abs() < 1e-15);
        assert!((project(&square, &Vector3::new(0.0, 0.8, 0.0)).gap + 0.2).abs() < 1e-15);
        // just before and after the first vertex: a short slip across the seam
        let before = project(&square, &Vector3::new(-1.1, -0.99, 0.0));
        let after = project(&square, &Vector3::new(-0.99, -1.1, 0.0));
        assert!((before.coords[0] - 7.99).abs() < 1e-12);
        assert!((after.coords[0] - 0.01).abs() < 1e-12);
        let slip = unwrapped_increment(square.coords_period(), after.coords - before.coords);
        assert!((slip[0] - 0.02).abs() < 1e-12);
        check_gradients(&square, &Vector3::new(0.2, 1.3, 0.0), 1e-6);
        Ok(())
    }

    /// `point_at` walks the pieces: each point projects back to its arc length with no gap,
    /// the tangent is the derivative of the point in the arc length, a closed polyline wraps
    /// and an open one stops at its ends.
    #[test]
    fn the_point_at_an_arc_length_lies_on_the_polyline() -> Result<(), ContactError> {
        let step = rounded();
        let length = step.length;
        let h = 1e-6;
        // (points between the vertices: the tangent turns at the corner between the convex
        // arc and the lower floor)
        for i in 0..40 {
            let s = length * (i as f64 + 0.5) / 40.0;
            let (point, tangent) = step.point_at(s).expect("finite");
            let back = project(&step, &Vector3::new(point.x, point.y, 0.0));
            assert!(back.gap.abs() < 1e-12, "s = {s}: gap {}", back.gap);
            assert!(
                (back.coords[0] - s).abs() < 1e-12,
                "s = {s}: {}",
                back.coords[0]
            );
            let ahead = step.point_at(s + h).expect("finite").0;
            let behind = step.point_at(s - h).expect("finite").0;
            assert!(
                ((ahead - behind) / (2.0 * h) - tangent).norm() < 1e-6,
                "s = {s}"
            );
            assert!((tangent.norm() - 1.0).abs() < 1e-12);
        }
        assert_eq!(step.point_at(-1.0), step.point_at(0.0));
        assert_eq!(step.point_at(length + 1.0), step.point_at(length));
        assert_eq!(step.point_at(f64::NAN), None);
        let square = square()?;
        let (wrapped, tangent) = square.point_at(8.5).expect("finite");
        assert!((wrapped - Vector2::new(-0.5, -1.0)).norm() < 1e-15);
        assert_eq!(tangent, Vector2::new(1.0, 0.0));
        Ok(())
    }

    /// A step walked in -x, outside up: a floor at y = 1 from x = 2 to 1, a counter-clockwise
    /// quarter circle about (1, 0) down to (0, 0) (a rounded convex edge), a floor at y = 0 to
    /// x = -1, and a clockwise quarter circle about (-1, 1) up to (-2, 1) (a concave fillet).
    fn rounded() -> RigidPolyline {
        RigidPolyline::with_arcs(
            vec![
                Vector2::new(2.0, 1.0),
                Vector2::new(1.0, 1.0),
                Vector2::new(0.0, 0.0),
                Vector2::new(-1.0, 0.0),
                Vector2::new(-2.0, 1.0),
            ],
            vec![
                None,
                Some(Vector2::new(1.0, 0.0)),
                None,
                Some(Vector2::new(-1.0, 1.0)),
            ],
            false,
        )
        .expect("rounded profile")
    }

    /// On an arc the gap is the distance to its circle, signed by the side it is contacted
    /// on, and the arc length runs on along it; gradients and Hessians of both match finite
    /// differences on either arc, above and below the surface.
    #[test]
    fn arcs_project_on_their_circle() {
        let profile = rounded();
        // the rounded edge: outside its circle the gap is positive, inside negative
        let angle = 3.0 * PI / 4.0;
        let on = Vector2::new(1.0 + angle.cos(), angle.sin());
        let y = Vector3::new(on.x + 0.1 * angle.cos(), on.y + 0.1 * angle.sin(), 0.2);
        let p = project(&profile, &y);
        assert!((p.gap - 0.1).abs() < 1e-14, "{}", p.gap);
        let under = Vector3::new(on.x - 0.1 * angle.cos(), on.y - 0.1 * angle.sin(), 0.0);
        assert!((project(&profile, &under).gap + 0.1).abs() < 1e-14);
        assert!(
            (p.coords[0] - (1.0 + PI / 4.0)).abs() < 1e-14,
            "{:?}",
            p.coords
        );
        // the fillet: inside its circle, 0.6 from the centre, the point is 0.4 above it
        let q = Vector3::new(-1.0 - 0.6 * 0.5f64.sqrt(), 1.0 - 0.6 * 0.5f64.sqrt(), 0.0);
        let b = project(&profile, &q);
        assert!((b.gap - 0.4).abs() < 1e-14, "{}", b.gap);
        assert!((b.coords[0] - (2.0 + PI / 2.0 + PI / 4.0)).abs() < 1e-14);
        assert!((profile.coords_period()[0].is_none()));
        for y in [
            y,
            q,
            Vector3::new(0.4, 0.3, 0.0),
            Vector3::new(0.7, 0.9, 0.1),
            Vector3::new(-1.5, 0.1, 0.0),
            Vector3::new(-1.2, 0.6, 0.0),
        ] {
            check_gradients(&profile, &y, 1e-6);
        }
    }

    /// The closest point over the pieces is the nearest of a dense sampling of the profile,
    /// and the arc length is continuous across the joints of lines and arcs.
    #[test]
    fn arcs_are_searched_exactly() {
        let profile = rounded();
        let samples = profile.drawn_points();
        let dense: Vec<Vector2<f64>> = samples
            .windows(2)
            .flat_map(|w| (0..200).map(move |i| w[0] + (w[1] - w[0]) * (i as f64 / 200.0)))
            .collect();
        for k in 0..60 {
            let q = Vector2::new(
                -2.4 + 0.077 * k as f64,
                1.3 * ((k * 29 % 13) as f64 / 12.0) - 0.2,
            );
            let p = project(&profile, &lift(&q));
            let sampled = dense
                .iter()
                .map(|d| (q - d).norm())
                .fold(f64::INFINITY, f64::min);
            // the drawn chords sag by R (1 - cos 2.5 deg) below the arcs
            assert!(
                (p.gap.abs() - sampled).abs() < 1e-3,
                "{q:?}: {} vs {sampled}",
                p.gap
            );
        }
        for joint in [
            Vector2::new(1.0, 1.0),
            Vector2::new(0.0, 0.0),
            Vector2::new(-1.0, 0.0),
        ] {
            let (a, b) = (
                project(&profile, &lift(&(joint + Vector2::new(1e-7, 0.0)))),
                project(&profile, &lift(&(joint - Vector2::new(1e-7, 0.0)))),
            );
            assert!((a.coords[0] - b.coords[0]).abs() < 1e-6, "{joint:?}");
        }
    }

    #[test]
    fn invalid_arcs_are_refused() {
        let invalid = |r: Result<RigidPolyline, ContactError>| {
            matches!(r, Err(ContactError::InvalidSurface(_)))
        };
        let (a, b) = (Vector2::new(1.0, 0.0), Vector2::new(-1.0, 0.0));
        // a half circle is ambiguous, ends off the circle are wrong, centres must match pieces
        assert!(invalid(RigidPolyline::with_arcs(
            vec![a, b],
            vec![Some(Vector2::zeros())],
            false
        )));
        assert!(invalid(RigidPolyline::with_arcs(
            vec![a, Vector2::new(0.0, 1.1)],
            vec![Some(Vector2::zeros())],
            false
        )));
        assert!(invalid(RigidPolyline::with_arcs(
            vec![a, b],
            vec![None, None],
            false
        )));
        assert!(
            RigidPolyline::with_arcs(
                vec![a, Vector2::new(0.0, 1.0)],
                vec![Some(Vector2::zeros())],
                false
            )
            .is_ok()
        );
    }

    /// The tree finds the same closest segment as a scan of all segments.
    #[test]
    fn the_search_tree_finds_what_a_full_scan_finds() -> Result<(), ContactError> {
        let wave: Vec<Vector2<f64>> = (0..200)
            .map(|k| {
                let x = k as f64 * 0.01;
                Vector2::new(x, 0.05 * (7.0 * x).sin())
            })
            .collect();
        let wave = RigidPolyline::new(wave, false)?;
        for k in 0..97 {
            let q = Vector2::new(
                -0.1 + 0.022 * k as f64,
                0.3 * ((k * 37 % 11) as f64 - 5.0) / 5.0,
            );
            let tiny = 64.0 * f64::EPSILON * (wave.scale + q.norm());
            let found = wave.nearest(&q, tiny).expect("closest");
            let scanned = (0..wave.segments.len())
                .map(|s| wave.closest_on(s, &q, tiny))
                .min_by(|a, b| a.distance.total_cmp(&b.distance))
                .expect("segments");
            assert!(
                (found.distance - scanned.distance).abs() <= 2.0 * tiny,
                "{q:?}"
            );
        }
        Ok(())
    }
}
