//! `FILLET RADIUS` of an analytical surface: every corner of its profile (where two pieces meet
//! with different directions) rounded by the circle of that radius tangent to both.
//!
//! At a corner `V` where the travel turns by the angle `phi` (counter-clockwise positive), the
//! fillet's centre `F` lies on the side the profile turns to, at distance `r` from both pieces:
//! it is the intersection, nearest to `V`, of the two pieces' curves offset by `r` to that side
//! (a line moves along its normal; a circle of radius `R` traversed with orientation `s`
//! (`+1` counter-clockwise) becomes the circle of radius `R - sigma s r` about the same centre,
//! `sigma = sign(phi)`). The fillet touches the pieces at the feet `T_in`, `T_out` of `F` on
//! them, which must lie on the pieces, and runs from `T_in` to `T_out` about `F`, turning by
//! `phi` (under 180 degrees, as every arc of a profile). The pieces are trimmed to the tangent
//! points; a piece that both its fillets consume entirely is dropped, and one they would
//! overlap on is refused.

use nalgebra::Vector2;
use std::f64::consts::PI;

use super::Piece;

/// `v` turned 90 degrees counter-clockwise.
fn perp(v: &Vector2<f64>) -> Vector2<f64> {
    Vector2::new(-v.y, v.x)
}

/// The curve a piece lies on, with its direction of travel.
#[derive(Clone, Copy, Debug)]
enum Curve {
    /// The line through `point` along the unit `direction`.
    Line {
        point: Vector2<f64>,
        direction: Vector2<f64>,
    },
    /// The circle about `centre` of `radius`, traversed counter-clockwise (`turn = 1`) or
    /// clockwise (`turn = -1`).
    Circle {
        centre: Vector2<f64>,
        radius: f64,
        turn: f64,
    },
}

impl Curve {
    /// The curve of `piece` from `from`.
    fn of(from: &Vector2<f64>, piece: &Piece) -> Option<Self> {
        match piece {
            Piece::Line { end } => Some(Self::Line {
                point: *from,
                direction: (end - from).try_normalize(0.0)?,
            }),
            Piece::Arc { end, centre } => {
                let (a, b) = (from - centre, end - centre);
                Some(Self::Circle {
                    centre: *centre,
                    radius: a.norm(),
                    turn: a.perp(&b).signum(),
                })
            }
        }
    }

    /// The unit direction of travel at `p` on the curve.
    fn tangent(&self, p: &Vector2<f64>) -> Vector2<f64> {
        match self {
            Self::Line { direction, .. } => *direction,
            Self::Circle {
                centre,
                radius,
                turn,
            } => perp(&(p - centre)) * (*turn / radius),
        }
    }

    /// The curve at signed distance `d` to the left of the travel; `None` for a circle that
    /// would shrink to nothing.
    fn offset(&self, d: f64) -> Option<Self> {
        match *self {
            Self::Line { point, direction } => Some(Self::Line {
                point: point + perp(&direction) * d,
                direction,
            }),
            Self::Circle {
                centre,
                radius,
                turn,
            } => {
                let radius = radius - turn * d;
                (radius > 0.0).then_some(Self::Circle {
                    centre,
                    radius,
                    turn,
                })
            }
        }
    }

    /// The closest point to `p` on the curve (`p` off a circle's centre).
    fn foot(&self, p: &Vector2<f64>) -> Vector2<f64> {
        match self {
            Self::Line { point, direction } => point + direction * direction.dot(&(p - point)),
            Self::Circle { centre, radius, .. } => centre + (p - centre).normalize() * *radius,
        }
    }

