//! Rigid polyline in the plane (2D): a chain of straight segments, open or closed, such as a
//! floor, a ramp or a punch profile meshed with rigid line elements.

use nalgebra::{Matrix2x3, Matrix3, Vector2, Vector3};
use rstar::{AABB, PointDistance, RTree, RTreeObject};

use crate::error::ContactError;
use crate::surface::{Projection, RigidSurface, SurfaceShape};

/// One segment `P_k -> P_{k+1}` in the plane.
#[derive(Clone, Debug)]
struct Segment {
    start: Vector2<f64>,
    /// Unit tangent `t_k = (P_{k+1} - P_k) / L_k`.
    tangent: Vector2<f64>,
    /// Outward unit normal `n_k`: the tangent turned clockwise, `(t_y, -t_x)`.
    normal: Vector2<f64>,
    /// Length `L_k`.
    length: f64,
    /// Arc length `s_k` of `P_k` from the first vertex.
    arc: f64,
}

/// Where on a segment a point's closest point lies.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Feature {
    /// The interior, at arc length `u` from the segment's start.
    Interior(f64),
    /// Vertex `j` of the polyline.
    Vertex(usize),
}

/// A segment's closest point to a point, with its distance.
#[derive(Clone, Copy, Debug)]
struct Closest {
    segment: usize,
    feature: Feature,
    point: Vector2<f64>,
    distance: f64,
}

/// A segment in the search tree.
#[derive(Clone, Debug)]
struct Located {
    index: usize,
    start: Vector2<f64>,
    end: Vector2<f64>,
}

impl RTreeObject for Located {
    type Envelope = AABB<[f64; 2]>;

    fn envelope(&self) -> Self::Envelope {
        let (low, high) = (self.start.inf(&self.end), self.start.sup(&self.end));
        AABB::from_corners([low.x, low.y], [high.x, high.y])
    }
}

impl PointDistance for Located {
    /// Square of the exact distance to the segment (a NaN counts as infinitely far).
    fn distance_2(&self, point: &[f64; 2]) -> f64 {
        let q = Vector2::new(point[0], point[1]);
        let edge = self.end - self.start;
        let t = ((q - self.start).dot(&edge) / edge.norm_squared()).clamp(0.0, 1.0);
        let d = (q - self.start - edge * t).norm_squared();
        if d.is_nan() { f64::INFINITY } else { d }
    }
}

/// A polyline of vertices `P_0 .. P_m` in the body frame's plane `z = 0` (a closed one also has
/// the segment `P_m -> P_0`), contacted on the side of its outward normals: each segment's
/// direction turned clockwise (the right-hand side walking along it; for a closed polyline
/// counter-clockwise about its inside, the outside).
///
/// With `q` the in-plane point and `p` its closest point on the polyline (exact, over all
/// segments):
/// * on the interior of segment `k` (`p = P_k + u t_k`, `0 < u < L_k`): `g = n_k.(q - P_k)`,
///   `dg/dy = n_k`, `xi_0 = s_k + u` (arc length), `d xi_0/dy = t_k`; second derivatives vanish;
/// * at vertex `P_j`: with `N_j` the sum of the normals of the segments meeting there (the
///   pseudo-normal) and `s = sign((q - P_j).N_j)` (`+` on ties), `g = s |q - P_j|`,
///   `dg/dy = s (q - P_j)/|q - P_j|` (`N_j/|N_j|` when `|q - P_j| ~ 0`),
///   `d^2g/dy^2 = s (I - e_z e_z^T - dg/dy dg/dy^T)/|q - P_j|` (zero when `|q - P_j| ~ 0`),
///   `xi_0 = s_j`, `d xi_0/dy = 0`.
///
/// Always `xi_1 = y_z`, `d xi_1/dy = e_z`; a closed polyline's `xi_0` has the period of its
/// length. The gap is the signed distance, C1 across the segments' ends on the outside. Equally
/// distant features (to round-off) resolve to a segment's interior before a vertex, then to the
/// lowest segment. Segments are found through an R*-tree of their bounding boxes, so that a
/// projection visits the few segments near the point rather than all.
#[derive(Clone, Debug)]
pub struct RigidPolyline {
    vertices: Vec<Vector2<f64>>,
    closed: bool,
    segments: Vec<Segment>,
    /// Pseudo-normal `N_j` of each vertex.
    vertex_normals: Vec<Vector2<f64>>,
    tree: RTree<Located>,
    /// Total length (the period of a closed polyline's arc length).
    length: f64,
    /// Largest vertex norm, the length scale of round-off tolerances.
    scale: f64,
}

