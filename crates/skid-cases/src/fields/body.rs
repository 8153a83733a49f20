//! A rigid body's frame: a finite drawing of its contact surface in its current pose, with the
//! rigid-body velocity field (the drawings are described in the documentation of
//! [`crate::fields`]).

use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::io;

use nalgebra::{SVector, Vector3};
use skid_contact::kinematics::Turning;
use skid_contact::surface::{RigidSurface, SurfaceShape};
use skid_fem::cell::embed;
use skid_integrator::{Model, State};

use super::invalid_data;
use super::vtu::{DataArray, Grid};

/// Segments of a drawn cylinder around its circumference.
pub const CIRCLE_SEGMENTS: usize = 144;
/// Margin of the drawing of an unbounded surface beyond the part at each end, as a fraction of
/// the part's extent in that direction.
pub const MARGIN: f64 = 0.25;

/// Points and cells of a drawing, in one frame.
struct Drawing {
    points: Vec<Vector3<f64>>,
    cells: Vec<Vec<usize>>,
}

/// Rigid body `body`'s `surface` in its current pose in `state`, drawn over the part whose
/// nodes are at `current`, with point data `velocity` = `v_c + omega x (x - c)` (m/s), `omega`
/// the spatial angular velocity: `omega e` about a fixed axis `e`, `Q W` for a body free to turn
/// with body-frame angular velocity `W`.
pub(super) fn body_grid<const D: usize>(
    model: &Model<D>,
    state: &State,
    body: usize,
    surface: &dyn RigidSurface,
    current: &[Vector3<f64>],
) -> io::Result<Grid> {
    let frame = model.body_frame(&state.x, body, &state.orientations);
    let name = &model.bodies()[body].name;
    let degenerate = || invalid_data(format!("rigid body '{name}': its frame is not finite"));
    let around = current
        .iter()
        .map(|x| frame.to_body(x))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(degenerate)?;
    let drawing = draw(&surface.shape(), &around, D == 2);
    let points = drawing
        .points
        .iter()
        .map(|y| frame.to_world(y))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(degenerate)?;
    let dofs = model.dofs();
    let equations = dofs.body_translation(body);
    let translation = embed(&SVector::<f64, D>::from_fn(|i, _| {
        equations[i].map_or(0.0, |eq| state.v[eq])
    }));
    let rates = Vector3::from_fn(|i, _| {
        dofs.body_rotations(body)
            .get(i)
            .map_or(0.0, |&eq| state.v[eq])
    });
    let spin = match frame.turning {
        Turning::About(axis) => axis.into_inner() * rates[0],
        Turning::Free(axes) => frame.orientation * (axes * rates),
    };
    let velocity: Vec<Vector3<f64>> = points
        .iter()
        .map(|p| translation + spin.cross(&(p - frame.center)))
        .collect();
    Ok(Grid {
        points,
        cells: drawing.cells,
        point_data: vec![DataArray::vectors("velocity", &velocity)],
        cell_data: Vec::new(),
    })
}

