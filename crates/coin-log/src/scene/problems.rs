//! What is wrong with a scene: each [`Problem`] names the key, the value and what is allowed, and validation
//! collects every one ([`ProblemCollector`]) before it fails with all of them ([`SceneProblems`]).

use std::fmt;
use std::str::FromStr;

/// One thing wrong with a scene: the key, the value found and what is allowed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// Dotted key (`body.mass`).
    pub key: String,
    /// The value found, TOML-like (`-1`, `"dop854"`, `NaN`), or empty when the key is missing.
    pub value: String,
    /// What is wrong and what is allowed (`is outside (0, ∞)`).
    pub reason: String,
    /// The command-line flag that set the value, if any (`--rate`).
    pub flag: Option<String>,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.value.is_empty() {
            write!(f, "`{}` {}", self.key, self.reason)?;
        } else {
            // A value may be anything given (a 100 kB `--set run.integrator=…`): shown cut, as paths are.
            let value = crate::files::cut(&self.value, crate::files::SHOWN_CHARS);
            write!(f, "`{}` = {value} {}", self.key, self.reason)?;
        }
        if let Some(flag) = &self.flag {
            write!(f, " (set by `{flag}`)")?;
        }
        Ok(())
    }
}

/// Every problem found in a scene: never empty, by construction, so that an invalid scene always says
/// what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneProblems(pub(super) Vec<Problem>);

impl SceneProblems {
    /// The problems of `list`, or `None` when it is empty.
    pub(crate) fn from_vec(list: Vec<Problem>) -> Option<Self> {
        (!list.is_empty()).then_some(Self(list))
    }

    /// The problems, in the order found.
    pub fn iter(&self) -> impl Iterator<Item = &Problem> {
        self.0.iter()
    }
}

impl fmt::Display for SceneProblems {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let [one] = self.0.as_slice() {
            return one.fmt(f);
        }
        write!(f, "{} problems:", self.0.len())?;
        for p in self.iter() {
            write!(f, "\n  {p}")?;
        }
        Ok(())
    }
}

/// Collects problems, naming the flag that set a key when one did.
pub(crate) struct ProblemCollector<'a> {
    pub(crate) list: Vec<Problem>,
    provenance: &'a [(&'static str, &'static str)],
}

impl<'a> ProblemCollector<'a> {
    pub(crate) fn new(provenance: &'a [(&'static str, &'static str)]) -> Self {
        Self {
            list: Vec::new(),
            provenance,
        }
    }

    pub(crate) fn push(
        &mut self,
        key: impl Into<String>,
        value: impl Into<String>,
        reason: impl Into<String>,
    ) {
        let key = key.into();
        self.list.push(Problem {
            flag: flag_of(self.provenance, &key).map(str::to_string),
            key,
            value: value.into(),
            reason: reason.into(),
        });
    }

    /// Reports a problem with `key`, which then gives no value.
    pub(crate) fn reject<T>(
        &mut self,
        key: impl Into<String>,
        value: impl Into<String>,
        reason: impl Into<String>,
    ) -> Option<T> {
        self.push(key, value, reason);
        None
    }

    pub(super) fn missing<T>(&mut self, key: &str, reason: impl Into<String>) -> Option<T> {
        self.reject(key, String::new(), reason)
    }

    /// A required number: `value` when it is finite and `ok`, else NaN, `bad` or `missing` reported.
    pub(super) fn required(
        &mut self,
        key: &str,
        value: Option<f64>,
        ok: impl Fn(f64) -> bool,
        bad: &str,
        missing: impl Into<String>,
    ) -> f64 {
        match value {
            Some(v) if v.is_finite() && ok(v) => v,
            Some(v) => self.reject(key, number(v), bad).unwrap_or(f64::NAN),
            None => self.missing(key, missing).unwrap_or(f64::NAN),
        }
    }

    /// A name parsed, or `None` with the reason made of the error reported.
    pub(super) fn parse<T: FromStr>(
        &mut self,
        key: &str,
        name: &str,
        reason: impl FnOnce(T::Err) -> String,
    ) -> Option<T> {
        name.parse()
            .map_err(|e| self.push(key, quoted(name), reason(e)))
            .ok()
    }

    /// A required number that must be finite and > 0.
    pub(super) fn positive(&mut self, key: &str, value: f64) -> bool {
        let ok = value.is_finite() && value > 0.0;
        if !ok {
            self.push(key, number(value), POSITIVE);
        }
        ok
    }

    /// Any finite number.
    pub(super) fn finite(&mut self, key: &str, value: f64) -> bool {
        let ok = value.is_finite();
        if !ok {
            self.push(key, number(value), NOT_FINITE);
        }
        ok
    }

    /// A vector of three finite numbers.
    pub(super) fn vector3(&mut self, key: &str, value: &[f64]) -> Option<[f64; 3]> {
        let reason = match *value {
            [x, y, z] if [x, y, z].iter().all(|v| v.is_finite()) => return Some([x, y, z]),
            [_, _, _] => "has a non-finite component: give three finite numbers".to_string(),
            _ => format!(
                "has {} components: give three, [ω_X, ω_Y, ω_Z]",
                value.len()
            ),
        };
        self.reject(key, numbers(value), reason)
    }
}

/// The flag that set `key`, in a provenance list of (key, flag).
pub(super) fn flag_of(
    provenance: &[(&'static str, &'static str)],
    key: &str,
) -> Option<&'static str> {
    provenance.iter().find(|(k, _)| *k == key).map(|(_, f)| *f)
}

/// Why a number that must be finite and > 0 is refused.
pub(super) const POSITIVE: &str = "is outside (0, ∞): give a finite number > 0";
pub(super) const NOT_FINITE: &str = "is not a finite number";

pub(super) fn quoted(s: &str) -> String {
    format!("{s:?}")
}

/// A number as the user would write it (`-1`, `0.5`, `1e-9`, `NaN`, `inf`).
pub(super) fn number(value: f64) -> String {
    super::Short(value).to_string()
}

pub(super) fn numbers(values: &[f64]) -> String {
    let parts: Vec<String> = values.iter().map(|v| number(*v)).collect();
    format!("[{}]", parts.join(", "))
}
