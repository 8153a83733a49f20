//! Time projecting 10^4 points onto triangulated surfaces of 10^2 to 10^5 triangles.
//!
//! Each surface is a closed "cube sphere": every face of the cube `[-1, 1]^3` divided into
//! `k x k` squares, each split into two triangles, with the vertices pushed onto the unit sphere
//! (`12 k^2` triangles). The query points lie on a golden-angle spiral in the shell
//! `0.9 <= |y| <= 1.1`. The table gives, per surface, the time to build it, to project every point
//! with [`RigidSurface::project`], and, up to about 10^4 triangles, to find every point's distance
//! by a scan over all triangles (skipping those whose bounding sphere is farther than the best so
//! far); the scan also checks the projections' gaps.
//!
//! Run with `cargo run --release -p skid-contact --example projection_cost`.

use std::collections::HashMap;
use std::hint::black_box;
use std::time::Instant;

use nalgebra::Vector3;
use skid_contact::{CylinderChart, RigidSurface, TriangulatedSurface};

const POINTS: usize = 10_000;

/// Vertices and outward counter-clockwise triangles of the cube sphere with `k x k` squares a face.
fn cube_sphere(k: usize) -> (Vec<Vector3<f64>>, Vec<[usize; 3]>) {
    let mut vertices = Vec::new();
    let mut index: HashMap<[usize; 3], usize> = HashMap::new();
    let mut vertex = |p: [usize; 3]| {
        *index.entry(p).or_insert_with(|| {
            let cube = Vector3::from(p.map(|i| 2.0 * i as f64 / k as f64 - 1.0));
            vertices.push(cube.normalize());
            vertices.len() - 1
        })
    };
    let mut triangles = Vec::with_capacity(12 * k * k);
    for axis in 0..3 {
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0, k] {
            for u in 0..k {
                for v in 0..k {
                    let mut corner = |du: usize, dv: usize| {
                        let mut p = [0; 3];
                        (p[axis], p[b], p[c]) = (side, u + du, v + dv);
                        vertex(p)
                    };
                    let [p00, p10, p11, p01] =
                        [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                    // (b, c) turns counter-clockwise about +axis: reverse on the low side
                    if side == k {
                        triangles.extend([[p00, p10, p11], [p00, p11, p01]]);
                    } else {
                        triangles.extend([[p00, p11, p10], [p00, p01, p11]]);
                    }
                }
            }
        }
    }
    (vertices, triangles)
}

/// One triangle for the scan: corners, unit normal and bounding sphere.
struct Scanned {
    corners: [Vector3<f64>; 3],
    normal: Vector3<f64>,
    centre: Vector3<f64>,
    bound: f64,
}

impl Scanned {
    fn new(corners: [Vector3<f64>; 3]) -> Self {
        let [a, b, c] = corners;
        let centre = (a + b + c) / 3.0;
        Self {
            corners,
            normal: (b - a).cross(&(c - a)).normalize(),
            centre,
            bound: corners
                .iter()
                .map(|p| (p - centre).norm())
                .fold(0.0, f64::max),
        }
    }

    /// Distance from `y`: to the plane if the projection falls inside, else to the nearest edge.
    fn distance(&self, y: &Vector3<f64>) -> f64 {
        let [a, b, c] = self.corners;
        let height = self.normal.dot(&(y - a));
        let in_plane = y - self.normal * height;
        let closed = [a, b, c, a];
        let edges = closed.windows(2).map(|e| (e[0], e[1] - e[0]));
        if edges
            .clone()
            .all(|(start, edge)| edge.cross(&(in_plane - start)).dot(&self.normal) >= 0.0)
        {
            return height.abs();
        }
        edges
            .map(|(start, edge)| {
                let t = ((y - start).dot(&edge) / edge.norm_squared()).clamp(0.0, 1.0);
                (y - start - edge * t).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// Distance from `y` to the nearest of `triangles`, skipping those whose bounding sphere lies
/// farther than the best so far.
fn scan(y: &Vector3<f64>, triangles: &[Scanned]) -> f64 {
    let mut best = f64::INFINITY;
    for triangle in triangles {
        if (y - triangle.centre).norm() - triangle.bound <= best {
            best = best.min(triangle.distance(y));
        }
    }
    best
}

/// Result of `run` and its fastest wall time in ms over three runs (the machine may be shared).
fn fastest<T>(mut run: impl FnMut() -> T) -> (T, f64) {
    let mut best = f64::INFINITY;
    let mut result = None;
    for _ in 0..3 {
        let start = Instant::now();
        result = Some(black_box(run()));
        best = best.min(start.elapsed().as_secs_f64() * 1e3);
    }
    (result.expect("three runs"), best)
}

fn main() {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let points: Vec<Vector3<f64>> = (0..POINTS)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / POINTS as f64;
            let (s, c) = (golden * i as f64).sin_cos();
            let radius = 0.9 + 0.2 * (i as f64 * 2f64.sqrt()).fract();
            Vector3::new(c, s, 0.0) * ((1.0 - z * z).sqrt() * radius) + Vector3::z() * (z * radius)
        })
        .collect();
    let chart = CylinderChart {
        radius: 1.0,
        axis: Vector3::z(),
    };
    println!("{POINTS} points; fastest of three runs, in ms");
    println!("triangles      build    project       scan");
    for k in [3, 9, 29, 91] {
        let (vertices, triangles) = cube_sphere(k);
        let (surface, build) = fastest(|| {
            TriangulatedSurface::new(vertices.clone(), triangles.clone(), chart)
                .expect("a closed cube sphere is a valid mesh")
        });
        let (gaps, project) = fastest(|| -> Vec<Option<f64>> {
            points
                .iter()
                .map(|y| surface.project(y).map(|p| p.gap))
                .collect()
        });
        let mut scan_time = "-".to_string();
        if triangles.len() < 20_000 {
            let scanned: Vec<Scanned> = triangles
                .iter()
                .map(|t| Scanned::new(t.map(|i| vertices[i])))
                .collect();
            let (distances, time) =
                fastest(|| -> Vec<f64> { points.iter().map(|y| scan(y, &scanned)).collect() });
            for (gap, distance) in gaps.iter().zip(&distances) {
                if let Some(gap) = gap {
                    assert!((gap.abs() - distance).abs() <= 1e-12, "{gap} vs {distance}");
                }
            }
            scan_time = format!("{time:.2}");
        }
        println!(
            "{:>9} {build:>10.2} {project:>10.2} {scan_time:>10}",
            triangles.len()
        );
    }
}
