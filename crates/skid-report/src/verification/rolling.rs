//! The rolling ball of the verification section: a rigid ball free to turn and translate,
//! pressed by a force `F` along `-y` onto a deformable block and launched along `+x` at `v0`
//! without spin. Coulomb friction `mu` slows its slide at `mu F / m` and spins it up about `z`
//! at `mu F R / J` until its contact point stops slipping, at
//! `t* = v0 / (mu F (1/m + R^2/J))`; then it rolls at `v* = v0 m R^2 / (J + m R^2)` (5/7 v0 for
//! a solid ball). From its `history.csv`:
//!
//! - the friction resultant never exceeds `mu N` (to [`SLIDING_TOLERANCE`]), and over
//!   `0.1 t*` to `0.5 t*`, in every increment in which every closed contact slides, it falls
//!   short of `mu N` by less than [`LATERAL_SLIP`]: each contact's friction is `mu` times its
//!   normal force against its own slip, and the block's surface bulging sideways under the ball
//!   makes the contacts on either side of `z = 0` slip slightly apart, so that their forces'
//!   sum is shorter than the sum of their sizes. This check replaces the Coulomb section's,
//!   whose last sliding increment is, for a ball, the one where the slip vanishes and the slip
//!   directions part altogether;
//! - the sliding deceleration and spin-up (least squares over `0.1 t*` to `0.9 t*`) within
//!   [`RATE_TOLERANCE`] of `mu F / m` and `mu F R / J` (the normal force follows the ball's
//!   bounce on the block, its mean within 0.4 % of `F`);
//! - the time the slip velocity `v + omega_z R`, fitted over the same span, reaches zero within
//!   [`RATE_TOLERANCE`] of `t*`;
//! - the mean speed after `1.05 t*` within [`ROLLING_TOLERANCE`] of `v*`;
//! - by symmetry about `z = 0`, no drift along `z` and no turn about `x` or `y`: each below
//!   [`SYMMETRY_TOLERANCE`] of `v0` (of `v0 / R` for the turns).

use std::fmt::Write as _;
use std::path::Path;

use super::SceneRun;
use super::friction_rows::{FrictionRow, friction_rows};
use crate::ReportError;
use crate::format::{Checks, Sig, percent};
use crate::read;
use skid_cases::csv_out::CsvTable;
use skid_cases::model_spec::{LoadSpec, ModelSpec, RigidSurfaceSpec};

/// Largest excess of `|T| / (mu N)` over 1 (the history's 10 digits).
pub const SLIDING_TOLERANCE: f64 = 1e-6;
/// Largest shortfall of `|T| / (mu N)` from 1 while every contact slides, over `0.1 t*` to
/// `0.5 t*` (measured: 3e-5; the contacts' slip directions differ by the block's lateral bulge).
pub const LATERAL_SLIP: f64 = 1e-4;
/// Largest relative error of the sliding deceleration, the spin-up and `t*` (measured: +0.14 %,
/// +0.10 % and -0.18 % on `3d-ball-rolling-on-block`).
pub const RATE_TOLERANCE: f64 = 0.01;
/// Largest relative error of the rolling speed (measured: -0.18 %; the speed swings by +-0.5 %
/// as the contact passes from node to node).
pub const ROLLING_TOLERANCE: f64 = 0.005;
/// Largest drift across the plane of symmetry, relative (measured: 1.3e-11).
pub const SYMMETRY_TOLERANCE: f64 = 1e-8;

/// A ball launched along `x` and pressed along `-y` onto a deformable block.
#[derive(Clone, Debug, PartialEq)]
pub struct RollingBall {
    /// The ball's name (its history columns' prefix).
    pub name: String,
    /// The frictional pair on it.
    pub pair: String,
    /// Friction coefficient.
    pub mu: f64,
    /// Mass `m`, kg.
    pub mass: f64,
    /// Moment of inertia `J` about `z`, kg m^2.
    pub inertia: f64,
    /// Radius `R`, m.
    pub radius: f64,
    /// The pressing force `F`, N.
    pub force: f64,
    /// Launch speed `v0`, m/s.
    pub speed: f64,
}

