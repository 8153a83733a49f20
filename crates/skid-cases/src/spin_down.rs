//! The measures of a spin-down (DRUM.md section 2) from a body's rotation history: the stop
//! time, the deceleration while it slides and what it does after the stop. The drum case's
//! summary and the report's reading of model runs share them.

/// One state of a turning body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinPoint {
    /// Time, s.
    pub time: f64,
    /// Angle, rad.
    pub angle: f64,
    /// Angular velocity, rad/s.
    pub omega: f64,
}

/// A spin-down measured from its history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinDown {
    /// First time `omega` reaches zero from the sign of `omega0` (linear interpolation between
    /// the two states that bracket it), from the first state, s.
    pub t_stop: Option<f64>,
    /// Least-squares deceleration `-sign(omega0) d omega/dt` over the states in
    /// `[0.1, 0.9] t_stop` (over every state if it does not stop), rad/s^2.
    pub deceleration: Option<f64>,
    /// Largest `|omega|` after the stop, rad/s.
    pub post_stop_max_abs_omega: Option<f64>,
    /// Largest `|angle - angle(t_stop)|` after the stop, rad.
    pub post_stop_max_angle_change: Option<f64>,
}

impl SpinDown {
    /// Measures the spin-down of `points` (the dynamic history, time non-decreasing, its first
    /// state where it starts) from the initial angular velocity `omega0`.
    pub fn measure(points: &[SpinPoint], omega0: f64) -> Self {
        let t0 = points.first().map_or(0.0, |p| p.time);
        let stop = first_stop(points, omega0);
        let t_stop = stop.map(|(t, _)| t - t0);
        let sliding = match t_stop {
            Some(ts) => window(points, 0.1 * ts, 0.9 * ts),
            None => points.to_vec(),
        };
        let after: Vec<&SpinPoint> = match stop {
            Some((ts, _)) => points.iter().filter(|p| p.time > ts).collect(),
            None => Vec::new(),
        };
        Self {
            t_stop,
            deceleration: slope(&sliding).map(|s| -s * omega0.signum()),
            post_stop_max_abs_omega: stop
                .map(|_| after.iter().map(|p| p.omega.abs()).fold(0.0, f64::max)),
            post_stop_max_angle_change: stop.map(|(_, angle)| {
                after
                    .iter()
                    .map(|p| (p.angle - angle).abs())
                    .fold(0.0, f64::max)
            }),
        }
    }
}

/// The states of `points` whose time from the first is within `[lo, hi]`.
pub fn window(points: &[SpinPoint], lo: f64, hi: f64) -> Vec<SpinPoint> {
    let t0 = points.first().map_or(0.0, |p| p.time);
    points
        .iter()
        .copied()
        .filter(|p| p.time - t0 >= lo && p.time - t0 <= hi)
        .collect()
}

/// Time and angle, linearly interpolated, where `omega` first crosses zero from the sign of
/// `omega0`.
fn first_stop(points: &[SpinPoint], omega0: f64) -> Option<(f64, f64)> {
    let sign = omega0.signum();
    points.windows(2).find_map(|w| {
        let (a, b) = (w[0], w[1]);
        (a.omega * sign > 0.0 && b.omega * sign <= 0.0).then(|| {
            let s = a.omega / (a.omega - b.omega);
            (
                a.time + s * (b.time - a.time),
                a.angle + s * (b.angle - a.angle),
            )
        })
    })
}

/// Least-squares slope of omega(t).
fn slope(points: &[SpinPoint]) -> Option<f64> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let mt = points.iter().map(|p| p.time).sum::<f64>() / n;
    let mw = points.iter().map(|p| p.omega).sum::<f64>() / n;
    let sxy: f64 = points.iter().map(|p| (p.time - mt) * (p.omega - mw)).sum();
    let sxx: f64 = points.iter().map(|p| (p.time - mt).powi(2)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}
