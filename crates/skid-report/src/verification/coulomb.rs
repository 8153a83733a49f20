//! The Coulomb part of the verification section: every run of a scene with a frictional pair,
//! checked against Coulomb's law from its `history.csv`, per pair:
//!
//! - the friction resultant never exceeds `mu` times the normal one, `|T| <= mu N (1 + tol)`,
//!   in any increment; and, unless the scene must stick, in the last increment in which every
//!   closed contact slides (there must be one), `|T| = mu N` to [`COULOMB_TOLERANCE`] (in 3D
//!   the slip directions settle first, and the resultant of forces in different directions is
//!   short of `mu N` until they have; a block that must stick may slide for a moment as its
//!   loading sets it vibrating, as the 3D pushed block at 0.99 mu N does at the end of its
//!   ramp, while its slip directions have not settled);
//! - a block on a fixed flat ([`BlockOnFlat`]), whose held loads decide: if they exceed the
//!   friction limit, every closed contact slides over the settled hold; if not, none slides
//!   there, and the friction and normal resultants balance the held loads to
//!   [`BALANCE_TOLERANCE`] of `mu N`. A dynamic step's contact forces act as impulses: those of a
//!   contact that sticks alternate about the static value from one increment to the next, so
//!   the balance is judged on the mean of the last two increments;
//! - runs of one scene that differ only in the size of their loads (a family: the same model
//!   but for names, descriptions and load values) and that stick and slide bracket the
//!   threshold: the one that sticks at the largest ratio `r` and the one that slides at the
//!   smallest must both behave as predicted, within [`THRESHOLD_BRACKET`] of `r = 1`;
//! - a block moved over a fixed flat by prescribed motions ([`MovedBlock`]): the reactions
//!   along the flat balance the friction ([`reactions`]).

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::SceneRun;
use super::friction_rows::{BALANCE_TOLERANCE, FrictionRow, friction_rows};
use super::reactions::{self, MovedRun};
use crate::ReportError;
use crate::block_on_flat::BlockOnFlat;
use crate::format::{Checks, percent, show};
use crate::moved_block::MovedBlock;
use crate::read;
use skid_cases::model_spec::ContactPairSpec;

/// Relative tolerance of the Coulomb checks (the history carries 10 significant digits).
pub const COULOMB_TOLERANCE: f64 = 1e-6;
/// Largest distance from `r = 1` of the runs that bracket a family's stick/slip threshold.
pub const THRESHOLD_BRACKET: f64 = 0.01;

/// What a block on a flat did over its settled hold, against what its loads predict.
struct HeldState {
    scene: BlockOnFlat,
    /// The increments of the settled hold.
    increments: usize,
    /// The most contacts sliding in any of them, and the fewest closed.
    most_sliding: usize,
    fewest_active: usize,
    /// `|T|` and `N` of the mean of the last two increments.
    mean: Option<(f64, f64)>,
}

impl HeldState {
    fn of(scene: BlockOnFlat, rows: &[FrictionRow]) -> Self {
        let settled: Vec<&FrictionRow> = rows
            .iter()
            .filter(|r| r.time >= scene.settled_from())
            .collect();
        let mean = match settled.as_slice() {
            [.., a, b] => {
                let t: f64 = a
                    .tangential
                    .iter()
                    .zip(&b.tangential)
                    .map(|(x, y)| (0.5 * (x + y)).powi(2))
                    .sum();
                Some((t.sqrt(), 0.5 * (a.normal + b.normal)))
            }
            _ => None,
        };
        Self {
            increments: settled.len(),
            most_sliding: settled.iter().map(|r| r.sliding).max().unwrap_or(0),
            fewest_active: settled.iter().map(|r| r.active).min().unwrap_or(0),
            mean,
            scene,
        }
    }

    /// Every settled increment has closed contacts, and they all slide (if the scene must
    /// slide) or none does (if it must stick).
    fn as_predicted(&self) -> bool {
        self.increments >= 2
            && self.fewest_active > 0
            && if self.scene.sticks() {
                self.most_sliding == 0
            } else {
                self.most_sliding == self.fewest_active
            }
    }

    /// The largest difference of the mean resultants from the held loads, over `mu N`.
    fn balance_error(&self) -> Option<f64> {
        let (t, n) = self.mean?;
        let limit = self.scene.mu * self.scene.normal;
        Some(((t - self.scene.tangential).abs()).max((n - self.scene.normal).abs()) / limit)
    }