impl RollingBall {
    /// The ball of a 3D scene whose only rigid body is free to turn and translate, carries a
    /// sphere (a surface of revolution of arcs about one centre on its axis), is launched
    /// along `+x` without spin and pressed along `-y` by its one load, and is the master of the
    /// one frictional pair.
    pub fn recognise(spec: &ModelSpec) -> Option<Self> {
        let [body] = spec.rigid_bodies.as_slice() else {
            return None;
        };
        let [pair] = spec.contact.as_slice() else {
            return None;
        };
        let [load] = spec.loads.as_slice() else {
            return None;
        };
        let held = spec
            .boundary
            .iter()
            .any(|b| b.body.as_deref() == Some(body.name.as_str()));
        if spec.dimension != 3 || held || pair.master != body.name || pair.mu <= 0.0 {
            return None;
        }
        let Some(RigidSurfaceSpec::Revolution {
            profile, centres, ..
        }) = &body.surface
        else {
            return None;
        };
        let sphere = !centres.is_empty()
            && centres.iter().all(|c| *c == Some([0.0, 0.0]))
            && profile.first().is_some_and(|p| p[0] == 0.0)
            && profile.last().is_some_and(|p| p[0] == 0.0);
        let radius = profile.iter().map(|p| p[0]).fold(0.0, f64::max);
        let LoadSpec::Concentrated {
            body: Some(loaded),
            force: Some(force),
            moment: None,
            amplitude: None,
            ..
        } = load
        else {
            return None;
        };
        let v = body.initial_velocity.as_deref()?;
        let spin = body.initial_angular_velocity.unwrap_or([0.0; 3]);
        let [0.0, f, 0.0] = force.as_slice() else {
            return None;
        };
        let [v0, 0.0, 0.0] = v else {
            return None;
        };
        let principal = body.products_of_inertia.is_none_or(|p| p == [0.0; 3]);
        let pressed =
            loaded == &body.name && *f < 0.0 && *v0 > 0.0 && spin == [0.0; 3] && principal;
        (sphere && pressed)
            .then(|| Self {
                name: body.name.clone(),
                pair: pair.name.clone(),
                mu: pair.mu,
                mass: body.mass,
                inertia: body.moments_of_inertia.map_or(0.0, |j| j[2]),
                radius,
                force: -f,
                speed: *v0,
            })
            .filter(|ball| ball.mass > 0.0 && ball.inertia > 0.0 && ball.radius > 0.0)
    }

    /// `mu F / m`, m/s^2.
    pub fn deceleration(&self) -> f64 {
        self.mu * self.force / self.mass
    }

    /// `mu F R / J`, rad/s^2.
    pub fn spin_up(&self) -> f64 {
        self.mu * self.force * self.radius / self.inertia
    }

    /// `t* = v0 / (mu F (1/m + R^2/J))`, s.
    pub fn rolling_time(&self) -> f64 {
        self.speed / (self.deceleration() + self.spin_up() * self.radius)
    }

    /// `v* = v0 m R^2 / (J + m R^2)`, m/s.
    pub fn rolling_speed(&self) -> f64 {
        let m_r2 = self.mass * self.radius * self.radius;
        self.speed * m_r2 / (self.inertia + m_r2)
    }
}

/// One converged state of the ball.
struct BallRow {
    time: f64,
    speed: f64,
    spin: f64,
    /// `max(|v_z| / v0, |omega_x| R / v0, |omega_y| R / v0)`.
    asymmetry: f64,
}

/// What a run of the ball measured.
struct Measured {
    /// Largest `|T| / (mu N)` over the run.
    largest_ratio: f64,
    /// Largest `1 - |T| / (mu N)` over `0.1 t*` to `0.5 t*` where all contacts slide (`None`:
    /// no such increment).
    sliding: Option<f64>,
    deceleration: Option<f64>,
    spin_up: Option<f64>,
    rolling_time: Option<f64>,
    rolling_speed: Option<f64>,
    asymmetry: f64,
}