impl RigidPolyline {
    /// The polyline through `vertices` (at least 2; at least 3 if `closed`).
    ///
    /// # Errors
    /// [`ContactError::InvalidSurface`] for too few or non-finite vertices, or a segment
    /// shorter than `1e-12` of the largest vertex distance from the origin.
    pub fn new(vertices: Vec<Vector2<f64>>, closed: bool) -> Result<Self, ContactError> {
        let invalid = |message: String| Err(ContactError::InvalidSurface(message));
        let least = if closed { 3 } else { 2 };
        if vertices.len() < least {
            return invalid(format!(
                "a{} polyline needs at least {least} vertices, got {}",
                if closed { " closed" } else { "n open" },
                vertices.len()
            ));
        }
        if let Some(v) = vertices.iter().find(|v| !v.iter().all(|c| c.is_finite())) {
            return invalid(format!("non-finite polyline vertex {v:?}"));
        }
        let scale = vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let count = if closed {
            vertices.len()
        } else {
            vertices.len() - 1
        };
        let mut segments = Vec::with_capacity(count);
        let mut arc = 0.0;
        for k in 0..count {
            let (a, b) = (vertices[k], vertices[(k + 1) % vertices.len()]);
            let length = (b - a).norm();
            if length <= 1e-12 * scale.max(f64::MIN_POSITIVE) {
                return invalid(format!(
                    "polyline segment {k} from {a:?} to {b:?} has no length"
                ));
            }
            let tangent = (b - a) / length;
            segments.push(Segment {
                start: a,
                tangent,
                normal: Vector2::new(tangent.y, -tangent.x),
                length,
                arc,
            });
            arc += length;
        }
        let mut vertex_normals = vec![Vector2::zeros(); vertices.len()];
        for (k, segment) in segments.iter().enumerate() {
            vertex_normals[k] += segment.normal;
            vertex_normals[(k + 1) % vertices.len()] += segment.normal;
        }
        let tree = RTree::bulk_load(
            segments
                .iter()
                .enumerate()
                .map(|(index, s)| Located {
                    index,
                    start: s.start,
                    end: s.start + s.tangent * s.length,
                })
                .collect(),
        );
        Ok(Self {
            vertices,
            closed,
            segments,
            vertex_normals,
            tree,
            length: arc,
            scale,
        })
    }

    /// Index of the vertex at the end of segment `k`.
    fn end_vertex(&self, k: usize) -> usize {
        (k + 1) % self.vertices.len()
    }

    /// The closest point of segment `k` to `q`; within `tiny` of an end, that end's vertex.
    fn closest_on(&self, k: usize, q: &Vector2<f64>, tiny: f64) -> Closest {
        let segment = &self.segments[k];
        let u = (q - segment.start).dot(&segment.tangent);
        let (feature, point) = if u <= tiny {
            (Feature::Vertex(k), segment.start)
        } else if u >= segment.length - tiny {
            (
                Feature::Vertex(self.end_vertex(k)),
                self.vertices[self.end_vertex(k)],
            )
        } else {
            (Feature::Interior(u), segment.start + segment.tangent * u)
        };
        Closest {
            segment: k,
            feature,
            point,
            distance: (q - point).norm(),
        }
    }