    /// The table's cell: the ratio, the verdict and what slid.
    fn cell(&self) -> String {
        format!(
            "{} ({}): {} of {} closed slide",
            show(Some(self.scene.ratio())),
            if self.scene.sticks() {
                "sticks"
            } else {
                "slides"
            },
            self.most_sliding,
            self.fewest_active
        )
    }
}

/// The Coulomb part of the section (see the module documentation).
pub(super) fn section(runs: &[&SceneRun], checks: &mut Checks) -> Result<String, ReportError> {
    let mut out = String::from(
        "### Coulomb friction of the block scenes\n\n\
         Per frictional pair, from `history.csv`: the largest `|T| / (mu N)` over all \
         increments, and `|T| / (mu N)` in the last increment in which every closed contact \
         slides. For a block on a fixed flat, the held loads' `r = T / (mu N)`, whether \
         Coulomb's law lets it stick, and the most contacts that slide (of the fewest closed) \
         over the second half of the hold.\n\n\
         | run | pair | mu | increments | max \\|T\\| / (mu N) | last sliding increment \
         | there: \\|T\\| / (mu N) | held loads: r |\n|---|---|---|---|---|---|---|---|\n",
    );
    let mut families: BTreeMap<String, Vec<(&str, HeldState)>> = BTreeMap::new();
    let mut moved = Vec::new();
    for run in runs {
        if !run.completed_or_recorded(checks) {
            continue;
        }
        let path = run.dir.join("history.csv");
        let text = read(&path)?;
        let block = BlockOnFlat::recognise(&run.spec);
        if let Some(block) = MovedBlock::recognise(&run.spec) {
            moved.push(MovedRun {
                run,
                rows: friction_rows(&text, &path, &block.pair, run.spec.dimension)?,
                block,
                history: text.clone(),
            });
        }
        for pair in run.spec.contact.iter().filter(|p| p.mu > 0.0) {
            let rows = friction_rows(&text, &path, &pair.name, run.spec.dimension)?;
            let held = block
                .clone()
                .filter(|b| b.pair == pair.name)
                .map(|b| HeldState::of(b, &rows));
            let must_stick = held.as_ref().is_some_and(|h| h.scene.sticks());
            pair_checks(&mut out, checks, run, pair, &rows, must_stick);
            let _ = writeln!(
                out,
                " {} |",
                held.as_ref().map_or_else(|| "-".into(), HeldState::cell)
            );
            if let Some(held) = held {
                held_checks(checks, &format!("{} ({})", run.name, pair.name), &held);
                families
                    .entry(family(run)?)
                    .or_default()
                    .push((run.name.as_str(), held));
            }
        }
    }
    for members in families.values() {
        bracket_check(&mut out, checks, members);
    }
    out.push_str(&reactions::section(&moved, checks)?);
    Ok(out)
}

/// The checks of every frictional pair, and its table row but for the last cell.
fn pair_checks(
    out: &mut String,
    checks: &mut Checks,
    run: &SceneRun,
    pair: &ContactPairSpec,
    rows: &[FrictionRow],
    must_stick: bool,
) {
    let mu = pair.mu;
    let label = format!("{} ({})", run.name, pair.name);
    let ratio = |r: &FrictionRow| (r.normal > 0.0).then(|| r.friction() / (mu * r.normal));
    let worst = rows.iter().filter_map(ratio).reduce(f64::max);
    let last_sliding = rows
        .iter()
        .rposition(|r| r.active > 0 && r.sliding == r.active);
    let last = last_sliding.map(|k| &rows[k]);
    let _ = write!(
        out,
        "| {} | {} | {} | {} | {} | {} | {} |",
        run.name,
        pair.name,
        mu,
        rows.len(),
        show(worst),
        last_sliding.map_or_else(|| "none".into(), |k| format!("{} of {}", k + 1, rows.len())),
        show(last.and_then(ratio)),
    );
    checks.record(
        &format!("{label}: |T| <= mu N in every increment"),
        worst.is_some_and(|w| w <= 1.0 + COULOMB_TOLERANCE),
        format!("largest |T| / (mu N) {}", show(worst)),
    );
    if must_stick {
        return;
    }
    checks.record(
        &format!("{label}: |T| = mu N in the last increment in which every contact slides"),
        last.and_then(ratio)
            .is_some_and(|v| (v - 1.0).abs() <= COULOMB_TOLERANCE),
        last.map_or_else(
            || "no increment in which every closed contact slides".into(),
            |r| {
                format!(
                    "{} contacts sliding, |T| / (mu N) = {}",
                    r.sliding,
                    show(ratio(r))
                )
            },
        ),
    );
}