/// The slope and intercept of the least-squares line through `points`; `None` for fewer than
/// two distinct abscissae.
fn line(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    (sxx > 0.0).then(|| (sxy / sxx, my - sxy / sxx * mx))
}

/// The ball's states from a run's `history.csv` text (the dynamic ones: time > 0).
fn ball_rows(ball: &RollingBall, text: &str, path: &Path) -> Result<Vec<BallRow>, ReportError> {
    let table = CsvTable::new(text, path)?;
    let names: Vec<String> = ["v_x", "v_z", "omega_x", "omega_y", "omega_z"]
        .iter()
        .map(|what| format!("{}.{what}", ball.name))
        .collect();
    let time = table.column("time")?;
    let c = names
        .iter()
        .map(|n| table.column(n))
        .collect::<Result<Vec<_>, _>>()?;
    let mut rows = Vec::new();
    for row in table {
        let row = row?;
        let t: f64 = row.number(time)?;
        if t <= 0.0 {
            continue;
        }
        let [vx, vz, wx, wy, wz]: [f64; 5] = [
            row.number(c[0])?,
            row.number(c[1])?,
            row.number(c[2])?,
            row.number(c[3])?,
            row.number(c[4])?,
        ];
        let turn = wx.abs().max(wy.abs()) * ball.radius;
        rows.push(BallRow {
            time: t,
            speed: vx,
            spin: wz,
            asymmetry: vz.abs().max(turn) / ball.speed,
        });
    }
    Ok(rows)
}

/// `Measured` from the ball's states and its pair's friction rows.
fn measure(ball: &RollingBall, rows: &[BallRow], friction: &[FrictionRow]) -> Measured {
    let t_star = ball.rolling_time();
    let ratio = |f: &FrictionRow| f.friction() / (ball.mu * f.normal);
    let largest_ratio = friction
        .iter()
        .filter(|f| f.normal > 0.0)
        .map(ratio)
        .fold(0.0, f64::max);
    let sliding = friction
        .iter()
        .filter(|f| f.time >= 0.1 * t_star && f.time <= 0.5 * t_star && f.active > 0)
        .filter(|f| f.sliding == f.active)
        .map(|f| 1.0 - ratio(f))
        .reduce(f64::max);
    let slide: Vec<&BallRow> = rows
        .iter()
        .filter(|r| r.time >= 0.1 * t_star && r.time <= 0.9 * t_star)
        .collect();
    let fit = |value: &dyn Fn(&BallRow) -> f64| {
        line(&slide.iter().map(|r| (r.time, value(r))).collect::<Vec<_>>())
    };
    let deceleration = fit(&|r| r.speed).map(|(slope, _)| -slope);
    let spin_up = fit(&|r| r.spin).map(|(slope, _)| -slope);
    let rolling_time = fit(&|r| r.speed + r.spin * ball.radius)
        .filter(|(slope, _)| *slope < 0.0)
        .map(|(slope, intercept)| -intercept / slope);
    let rolled: Vec<f64> = rows
        .iter()
        .filter(|r| r.time >= 1.05 * t_star)
        .map(|r| r.speed)
        .collect();
    let rolling_speed =
        (!rolled.is_empty()).then(|| rolled.iter().sum::<f64>() / rolled.len() as f64);
    Measured {
        largest_ratio,
        sliding,
        deceleration,
        spin_up,
        rolling_time,
        rolling_speed,
        asymmetry: rows.iter().map(|r| r.asymmetry).fold(0.0, f64::max),
    }
}

