//! What `verify` reports: one [`CheckResult`] per check id and file, serialised exactly as format.md's
//! `--json` shape (`{"files": [{"path", "exit_code", "verdict", "problem", "checks": [{"id", "status",
//! "value", "tolerance", "reason"}]}]}`).

use serde::Serialize;

coin_log_names::named_enum! {
    /// The checks, with the contract's ids (format.md: verify), in report order.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
    #[serde(rename_all = "lowercase")]
    pub enum CheckId: "check" {
        /// File structure, indexes, CRCs, statistics, schemas, message shapes and times.
        Integrity = "integrity",
        /// Energy recomputed from the stored state; its drift and agreement with `/coin/energy`.
        Energy = "energy",
        /// Chaplygin–Appell integrals C1, C2 (physics §6).
        Invariants = "invariants",
        /// Steady motions stay steady (physics §4).
        Steady = "steady",
        /// The rolling constraint: centre velocity from positions against a(−ω_Z e_X + ω_X e_Z).
        Constraint = "constraint",
        /// Channels agree with each other (quaternion, contact, height, reaction).
        Consistency = "consistency",
        /// The model is valid: N ≥ 0 and |F| ≤ μN.
        Validity = "validity",
        /// The nutation period and heading advance per period against the quadrature (physics §10).
        Nutation = "nutation",
    }
}

impl CheckId {
    /// The checks a file must run to be verified (format.md: verify): integrity, energy, and constraint
    /// or steady (the motion).
    pub const REQUIRED: [Self; 4] = [
        Self::Integrity,
        Self::Energy,
        Self::Constraint,
        Self::Steady,
    ];
}

coin_log_names::named_enum! {
    /// Outcome of one check.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
    #[serde(rename_all = "lowercase")]
    pub enum Status: "status" {
        /// Ran and the value is within tolerance.
        Pass = "pass",
        /// Ran and the value is outside tolerance (or the file cannot support it).
        Fail = "fail",
        /// Could not run; the reason says why.
        Skip = "skip",
    }
}

/// One check's result: the measured value, its tolerance, and a sentence saying what was measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckResult {
    /// Which check.
    pub id: CheckId,
    /// Pass, fail or skip.
    pub status: Status,
    /// The measured value (dimensionless unless the reason says otherwise); `None` when skipped.
    pub value: Option<f64>,
    /// The tolerance it was held to.
    pub tolerance: Option<f64>,
    /// What was measured, where the worst case is, or why the check could not run.
    pub reason: String,
}

impl CheckResult {
    /// A check that ran: pass when `value ≤ tolerance`.
    #[must_use]
    pub fn measured(id: CheckId, value: f64, tolerance: f64, reason: String) -> Self {
        let status = if value <= tolerance {
            Status::Pass
        } else {
            Status::Fail
        };
        Self {
            id,
            status,
            value: Some(value),
            tolerance: Some(tolerance),
            reason,
        }
    }

    /// A check that could not run.
    #[must_use]
    pub fn skip(id: CheckId, reason: impl Into<String>) -> Self {
        Self {
            id,
            status: Status::Skip,
            value: None,
            tolerance: None,
            reason: reason.into(),
        }
    }
}

coin_log_names::named_enum! {
    /// The overall status of one file (format.md: verify, Output).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
    #[serde(rename_all = "kebab-case")]
    pub enum Verdict: "verdict" {
        /// Every check that ran passed, and the required ones ran (exit 0).
        Ok = "ok",
        /// A check failed (exit 1).
        Failed = "failed",
        /// No check failed, but the required checks could not run: `energy`, or both `constraint` and
        /// `steady` (exit 1, as a failure, for scripts that only read the exit code).
        CannotVerify = "cannot-verify",
        /// The file is unreadable, truncated, corrupt, not MCAP or not a coin-log file (exit 2).
        Unusable = "unusable",
    }
}

impl Verdict {
    /// The exit code of a file with this verdict.
    #[must_use]
    pub fn exit_code(self) -> u8 {
        match self {
            Self::Ok => 0,
            Self::Failed | Self::CannotVerify => 1,
            Self::Unusable => 2,
        }
    }

    /// How the table shows it.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::Failed => "FAILED",
            Self::CannotVerify => "CANNOT VERIFY",
            Self::Unusable => "UNUSABLE",
        }
    }
}

/// The verdict on one file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FileReport {
    /// The path as given.
    pub path: String,
    /// 0 every check that ran passed, 1 a check failed or the file cannot be verified, 2 unreadable /
    /// truncated / corrupt / not MCAP / not a coin-log file.
    pub exit_code: u8,
    /// The overall status; `exit_code` follows from it.
    pub verdict: Verdict,
    /// Why the file is unusable or cannot be verified, in one sentence; `None` when every check ran or
    /// the checks' reasons say it all.
    pub problem: Option<String>,
    /// The checks, in [`CheckId::ALL`] order (empty when the file could not be read at all).
    pub checks: Vec<CheckResult>,
}

impl FileReport {
    /// A file that could not be read at all, and why (exit 2).
    #[must_use]
    pub fn unusable(path: String, problem: String) -> Self {
        Self {
            path,
            exit_code: Verdict::Unusable.exit_code(),
            verdict: Verdict::Unusable,
            problem: Some(problem),
            checks: Vec::new(),
        }
    }

    /// The result of check `id`, if it is in the report.
    #[must_use]
    pub fn check(&self, id: CheckId) -> Option<&CheckResult> {
        self.checks.iter().find(|c| c.id == id)
    }
}

/// The verdict on several files (the `--json` document).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// One entry per file, in the order given.
    pub files: Vec<FileReport>,
}

impl Report {
    /// The worst exit code: 2 > 1 > 0.
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        self.files.iter().map(|f| f.exit_code).max().unwrap_or(0)
    }
}
