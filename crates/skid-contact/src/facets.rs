//! Faceted rigid drum: a regular polygon inscribed in the drum circle, extruded along the axis
//! (72 R2D2 lines in 2D; 72 R3D4 quads, or rigid M3D4R/S4R, in 3D).

use std::f64::consts::{PI, TAU};

use nalgebra::{Matrix3, Vector2, Vector3};

use crate::error::ContactError;
use crate::surface::{AnalyticCylinder, Projection, RigidSurface, SurfaceShape};

/// Convex regular prism of `n` facets inscribed in the circle of radius `R` about the body-frame
/// unit axis `e` through the origin, of infinite axial extent.
///
/// In-plane coordinates are `q = (b1.y, b2.y)` with `b1`, `b2 = e x b1` as in
/// [`AnalyticCylinder`]. Vertex `k` is `V_k = R (cos phi_k, sin phi_k)`,
/// `phi_k = phi_0 + 2 pi k / n`; facet `k` runs from `V_k` to `V_{k+1}` with length
/// `L = 2 R sin(pi/n)`, unit tangent `tau_k = (-sin m_k, cos m_k)` (counter-clockwise about `e`),
/// outward normal `nu_k = tau_k x e = (cos m_k, sin m_k)`, `m_k = phi_k + pi/n`, apothem
/// `d = R cos(pi/n)` and local coordinate `xi_k = (q - V_k).tau_k / L`.
///
/// * Outside (`max_k (nu_k.q - d) >= 0`): the exact distance to the closest point. On facet `k`
///   (`0 < xi_k < 1`): `g = nu_k.q - d`, `dg/dy = nu_k`, `xi_0 = s_k + xi_k L` with `s_k = k L`,
///   `d xi_0/dy = tau_k`. In the exterior wedge of vertex `V_j`: `g = |q - V_j|`,
///   `dg/dy = (q - V_j)/|q - V_j|` (the bisector `(nu_{j-1} + nu_j)/|nu_{j-1} + nu_j|` when
///   `|q - V_j| ~ 0`), `d^2g/dy^2 = (I - e e^T - dg/dy dg/dy^T)/|q - V_j|` (zero when
///   `|q - V_j| ~ 0`), `xi_0 = s_j`, `d xi_0/dy = 0`. This distance is C1. All other second
///   derivatives vanish: gaps and coordinates are affine on a facet.
/// * Inside: `g = max_k (nu_k.q - d)`, attained on the facet `k` of the angular sector of `q`,
///   with `dg/dy = nu_k`, `xi_0 = s_k + xi_k L`, `d xi_0/dy = tau_k`. Across a vertex bisector the
///   nearest facet switches, so `dg/dy` and `xi_0` jump there by design (penetrated states only).
///
/// Always `xi_1 = e.y`, `d xi_1/dy = e`; `xi_0` has period `n L`. Points within the round-off
/// length `64 eps (R + |q|)` of the surface count as outside, and projections within it of a
/// vertex as that vertex (so a node on a vertex gets the bisector normal).
///
/// The candidate facet is the sector `k = floor((atan2(q) - phi_0) n / (2 pi))`; facets `k - 1..=k + 1`
/// and their vertices are tested, which covers every closest feature of a point in that sector
/// even if round-off picked a neighbouring sector.
#[derive(Clone, Debug)]
pub struct FacetedCylinder {
    radius: f64,
    axis: Vector3<f64>,
    b1: Vector3<f64>,
    b2: Vector3<f64>,
    facets: usize,
    first_vertex_angle: f64,
    apothem: f64,
    length: f64,
    /// Per vertex `k`, the unit direction `(cos phi_k, sin phi_k)` (the sines and cosines of
    /// the vertex angles, evaluated once here instead of at every projection).
    directions: Vec<Vector2<f64>>,
    /// Per facet `k`, its start vertex, tangent and normal.
    facet_table: Vec<Facet>,
}

/// One facet in in-plane coordinates.
#[derive(Clone, Debug)]
struct Facet {
    start: Vector2<f64>,
    tangent: Vector2<f64>,
    normal: Vector2<f64>,
}

