//! The catalogue, one CSV row per run (format.md: The catalogue, which gives its CSV and its columns).
//! Every column but `wall_time_s` depends only on the sweep and the run's index, so that a sharded
//! sweep's collected catalogue equals the one-process one.

use crate::format::metadata::number_string as number;
use crate::format::Termination;
use crate::record::RecordSummary;
use crate::verify::Verdict;

coin_log_names::named_enum! {
    /// Whether a run finished (recorded to its end or to a physical event, and verified when asked).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    pub enum RunStatus: "status" {
        /// Recorded, and verified `ok` when the sweep verifies.
        Finished = "finished",
        /// Not: the `failure` and `reason` columns say why.
        Failed = "failed",
    }
}

coin_log_names::named_enum! {
    /// What made a run fail.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    pub enum FailureKind: "failure" {
        /// The values give no valid scene (or a bounded draw found no value): no file.
        Scene = "scene",
        /// The integration failed (step-size underflow, non-finite, Newton failure): the file holds the
        /// samples up to the failure.
        Numerical = "numerical",
        /// The file was recorded, but `verify` did not judge it `ok`.
        Verify = "verify",
        /// Writing the file failed (a full disk, a lost folder): no file. Redone on resume.
        Io = "io",
    }
}

/// Whether a row's `status`, `failure`, `file` and `verify` cells agree as a run writes them: a finished
/// run, and one that failed in its numerics or its verdict, has a file; one that failed on its scene or
/// on I/O has none; a file's `verify` cell is `off` exactly when the sweep does not verify (`verifies`
/// `None`: not known, not checked).
pub fn consistent([status, failure, file, verify]: [&str; 4], verifies: Option<bool>) -> bool {
    let wants_file = match (status.parse(), failure.parse()) {
        (Ok(RunStatus::Finished), _) if failure.is_empty() => true,
        (Ok(RunStatus::Failed), Ok(FailureKind::Numerical | FailureKind::Verify)) => true,
        (Ok(RunStatus::Failed), Ok(FailureKind::Scene | FailureKind::Io)) => false,
        _ => return false,
    };
    let has_file = !file.is_empty();
    has_file == wants_file && (!has_file || verifies.is_none_or(|v| v != (verify == "off")))
}

/// The run index in an `index` cell as a run writes it (`+01` parses as 1, and a row kept with that
/// cell would not be the run's).
pub fn index_of(cell: &str) -> Option<u64> {
    cell.parse().ok().filter(|i: &u64| i.to_string() == cell)
}

/// The catalogue's header: `index`, one column per swept key (named by the key), then the rest.
pub fn columns<'a>(keys: impl Iterator<Item = &'a str>) -> Vec<String> {
    let blank = Row::failed(0, Vec::new(), FailureKind::Scene);
    let trailing = blank.trailing().map(|(column, _)| column);
    let columns = std::iter::once("index").chain(keys).chain(trailing);
    columns.map(str::to_string).collect()
}

/// What `analyse` predicts for a run's initial state, by quadrature of the conservative motion
/// (format.md: The catalogue): the motion, the stability of the steady motion the run starts on (or,
/// perturbed, starts from) and how the run should end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Prediction {
    pub motion: &'static str,
    pub stability: Option<&'static str>,
    pub termination: Termination,
}

/// A recorded run: its file's name in the folder and SHA-256, `record`'s summary and `verify`'s verdict
/// (when the sweep verifies).
#[derive(Debug, Clone, PartialEq)]
pub struct Recorded {
    pub file: String,
    pub sha256: String,
    pub summary: RecordSummary,
    pub verify: Option<Verdict>,
}

/// One run's row: the swept keys' values as cells ([`cell`]), the failure's detail (empty for a finished
/// run), and the wall time of the run (resolve, record, hash, verify) in seconds.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub index: u64,
    pub values: Vec<String>,
    pub status: RunStatus,
    pub failure: Option<FailureKind>,
    pub reason: String,
    pub recorded: Option<Recorded>,
    pub prediction: Option<Prediction>,
    pub wall_time: f64,
}

/// A swept value as a cell: numbers shortest, strings as they are, arrays and tables as TOML.
pub fn cell(value: &toml::Value) -> String {
    match value {
        toml::Value::Float(x) => number(*x),
        toml::Value::String(s) => s.clone(),
        other => toml_text(other),
    }
}

/// A value as TOML, with its numbers in their shortest form: toml writes a float in full positional
/// notation (1e300 with 301 digits, 1e-7 as 0.0000001), which the contract's number format is not.
pub(super) fn toml_text(value: &toml::Value) -> String {
    let list = |items: Vec<String>| items.join(", ");
    match value {
        toml::Value::Float(x) if x.is_finite() => number(*x),
        toml::Value::Array(items) => format!("[{}]", list(items.iter().map(toml_text).collect())),
        toml::Value::Table(table) if !table.is_empty() => {
            let entries = table
                .iter()
                .map(|(k, v)| format!("{} = {}", key_text(k), toml_text(v)));
            format!("{{ {} }}", list(entries.collect()))
        }
        other => other.to_string(),
    }
}

