//! Rigid triangle mesh (the exterior faces of a tetrahedral C3D4 drum) with exact closest points
//! found through an R*-tree, and convected coordinates from a cylinder or plane chart.

use std::collections::BTreeMap;

use nalgebra::{Matrix3, Vector2, Vector3};
use rstar::{AABB, RTree, RTreeObject};

use crate::error::ContactError;
use crate::facets::FacetedCylinder;
use crate::plane::RigidPlane;
use crate::search::nearest_chain;
use crate::surface::{
    AnalyticCylinder, Projection, RigidSurface, Slip, SurfacePoint, SurfaceShape,
};

/// Cylinder whose coordinates label points of a triangulated drum: `xi_0 = R atan2(p.b2, p.b1)`,
/// `xi_1 = e.p` for a surface point `p`, with `b1`, `b2` as in [`AnalyticCylinder`].
#[derive(Clone, Copy, Debug)]
pub struct CylinderChart {
    /// Radius `R > 0` scaling the angle into an arc length.
    pub radius: f64,
    /// Axis `e` through the body-frame origin (normalised on use).
    pub axis: Vector3<f64>,
}

/// The surface whose coordinates label the points of a triangle mesh: those of the closest point
/// on the mesh, read on the chart.
#[derive(Clone, Copy, Debug)]
pub enum SurfaceChart {
    /// A drum's chart (see [`CylinderChart`]); `xi_0` has period `2 pi R`.
    Cylinder(CylinderChart),
    /// `xi = (t1.p, t2.p)` for a surface point `p`, as on the [`RigidPlane`] of outward `normal`
    /// and first in-plane direction `tangent = t1`: labels of any mesh's points (unique where
    /// the mesh is a graph over the plane), while its slip is measured in lengths in the
    /// tangent plane (see [`TriangulatedSurface`]'s `slip`).
    Plane {
        /// Normal `n` of the chart plane (normalised on use).
        normal: Vector3<f64>,
        /// First in-plane direction `t1` (its part along `n` is removed on use).
        tangent: Vector3<f64>,
    },
}

/// Relative tolerance of [`CylinderChart::first_triangle_off`]: on the radii of a triangle's
/// corners (over the largest) and on a normal's part across the axis.
pub const ON_CYLINDER_TOLERANCE: f64 = 1e-6;

impl CylinderChart {
    /// The first of `triangles` (indices into `vertices`) that lies neither on a cylinder about
    /// the chart's axis (its corners at one radius within [`ON_CYLINDER_TOLERANCE`] of it) nor
    /// across the axis (a drum's end face: unit normal along the axis within that tolerance);
    /// `None` if every triangle does one or the other. A triangle that names a vertex that does
    /// not exist is left to [`TriangulatedSurface::new`] to report.
    ///
    /// Slip is counted in the chart's arc length `R dtheta`, which at radius `r` weighs a slip
    /// `R / r` times, and friction with it: exact on the chart's own cylinder, wrong on faces
    /// that are not about its axis. (A coaxial face at another radius, a hollow drum's bore,
    /// passes: it is told from the drum's outside by nothing but where contact happens.)
    pub fn first_triangle_off(
        &self,
        vertices: &[Vector3<f64>],
        triangles: &[[usize; 3]],
    ) -> Option<usize> {
        let e = self.axis.try_normalize(0.0)?;
        let radius = |v: &Vector3<f64>| (v - e * e.dot(v)).norm();
        triangles.iter().position(|t| {
            let Some(corners) = t
                .iter()
                .map(|&i| vertices.get(i))
                .collect::<Option<Vec<_>>>()
            else {
                return false;
            };
            let radii = corners.iter().map(|v| radius(v));
            let (least, most) =
                radii.fold((f64::INFINITY, 0.0_f64), |(a, b), r| (a.min(r), b.max(r)));
            let round = most - least <= ON_CYLINDER_TOLERANCE * most;
            let normal = (corners[1] - corners[0]).cross(&(corners[2] - corners[0]));
            let across = normal
                .try_normalize(0.0)
                .is_some_and(|n| (n - e * e.dot(&n)).norm() <= ON_CYLINDER_TOLERANCE);
            !(round || across)
        })
    }
}

impl From<CylinderChart> for SurfaceChart {
    fn from(chart: CylinderChart) -> Self {
        Self::Cylinder(chart)
    }
}

/// A chart made ready to project.
#[derive(Clone, Debug)]
enum Chart {
    Cylinder(AnalyticCylinder),
    Plane(RigidPlane),
}

impl Chart {
    fn new(chart: SurfaceChart) -> Result<Self, ContactError> {
        Ok(match chart {
            SurfaceChart::Cylinder(c) => Self::Cylinder(AnalyticCylinder::new(c.radius, c.axis)?),
            SurfaceChart::Plane { normal, tangent } => {
                Self::Plane(RigidPlane::new(normal, tangent)?)
            }
        })
    }

    fn surface(&self) -> &dyn RigidSurface {
        match self {
            Self::Cylinder(c) => c,
            Self::Plane(p) => p,
        }
    }
}

/// Closest feature of one triangle to a point.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Feature {
    /// Interior of the triangle.
    Face,
    /// Interior of edge `i`, from corner `i` to corner `i + 1 (mod 3)`.
    Edge(usize),
    /// Corner `i`.
    Vertex(usize),
}

impl Feature {
    /// Preference among equally distant features: the face, then an edge, then a vertex.
    fn rank(self) -> u8 {
        match self {
            Feature::Face => 2,
            Feature::Edge(_) => 1,
            Feature::Vertex(_) => 0,
        }
    }
}

/// One triangle with its angle-weighted pseudo-normals.
#[derive(Clone, Debug)]
struct Triangle {
    corners: [Vector3<f64>; 3],
    /// Outward unit normal `(b - a) x (c - a) / |(b - a) x (c - a)|`.
    normal: Vector3<f64>,
    /// Pseudo-normal of edge `i`: the sum of the unit normals of the triangles sharing it.
    edge_normals: [Vector3<f64>; 3],
    /// Pseudo-normal of corner `i`: `sum_t alpha_t n_t` over incident triangles `t`, `alpha_t` the
    /// triangle's angle at the corner.
    vertex_normals: [Vector3<f64>; 3],
    /// Whether edge `i` is on the mesh's boundary (no other triangle has it).
    boundary_edges: [bool; 3],
    /// Whether corner `i` is on the mesh's boundary (on a boundary edge of any triangle).
    boundary_corners: [bool; 3],
    /// Centroid, for the tests' orientation checks.
    #[cfg(test)]
    centre: Vector3<f64>,
}