/// The stick or slip of a block on a flat over its settled hold, and a sticking block's
/// balance.
fn held_checks(checks: &mut Checks, label: &str, held: &HeldState) {
    let scene = &held.scene;
    let from = format!("from t = {} s", show(Some(scene.settled_from())));
    let what = if scene.sticks() {
        "no contact slides"
    } else {
        "every closed contact slides"
    };
    checks.record(
        &format!(
            "{label}: held loads at r = T / (mu N) = {}: {what} {from}",
            show(Some(scene.ratio()))
        ),
        held.as_predicted(),
        format!(
            "{} increments, at most {} sliding of at least {} closed",
            held.increments, held.most_sliding, held.fewest_active
        ),
    );
    if scene.sticks() {
        let error = held.balance_error();
        checks.record(
            &format!("{label}: the friction and normal resultants balance the held loads"),
            error.is_some_and(|e| e <= BALANCE_TOLERANCE),
            held.mean.map_or_else(
                || "fewer than two increments in the settled hold".into(),
                |(t, n)| {
                    format!(
                        "|T| {} N against {} N, N {} N against {} N: {} of mu N",
                        show(Some(t)),
                        show(Some(scene.tangential)),
                        show(Some(n)),
                        show(Some(scene.normal)),
                        show(error)
                    )
                },
            ),
        );
    }
}

/// The family of a run: its model without names, descriptions and the values of its loads.
///
/// # Errors
/// [`ReportError::Parse`] should its model not serialize.
fn family(run: &SceneRun) -> Result<String, ReportError> {
    let mut value = serde_json::to_value(&run.spec).map_err(|e| ReportError::Parse {
        path: run.dir.clone(),
        message: format!("its model does not serialize: {e}"),
    })?;
    if let Some(map) = value.as_object_mut() {
        map.remove("name");
        map.remove("description");
        if let Some(loads) = map.get_mut("loads").and_then(|l| l.as_array_mut()) {
            for load in loads.iter_mut().filter_map(|l| l.as_object_mut()) {
                for field in ["force", "moment", "acceleration", "pressure"] {
                    load.remove(field);
                }
            }
        }
    }
    Ok(value.to_string())
}

/// The threshold check of a family with runs that stick and runs that slide (see the module
/// documentation); nothing for other families.
fn bracket_check(out: &mut String, checks: &mut Checks, members: &[(&str, HeldState)]) {
    let closest = |sticks: bool| {
        members
            .iter()
            .filter(|(_, h)| h.scene.sticks() == sticks)
            .min_by(|(_, a), (_, b)| {
                let d = |h: &HeldState| (h.scene.ratio() - 1.0).abs();
                d(a).total_cmp(&d(b))
            })
    };
    let (Some((below, low)), Some((above, high))) = (closest(true), closest(false)) else {
        return;
    };
    let (r_low, r_high) = (low.scene.ratio(), high.scene.ratio());
    let _ = writeln!(
        out,
        "\nThe stick/slip threshold of {below} and {above}: between r = {} and r = {}.\n",
        show(Some(r_low)),
        show(Some(r_high))
    );
    checks.record(
        &format!(
            "{below} and {above}: the stick/slip threshold lies at r = 1 within {} %",
            percent(Some(THRESHOLD_BRACKET))
        ),
        low.as_predicted()
            && high.as_predicted()
            && 1.0 - r_low <= THRESHOLD_BRACKET
            && r_high - 1.0 <= THRESHOLD_BRACKET,
        format!(
            "{below} at r = {} {}, {above} at r = {} {}",
            show(Some(r_low)),
            if low.as_predicted() {
                "sticks"
            } else {
                "does not stick"
            },
            show(Some(r_high)),
            if high.as_predicted() {
                "slides"
            } else {
                "does not slide"
            },
        ),
    );
}