/// The rolling balls' part of the section: a table and the checks (see the module
/// documentation).
///
/// # Errors
/// [`ReportError`] if a completed run's `history.csv` is absent or lacks the ball's or the
/// pair's columns.
pub fn section(
    runs: &[(&SceneRun, RollingBall)],
    checks: &mut Checks,
) -> Result<String, ReportError> {
    let mut out = String::from(
        "### Rolling balls\n\n\
         A ball launched without spin slides, slowed at `mu F / m` and spun up at \
         `mu F R / J`, until its contact point stops slipping at \
         `t* = v0 / (mu F (1/m + R^2/J))`; then it rolls at `v* = v0 m R^2 / (J + m R^2)`. \
         Rates fitted over `0.1 t*` to `0.9 t*`, `t*` where the fitted slip velocity \
         `v + omega_z R` vanishes, the rolling speed the mean after `1.05 t*`.\n\n\
         | run | deceleration [m/s^2] | analytic | spin-up [rad/s^2] | analytic | t* [s] \
         | analytic | rolling speed [m/s] | analytic |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let show = |v: Option<f64>| v.map_or_else(|| "n/a".to_string(), |v| Sig(v).to_string());
    for (run, ball) in runs {
        if !run.completed_or_recorded(checks) {
            continue;
        }
        let path = run.dir.join("history.csv");
        let text = read(&path)?;
        let rows = ball_rows(ball, &text, &path)?;
        let friction = friction_rows(&text, &path, &ball.pair, 3)?;
        let m = measure(ball, &rows, &friction);
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            run.name,
            show(m.deceleration),
            Sig(ball.deceleration()),
            show(m.spin_up),
            Sig(ball.spin_up()),
            show(m.rolling_time),
            Sig(ball.rolling_time()),
            show(m.rolling_speed),
            Sig(ball.rolling_speed()),
        );
        let name = &run.name;
        let relative = |value: Option<f64>, exact: f64| value.map(|v| (v / exact - 1.0).abs());
        checks.check(
            &format!("{name}: |T| <= mu N in every increment (largest |T| / (mu N) - 1)"),
            Some(m.largest_ratio - 1.0),
            SLIDING_TOLERANCE,
            "",
        );
        checks.check(
            &format!(
                "{name}: |T| short of mu N by less than {} while every contact slides \
                 (0.1 t* to 0.5 t*)",
                Sig(LATERAL_SLIP)
            ),
            m.sliding,
            LATERAL_SLIP,
            "no increment in which every contact slides",
        );
        for (what, value, exact) in [
            ("sliding deceleration", m.deceleration, ball.deceleration()),
            ("spin-up", m.spin_up, ball.spin_up()),
            ("time rolling starts", m.rolling_time, ball.rolling_time()),
        ] {
            checks.check_fraction(
                &format!(
                    "{name}: {what} within {} % of the analytic",
                    percent(Some(RATE_TOLERANCE))
                ),
                relative(value, exact),
                RATE_TOLERANCE,
                "not measurable (too few sliding increments)",
            );
        }
        checks.check_fraction(
            &format!(
                "{name}: rolling speed within {} % of v* = {}",
                percent(Some(ROLLING_TOLERANCE)),
                Sig(ball.rolling_speed())
            ),
            relative(m.rolling_speed, ball.rolling_speed()),
            ROLLING_TOLERANCE,
            "the run ends before the ball rolls",
        );
        checks.check(
            &format!("{name}: no drift along z nor turn about x or y (relative to v0)"),
            Some(m.asymmetry),
            SYMMETRY_TOLERANCE,
            "",
        );
    }
    out.push('\n');
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ball of `cases/verification/3d-ball-rolling-on-block.json`.
    fn ball() -> RollingBall {
        RollingBall {
            name: "ball".into(),
            pair: "block-ball".into(),
            mu: 0.3,
            mass: 1.0,
            inertia: 0.001,
            radius: 0.05,
            force: 9.81,
            speed: 1.0,
        }
    }

    /// A history of the ball sliding and then rolling with friction `friction` times `mu N`
    /// while it slides, 0.12 s in increments of 0.25 ms.
    fn history(friction: f64) -> String {
        let b = ball();
        let (a, alpha) = (b.deceleration() * friction, b.spin_up() * friction);
        let t_star = b.speed / (a + alpha * b.radius);
        let mut text = String::from(
            "time,ball.v_x,ball.v_z,ball.omega_x,ball.omega_y,ball.omega_z,\
             block-ball.normal_force,block-ball.tangential_force_1,\
             block-ball.tangential_force_2,block-ball.active,block-ball.sliding\n",
        );
        for k in 0..=480 {
            let t = k as f64 * 2.5e-4;
            let s = t.min(t_star);
            let (v, w) = (b.speed - a * s, -alpha * s);
            let (tangential, sliding) = if t < t_star {
                (friction * b.mu * b.force, 5)
            } else {
                (0.0, 0)
            };
            let _ = writeln!(
                text,
                "{t:.9e},{v:.9e},0,0,0,{w:.9e},{:.9e},{tangential:.9e},0,5,{sliding}",
                b.force
            );
        }
        text
    }

    fn measured(friction: f64) -> Measured {
        let (b, text, path) = (ball(), history(friction), Path::new("history.csv"));
        let rows = ball_rows(&b, &text, path).expect("ball columns");
        let pair = friction_rows(&text, path, &b.pair, 3).expect("pair columns");
        measure(&b, &rows, &pair)
    }

    #[test]
    fn the_analytic_ball_passes_and_too_little_friction_fails() {
        let b = ball();
        assert!((b.rolling_speed() - 5.0 / 7.0).abs() < 1e-15);
        assert!((b.rolling_time() - 2.0 / (7.0 * 0.3 * 9.81)).abs() < 1e-15);
        let exact = measured(1.0);
        let relative = |v: Option<f64>, e: f64| (v.expect("measured") / e - 1.0).abs();
        assert!(exact.largest_ratio - 1.0 < 1e-9);
        assert!(exact.sliding.expect("sliding increments") < 1e-9);
        assert!(relative(exact.deceleration, b.deceleration()) < 1e-6);
        assert!(relative(exact.spin_up, b.spin_up()) < 1e-6);
        assert!(relative(exact.rolling_time, b.rolling_time()) < 1e-6);
        assert!(relative(exact.rolling_speed, b.rolling_speed()) < 1e-6);
        assert_eq!(exact.asymmetry, 0.0);
        // 2 % too little friction: short of mu N, slowed and spun too little
        let weak = measured(0.98);
        assert!(weak.sliding.expect("sliding increments") > LATERAL_SLIP);
        assert!(relative(weak.deceleration, b.deceleration()) > RATE_TOLERANCE);
        assert!(relative(weak.spin_up, b.spin_up()) > RATE_TOLERANCE);
        // the rolling speed does not depend on the friction, the time it starts does
        assert!(relative(weak.rolling_speed, b.rolling_speed()) < 1e-6);
        assert!(relative(weak.rolling_time, b.rolling_time()) > RATE_TOLERANCE);
    }

    #[test]
    fn only_a_launched_pressed_sphere_is_a_rolling_ball() {
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../cases/verification/3d-ball-rolling-on-block.json"),
        )
        .expect("scene");
        let spec: ModelSpec = serde_json::from_str(&text).expect("model");
        assert_eq!(RollingBall::recognise(&spec), Some(ball()));
        let mut spinning = spec.clone();
        spinning.rigid_bodies[0].initial_angular_velocity = Some([0.0, 0.0, -1.0]);
        assert_eq!(RollingBall::recognise(&spinning), None);
        let mut held = spec.clone();
        held.boundary.push(skid_cases::model_spec::BoundarySpec {
            body: Some("ball".into()),
            node_set: None,
            dofs: vec![skid_cases::model_spec::Dof::Rz],
            value: None,
            amplitude: None,
            step_factors: None,
        });
        assert_eq!(RollingBall::recognise(&held), None);
        let mut cylinder = spec;
        cylinder.rigid_bodies[0].surface = Some(RigidSurfaceSpec::Cylinder {
            radius: 0.05,
            axis: [0.0, 0.0, 1.0],
        });
        assert_eq!(RollingBall::recognise(&cylinder), None);
    }
}