    /// The points where the curve meets `other`.
    fn intersections(&self, other: &Self) -> Vec<Vector2<f64>> {
        match (*self, *other) {
            (
                Self::Line {
                    point: p,
                    direction: t,
                },
                Self::Line {
                    point: q,
                    direction: u,
                },
            ) => {
                // p + a t = q + b u
                let det = t.perp(&u);
                if det.abs() <= 1e-12 {
                    return Vec::new();
                }
                vec![p + t * ((q - p).perp(&u) / det)]
            }
            (Self::Line { point, direction }, Self::Circle { centre, radius, .. })
            | (Self::Circle { centre, radius, .. }, Self::Line { point, direction }) => {
                // |point + a direction - centre| = radius
                let w = point - centre;
                let half_b = direction.dot(&w);
                let discriminant = half_b * half_b - (w.norm_squared() - radius * radius);
                if discriminant < 0.0 {
                    return Vec::new();
                }
                let root = discriminant.sqrt();
                vec![
                    point + direction * (-half_b - root),
                    point + direction * (-half_b + root),
                ]
            }
            (
                Self::Circle {
                    centre: c1,
                    radius: r1,
                    ..
                },
                Self::Circle {
                    centre: c2,
                    radius: r2,
                    ..
                },
            ) => {
                let d = c2 - c1;
                let distance = d.norm();
                if distance == 0.0 {
                    return Vec::new();
                }
                // the chord's foot on the line of centres, and its half length
                let a = (r1 * r1 - r2 * r2 + distance * distance) / (2.0 * distance);
                let h2 = r1 * r1 - a * a;
                if h2 < 0.0 {
                    return Vec::new();
                }
                let e = d / distance;
                let foot = c1 + e * a;
                let h = h2.sqrt();
                vec![foot + perp(&e) * h, foot - perp(&e) * h]
            }
        }
    }
}

/// Where `p` (on the piece's curve) lies along the piece from `from` to `to`: 0 at its start, 1
/// at its end.
fn along(curve: &Curve, from: &Vector2<f64>, to: &Vector2<f64>, p: &Vector2<f64>) -> f64 {
    match curve {
        Curve::Line { direction, .. } => direction.dot(&(p - from)) / direction.dot(&(to - from)),
        Curve::Circle { centre, turn, .. } => {
            let angle = |q: &Vector2<f64>| {
                let (a, b) = (from - centre, q - centre);
                turn * a.perp(&b).atan2(a.dot(&b))
            };
            angle(p) / angle(to)
        }
    }
}

/// A fillet: the tangent points on the incoming and outgoing pieces and the centre.
#[derive(Clone, Copy, Debug)]
struct Fillet {
    incoming: Vector2<f64>,
    outgoing: Vector2<f64>,
    centre: Vector2<f64>,
}

