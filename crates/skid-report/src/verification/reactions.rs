//! The reactions of blocks moved over a fixed flat by prescribed motions ([`MovedBlock`]),
//! checked from `history.csv`: in every increment, the component along the flat of the
//! prescribed motions' reactions, `|R_t|`, equals the friction resultant `|T|`, and, in every
//! increment in which every closed contact slides (there must be one), `mu N`, both to
//! [`BALANCE_TOLERANCE`] of `mu N` (Newton's force tolerance is 1e-6 of the forces; the
//! history carries 10 significant digits).

use std::fmt::Write as _;

use super::SceneRun;
use super::friction_rows::{BALANCE_TOLERANCE, FrictionRow};
use crate::ReportError;
use crate::format::{Checks, show};
use crate::moved_block::MovedBlock;
use skid_cases::csv_out::CsvTable;

/// `|R_t|` and the pair's resultants in one increment.
struct Balance {
    along_flat: f64,
    friction: f64,
    normal: f64,
    sliding: bool,
}

/// A completed run of a moved block, with its history's text and its pair's rows.
pub(super) struct MovedRun<'a> {
    pub run: &'a SceneRun,
    pub block: MovedBlock,
    pub history: String,
    pub rows: Vec<FrictionRow>,
}

/// The table and checks of the moved blocks `runs`; empty if there is none.
pub(super) fn section(runs: &[MovedRun<'_>], checks: &mut Checks) -> Result<String, ReportError> {
    let mut out = String::new();
    for MovedRun {
        run,
        block,
        history,
        rows,
    } in runs
    {
        if out.is_empty() {
            out.push_str(
                "\n### Reactions of the moved blocks\n\n\
                 Blocks moved over a fixed flat by prescribed motions in static steps: the \
                 component along the flat of the reactions' resultant, `|R_t|`, against the \
                 friction resultant `|T|` in every increment, and against `mu N` where every \
                 closed contact slides, as fractions of `mu N`.\n\n\
                 | run | pair | increments | max \\|\\|R_t\\| - \\|T\\|\\| / (mu N) \
                 | sliding increments | there: max \\|\\|R_t\\| - mu N\\| / (mu N) |\n\
                 |---|---|---|---|---|---|\n",
            );
        }
        let balances = balances(block, run, history, rows)?;
        let limit = |b: &Balance| block.mu * b.normal;
        let against_friction = balances
            .iter()
            .filter(|b| b.normal > 0.0)
            .map(|b| (b.along_flat - b.friction).abs() / limit(b))
            .reduce(f64::max);
        let sliding: Vec<&Balance> = balances.iter().filter(|b| b.sliding).collect();
        let against_mu_n = sliding
            .iter()
            .map(|b| (b.along_flat - limit(b)).abs() / limit(b))
            .reduce(f64::max);
        let label = format!("{} ({})", run.name, block.pair);
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} |",
            run.name,
            block.pair,
            balances.len(),
            show(against_friction),
            sliding.len(),
            show(against_mu_n)
        );
        checks.record(
            &format!(
                "{label}: the reactions along the flat balance the friction in every increment"
            ),
            against_friction.is_some_and(|e| e <= BALANCE_TOLERANCE),
            format!("largest ||R_t| - |T|| {} of mu N", show(against_friction)),
        );
        checks.record(
            &format!("{label}: the reactions along the flat are mu N while every contact slides"),
            against_mu_n.is_some_and(|e| e <= BALANCE_TOLERANCE),
            format!(
                "{} sliding increments, largest ||R_t| - mu N| {} of mu N",
                sliding.len(),
                show(against_mu_n)
            ),
        );
    }
    Ok(out)
}

/// `|R_t|` and the pair's resultants in each row of the history `text`.
fn balances(
    block: &MovedBlock,
    run: &SceneRun,
    text: &str,
    rows: &[FrictionRow],
) -> Result<Vec<Balance>, ReportError> {
    let path = run.dir.join("history.csv");
    let table = CsvTable::new(text, &path)?;
    let columns = block
        .reactions
        .iter()
        .map(|(axis, name)| Ok((*axis, table.column(name)?)))
        .collect::<Result<Vec<_>, ReportError>>()?;
    let mut out = Vec::new();
    for (row, pair) in table.zip(rows) {
        let row = row?;
        let mut resultant = [0.0; 3];
        for &(axis, column) in &columns {
            resultant[axis] += row.number::<f64>(column)?;
        }
        out.push(Balance {
            along_flat: block.along_flat(&resultant),
            friction: pair.friction(),
            normal: pair.normal,
            sliding: pair.active > 0 && pair.sliding == pair.active,
        });
    }
    Ok(out)
}
