//! Number formatting, check lists and check counts shared by the report's sections.

use std::fmt::Write as _;

/// How many acceptance checks passed, failed and were skipped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Passed.
    pub passed: usize,
    /// Failed.
    pub failed: usize,
    /// Skipped because a run is absent.
    pub skipped: usize,
}

impl std::ops::AddAssign for Counts {
    fn add_assign(&mut self, other: Self) {
        self.passed += other.passed;
        self.failed += other.failed;
        self.skipped += other.skipped;
    }
}

impl Counts {
    /// The closing line of a check list: `N passed, N failed, N skipped`.
    pub fn line(&self) -> String {
        let mut s = String::new();
        let _ = write!(
            s,
            "{} passed, {} failed, {} skipped",
            self.passed, self.failed, self.skipped
        );
        s
    }
}

/// An acceptance list being written: one markdown line per check, and the counts.
#[derive(Debug, Default)]
pub struct Checks {
    /// The list so far.
    pub text: String,
    /// Its counts.
    pub counts: Counts,
}

impl Checks {
    /// A check that `value < limit`; `None` (not measurable) fails, `why` says why.
    pub fn check(&mut self, label: &str, value: Option<f64>, limit: f64, why: &str) {
        match value {
            Some(v) => self.record(label, v < limit, Sig(v).to_string()),
            None => self.record(label, false, why.to_string()),
        }
    }

    /// [`Self::check`] of a relative difference, shown in percent.
    pub fn check_fraction(&mut self, label: &str, value: Option<f64>, limit: f64, why: &str) {
        match value {
            Some(v) => self.record(label, v < limit, format!("{} %", Sig(100.0 * v))),
            None => self.record(label, false, why.to_string()),
        }
    }

    /// A check that passed (`ok`) or failed, with what it found.
    pub fn record(&mut self, label: &str, ok: bool, shown: String) {
        let verdict = if ok {
            self.counts.passed += 1;
            "PASS"
        } else {
            self.counts.failed += 1;
            "FAIL"
        };
        let _ = writeln!(self.text, "- **{verdict}** {label}: {shown}");
    }

    /// A check that could not be made, and why.
    pub fn skip(&mut self, label: &str, why: &str) {
        self.counts.skipped += 1;
        let _ = writeln!(self.text, "- SKIPPED {label}: {why}");
    }
}

/// A number to 4 significant digits, plainly or in exponent form.
pub struct Sig(pub f64);

impl std::fmt::Display for Sig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        if !v.is_finite() {
            return write!(f, "{v}");
        }
        if v == 0.0 || (1e-3..1e5).contains(&v.abs()) {
            let magnitude = if v == 0.0 {
                0
            } else {
                v.abs().log10().floor() as i32
            };
            let digits = (3 - magnitude).clamp(0, 7) as usize;
            write!(f, "{v:.digits$}")
        } else {
            write!(f, "{v:.3e}")
        }
    }
}

/// [`Sig`], or `n/a`.
pub fn show(v: Option<f64>) -> String {
    v.map_or_else(|| "n/a".into(), |v| Sig(v).to_string())
}

/// A limit as written by hand: at most 6 decimals, trailing zeros dropped (`2`, `0.5`).
pub fn plain(v: f64) -> String {
    let s = format!("{v:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// A fraction shown in percent ([`show`] of `100 v`).
pub fn percent(v: Option<f64>) -> String {
    show(v.map(|v| 100.0 * v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sig_shows_four_significant_digits() {
        assert_eq!(Sig(0.100738).to_string(), "0.1007");
        assert_eq!(Sig(60.0).to_string(), "60.00");
        assert_eq!(Sig(0.0).to_string(), "0.000");
        assert_eq!(Sig(2.5e-5).to_string(), "2.500e-5");
        assert_eq!(Sig(-1.5e6).to_string(), "-1.500e6");
        assert_eq!(Sig(f64::NAN).to_string(), "NaN");
        assert_eq!(percent(Some(0.0123)), "1.230");
        assert_eq!(show(None), "n/a");
        assert_eq!(plain(100.0 * 0.03), "3");
        assert_eq!(plain(0.5), "0.5");
        assert_eq!(plain(1e-6), "0.000001");
    }

    #[test]
    fn counts_add_up_and_print() {
        let mut a = Counts {
            passed: 1,
            failed: 2,
            skipped: 3,
        };
        a += a;
        assert_eq!(a.line(), "2 passed, 4 failed, 6 skipped");
    }
}
