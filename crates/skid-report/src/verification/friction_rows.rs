//! A contact pair's resultants per increment, read from a model run's `history.csv`: the normal
//! force `N`, the friction resultant's components `T` in the surface's tangent directions, and
//! how many contacts are closed and sliding; and the tolerance to which the Coulomb scenes
//! balance them against their loads.

use std::path::Path;

use crate::ReportError;
use skid_cases::csv_out::CsvTable;

/// Largest difference between the resultants of a sticking block and its held loads, as a
/// fraction of `mu N` (measured: 6e-7 on the pushed block at half of `mu N`, 4e-10 on the
/// incline at 0.995 of its threshold).
pub const BALANCE_TOLERANCE: f64 = 1e-5;

/// A pair's resultants in one increment of the history.
pub(super) struct FrictionRow {
    pub time: f64,
    pub normal: f64,
    /// The friction resultant's components in the surface's tangent directions.
    pub tangential: Vec<f64>,
    pub active: usize,
    pub sliding: usize,
}

impl FrictionRow {
    /// `|T|`.
    pub fn friction(&self) -> f64 {
        self.tangential.iter().map(|t| t * t).sum::<f64>().sqrt()
    }
}

/// The rows of `pair` in a model run's `history.csv` text of dimension `dimension`.
pub(super) fn friction_rows(
    text: &str,
    path: &Path,
    pair: &str,
    dimension: usize,
) -> Result<Vec<FrictionRow>, ReportError> {
    let table = CsvTable::new(text, path)?;
    let names: Vec<String> = (1..dimension)
        .map(|k| format!("{pair}.tangential_force_{k}"))
        .chain(["normal_force", "active", "sliding"].map(|what| format!("{pair}.{what}")))
        .chain(["time".to_string()])
        .collect();
    let columns = names
        .iter()
        .map(|n| table.column(n))
        .collect::<Result<Vec<_>, _>>()?;
    let (tangential, rest) = columns.split_at(dimension - 1);
    let [normal, active, sliding, time] = [rest[0], rest[1], rest[2], rest[3]];
    let mut rows = Vec::new();
    for row in table {
        let row = row?;
        rows.push(FrictionRow {
            time: row.number(time)?,
            normal: row.number(normal)?,
            tangential: tangential
                .iter()
                .map(|&c| row.number(c))
                .collect::<Result<_, _>>()?,
            active: row.number(active)?,
            sliding: row.number(sliding)?,
        });
    }
    Ok(rows)
}