/// The drawing of `shape` (body frame) over the body-frame points `around`; `planar`: 2D.
fn draw(shape: &SurfaceShape, around: &[Vector3<f64>], planar: bool) -> Drawing {
    match shape {
        SurfaceShape::Cylinder {
            radius,
            axis,
            reference,
        } => {
            let across = axis.cross(reference);
            let ring = (0..CIRCLE_SEGMENTS)
                .map(|k| {
                    let (sin, cos) = (TAU * k as f64 / CIRCLE_SEGMENTS as f64).sin_cos();
                    (reference * cos + across * sin) * *radius
                })
                .collect();
            extrude(ring, axis, around, planar, true)
        }
        SurfaceShape::Prism { axis, vertices } => {
            extrude(vertices.clone(), axis, around, planar, true)
        }
        SurfaceShape::Extrusion {
            axis,
            reference,
            profile,
            closed,
        } => {
            let up = axis.cross(reference);
            let section = profile.iter().map(|p| reference * p.x + up * p.y).collect();
            extrude(section, axis, around, planar, *closed)
        }
        SurfaceShape::Plane { normal, tangents } if planar => {
            // the in-plane direction whose clockwise turn is the normal
            let along = Vector3::z()
                .cross(normal)
                .try_normalize(1e-12)
                .unwrap_or(tangents[0]);
            let [low, high] = span(around, &along);
            Drawing {
                points: vec![along * low, along * high],
                cells: vec![vec![0, 1]],
            }
        }
        SurfaceShape::Plane { tangents, .. } => {
            let [t1, t2] = tangents;
            let ([a0, a1], [b0, b1]) = (span(around, t1), span(around, t2));
            Drawing {
                points: vec![
                    t1 * a0 + t2 * b0,
                    t1 * a1 + t2 * b0,
                    t1 * a1 + t2 * b1,
                    t1 * a0 + t2 * b1,
                ],
                cells: vec![vec![0, 1, 2, 3]],
            }
        }
        SurfaceShape::Revolution {
            axis,
            reference,
            profile,
            closed,
        } => {
            // a ring of points per profile point, quadrilaterals between consecutive rings
            let across = axis.cross(reference);
            let points = profile
                .iter()
                .flat_map(|p| {
                    (0..CIRCLE_SEGMENTS).map(move |k| {
                        let (sin, cos) = (TAU * k as f64 / CIRCLE_SEGMENTS as f64).sin_cos();
                        (reference * cos + across * sin) * p.x + axis * p.y
                    })
                })
                .collect();
            let rings = profile.len();
            let bands = if *closed {
                rings
            } else {
                rings.saturating_sub(1)
            };
            let at = |ring: usize, k: usize| (ring % rings) * CIRCLE_SEGMENTS + k % CIRCLE_SEGMENTS;
            let cells = (0..bands)
                .flat_map(|j| {
                    (0..CIRCLE_SEGMENTS)
                        .map(move |k| vec![at(j, k), at(j, k + 1), at(j + 1, k + 1), at(j + 1, k)])
                })
                .collect();
            Drawing { points, cells }
        }
        SurfaceShape::Polyline { vertices, closed } => {
            extrude(vertices.clone(), &Vector3::z(), around, true, *closed)
        }
        SurfaceShape::Triangles(triangles) => {
            // shared corners become shared points
            let mut index: BTreeMap<[u64; 3], usize> = BTreeMap::new();
            let mut points = Vec::new();
            let cells = triangles
                .iter()
                .map(|corners| {
                    corners
                        .iter()
                        .map(|c| {
                            *index.entry(c.map(f64::to_bits).into()).or_insert_with(|| {
                                points.push(*c);
                                points.len() - 1
                            })
                        })
                        .collect()
                })
                .collect();
            Drawing { points, cells }
        }
    }
}

/// The polygon `ring` (closed if `closed`; counter-clockwise about `axis` when it is): in 2D
/// its lines; in 3D the band of quadrilaterals between its copies at both ends of the span of
/// `around` along `axis`.
fn extrude(
    ring: Vec<Vector3<f64>>,
    axis: &Vector3<f64>,
    around: &[Vector3<f64>],
    planar: bool,
    closed: bool,
) -> Drawing {
    let n = ring.len();
    let next = |k: usize| (k + 1) % n;
    let sides = if closed { n } else { n.saturating_sub(1) };
    if planar {
        return Drawing {
            points: ring,
            cells: (0..sides).map(|k| vec![k, next(k)]).collect(),
        };
    }
    let [low, high] = span(around, axis);
    let points = [low, high]
        .iter()
        .flat_map(|&a| ring.iter().map(move |p| p + axis * a))
        .collect();
    Drawing {
        points,
        cells: (0..sides)
            .map(|k| vec![k, next(k), n + next(k), n + k])
            .collect(),
    }
}

/// The range `[lo - m, hi + m]` of `p . direction` over the points, `m = MARGIN (hi - lo)`.
fn span(points: &[Vector3<f64>], direction: &Vector3<f64>) -> [f64; 2] {
    let (lo, hi) = points
        .iter()
        .map(|p| p.dot(direction))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    let margin = MARGIN * (hi - lo);
    [lo - margin, hi + margin]
}
