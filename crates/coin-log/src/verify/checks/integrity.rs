//! `integrity`: the file's structure, schemas, message shapes and log times (format.md: verify, Checks).
//! The value is the number of problems found; the tolerance is 0.

use crate::verify::report::{CheckId, CheckResult};
use coin_log_mcap::BoundedFindings;

/// The integrity result from the problems found and a description of what was read.
#[must_use]
pub fn finish(problems: &BoundedFindings, read: &str, notes: &[String]) -> CheckResult {
    let mut reason = if problems.is_empty() {
        format!("{read}: structure, indexes, CRCs, statistics, schemas, message shapes and times are consistent")
    } else {
        format!("{read}: {}", problems.summary())
    };
    for n in notes {
        reason.push_str("; ");
        reason.push_str(n);
    }
    #[allow(clippy::cast_precision_loss)]
    CheckResult::measured(CheckId::Integrity, problems.total() as f64, 0.0, reason)
}