impl FacetedCylinder {
    /// Prism of `facets >= 3` facets inscribed in the circle of `radius > 0` about `axis`
    /// (normalised here), first vertex at the finite angle `first_vertex_angle` from `b1`.
    ///
    /// # Errors
    /// [`ContactError::InvalidSurface`] for fewer than 3 facets, a non-positive or non-finite
    /// radius, a zero or non-finite axis, or a non-finite angle.
    pub fn new(
        radius: f64,
        axis: Vector3<f64>,
        facets: usize,
        first_vertex_angle: f64,
    ) -> Result<Self, ContactError> {
        if facets < 3 {
            return Err(ContactError::InvalidSurface(format!(
                "a faceted cylinder needs at least 3 facets, got {facets}"
            )));
        }
        if !first_vertex_angle.is_finite() {
            return Err(ContactError::InvalidSurface(format!(
                "first vertex angle must be finite, got {first_vertex_angle}"
            )));
        }
        let circle = AnalyticCylinder::new(radius, axis)?;
        let half_angle = PI / facets as f64;
        let vertex_angle = |k: usize| first_vertex_angle + TAU * k as f64 / facets as f64;
        let directions: Vec<Vector2<f64>> = (0..facets)
            .map(|k| {
                let (sin, cos) = vertex_angle(k).sin_cos();
                Vector2::new(cos, sin)
            })
            .collect();
        let facet_table = (0..facets)
            .map(|k| {
                let (sin, cos) = (vertex_angle(k) + half_angle).sin_cos();
                Facet {
                    start: directions[k] * radius,
                    tangent: Vector2::new(-sin, cos),
                    normal: Vector2::new(cos, sin),
                }
            })
            .collect();
        Ok(Self {
            radius,
            axis: circle.axis(),
            b1: circle.reference_direction(),
            b2: circle.axis().cross(&circle.reference_direction()),
            facets,
            first_vertex_angle,
            apothem: radius * half_angle.cos(),
            length: 2.0 * radius * half_angle.sin(),
            directions,
            facet_table,
        })
    }

    /// Circumradius `R`.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Unit axis `e` (body frame).
    pub fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    /// Number of facets `n`.
    pub fn facet_count(&self) -> usize {
        self.facets
    }

    /// Facet length `L = 2 R sin(pi/n)`.
    pub fn facet_length(&self) -> f64 {
        self.length
    }

    /// Apothem (inscribed radius) `d = R cos(pi/n)`.
    pub fn apothem(&self) -> f64 {
        self.apothem
    }

    /// Vertex `V_k = R (cos phi_k b1 + sin phi_k b2)` (body frame, in the plane `e.y = 0`),
    /// `phi_k = phi_0 + 2 pi k / n`; `k` is taken modulo `n`.
    pub fn vertex(&self, k: usize) -> Vector3<f64> {
        self.lift(&self.vertex_2d(k % self.facets))
    }

    fn vertex_2d(&self, k: usize) -> Vector2<f64> {
        self.directions[k] * self.radius
    }

    fn lift(&self, v: &Vector2<f64>) -> Vector3<f64> {
        self.b1 * v.x + self.b2 * v.y
    }

    /// Facet `k` of the angular sector `phi_k <= atan2(q) < phi_{k+1}` (modulo `2 pi`).
    fn sector(&self, q: &Vector2<f64>) -> usize {
        let n = self.facets as f64;
        let turns = ((q.y.atan2(q.x) - self.first_vertex_angle) * n / TAU).floor();
        (turns.rem_euclid(n) as usize).min(self.facets - 1)
    }
}

impl RigidSurface for FacetedCylinder {
    fn shape(&self) -> SurfaceShape {
        SurfaceShape::Prism {
            axis: self.axis,
            vertices: (0..self.facets).map(|k| self.vertex(k)).collect(),
        }
    }