    /// The closest feature over all segments, as a scan in segment order finds it: a later
    /// segment replaces the best so far if nearer by more than `tolerance`, or no more than
    /// `tolerance` farther with its interior against a vertex. Only the segments the tree
    /// yields nearest first are scanned, up to the first one more than `2 tolerance` farther
    /// than all before it (one left out could never replace a candidate).
    fn nearest(&self, q: &Vector2<f64>, tolerance: f64) -> Option<Closest> {
        let mut candidates: Vec<Closest> = Vec::new();
        let mut farthest = f64::NEG_INFINITY;
        for located in self.tree.nearest_neighbor_iter(&[q.x, q.y]) {
            let closest = self.closest_on(located.index, q, tolerance);
            if !candidates.is_empty() && closest.distance > farthest + 2.0 * tolerance {
                break;
            }
            farthest = farthest.max(closest.distance);
            candidates.push(closest);
        }
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
    /// The segment whose interior holds the closest point to `q`, with its outward normal;
    /// `None` where the closest point is a vertex (or `q` is not finite).
    pub(crate) fn interior_segment(&self, q: &Vector2<f64>) -> Option<(usize, Vector2<f64>)> {
        if !q.iter().all(|c| c.is_finite()) {
            return None;
        }
        let tiny = 64.0 * f64::EPSILON * (self.scale + q.norm());
        let closest = self.nearest(q, tiny)?;
        matches!(closest.feature, Feature::Interior(_))
            .then(|| (closest.segment, self.segments[closest.segment].normal))
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
            vertices: self.vertices.iter().map(lift).collect(),
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
        let (gap, gap_gradient, gap_hessian, arc, arc_gradient) = match closest.feature {
            Feature::Interior(u) => (
                segment.normal.dot(&(q - segment.start)),
                lift(&segment.normal),
                Matrix3::zeros(),
                segment.arc + u,
                lift(&segment.tangent),
            ),
            Feature::Vertex(j) => {
                let offset = q - closest.point;
                let pseudo = self.vertex_normals[j];
                let sign = if offset.dot(&pseudo) >= 0.0 {
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
                    let normal = pseudo.try_normalize(0.0).unwrap_or(segment.normal);
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
                )
            }
        };
        Some(Projection {
            gap,
            gap_gradient,
            coords: Vector2::new(arc, y.z),
            coords_gradient: [arc_gradient, Vector3::z()],
            gap_hessian,
            coords_hessian: [Matrix3::zeros(); 2],
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
    use crate::kinematics::slip_increment;
    use crate::plane::RigidPlane;

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

    /// A closed square, counter-clockwise: outside positive, inside negative, and the arc
    /// length wraps with the period of its perimeter.
    #[test]
    fn a_closed_polyline_wraps_its_arc_length() -> Result<(), ContactError> {
        let square = RigidPolyline::new(
            vec![
                Vector2::new(-1.0, -1.0),
                Vector2::new(1.0, -1.0),
                Vector2::new(1.0, 1.0),
                Vector2::new(-1.0, 1.0),
            ],
            true,
        )?;
        assert_eq!(square.coords_period(), [Some(8.0), None]);
        assert!((project(&square, &Vector3::new(1.5, 0.0, 0.0)).gap - 0.5).abs() < 1e-15);
        assert!((project(&square, &Vector3::new(0.0, 0.8, 0.0)).gap + 0.2).abs() < 1e-15);
        // just before and after the first vertex: a short slip across the seam
        let before = project(&square, &Vector3::new(-1.1, -0.99, 0.0));
        let after = project(&square, &Vector3::new(-0.99, -1.1, 0.0));
        assert!((before.coords[0] - 7.99).abs() < 1e-12);
        assert!((after.coords[0] - 0.01).abs() < 1e-12);
        let slip = slip_increment(&square, &before.coords, &after.coords);
        assert!((slip[0] - 0.02).abs() < 1e-12);
        check_gradients(&square, &Vector3::new(0.2, 1.3, 0.0), 1e-6);
        Ok(())
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