/// Closest point of one triangle.
struct Closest {
    point: Vector3<f64>,
    feature: Feature,
    distance: f64,
}

/// Closest point to `y` of the triangle of `corners` `a_i` and unit normal `n`: the plane
/// projection `p = y - (n.(y - a_0)) n` if it lies in the (closed) triangle, otherwise the
/// closest of the three edges' clamped segment projections `a_i + clamp(t, 0, 1) (a_{i+1} - a_i)`,
/// `t = (y - a_i).(a_{i+1} - a_i) / |a_{i+1} - a_i|^2` (an edge for `0 < t < 1`, else a corner).
fn closest(corners: &[Vector3<f64>; 3], normal: &Vector3<f64>, y: &Vector3<f64>) -> Closest {
    let height = normal.dot(&(y - corners[0]));
    let in_plane = y - normal * height;
    let inside = (0..3).all(|i| {
        let (a, b) = (corners[i], corners[(i + 1) % 3]);
        (b - a).cross(&(in_plane - a)).dot(normal) >= 0.0
    });
    if inside {
        return Closest {
            point: in_plane,
            feature: Feature::Face,
            distance: height.abs(),
        };
    }
    let on_edge = |i: usize| {
        let (a, b) = (corners[i], corners[(i + 1) % 3]);
        let edge = b - a;
        let t = (y - a).dot(&edge) / edge.norm_squared();
        let (point, feature) = if t <= 0.0 {
            (a, Feature::Vertex(i))
        } else if t >= 1.0 {
            (b, Feature::Vertex((i + 1) % 3))
        } else {
            (a + edge * t, Feature::Edge(i))
        };
        Closest {
            point,
            feature,
            distance: (y - point).norm(),
        }
    };
    let mut best = on_edge(0);
    for i in 1..3 {
        let candidate = on_edge(i);
        if candidate.distance < best.distance {
            best = candidate;
        }
    }
    best
}

impl Closest {
    /// Whether this closest point, of a later triangle, replaces `best` in the index-order scan:
    /// it is nearer by more than `tolerance`, or no more than `tolerance` farther with a
    /// higher-ranked feature.
    fn replaces(&self, best: &Closest, tolerance: f64) -> bool {
        self.distance < best.distance - tolerance
            || (self.distance <= best.distance + tolerance
                && self.feature.rank() > best.feature.rank())
    }
}

/// A triangle's corners and normal in the search tree, with its index in the mesh.
#[derive(Clone, Debug)]
struct Located {
    index: usize,
    corners: [Vector3<f64>; 3],
    normal: Vector3<f64>,
}

impl Located {
    fn closest(&self, y: &Vector3<f64>) -> Closest {
        closest(&self.corners, &self.normal, y)
    }
}

impl RTreeObject for Located {
    type Envelope = AABB<[f64; 3]>;

    /// Axis-aligned bounding box of the corners.
    fn envelope(&self) -> Self::Envelope {
        let [a, b, c] = self.corners;
        AABB::from_corners(a.inf(&b).inf(&c).into(), a.sup(&b).sup(&c).into())
    }
}

impl Triangle {
    /// Whether `feature` lies on the mesh's boundary: an edge of this triangle only, or a
    /// corner on such an edge.
    fn on_boundary(&self, feature: Feature) -> bool {
        match feature {
            Feature::Face => false,
            Feature::Edge(i) => self.boundary_edges[i],
            Feature::Vertex(i) => self.boundary_corners[i],
        }
    }

    fn pseudo_normal(&self, feature: Feature) -> Vector3<f64> {
        match feature {
            Feature::Face => self.normal,
            Feature::Edge(i) => self.edge_normals[i],
            Feature::Vertex(i) => self.vertex_normals[i],
        }
    }

    /// `dp/dy` of the closest point: `I - n n^T` on the face, `u u^T` on an edge of unit
    /// direction `u`, zero at a corner (all symmetric).
    fn closest_point_jacobian(&self, feature: Feature) -> Matrix3<f64> {
        match feature {
            Feature::Face => Matrix3::identity() - self.normal * self.normal.transpose(),
            Feature::Edge(i) => {
                let u = (self.corners[(i + 1) % 3] - self.corners[i]).normalize();
                u * u.transpose()
            }
            Feature::Vertex(_) => Matrix3::zeros(),
        }
    }
}

/// Triangle mesh (body frame), triangles counter-clockwise seen from outside.
///
/// With `p` the closest point of the mesh to `y` (over all triangles; face, edge or vertex
/// Voronoi region, Ericson 2005 §5.1.5) and `N` the angle-weighted pseudo-normal of its feature
/// (Baerentzen & Aanaes 2005), `s = sign((y - p).N)` (`+` on ties):
/// * `g = s |y - p|` (`= n.(y - a)` in a face region), `dg/dy = s (y - p)/|y - p|` (`= n` in a
///   face region; `N/|N|` when `|y - p| ~ 0`), `d^2g/dy^2 = s (I - dp/dy - d d^T)/|y - p|` with
///   `d = (y - p)/|y - p|` (zero in a face region and when `|y - p| ~ 0`);
/// * `xi` the chart's coordinates of `p` (for a [`CylinderChart`] `xi = (R atan2(p.b2, p.b1),
///   e.p)`, with period `2 pi R` in `xi_0`), with `d xi/dy = (dp/dy)^T d xi/dp`, `dp/dy = I - n n^T` (face), `u u^T` (edge of direction `u`),
///   `0` (vertex), and, `p` being affine in `y` within a region,
///   `d^2 xi/dy^2 = (dp/dy)^T (d^2 xi/dp^2) dp/dy`.
///
/// The sign is that of a closed, consistently oriented mesh. An open mesh's boundary (the edges
/// of one triangle only and their corners) is the surface's edge: a point whose closest feature
/// lies on it is beyond the surface, off it whichever side of the boundary triangle's plane it
/// stands, so there `s = +1` (a node sliding past the edge leaves the surface instead of being
/// caught on it). Equally distant features (to round-off) resolve to the face,
/// then the edge, then the lowest triangle index. The projection is undefined (`None`) if `p`
/// lies on a cylinder chart's axis.
///
/// The closest triangles are found in an R*-tree of the triangles' bounding boxes, bulk-loaded
/// on construction, so that a projection visits the few triangles near `y` rather than all.
#[derive(Clone, Debug)]
pub struct TriangulatedSurface {
    triangles: Vec<Triangle>,
    tree: RTree<Located>,
    chart: Chart,
    /// Largest vertex norm, the length scale of round-off tolerances.
    scale: f64,
}

