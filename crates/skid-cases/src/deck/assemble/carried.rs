//! Loads and prescribed motions carried into later steps with a step-time amplitude. Abaqus
//! holds such a load, in the steps that do not give it again, at its amplitude's value at the
//! end of the step that gave it; the model reads every amplitude afresh in each step. Unless the
//! amplitude holds that value over the later steps anyway, the load gets a total-time amplitude
//! of its own, `<amplitude>@<step>` (step counted from 1): the step-time table up to the end of
//! the giving step, shifted to the total time at that step's start, and held at its end value
//! after, which is exactly Abaqus's history of it.

use skid_integrator::Amplitude;

use super::*;
use crate::model_spec::{AmplitudeSpec, AmplitudeTime};

/// The time period of step `k` of the deck (that of its procedure line; 1 without one, which
/// is refused elsewhere).
fn step_period(defs: &Definitions, k: usize) -> f64 {
    match defs.steps[k].procedure {
        Some((Procedure::Static { period, .. } | Procedure::Dynamic { period, .. }, _)) => period,
        None => 1.0,
    }
}

/// The amplitudes that carried loads and motions follow instead of their own.
#[derive(Default)]
pub(super) struct Frozen {
    /// The generated total-time amplitudes, in the order made.
    pub amplitudes: Vec<AmplitudeSpec>,
    /// The lines whose loads or motions follow one: (step that gave it, line) -> its name.
    renamed: Vec<((usize, Location), String)>,
}

impl Frozen {
    /// Notes that the load or motion of the line `location`, given in step `given` with the
    /// amplitude `name`, is in force in step `step`: if it is carried there (`step > given`)
    /// with a step-time amplitude that does not hold its value at the end of step `given`
    /// over the whole of step `step`, it follows a generated total-time amplitude from then
    /// on (see the module documentation).
    pub fn note(
        &mut self,
        defs: &Definitions,
        name: &str,
        (given, step): (usize, usize),
        location: &Location,
    ) {
        let Some(amplitude) = defs.amplitudes.get(&key(name)) else {
            return;
        };
        let key = (given, location.clone());
        if step == given
            || amplitude.value.time == AmplitudeTime::Total
            || self.renamed.iter().any(|(k, _)| *k == key)
        {
            return;
        }
        let points = &amplitude.value.points;
        // the reader checked the table (times from 0, increasing, finite numbers)
        let Ok(table) = Amplitude::new(points.clone()) else {
            return;
        };
        let end = step_period(defs, given);
        let held = table.at(end);
        let period = step_period(defs, step);
        let holds = table.at(0.0) == held
            && table.at(period) == held
            && points
                .iter()
                .filter(|&&(t, _)| t > 0.0 && t < period)
                .all(|&(_, a)| a == held);
        if holds {
            return;
        }
        let frozen = format!("{name}@{}", given + 1);
        if !self.amplitudes.iter().any(|a| a.name == frozen) {
            let start: f64 = (0..given).map(|k| step_period(defs, k)).sum();
            let mut table: Vec<[f64; 2]> = points
                .iter()
                .filter(|&&(t, _)| t < end)
                .map(|&(t, a)| [start + t, a])
                .collect();
            table.push([start + end, held]);
            self.amplitudes.push(AmplitudeSpec {
                name: frozen.clone(),
                points: table,
                time: AmplitudeTime::Total,
            });
        }
        self.renamed.push((key, frozen));
    }

    /// The amplitude that the load or motion of the line `location`, given in step `given`,
    /// follows in the model, if it is a generated one.
    pub fn of(&self, given: usize, location: &Location) -> Option<&String> {
        self.renamed
            .iter()
            .find(|((g, l), _)| *g == given && l == location)
            .map(|(_, name)| name)
    }
}