    fn project(&self, y: &Vector3<f64>) -> Option<Projection> {
        if !y.iter().all(|c| c.is_finite()) {
            return None;
        }
        let q = Vector2::new(self.b1.dot(y), self.b2.dot(y));
        let n = self.facets;
        let sector = self.sector(&q);
        // the sector facet and its neighbours, in case round-off picked the wrong sector
        let candidates = [(sector + n - 1) % n, sector, (sector + 1) % n].map(|k| {
            let facet = &self.facet_table[k];
            let plane_gap = facet.normal.dot(&q) - self.apothem;
            let xi = (q - facet.start).dot(&facet.tangent) / self.length;
            (k, facet, plane_gap, xi)
        });
        let tiny = 64.0 * f64::EPSILON * (self.radius + q.norm());
        // (g, dg/dy, d^2g/dy^2, xi_0, d xi_0/dy) with facet k as the closest feature
        let on_facet = |(k, facet, plane_gap, xi): &(usize, &Facet, f64, f64)| {
            (
                *plane_gap,
                self.lift(&facet.normal),
                Matrix3::zeros(),
                (*k as f64 + xi) * self.length,
                self.lift(&facet.tangent),
            )
        };
        let nearest_plane = candidates.iter().max_by(|a, b| a.2.total_cmp(&b.2))?;
        let (gap, gap_gradient, gap_hessian, arc, arc_gradient) = if nearest_plane.2 < -tiny {
            on_facet(nearest_plane)
        } else if let Some(front) = candidates
            .iter()
            .find(|c| c.2 >= -tiny && c.3 * self.length > tiny && (1.0 - c.3) * self.length > tiny)
        {
            // in front of the facet, within its slab: the facet is the closest feature
            on_facet(front)
        } else {
            // in a vertex wedge: the nearest vertex of the candidate facets
            let (j, offset) = (0..4)
                .map(|i| {
                    let j = (sector + n - 1 + i) % n;
                    (j, q - self.vertex_2d(j))
                })
                .min_by(|a, b| a.1.norm().total_cmp(&b.1.norm()))?;
            let distance = offset.norm();
            let (direction, curvature) = if distance > tiny {
                let direction = self.lift(&(offset / distance));
                let across = Matrix3::identity()
                    - self.axis * self.axis.transpose()
                    - direction * direction.transpose();
                (direction, across / distance)
            } else {
                (self.lift(&self.directions[j]), Matrix3::zeros())
            };
            (
                distance,
                direction,
                curvature,
                j as f64 * self.length,
                Vector3::zeros(),
            )
        };
        Some(Projection {
            gap,
            gap_gradient,
            coords: Vector2::new(arc, self.axis.dot(y)),
            coords_gradient: [arc_gradient, self.axis],
            gap_hessian,
            // xi_0 is affine on a facet and constant in a wedge; xi_1 is linear
            coords_hessian: [Matrix3::zeros(); 2],
        })
    }