impl TriangulatedSurface {
    /// Mesh of `triangles` (indices into `vertices`, counter-clockwise seen from outside) with
    /// convected coordinates from `chart`.
    ///
    /// # Errors
    /// [`ContactError::InvalidSurface`] for no triangles, non-finite vertices, out-of-range or
    /// repeated indices, degenerate triangles (`|(b - a) x (c - a)| <= 1e-12 l_max^2`), or an
    /// invalid chart.
    pub fn new(
        vertices: Vec<Vector3<f64>>,
        triangles: Vec<[usize; 3]>,
        chart: impl Into<SurfaceChart>,
    ) -> Result<Self, ContactError> {
        let chart = Chart::new(chart.into())?;
        let invalid = |message: String| Err(ContactError::InvalidSurface(message));
        if triangles.is_empty() {
            return invalid("triangle mesh has no triangles".into());
        }
        if let Some(v) = vertices.iter().find(|v| !v.iter().all(|c| c.is_finite())) {
            return invalid(format!("non-finite mesh vertex {v:?}"));
        }
        let mut normals = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(i) = tri.iter().find(|&&i| i >= vertices.len()) {
                return invalid(format!(
                    "triangle {t} refers to vertex {i} of {}",
                    vertices.len()
                ));
            }
            let [a, b, c] = tri.map(|i| vertices[i]);
            let cross = (b - a).cross(&(c - a));
            let longest = [b - a, c - b, a - c]
                .iter()
                .map(|e| e.norm_squared())
                .fold(0.0, f64::max);
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
                return invalid(format!("triangle {t} repeats a vertex: {tri:?}"));
            }
            if cross.norm() <= 1e-12 * longest {
                return invalid(format!("triangle {t} is degenerate: {tri:?}"));
            }
            normals.push(cross.normalize());
        }
        // each edge's pseudo-normal and the number of triangles that have it
        let mut edge_sums: BTreeMap<(usize, usize), (Vector3<f64>, usize)> = BTreeMap::new();
        let mut vertex_sums = vec![Vector3::zeros(); vertices.len()];
        for (tri, normal) in triangles.iter().zip(&normals) {
            for i in 0..3 {
                let (a, b, c) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
                let sum = edge_sums.entry((a.min(b), a.max(b))).or_default();
                *sum = (sum.0 + normal, sum.1 + 1);
                let angle = (vertices[b] - vertices[a]).angle(&(vertices[c] - vertices[a]));
                vertex_sums[a] += normal * angle;
            }
        }
        let mut boundary_vertices = vec![false; vertices.len()];
        for (&(a, b), _) in edge_sums.iter().filter(|(_, (_, count))| *count == 1) {
            boundary_vertices[a] = true;
            boundary_vertices[b] = true;
        }
        let built = triangles
            .iter()
            .zip(&normals)
            .map(|(tri, normal)| {
                let corners = tri.map(|i| vertices[i]);
                let edge = |i: usize| {
                    let (a, b) = (tri[i], tri[(i + 1) % 3]);
                    edge_sums
                        .get(&(a.min(b), a.max(b)))
                        .copied()
                        .unwrap_or((*normal, 1))
                };
                let edges = [edge(0), edge(1), edge(2)];
                Triangle {
                    corners,
                    normal: *normal,
                    edge_normals: edges.map(|(sum, _)| sum),
                    vertex_normals: tri.map(|i| vertex_sums[i]),
                    boundary_edges: edges.map(|(_, count)| count == 1),
                    boundary_corners: tri.map(|i| boundary_vertices[i]),
                    #[cfg(test)]
                    centre: (corners[0] + corners[1] + corners[2]) / 3.0,
                }
            })
            .collect::<Vec<_>>();
        let tree = RTree::bulk_load(
            built
                .iter()
                .enumerate()
                .map(|(index, t)| Located {
                    index,
                    corners: t.corners,
                    normal: t.normal,
                })
                .collect(),
        );
        let scale = vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        Ok(Self {
            triangles: built,
            tree,
            chart,
            scale,
        })
    }

    /// Closed triangulation of the prism `drum` between the axial positions `axial_range[0] <
    /// axial_range[1]`: each rectangular facet split into two coplanar triangles along the
    /// diagonal from `V_k` at the low end to `V_{k+1}` at the high end, plus fan end caps around
    /// the axis points, outward oriented; chart `(R, e)` of the drum.
    ///
    /// # Errors
    /// [`ContactError::InvalidSurface`] for a non-finite or empty axial range.
    pub fn closed_prism(
        drum: &FacetedCylinder,
        axial_range: [f64; 2],
    ) -> Result<Self, ContactError> {
        let [low, high] = axial_range;
        if !(low.is_finite() && high.is_finite() && low < high) {
            return Err(ContactError::InvalidSurface(format!(
                "prism needs a finite axial range low < high, got {axial_range:?}"
            )));
        }
        let n = drum.facet_count();
        let e = drum.axis();
        // vertices: ring at `low` (0..n), ring at `high` (n..2n), then the two axis points
        let mut vertices: Vec<Vector3<f64>> = (0..n).map(|k| drum.vertex(k) + e * low).collect();
        vertices.extend((0..n).map(|k| drum.vertex(k) + e * high));
        vertices.push(e * low);
        vertices.push(e * high);
        let mut triangles = Vec::with_capacity(4 * n);
        for k in 0..n {
            let next = (k + 1) % n;
            triangles.push([k, next, n + next]);
            triangles.push([k, n + next, n + k]);
            triangles.push([2 * n, next, k]);
            triangles.push([2 * n + 1, n + k, n + next]);
        }
        Self::new(
            vertices,
            triangles,
            CylinderChart {
                radius: drum.radius(),
                axis: e,
            },
        )
    }

    /// Closest feature over all triangles, `(triangle index, closest point)`, as a scan of the
    /// triangles in index order finds it: the first triangle is the best so far, and each later
    /// one replaces it if nearer by more than `tolerance`, or no more than `tolerance` farther
    /// with a higher-ranked feature (face, then edge, then vertex).
    ///
    /// Only the candidates are scanned: the chain of ties from the nearest triangle
    /// ([`crate::search::nearest_chain`]). Each triangle left out is then more than
    /// `2 tolerance` farther than every candidate, so it never replaces one, while every
    /// candidate replaces it; leaving it out does not change the result. This holds for a
    /// `tolerance` above the round-off of the distances, as in [`RigidSurface::project`].
    fn nearest(&self, y: &Vector3<f64>, tolerance: f64) -> Option<(usize, Closest)> {
        let mut candidates = nearest_chain(&self.tree, [y.x, y.y, y.z], tolerance, |located| {
            let closest = located.closest(y);
            let distance = closest.distance;
            ((located.index, closest), distance)
        });
        candidates.sort_unstable_by_key(|(index, _)| *index);
        candidates.into_iter().reduce(|best, candidate| {
            if candidate.1.replaces(&best.1, tolerance) {
                candidate
            } else {
                best
            }
        })
    }
}