/// A table key as toml writes it (bare, or quoted as it quotes it): `{ K = 0 }`, unwrapped.
fn key_text(key: &str) -> String {
    let one = toml::Value::Table(toml::Table::from_iter([(key.to_string(), 0.into())]));
    let text = one.to_string();
    let inner = text
        .strip_prefix("{ ")
        .and_then(|t| t.strip_suffix(" = 0 }"));
    inner.map_or_else(|| key.to_string(), str::to_string)
}

impl Row {
    /// A run that failed with `failure` before it had a file; the reason and the wall time are filled in
    /// when it ends.
    pub fn failed(index: u64, values: Vec<String>, failure: FailureKind) -> Self {
        Self {
            index,
            values,
            status: RunStatus::Failed,
            failure: Some(failure),
            reason: String::new(),
            recorded: None,
            prediction: None,
            wall_time: 0.0,
        }
    }

    /// The cells after the swept keys, each with its column's name.
    fn trailing(&self) -> [(&'static str, String); 20] {
        let r = self.recorded.as_ref();
        let s = r.map(|r| &r.summary);
        let opt = |x: Option<f64>| x.map(number).unwrap_or_default();
        let p = self.prediction.as_ref();
        [
            ("status", self.status.name().to_string()),
            ("termination", text(s.map(|s| s.termination.name()))),
            ("t_end", opt(s.map(|s| s.termination_time))),
            (
                "verify",
                text(r.map(|r| r.verify.map_or("off", Verdict::name))),
            ),
            ("failure", text(self.failure.map(|f| f.name()))),
            ("reason", one_line(&self.reason)),
            ("file", text(r.map(|r| &r.file))),
            ("bytes", text(s.map(|s| s.bytes))),
            ("sha256", text(r.map(|r| &r.sha256))),
            ("samples", text(s.map(|s| s.samples))),
            ("messages", text(s.map(|s| s.messages))),
            ("steps", text(s.map(|s| s.stats.steps))),
            ("energy_drift", opt(s.map(|s| s.energy_drift))),
            ("invariant_drift", opt(s.and_then(|s| s.invariant_drift))),
            ("steady_residual", opt(s.and_then(|s| s.steady_residual))),
            ("event_trusted", text(s.and_then(|s| s.event_trusted))),
            ("predicted_motion", text(p.map(|p| p.motion))),
            ("predicted_stability", text(p.and_then(|p| p.stability))),
            (
                "predicted_termination",
                text(p.map(|p| p.termination.name())),
            ),
            ("wall_time_s", number(self.wall_time)),
        ]
    }

    /// The row's cells, in the order of [`columns`].
    pub fn fields(&self) -> Vec<String> {
        let mut fields = vec![self.index.to_string()];
        fields.extend(self.values.iter().cloned());
        fields.extend(self.trailing().map(|(_, cell)| cell));
        fields
    }

    /// The row as one CSV line, without the line break.
    pub fn line(&self) -> String {
        crate::csv::line(&self.fields())
    }
}

fn text(value: Option<impl ToString>) -> String {
    value.map(|v| v.to_string()).unwrap_or_default()
}

/// Line breaks as `; `, so that every row is one line (the journal's unit).
fn one_line(text: &str) -> String {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_written_in_their_shortest_form() {
        assert_eq!(cell(&toml::Value::Float(0.1)), "0.1");
        assert_eq!(cell(&toml::Value::Float(1e-12)), "1e-12");
        assert_eq!(cell(&toml::Value::Float(5.0)), "5.0");
        assert_eq!(cell(&toml::Value::Integer(250)), "250");
        assert_eq!(cell(&toml::Value::from("hoop")), "hoop");
        assert_eq!(cell(&toml::Value::from(vec![0.0, 1.5])), "[0.0, 1.5]");
        assert_eq!(
            cell(&toml::Value::from(vec![1e300, 1e-7, 2.5])),
            "[1e300, 1e-7, 2.5]"
        );
        let steady: toml::Value = toml::from_str::<toml::Table>(
            r#"v = { kind = "circle", theta = 1e-9, "a b" = [1, { c = 1e22 }], e = {}, f = [], n = nan }"#,
        )
        .unwrap()["v"]
            .clone();
        assert_eq!(
            cell(&steady),
            r#"{ "a b" = [1, { c = 1e22 }], e = {}, f = [], kind = "circle", n = nan, theta = 1e-9 }"#
        );
        // Otherwise as toml writes it.
        for text in [
            r#"{ kind = "circle", theta = 0.3, branch = "+" }"#,
            r#"[[0.0, 0.2], { "x.y" = 1, z = [true, "s"] }]"#,
            "[]",
            "{}",
        ] {
            let v = toml::from_str::<toml::Table>(&format!("v = {text}")).unwrap()["v"].clone();
            assert_eq!(cell(&v), v.to_string());
        }
        assert_eq!(
            one_line("2 problems:\n  `a` x\n  `b` y"),
            "2 problems:; `a` x; `b` y"
        );
    }
}