/// The profile from `start` along `pieces` with each corner rounded by a fillet of `radius`
/// (see the module documentation); `closed` if its end is its start (the corner there is
/// rounded too, and the new start is the tangent point after it). Pieces shorter than `tol`
/// are dropped. Errors name the corner: the index of its point (0 the start, `k` the end of
/// piece `k - 1`) and why no fillet fits there.
pub(super) fn fillet(
    start: &Vector2<f64>,
    pieces: &[Piece],
    closed: bool,
    radius: f64,
    tol: f64,
) -> Result<(Vector2<f64>, Vec<Piece>), (usize, String)> {
    let m = pieces.len();
    let points: Vec<Vector2<f64>> = std::iter::once(*start)
        .chain(pieces.iter().map(Piece::end))
        .collect();
    let curves = (0..m)
        .map(|k| {
            Curve::of(&points[k], &pieces[k])
                .ok_or_else(|| (k + 1, "the LINE ending here has zero length".to_string()))
        })
        .collect::<Result<Vec<Curve>, _>>()?;
    // fillets[k]: at point k, between piece k - 1 (piece m - 1 for the start of a closed
    // profile) and piece k
    let mut fillets: Vec<Option<Fillet>> = vec![None; m];
    let first = if closed { 0 } else { 1 };
    for k in first..m {
        let before = if k == 0 { m - 1 } else { k - 1 };
        let corner = points[k];
        let (t_in, t_out) = (curves[before].tangent(&corner), curves[k].tangent(&corner));
        let turn = t_in.perp(&t_out).atan2(t_in.dot(&t_out));
        if turn.abs() <= 1e-9 {
            continue;
        }
        let fail = |why: &str| (k, why.to_string());
        if PI - turn.abs() <= 1e-9 {
            return Err(fail("the profile turns back on itself: no fillet fits"));
        }
        let side = turn.signum() * radius;
        let too_tight = "FILLET RADIUS is not smaller than the radius of the arc inside the corner";
        let incoming = curves[before].offset(side).ok_or_else(|| fail(too_tight))?;
        let outgoing = curves[k].offset(side).ok_or_else(|| fail(too_tight))?;
        let centre = incoming
            .intersections(&outgoing)
            .into_iter()
            .min_by(|a, b| (a - corner).norm().total_cmp(&(b - corner).norm()))
            .ok_or_else(|| fail("no circle of FILLET RADIUS touches both pieces"))?;
        let fillet = Fillet {
            incoming: curves[before].foot(&centre),
            outgoing: curves[k].foot(&centre),
            centre,
        };
        let on_incoming = along(
            &curves[before],
            &points[before],
            &points[before + 1],
            &fillet.incoming,
        );
        let on_outgoing = along(&curves[k], &points[k], &points[k + 1], &fillet.outgoing);
        let inside = |s: f64| (-1e-9..=1.0 + 1e-9).contains(&s);
        if !(inside(on_incoming) && inside(on_outgoing)) {
            return Err(fail(
                "FILLET RADIUS is too large for the pieces that meet here",
            ));
        }
        fillets[k] = Some(fillet);
    }
    let new_start = fillets[0].map_or(*start, |f| f.outgoing);
    let mut out = Vec::with_capacity(2 * m);
    for k in 0..m {
        let next = if k + 1 == m { 0 } else { k + 1 };
        let at_end = (k + 1 < m || closed).then(|| fillets[next]).flatten();
        let from = fillets[k].map_or(points[k], |f| f.outgoing);
        let to = at_end.map_or(points[k + 1], |f| f.incoming);
        let (s0, s1) = (
            along(&curves[k], &points[k], &points[k + 1], &from),
            along(&curves[k], &points[k], &points[k + 1], &to),
        );
        if s0 > s1 + 1e-9 {
            return Err((
                k + 1,
                "FILLET RADIUS is too large: the fillets at both ends of the piece ending here \
                 overlap"
                    .to_string(),
            ));
        }
        if (to - from).norm() > tol {
            out.push(match pieces[k] {
                Piece::Line { .. } => Piece::Line { end: to },
                Piece::Arc { centre, .. } => Piece::Arc { end: to, centre },
            });
        }
        if let Some(f) = at_end {
            out.push(Piece::Arc {
                end: f.outgoing,
                centre: f.centre,
            });
        }
    }
    Ok((new_start, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(x: f64, y: f64) -> Piece {
        Piece::Line {
            end: Vector2::new(x, y),
        }
    }

    fn arc(x: f64, y: f64, cx: f64, cy: f64) -> Piece {
        Piece::Arc {
            end: Vector2::new(x, y),
            centre: Vector2::new(cx, cy),
        }
    }

    /// The direction of travel at the start and at the end of each piece from `start`.
    fn tangents(start: &Vector2<f64>, pieces: &[Piece]) -> Vec<(Vector2<f64>, Vector2<f64>)> {
        let mut from = *start;
        pieces
            .iter()
            .map(|p| {
                let curve = Curve::of(&from, p).expect("piece");
                let end = p.end();
                let t = (curve.tangent(&from), curve.tangent(&end));
                from = end;
                t
            })
            .collect()
    }

    /// Asserts that the profile has no corner: each piece leaves in the direction the one
    /// before it arrived (and the last piece arrives as the first leaves, if `closed`), and
    /// that each arc's ends are at its radius from its centre.
    fn assert_smooth(start: &Vector2<f64>, pieces: &[Piece], closed: bool) {
        let t = tangents(start, pieces);
        for k in 1..t.len() {
            assert!(
                (t[k - 1].1 - t[k].0).norm() < 1e-9,
                "corner before piece {k}"
            );
        }
        if closed {
            assert!((t[t.len() - 1].1 - t[0].0).norm() < 1e-9, "corner at start");
        }
        let mut from = *start;
        for p in pieces {
            if let Piece::Arc { end, centre } = p {
                let (a, b) = ((from - centre).norm(), (end - centre).norm());
                assert!((a - b).abs() < 1e-12, "arc ends at {a} and {b}");
            }
            from = p.end();
        }
    }

    #[test]
    fn a_right_angle_gets_a_quarter_circle() {
        // travel +x then -y: a right turn; the centre lies to the right of both lines
        let start = Vector2::new(-1.0, 0.0);
        let (s, pieces) = fillet(
            &start,
            &[line(0.0, 0.0), line(0.0, -1.0)],
            false,
            0.1,
            1e-12,
        )
        .expect("fits");
        assert_eq!(s, start);
        assert_eq!(pieces.len(), 3);
        let expected = [line(-0.1, 0.0), arc(0.0, -0.1, -0.1, -0.1), line(0.0, -1.0)];
        for (p, e) in pieces.iter().zip(&expected) {
            let (Piece::Line { end: a } | Piece::Arc { end: a, .. }) = p;
            let (Piece::Line { end: b } | Piece::Arc { end: b, .. }) = e;
            assert!((a - b).norm() < 1e-12, "{p:?} against {e:?}");
        }
        let Piece::Arc { centre, .. } = pieces[1] else {
            panic!("fillet is an arc")
        };
        assert!((centre - Vector2::new(-0.1, -0.1)).norm() < 1e-12);
        assert_smooth(&s, &pieces, false);
    }

    #[test]
    fn a_closed_square_gets_four_fillets_and_starts_after_the_first() {
        let start = Vector2::new(0.0, 0.0);
        let square = [
            line(1.0, 0.0),
            line(1.0, 1.0),
            line(0.0, 1.0),
            line(0.0, 0.0),
        ];
        let (s, pieces) = fillet(&start, &square, true, 0.25, 1e-12).expect("fits");
        assert!((s - Vector2::new(0.25, 0.0)).norm() < 1e-12);
        assert_eq!(pieces.len(), 8);
        let last = match pieces[7] {
            Piece::Arc { end, .. } => end,
            Piece::Line { .. } => panic!("the profile ends with the fillet at its start"),
        };
        assert!((last - s).norm() < 1e-12, "closed");
        assert_smooth(&s, &pieces, true);
        // half the side: the fillets meet, the lines vanish
        let (s, pieces) = fillet(&start, &square, true, 0.5, 1e-12).expect("fits");
        assert_eq!(pieces.len(), 4, "{pieces:?}");
        assert_smooth(&s, &pieces, true);
        let err = fillet(&start, &square, true, 0.6, 1e-12).expect_err("too large");
        assert!(err.1.contains("too large"), "{err:?}");
    }

    #[test]
    fn corners_between_lines_and_arcs_are_rounded_tangentially() {
        // a line into a clockwise quarter circle, turning left by 45 degrees, a second one
        // after it, turning left by 90 degrees (a valley between two bumps), and a line
        let start = Vector2::new(-1.0, 0.0);
        let pieces = [
            line(0.0, 0.0),
            arc(1.0, 0.0, 0.5, -0.5),
            arc(2.0, 0.0, 1.5, -0.5),
            line(3.0, 1.0),
        ];
        let (s, rounded) = fillet(&start, &pieces, false, 0.05, 1e-12).expect("fits");
        assert_eq!(rounded.len(), 7, "{rounded:?}");
        assert_smooth(&s, &rounded, false);
        // three fillets of the radius, the two arcs trimmed on their own circles
        let mut from = s;
        let mut radii = Vec::new();
        for p in &rounded {
            if let Piece::Arc { centre, .. } = p {
                radii.push((from - centre).norm());
            }
            from = p.end();
        }
        radii.sort_by(f64::total_cmp);
        let expected = [0.05, 0.05, 0.05, 0.5_f64.sqrt(), 0.5_f64.sqrt()];
        assert_eq!(radii.len(), expected.len());
        for (r, e) in radii.iter().zip(expected) {
            assert!((r - e).abs() < 1e-12, "{radii:?}");
        }
        // a smooth joint is left alone
        let smooth = [line(0.0, 0.0), arc(1.0, -1.0, 0.0, -1.0)];
        let (_, kept) = fillet(&start, &smooth, false, 0.1, 1e-12).expect("nothing to round");
        assert_eq!(kept, smooth.to_vec());
    }

    #[test]
    fn radii_that_do_not_fit_are_refused_at_their_corner() {
        let start = Vector2::new(-1.0, 0.0);
        // a left turn of 45 degrees into a counter-clockwise arc of radius 0.1: the fillet
        // would lie inside that arc, which 0.2 does not fit
        let c = Vector2::new(-0.1, 0.1) / 2.0_f64.sqrt();
        let pieces = [line(0.0, 0.0), arc(0.0, 0.2 / 2.0_f64.sqrt(), c.x, c.y)];
        let err = fillet(&start, &pieces, false, 0.2, 1e-12).expect_err("too tight");
        assert_eq!(err.0, 1, "{err:?}");
        assert!(err.1.contains("not smaller"), "{err:?}");
        fillet(&start, &pieces, false, 0.05, 1e-12).expect("fits inside the arc");
        // a hairpin
        let pieces = [line(0.0, 0.0), line(-0.5, 0.0)];
        let err = fillet(&start, &pieces, false, 0.1, 1e-12).expect_err("hairpin");
        assert!(err.1.contains("turns back"), "{err:?}");
        // a short piece before the corner
        let pieces = [line(-0.95, 0.0), line(-0.95, 1.0)];
        let err = fillet(&start, &pieces, false, 0.1, 1e-12).expect_err("short");
        assert_eq!(err.0, 1, "{err:?}");
    }
}