impl RigidSurface for TriangulatedSurface {
    fn shape(&self) -> SurfaceShape {
        SurfaceShape::Triangles(self.triangles.iter().map(|t| t.corners).collect())
    }

    fn project(&self, y: &Vector3<f64>) -> Option<Projection> {
        if !y.iter().all(|c| c.is_finite()) {
            return None;
        }
        let tiny = 64.0 * f64::EPSILON * (self.scale + y.norm());
        let (index, closest) = self.nearest(y, tiny)?;
        let triangle = &self.triangles[index];
        let jacobian = triangle.closest_point_jacobian(closest.feature);
        let (gap, gap_gradient, gap_hessian) = if closest.feature == Feature::Face {
            let height = triangle.normal.dot(&(y - triangle.corners[0]));
            (height, triangle.normal, Matrix3::zeros())
        } else {
            let offset = y - closest.point;
            let pseudo = triangle.pseudo_normal(closest.feature);
            let sign = if triangle.on_boundary(closest.feature) || offset.dot(&pseudo) >= 0.0 {
                1.0
            } else {
                -1.0
            };
            let (gradient, curvature) = if closest.distance > tiny {
                let direction = offset / closest.distance;
                let across = Matrix3::identity() - jacobian - direction * direction.transpose();
                (direction * sign, across * (sign / closest.distance))
            } else {
                let normal = pseudo.try_normalize(0.0).unwrap_or(triangle.normal);
                (normal, Matrix3::zeros())
            };
            (sign * closest.distance, gradient, curvature)
        };
        let chart = self.chart.surface().project(&closest.point)?;
        Some(Projection {
            gap,
            gap_gradient,
            coords: chart.coords,
            coords_gradient: chart.coords_gradient.map(|g| jacobian * g),
            gap_hessian,
            coords_hessian: chart.coords_hessian.map(|h| jacobian * h * jacobian),
        })
    }

    fn coords_period(&self) -> [Option<f64>; 2] {
        self.chart.surface().coords_period()
    }