    fn coords_period(&self) -> [Option<f64>; 2] {
        [Some(self.facets as f64 * self.length), None]
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::kinematics::{RotatingFrame, evaluate};
    use crate::surface::{SurfacePoint, unwrapped_increment};
    use approx::assert_relative_eq;

    const R: f64 = 0.2;

    fn project(surface: &dyn RigidSurface, y: &Vector3<f64>) -> Projection {
        surface.project(y).expect("projection defined")
    }

    /// Central differences of gap and (unwrapped) coordinates against the exact gradients, and
    /// of the gradients against the exact second derivatives (relative to their size).
    pub(crate) fn check_gradients(surface: &dyn RigidSurface, y: &Vector3<f64>, tol: f64) {
        let p = project(surface, y);
        let h = 1e-7;
        let gradients =
            |p: &Projection| [p.gap_gradient, p.coords_gradient[0], p.coords_gradient[1]];
        let hessians = [p.gap_hessian, p.coords_hessian[0], p.coords_hessian[1]];
        for k in 0..3 {
            let mut yp = *y;
            let mut ym = *y;
            yp[k] += h;
            ym[k] -= h;
            let (pp, pm) = (project(surface, &yp), project(surface, &ym));
            let slip = unwrapped_increment(surface.coords_period(), pp.coords - pm.coords);
            let fd = [pp.gap - pm.gap, slip[0], slip[1]].map(|d| d / (2.0 * h));
            let exact = gradients(&p).map(|g| g[k]);
            for (f, e) in fd.iter().zip(exact) {
                assert!(
                    (f - e).abs() <= tol,
                    "at {y:?}, component {k}: finite difference {fd:?} vs exact {exact:?}"
                );
            }
            for ((plus, minus), hessian) in gradients(&pp).iter().zip(gradients(&pm)).zip(&hessians)
            {
                let fd = (plus - minus) / (2.0 * h);
                let exact = hessian.column(k);
                assert!(
                    (fd - exact).amax() <= tol * (1.0 + hessian.amax()),
                    "at {y:?}, column {k}: finite difference {fd:?} vs exact {exact:?}"
                );
            }
        }
    }

    fn polar(radius: f64, angle: f64, z: f64) -> Vector3<f64> {
        Vector3::new(radius * angle.cos(), radius * angle.sin(), z)
    }

    /// The tables hold exactly the sines and cosines of the vertex and facet-normal angles.
    #[test]
    fn tables_hold_the_vertex_and_normal_angles() {
        let (n, phi0) = (72, 0.013);
        let drum = FacetedCylinder::new(R, Vector3::z(), n, phi0).expect("drum");
        for k in 0..n {
            let angle = phi0 + TAU * k as f64 / n as f64;
            let (sin, cos) = angle.sin_cos();
            assert_eq!(drum.directions[k], Vector2::new(cos, sin));
            let facet = &drum.facet_table[k];
            assert_eq!(facet.start, Vector2::new(cos, sin) * R);
            let (sin, cos) = (angle + PI / n as f64).sin_cos();
            assert_eq!(facet.normal, Vector2::new(cos, sin));
            assert_eq!(facet.tangent, Vector2::new(-sin, cos));
        }
    }

    #[test]
    fn rejects_invalid_data() {
        let invalid = |r: Result<FacetedCylinder, ContactError>| {
            matches!(r, Err(ContactError::InvalidSurface(_)))
        };
        assert!(invalid(FacetedCylinder::new(R, Vector3::z(), 2, 0.0)));
        assert!(invalid(FacetedCylinder::new(0.0, Vector3::z(), 72, 0.0)));
        assert!(invalid(FacetedCylinder::new(-R, Vector3::z(), 72, 0.0)));
        assert!(invalid(FacetedCylinder::new(R, Vector3::zeros(), 72, 0.0)));
        assert!(invalid(FacetedCylinder::new(R, Vector3::z(), 72, f64::NAN)));
        let drum = FacetedCylinder::new(R, Vector3::z(), 72, 0.0).expect("drum");
        assert!(drum.project(&Vector3::new(f64::NAN, 0.0, 0.0)).is_none());
    }

    #[test]
    fn facet_midpoints_and_vertices_have_exact_gaps_and_coordinates() {
        let n = 72;
        let phi0 = 0.013;
        let drum = FacetedCylinder::new(R, Vector3::new(0.0, 0.0, 2.0), n, phi0).expect("drum");
        let half = PI / n as f64;
        let (d, l) = (R * half.cos(), 2.0 * R * half.sin());
        assert_relative_eq!(drum.apothem(), d, epsilon = 1e-16);
        assert_relative_eq!(drum.facet_length(), l, epsilon = 1e-16);
        assert_eq!(drum.coords_period(), [Some(n as f64 * l), None]);
        for k in [0, 1, 17, 35, 36, 54, 71] {
            let mid = phi0 + (2 * k + 1) as f64 * half;
            for offset in [0.003, 0.0, -0.002] {
                let p = project(&drum, &polar(d + offset, mid, 0.05));
                assert_relative_eq!(p.gap, offset, epsilon = 1e-15);
                assert_relative_eq!(p.gap_gradient, polar(1.0, mid, 0.0), epsilon = 1e-15);
                assert_relative_eq!(p.coords[0], (k as f64 + 0.5) * l, epsilon = 1e-14);
                assert_relative_eq!(p.coords[1], 0.05, epsilon = 1e-16);
                let tangent = polar(1.0, mid + PI / 2.0, 0.0);
                assert_relative_eq!(p.coords_gradient[0], tangent, epsilon = 1e-15);
                assert_relative_eq!(p.coords_gradient[1], Vector3::z(), epsilon = 1e-16);
            }
            // on the vertex (normal = bisector) and radially outside it, in its wedge
            let phi = phi0 + 2.0 * k as f64 * half;
            assert_relative_eq!(drum.vertex(k), polar(R, phi, 0.0), epsilon = 1e-16);
            for offset in [0.0, 0.004] {
                let p = project(&drum, &polar(R + offset, phi, 0.0));
                assert_relative_eq!(p.gap, offset, epsilon = 1e-15);
                assert_relative_eq!(p.gap_gradient, polar(1.0, phi, 0.0), epsilon = 1e-12);
                assert_relative_eq!(p.coords[0], k as f64 * l, epsilon = 1e-14);
                assert_relative_eq!(p.coords_gradient[0], Vector3::zeros());
            }
        }
    }

    #[test]
    fn vertex_wedge_distance_is_euclidean() {
        let drum = FacetedCylinder::new(R, Vector3::z(), 72, 0.0).expect("drum");
        let vertex = drum.vertex(10);
        let phi = 10.0 * TAU / 72.0;
        // the wedge of V_10 is spanned by the normals at phi -+ pi/72; stay strictly inside it
        for (angle, distance) in [(phi + 0.04, 0.01), (phi - 0.03, 0.002), (phi, 0.3)] {
            let y = vertex + polar(distance, angle, -0.7);
            let p = project(&drum, &y);
            assert_relative_eq!(p.gap, distance, epsilon = 1e-15);
            assert_relative_eq!(p.gap_gradient, polar(1.0, angle, 0.0), epsilon = 1e-12);
            assert_relative_eq!(p.coords[0], 10.0 * drum.facet_length(), epsilon = 1e-15);
            assert_relative_eq!(p.coords[1], -0.7);
        }
        // just outside the wedge the facet plane is nearest, just inside the vertex
        let beyond = drum.vertex(10) + polar(0.01, phi + PI / 72.0 + 1e-3, 0.0);
        let facet = project(&drum, &beyond);
        assert!(facet.coords_gradient[0].norm() > 0.99);
        let within = drum.vertex(10) + polar(0.01, phi + PI / 72.0 - 1e-3, 0.0);
        assert_eq!(project(&drum, &within).coords_gradient[0].norm(), 0.0);
        // C1: gap and normal agree on both sides of the wedge boundary to O(1e-3 * 0.01)
        assert_relative_eq!(facet.gap, project(&drum, &within).gap, epsilon = 1e-7);
    }

    #[test]
    fn gradients_match_finite_differences_outside() {
        let drum = FacetedCylinder::new(R, Vector3::z(), 72, 0.02).expect("drum");
        let step = TAU / 72.0;
        for k in [0usize, 5, 35, 71] {
            let phi = 0.02 + k as f64 * step;
            for angle in [
                phi + 1e-9, // just either side of the vertex bisector
                phi - 1e-9,
                phi + 0.3 * step, // facet interior
                phi - 0.45 * step,
                phi + 0.5 * step,  // facet midpoint (bisector of the facet)
                phi + 0.02 * step, // near the vertex, may be in the wedge
            ] {
                for radius in [R + 1e-4, R + 0.003, 1.5 * R] {
                    check_gradients(&drum, &polar(radius, angle, 0.1), 1e-6);
                }
            }
        }
    }

    #[test]
    fn gradients_match_finite_differences_inside_away_from_bisectors() {
        let drum = FacetedCylinder::new(R, Vector3::new(0.3, -0.5, 0.8), 72, 0.0).expect("drum");
        let step = TAU / 72.0;
        for k in [0usize, 12, 50] {
            for fraction in [0.1, 0.5, 0.85] {
                for depth in [1e-4, 0.002] {
                    let angle = (k as f64 + fraction) * step;
                    let inplane = drum.lift(&Vector2::new(angle.cos(), angle.sin()));
                    let y = inplane * (drum.apothem() - depth) + drum.axis() * 0.2;
                    assert!(project(&drum, &y).gap < 0.0);
                    check_gradients(&drum, &y, 1e-6);
                }
            }
        }
    }

    #[test]
    fn inside_gap_jumps_across_a_vertex_bisector_by_design() {
        let drum = FacetedCylinder::new(R, Vector3::z(), 72, 0.0).expect("drum");
        let phi = 3.0 * TAU / 72.0;
        let left = project(&drum, &polar(0.18, phi - 1e-9, 0.0));
        let right = project(&drum, &polar(0.18, phi + 1e-9, 0.0));
        // the gap is continuous (max of two planes) but its gradient switches facets
        assert_relative_eq!(left.gap, right.gap, epsilon = 1e-10);
        assert!((left.gap_gradient - right.gap_gradient).norm() > 0.08);
        // the arc length jumps too: the projections onto the two facet planes lie on either side of
        // the vertex, each (R - r) sin(pi/n) away from it
        let jump = 2.0 * (R - 0.18) * (PI / 72.0).sin();
        assert_relative_eq!(right.coords[0] - left.coords[0], jump, epsilon = 1e-9);
        assert_relative_eq!(
            right.coords[0],
            3.0 * drum.facet_length() + jump / 2.0,
            epsilon = 1e-9
        );
    }

    #[test]
    fn arc_length_is_continuous_across_vertices_and_grows_by_l_per_facet() {
        let drum = FacetedCylinder::new(R, Vector3::z(), 72, -0.4).expect("drum");
        let l = drum.facet_length();
        for k in 1..72 {
            let v = drum.vertex(k);
            let before = drum.vertex(k - 1);
            let after = drum.vertex(k + 1);
            let eps = 1e-10;
            // outward normals of facets k-1 and k point at the facet midpoints
            let (normal_prev, normal_next) = ((v + before).normalize(), (v + after).normalize());
            // left limit: above facet k-1 just before V_k; right limit: above facet k just after
            let left = project(&drum, &(v + (before - v) * eps + normal_prev * 0.001));
            let right = project(&drum, &(v + (after - v) * eps + normal_next * 0.001));
            assert!(
                left.coords_gradient[0].norm() > 0.99 && right.coords_gradient[0].norm() > 0.99
            );
            assert_relative_eq!(left.coords[0], k as f64 * l, epsilon = 1e-11);
            assert_relative_eq!(right.coords[0], k as f64 * l, epsilon = 1e-11);
            let mid_next = project(&drum, &((v + after) * 0.5 + normal_next * 0.001));
            let mid_prev = project(&drum, &((v + before) * 0.5 + normal_prev * 0.001));
            assert_relative_eq!(mid_next.coords[0] - mid_prev.coords[0], l, epsilon = 1e-12);
        }
        // the arc length wraps by one period n L at vertex 0
        let last = project(
            &drum,
            &(drum.vertex(0) + (drum.vertex(71) - drum.vertex(0)) * 1e-10),
        );
        let first = project(
            &drum,
            &(drum.vertex(0) + (drum.vertex(1) - drum.vertex(0)) * 1e-10),
        );
        assert_relative_eq!(last.coords[0], 72.0 * l, epsilon = 1e-11);
        assert_relative_eq!(first.coords[0], 0.0, epsilon = 1e-11);
        let slip = unwrapped_increment(drum.coords_period(), first.coords - last.coords);
        assert_relative_eq!(slip[0], 0.0, epsilon = 1e-11);
    }

    #[test]
    fn many_facets_approach_the_analytic_cylinder() {
        let axis = Vector3::new(0.2, 0.9, -0.3);
        let drum = FacetedCylinder::new(R, axis, 2000, 0.0).expect("drum");
        let circle = AnalyticCylinder::new(R, axis).expect("circle");
        let e = circle.axis();
        let b1 = circle.reference_direction();
        let b2 = e.cross(&b1);
        for i in 0..97 {
            let angle = -PI + TAU * (i as f64 + 0.37) / 97.0;
            for radius in [0.995 * R, R, 1.004 * R] {
                let y = (b1 * angle.cos() + b2 * angle.sin()) * radius + e * 0.03;
                let (f, c) = (project(&drum, &y), project(&circle, &y));
                assert!(
                    (f.gap - c.gap).abs() <= 1e-5 * R,
                    "gap {} vs {}",
                    f.gap,
                    c.gap
                );
                let arc = unwrapped_increment(drum.coords_period(), f.coords - c.coords);
                assert!(
                    arc[0].abs() <= 1e-5 * TAU * R,
                    "arc {} vs {}",
                    f.coords[0],
                    c.coords[0]
                );
                assert_relative_eq!(f.coords[1], c.coords[1], epsilon = 1e-15);
                assert!((f.gap_gradient - c.gap_gradient).norm() < 2e-3);
            }
        }
    }

    #[test]
    fn planar_point_with_z_axis() {
        let drum = FacetedCylinder::new(R, Vector3::z(), 72, 0.0).expect("drum");
        // the pad's contact point on top of the drum: y = R on the +y axis is the vertex V_18
        let p = project(&drum, &Vector3::new(0.0, R, 0.0));
        assert_relative_eq!(p.gap, 0.0, epsilon = 1e-15);
        assert_relative_eq!(p.gap_gradient, Vector3::y(), epsilon = 1e-15);
        assert_eq!(p.coords[1], 0.0);
        assert_relative_eq!(p.coords[0], 18.0 * drum.facet_length(), epsilon = 1e-14);
        assert_eq!(p.gap_gradient.z, 0.0);
        assert_eq!(p.coords_gradient[0].z, 0.0);
    }

    #[test]
    fn rotation_derivatives_through_kinematics_match_finite_differences() {
        let drum = FacetedCylinder::new(R, Vector3::z(), 72, 0.0).expect("drum");
        let h = 1e-7;
        let x_points = [
            Vector3::new(0.001, 0.2005, 0.0),
            Vector3::new(-0.05, 0.196, 0.0),
            Vector3::new(0.013, 0.2002, 0.0),
            Vector3::new(0.0301, 0.1985, 0.0),
        ];
        for angle in [0.0, 0.01, 0.7, -3.0] {
            for x in &x_points {
                let at = |theta: f64| {
                    let frame = RotatingFrame::about(Vector3::zeros(), Vector3::z(), theta);
                    evaluate(
                        &drum,
                        &frame,
                        x,
                        Some(&SurfacePoint::of_coords(Vector2::zeros())),
                    )
                    .expect("kinematics")
                };
                let (k, plus, minus) = (at(angle), at(angle + h), at(angle - h));
                let slip = unwrapped_increment(
                    drum.coords_period(),
                    plus.closest.coords - minus.closest.coords,
                );
                let fd = [plus.gap - minus.gap, slip[0], slip[1]].map(|d| d / (2.0 * h));
                for (f, e) in fd.iter().zip(k.d_drotation.map(|d| d[0])) {
                    assert!(
                        (f - e).abs() < 1e-6,
                        "x {x:?} angle {angle}: {fd:?} vs {:?}",
                        k.d_drotation
                    );
                }
            }
        }
        // on facet k the closed forms of the notes hold: dg/dtheta = (xi - 1/2) L,
        // d xi_0/dtheta = -(d + g)
        let frame = RotatingFrame::about(Vector3::zeros(), Vector3::z(), 0.0);
        let mid = 1.5 * TAU / 72.0;
        let y = polar(drum.apothem() + 0.001, mid, 0.0) + polar(0.003, mid + PI / 2.0, 0.0);
        let k = evaluate(&drum, &frame, &y, None).expect("kinematics");
        assert_relative_eq!(k.d_drotation[0][0], 0.003, epsilon = 1e-14);
        assert_relative_eq!(
            k.d_drotation[1][0],
            -(drum.apothem() + 0.001),
            epsilon = 1e-14
        );
    }
}