    /// With a cylinder chart, the increments of its coordinates (the default, see
    /// [`RigidSurface::slip`]). With a plane chart, lengths in the tangent plane at the start
    /// point `p_0` of normal `n_0`: `s_k = t_k . (y - p_0)`, gradients `t_k` and no curvature,
    /// with the chart's directions turned into that plane (`t_1` the chart's first direction's
    /// part in it, made unit, or its second's where the first is along `n_0`, `t_2 = n_0 x
    /// t_1`). On a flat mesh on its own plane chart these are the increments of the chart's
    /// coordinates; they stay lengths on a curved mesh or a mesh sloped against the chart,
    /// where a chart coordinate's increment would be the slip's projection (`cos a` times its
    /// length on a face at angle `a` to the chart).
    fn slip(&self, from: &SurfacePoint, y: &Vector3<f64>, to: &Projection) -> Slip {
        let tangents = match &self.chart {
            Chart::Plane(plane) => plane.tangents_across(&from.normal),
            Chart::Cylinder(_) => None,
        };
        let Some(tangents) = tangents else {
            return Slip::of_coordinates(self.coords_period(), &from.coords, to);
        };
        let moved = y - from.position;
        Slip {
            value: Vector2::new(tangents[0].dot(&moved), tangents[1].dot(&moved)),
            gradient: tangents,
            hessian: [Matrix3::zeros(); 2],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facets::tests::check_gradients;
    use crate::surface::unwrapped_increment;
    use approx::assert_relative_eq;
    use proptest::prelude::*;
    use std::f64::consts::{PI, TAU};

    const R: f64 = 0.2;

    fn project(surface: &dyn RigidSurface, y: &Vector3<f64>) -> Projection {
        surface.project(y).expect("projection defined")
    }

    fn z_chart(radius: f64) -> CylinderChart {
        CylinderChart {
            radius,
            axis: Vector3::z(),
        }
    }

    /// Cube `[-1, 1]^3`, vertex `i` at `(+-1, +-1, +-1)` with the bits of `i` giving `x, y, z`.
    fn cube() -> TriangulatedSurface {
        let vertices = (0..8)
            .map(|i| {
                Vector3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                )
            })
            .collect();
        let triangles = vec![
            [4, 5, 7],
            [4, 7, 6],
            [0, 2, 3],
            [0, 3, 1],
            [1, 3, 7],
            [1, 7, 5],
            [0, 4, 6],
            [0, 6, 2],
            [2, 6, 7],
            [2, 7, 3],
            [0, 1, 5],
            [0, 5, 4],
        ];
        TriangulatedSurface::new(vertices, triangles, z_chart(1.0)).expect("cube")
    }

    fn drum_72() -> FacetedCylinder {
        FacetedCylinder::new(R, Vector3::z(), 72, PI / 72.0).expect("drum")
    }

    /// An open mesh's boundary is the surface's edge: a point beyond a boundary edge or corner
    /// is off the surface, its gap the distance to that edge or corner, positive below the
    /// floor's plane as above it (the boundary triangle's normal alone would sign it as a
    /// penetration); within the floor's extent a point below it penetrates.
    #[test]
    fn an_open_mesh_boundary_is_the_surface_edge() -> Result<(), ContactError> {
        let vertices = vec![
            Vector3::new(-1.0, -1.0, 0.0),
            Vector3::new(1.0, -1.0, 0.0),
            Vector3::new(1.0, 1.0, 0.0),
            Vector3::new(-1.0, 1.0, 0.0),
        ];
        let floor = TriangulatedSurface::new(vertices, vec![[0, 1, 2], [0, 2, 3]], z_chart(1.0))?;
        for (y, nearest) in [
            // beyond the edge x = 1, below the plane
            (Vector3::new(1.5, 0.2, -0.2), Vector3::new(1.0, 0.2, 0.0)),
            // beyond the corner (1, 1)
            (Vector3::new(1.5, 1.5, -0.1), Vector3::new(1.0, 1.0, 0.0)),
            // beyond the edge y = -1, above the plane
            (Vector3::new(0.3, -1.4, 0.3), Vector3::new(0.3, -1.0, 0.0)),
        ] {
            let p = project(&floor, &y);
            assert_relative_eq!(p.gap, (y - nearest).norm(), epsilon = 1e-15);
            assert_relative_eq!(p.gap_gradient, (y - nearest).normalize(), epsilon = 1e-15);
            check_gradients(&floor, &y, 1e-6);
        }
        assert_relative_eq!(
            project(&floor, &Vector3::new(0.5, 0.2, -0.1)).gap,
            -0.1,
            epsilon = 1e-15
        );
        Ok(())
    }

    /// A tilted floor of two triangles, `z = 0.1 x` over `[-1, 1]^2`, with the plane chart of
    /// normal `+z`, `t1 = +x`: on a face the gap is the distance to the tilted plane and the
    /// coordinates those of the closest point, read on the chart.
    /// A hollow drum's faces (outside, bore and ends) are about the chart's axis or across it;
    /// a cam's, whose ring alternates radii, are not; a triangle with a missing vertex is left
    /// to the mesh's own checks.
    #[test]
    fn a_cylinder_chart_knows_the_faces_it_measures_slip_on() {
        let chart = z_chart(1.0);
        let ring = |radii: [f64; 2], z: f64| -> Vec<Vector3<f64>> {
            (0..8)
                .map(|k| {
                    let a = k as f64 * TAU / 8.0;
                    Vector3::new(a.cos(), a.sin(), 0.0) * radii[k % 2] + Vector3::z() * z
                })
                .collect()
        };
        // outside at r = 1 and bore at r = 0.5, at z = 0 and 1: rings 0, 1 outside, 2, 3 bore
        let vertices: Vec<Vector3<f64>> = [([1.0; 2], 0.0), ([1.0; 2], 1.0)]
            .into_iter()
            .chain([([0.5; 2], 0.0), ([0.5; 2], 1.0)])
            .flat_map(|(r, z)| ring(r, z))
            .collect();
        let band = |low: usize, high: usize| -> Vec<[usize; 3]> {
            (0..8)
                .flat_map(|k| {
                    let next = (k + 1) % 8;
                    [
                        [low + k, low + next, high + next],
                        [low + k, high + next, high + k],
                    ]
                })
                .collect()
        };
        let hollow: Vec<[usize; 3]> = [band(0, 8), band(16, 24), band(0, 16), band(8, 24)].concat();
        assert_eq!(chart.first_triangle_off(&vertices, &hollow), None);
        let cam: Vec<Vector3<f64>> = ring([1.0, 0.8], 0.0)
            .into_iter()
            .chain(ring([1.0, 0.8], 1.0))
            .collect();
        assert_eq!(chart.first_triangle_off(&cam, &band(0, 8)), Some(0));
        assert_eq!(chart.first_triangle_off(&vertices, &[[0, 1, 99]]), None);
    }

    #[test]
    fn a_plane_charted_mesh_slips_in_lengths_in_the_start_tangent_plane() -> Result<(), ContactError>
    {
        // a roof: two faces of slope 0.5 meeting at a ridge along y, read on the chart z = 0
        let roof = |x: f64, y: f64| Vector3::new(x, y, 0.5 * (1.0 - x.abs()));
        let vertices = vec![
            roof(-1.0, -1.0),
            roof(0.0, -1.0),
            roof(1.0, -1.0),
            roof(-1.0, 1.0),
            roof(0.0, 1.0),
            roof(1.0, 1.0),
        ];
        let triangles = vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
        let chart = SurfaceChart::Plane {
            normal: Vector3::z(),
            tangent: Vector3::x(),
        };
        let mesh = TriangulatedSurface::new(vertices, triangles, chart)?;
        let start = roof(0.4, 0.1);
        let from = project(&mesh, &start).closest(&start);
        let normal = Vector3::new(0.5, 0.0, 1.0).normalize();
        assert_relative_eq!(from.normal, normal, epsilon = 1e-15);
        assert_relative_eq!(from.position, start, epsilon = 1e-15);
        let slip = |y: Vector3<f64>| mesh.slip(&from, &y, &project(&mesh, &y));
        let still = slip(start);
        assert!(still.value.norm() < 1e-15, "{}", still.value);
        // orthonormal tangents of the sloped face, the first down the slope (the chart's x)
        let [down, along] = still.gradient;
        assert_relative_eq!(
            down,
            Vector3::new(1.0, 0.0, -0.5).normalize(),
            epsilon = 1e-15
        );
        assert_relative_eq!(along, Vector3::y(), epsilon = 1e-15);
        assert_eq!(still.hessian, [Matrix3::zeros(); 2]);
        // sliding 0.3 down the face and 0.2 along the ridge, and lifted off by 0.01: lengths,
        // where the chart's coordinates change by 0.3 cos a in x
        let moved = start + down * 0.3 + along * 0.2 + normal * 0.01;
        let p = project(&mesh, &moved);
        let s = slip(moved).value;
        assert_relative_eq!(s, Vector2::new(0.3, 0.2), epsilon = 1e-15);
        let chart_dx = p.coords[0] - from.coords[0];
        assert_relative_eq!(chart_dx, 0.3 * normal.z, epsilon = 1e-15);
        // a flat mesh on its own chart slips by the chart's coordinates
        let left = roof(-0.5, 0.0);
        let flat = TriangulatedSurface::new(
            vec![roof(-1.0, -1.0), roof(0.0, -1.0), roof(0.0, 1.0)],
            vec![[0, 1, 2]],
            SurfaceChart::Plane {
                normal: Vector3::new(-0.5, 0.0, 1.0),
                tangent: Vector3::x(),
            },
        )?;
        let from = project(&flat, &left).closest(&left);
        let to = left + Vector3::new(0.2, -0.1, 0.1);
        let p = project(&flat, &to);
        assert_relative_eq!(
            flat.slip(&from, &to, &p).value,
            p.coords - from.coords,
            epsilon = 1e-15
        );
        // a steeper face (slope 2, its part of x shorter than 1/sqrt 2) still slips down the
        // slope first, as the tangents turn continuously with the normal
        let steep = TriangulatedSurface::new(
            vec![Vector3::zeros(), Vector3::y(), Vector3::new(-0.5, 0.0, 1.0)],
            vec![[0, 1, 2]],
            chart,
        )?;
        let on = Vector3::new(-0.1, 0.3, 0.2);
        let from = project(&steep, &on).closest(&on);
        let slip = steep.slip(&from, &on, &project(&steep, &on));
        let down = Vector3::new(1.0, 0.0, -2.0) / 5.0_f64.sqrt();
        assert_relative_eq!(slip.gradient[0], down, epsilon = 1e-15);
        // a wall across the chart (normal x against the chart's first direction x): the
        // chart's second direction y leads
        let wall = TriangulatedSurface::new(
            vec![Vector3::zeros(), Vector3::y(), Vector3::z()],
            vec![[0, 1, 2]],
            chart,
        )?;
        let on = Vector3::new(0.0, 0.2, 0.2);
        let from = project(&wall, &on).closest(&on);
        let to = on + Vector3::new(0.05, 0.1, -0.3);
        let slip = wall.slip(&from, &to, &project(&wall, &to));
        assert_eq!(slip.gradient, [Vector3::y(), Vector3::z()]);
        assert_relative_eq!(slip.value, Vector2::new(0.1, -0.3), epsilon = 1e-15);
        Ok(())
    }

    #[test]
    fn a_plane_chart_labels_a_floor() -> Result<(), ContactError> {
        let floor = |x: f64, y: f64| Vector3::new(x, y, 0.1 * x);
        let vertices = vec![
            floor(-1.0, -1.0),
            floor(1.0, -1.0),
            floor(1.0, 1.0),
            floor(-1.0, 1.0),
        ];
        let chart = SurfaceChart::Plane {
            normal: Vector3::z(),
            tangent: Vector3::x(),
        };
        let mesh = TriangulatedSurface::new(vertices, vec![[0, 1, 2], [0, 2, 3]], chart)?;
        assert_eq!(mesh.coords_period(), [None, None]);
        let normal = Vector3::new(-0.1, 0.0, 1.0).normalize();
        let y = Vector3::new(0.3, 0.4, 0.2);
        let p = project(&mesh, &y);
        let gap = normal.dot(&(y - floor(0.3, 0.4)));
        assert_relative_eq!(p.gap, gap, epsilon = 1e-15);
        let closest = y - normal * gap;
        assert_relative_eq!(p.coords[0], closest.x, epsilon = 1e-15);
        assert_relative_eq!(p.coords[1], closest.y, epsilon = 1e-15);
        for y in [
            y,
            Vector3::new(-0.6, 0.2, -0.05),
            Vector3::new(1.2, 0.5, 0.3),
        ] {
            check_gradients(&mesh, &y, 1e-6);
        }
        let flat = SurfaceChart::Plane {
            normal: Vector3::z(),
            tangent: Vector3::z(),
        };
        let v = vec![Vector3::zeros(), Vector3::x(), Vector3::y()];
        assert!(matches!(
            TriangulatedSurface::new(v, vec![[0, 1, 2]], flat),
            Err(ContactError::InvalidSurface(_))
        ));
        Ok(())
    }

    #[test]
    fn rejects_invalid_data() {
        let invalid = |r: Result<TriangulatedSurface, ContactError>| {
            matches!(r, Err(ContactError::InvalidSurface(_)))
        };
        let v = vec![Vector3::zeros(), Vector3::x(), Vector3::y()];
        assert!(!invalid(TriangulatedSurface::new(
            v.clone(),
            vec![[0, 1, 2]],
            z_chart(1.0)
        )));
        assert!(invalid(TriangulatedSurface::new(
            v.clone(),
            vec![[0, 1, 3]],
            z_chart(1.0)
        )));
        assert!(invalid(TriangulatedSurface::new(
            v.clone(),
            vec![[0, 1, 1]],
            z_chart(1.0)
        )));
        assert!(invalid(TriangulatedSurface::new(
            v.clone(),
            vec![],
            z_chart(1.0)
        )));
        assert!(invalid(TriangulatedSurface::new(
            v.clone(),
            vec![[0, 1, 2]],
            z_chart(0.0)
        )));
        let chart = CylinderChart {
            radius: 1.0,
            axis: Vector3::zeros(),
        };
        assert!(invalid(TriangulatedSurface::new(
            v.clone(),
            vec![[0, 1, 2]],
            chart
        )));
        let collinear = vec![Vector3::zeros(), Vector3::x(), Vector3::x() * 2.0];
        assert!(invalid(TriangulatedSurface::new(
            collinear,
            vec![[0, 1, 2]],
            z_chart(1.0)
        )));
        let nan = vec![
            Vector3::zeros(),
            Vector3::x(),
            Vector3::new(f64::NAN, 1.0, 0.0),
        ];
        assert!(invalid(TriangulatedSurface::new(
            nan,
            vec![[0, 1, 2]],
            z_chart(1.0)
        )));
        let drum = drum_72();
        assert!(invalid(TriangulatedSurface::closed_prism(
            &drum,
            [0.1, 0.1]
        )));
        assert!(invalid(TriangulatedSurface::closed_prism(
            &drum,
            [0.0, f64::INFINITY]
        )));
    }

    #[test]
    fn single_triangle_voronoi_regions() {
        // triangle a = o, b = o + x, c = o + y with normal +z, away from the chart axis
        let o = Vector3::new(1.0, 1.0, 0.0);
        let mesh = TriangulatedSurface::new(
            vec![o, o + Vector3::x(), o + Vector3::y()],
            vec![[0, 1, 2]],
            z_chart(0.5),
        )
        .expect("triangle");
        // (point relative to o, closest point relative to o, signed distance); the edges and
        // corners of a lone triangle are all its boundary, so beyond them the gap is the
        // distance, below the plane as above it
        let cases = [
            ((0.2, 0.3, 0.5), (0.2, 0.3, 0.0), 0.5),   // face, above
            ((0.2, 0.3, -0.5), (0.2, 0.3, 0.0), -0.5), // face, below
            ((0.5, -0.3, 0.4), (0.5, 0.0, 0.0), 0.5),  // edge ab
            ((0.8, 0.8, 0.1), (0.5, 0.5, 0.0), 0.19f64.sqrt()), // edge bc
            ((-0.3, 0.5, -0.4), (0.0, 0.5, 0.0), 0.5), // edge ca, below
            ((-0.2, -0.1, 0.2), (0.0, 0.0, 0.0), 0.3), // vertex a
            ((1.3, -0.4, -1.2), (1.0, 0.0, 0.0), 1.3), // vertex b, below
            ((-0.3, 1.4, 1.2), (0.0, 1.0, 0.0), 1.3),  // vertex c
        ];
        for ((yx, yy, yz), (px, py, pz), gap) in cases {
            let y = o + Vector3::new(yx, yy, yz);
            let p = o + Vector3::new(px, py, pz);
            let proj = project(&mesh, &y);
            assert_relative_eq!(proj.gap, gap, epsilon = 1e-14);
            let normal = (y - p) * (gap.signum() / (y - p).norm());
            assert_relative_eq!(proj.gap_gradient, normal, epsilon = 1e-14);
            assert_relative_eq!(proj.coords[0], 0.5 * p.y.atan2(p.x), epsilon = 1e-14);
            assert_relative_eq!(proj.coords[1], p.z, epsilon = 1e-14);
            check_gradients(&mesh, &y, 1e-6);
        }
        // vertex region: the closest point does not move
        let corner = project(&mesh, &(o + Vector3::new(-0.2, -0.1, 0.2)));
        assert_eq!(corner.coords_gradient, [Vector3::zeros(); 2]);
        // on the surface the gradient is the pseudo-normal, here the face normal
        let on_edge = project(&mesh, &(o + Vector3::new(0.5, 0.0, 0.0)));
        assert_relative_eq!(on_edge.gap, 0.0, epsilon = 1e-15);
        assert_relative_eq!(on_edge.gap_gradient, Vector3::z(), epsilon = 1e-15);
        // chart coordinates are undefined for a closest point on the chart axis
        let on_axis = TriangulatedSurface::new(
            vec![Vector3::zeros(), Vector3::x(), Vector3::y()],
            vec![[0, 1, 2]],
            z_chart(0.5),
        )
        .expect("triangle");
        assert!(on_axis.project(&Vector3::new(-0.1, -0.1, 0.3)).is_none());
        assert!(mesh.project(&Vector3::new(f64::NAN, 0.0, 0.0)).is_none());
    }

    #[test]
    fn cube_signs_and_pseudo_normals() {
        let cube = cube();
        for t in &cube.triangles {
            assert!(t.normal.dot(&t.centre) > 0.0, "outward orientation");
            // every cube corner sees each incident face under a total angle pi/2
            for v in t.vertex_normals {
                assert_relative_eq!(v.abs(), Vector3::repeat(PI / 2.0), epsilon = 1e-14);
            }
            // cube edges join perpendicular faces, face diagonals coplanar triangles
            for e in t.edge_normals {
                let norm = e.norm();
                assert!((norm - 2f64.sqrt()).abs() < 1e-14 || (norm - 2.0).abs() < 1e-14);
            }
        }
        let cases = [
            (Vector3::new(0.3, 0.2, 0.5), -0.5),           // inside, top face
            (Vector3::new(0.9, 0.8, 0.95), -0.05),         // inside near a corner
            (Vector3::new(-0.7, 0.99, 0.1), -0.01),        // inside near +y face
            (Vector3::new(0.3, 0.2, 1.5), 0.5),            // outside, face
            (Vector3::new(1.2, 1.1, 0.5), 0.05f64.sqrt()), // outside, edge
            (Vector3::new(1.2, 1.3, 1.1), 0.14f64.sqrt()), // outside, corner
            (Vector3::new(-1.2, 0.5, -1.1), 0.05f64.sqrt()), // outside, edge
            (Vector3::new(-1.1, -1.2, -1.3), 0.14f64.sqrt()), // outside, corner
        ];
        for (y, gap) in cases {
            assert_relative_eq!(project(&cube, &y).gap, gap, epsilon = 1e-14);
            check_gradients(&cube, &y, 1e-6);
        }
    }

    #[test]
    fn closed_prism_matches_faceted_cylinder_on_the_lateral_surface() {
        let drum = drum_72();
        let mesh = TriangulatedSurface::closed_prism(&drum, [-0.05, 0.05]).expect("prism");
        assert_eq!(mesh.triangles.len(), 4 * 72);
        for t in &mesh.triangles {
            assert!(t.normal.dot(&t.centre) > 0.0, "outward orientation");
        }
        for i in 0..720 {
            let angle = TAU * (i as f64 + 0.123) / 720.0 - PI;
            // inside, the lateral faces stay nearer than the caps (depth < 0.01)
            for radius in [0.192, 0.1995, 0.2, 0.2003, 0.21, 0.3] {
                let z = 0.04 * ((i % 7) as f64 / 3.0 - 1.0);
                let y = Vector3::new(radius * angle.cos(), radius * angle.sin(), z);
                let (m, f) = (project(&mesh, &y), project(&drum, &y));
                assert_relative_eq!(m.gap, f.gap, epsilon = 1e-13);
                assert_relative_eq!(m.gap_gradient, f.gap_gradient, epsilon = 1e-9);
                assert_relative_eq!(m.coords[1], z, epsilon = 1e-15);
            }
        }
    }

    #[test]
    fn closed_prism_gradients_match_finite_differences() {
        let drum = drum_72();
        let mesh = TriangulatedSurface::closed_prism(&drum, [-0.05, 0.05]).expect("prism");
        let v = drum.vertex(9);
        let mid = (drum.vertex(9) + drum.vertex(10)) * 0.5;
        let points = [
            mid * 1.01 + Vector3::z() * 0.02,                   // face
            mid * 1.01 + (v - mid) * 0.3 - Vector3::z() * 0.01, // face, other triangle
            v * 1.02 + Vector3::z() * 0.013,                    // lateral edge (vertex line)
            mid * 1.01 + Vector3::z() * 0.06,                   // rim edge
            v * 1.02 + Vector3::z() * 0.051,                    // rim corner
            mid * 0.99 + Vector3::z() * 0.03,                   // inside, face
            v * 0.5 + Vector3::z() * 0.045,                     // inside, cap
        ];
        for y in &points {
            check_gradients(&mesh, y, 1e-6);
        }
        // the lateral-edge and rim-edge points lie in edge regions, the rim corner in a vertex one
        assert!(project(&mesh, &points[2]).coords_gradient[0].norm() < 1e-12);
        assert!(project(&mesh, &points[3]).coords_gradient[1].norm() < 1e-12);
        assert_eq!(
            project(&mesh, &points[4]).coords_gradient,
            [Vector3::zeros(); 2]
        );
    }

    #[test]
    fn slip_unwraps_across_the_chart_cut() {
        // facet 35 of this drum is centred on the -x axis, where atan2 jumps from pi to -pi
        let drum = drum_72();
        let mesh = TriangulatedSurface::closed_prism(&drum, [-0.05, 0.05]).expect("prism");
        let d = drum.apothem();
        let before = project(&mesh, &Vector3::new(-d - 0.001, 0.004, 0.01));
        let after = project(&mesh, &Vector3::new(-d - 0.002, -0.003, -0.02));
        assert!(before.coords[0] > 0.0 && after.coords[0] < 0.0);
        let slip = unwrapped_increment(mesh.coords_period(), after.coords - before.coords);
        let expected = R * ((0.004 / d).atan() + (0.003 / d).atan());
        assert_relative_eq!(slip[0], expected, epsilon = 1e-14);
        assert_relative_eq!(slip[1], -0.03, epsilon = 1e-15);
        check_gradients(&mesh, &Vector3::new(-d - 0.001, 1e-8, 0.01), 1e-6);
    }

    /// The closest triangle as a scan over every triangle in index order finds it, the
    /// definition that [`TriangulatedSurface::nearest`] computes with the tree.
    fn scan_all(mesh: &TriangulatedSurface, y: &Vector3<f64>, tolerance: f64) -> (usize, Closest) {
        let mut best: Option<(usize, Closest)> = None;
        for (index, t) in mesh.triangles.iter().enumerate() {
            let candidate = closest(&t.corners, &t.normal, y);
            let better = match &best {
                None => true,
                Some((_, b)) => {
                    candidate.distance < b.distance - tolerance
                        || (candidate.distance <= b.distance + tolerance
                            && candidate.feature.rank() > b.feature.rank())
                }
            };
            if better {
                best = Some((index, candidate));
            }
        }
        best.expect("a mesh has triangles")
    }

    /// Round-off tolerance of [`RigidSurface::project`] and three larger ones, by `choice`.
    fn tolerance(mesh: &TriangulatedSurface, y: &Vector3<f64>, choice: usize) -> f64 {
        let tiny = 64.0 * f64::EPSILON * (mesh.scale + y.norm());
        [
            tiny,
            1e-9 * mesh.scale,
            1e-4 * mesh.scale,
            1e-2 * mesh.scale,
        ][choice]
    }

    fn check_nearest(
        mesh: &TriangulatedSurface,
        y: &Vector3<f64>,
        tolerance: f64,
    ) -> Result<(), TestCaseError> {
        let (index, found) = mesh.nearest(y, tolerance).expect("a mesh has triangles");
        let (expected_index, expected) = scan_all(mesh, y, tolerance);
        prop_assert_eq!(
            (index, found.feature, found.distance, found.point),
            (
                expected_index,
                expected.feature,
                expected.distance,
                expected.point
            ),
            "y = {:?}, tolerance {:e}",
            y,
            tolerance
        );
        Ok(())
    }

    /// A coordinate in `range`, or one of `snapped` (on faces, edges, symmetry planes: ties).
    fn coordinate(range: std::ops::Range<f64>, snapped: Vec<f64>) -> BoxedStrategy<f64> {
        prop_oneof![range, proptest::sample::select(snapped)].boxed()
    }

    #[test]
    fn candidates_reach_past_the_best_when_the_scan_needs_them() {
        // from the origin: a face at 1.15, a vertex at 1.08, a vertex at 1, in index order
        let vertices = vec![
            Vector3::new(-1.0, -1.0, -1.15),
            Vector3::new(1.0, -1.0, -1.15),
            Vector3::new(0.0, 1.0, -1.15),
            Vector3::new(1.08, 0.0, 0.0),
            Vector3::new(2.0, 1.0, 0.0),
            Vector3::new(2.0, -1.0, 0.0),
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::new(-2.0, -1.0, 0.0),
            Vector3::new(-2.0, 1.0, 0.0),
        ];
        let triangles = vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]];
        let mesh = TriangulatedSurface::new(vertices, triangles, z_chart(1.0)).expect("mesh");
        let y = Vector3::zeros();
        // the vertex at 1.08 does not replace the face, the one at 1 does (more than 0.1 nearer);
        // among the triangles within 0.1 of the nearest alone, the vertex at 1.08 would stay
        let (index, found) = mesh.nearest(&y, 0.1).expect("nearest");
        assert_eq!((index, found.feature), (2, Feature::Vertex(0)));
        assert_eq!(found.distance, 1.0);
        check_nearest(&mesh, &y, 0.1).expect("as the scan");
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 512,
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x7e1a_5eed),
            ..ProptestConfig::default()
        })]

        /// Around and inside the cube, the tree finds the scan's triangle, distance and feature.
        #[test]
        fn cube_search_matches_the_scan(
            x in coordinate(-1.5..1.5, vec![-1.3, -1.0, -0.5, 0.0, 0.5, 1.0, 1.3]),
            y in coordinate(-1.5..1.5, vec![-1.3, -1.0, -0.5, 0.0, 0.5, 1.0, 1.3]),
            z in coordinate(-1.5..1.5, vec![-1.3, -1.0, -0.5, 0.0, 0.5, 1.0, 1.3]),
            choice in 0usize..4,
        ) {
            let cube = cube();
            let y = Vector3::new(x, y, z);
            check_nearest(&cube, &y, tolerance(&cube, &y, choice))?;
        }

        /// Around and inside the 72-sector closed prism, including its axis, vertex lines,
        /// facet middles, rims and caps.
        #[test]
        fn closed_prism_search_matches_the_scan(
            radius in coordinate(0.0..0.3, vec![0.0, 0.1, 0.2 * (PI / 72.0).cos(), R, 0.25]),
            sector in prop_oneof![
                (-PI..PI).boxed(),
                (0..144).prop_map(|k| f64::from(k) * PI / 72.0).boxed(),
            ],
            z in coordinate(-0.08..0.08, vec![-0.06, -0.05, 0.0, 0.02, 0.05, 0.06]),
            choice in 0usize..4,
        ) {
            let mesh = TriangulatedSurface::closed_prism(&drum_72(), [-0.05, 0.05])
                .expect("prism");
            let y = Vector3::new(radius * sector.cos(), radius * sector.sin(), z);
            check_nearest(&mesh, &y, tolerance(&mesh, &y, choice))?;
        }

        /// Among up to 200 random, overlapping triangles.
        #[test]
        fn triangle_soup_search_matches_the_scan(
            soup in proptest::collection::vec(proptest::array::uniform9(-1.0..1.0f64), 1..200),
            point in proptest::array::uniform3(-1.5..1.5f64),
            choice in 0usize..4,
        ) {
            let vertices = soup
                .iter()
                .flat_map(|t| t.chunks(3).map(|c| Vector3::new(c[0], c[1], c[2])))
                .collect();
            let triangles = (0..soup.len()).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
            let mesh = TriangulatedSurface::new(vertices, triangles, z_chart(1.0));
            prop_assume!(mesh.is_ok());
            let mesh = mesh.expect("valid soup");
            let y = Vector3::from(point);
            check_nearest(&mesh, &y, tolerance(&mesh, &y, choice))?;
        }
    }
}
