//! What is wrong with a scene: each [`Problem`] names the key, the value and what is allowed, and validation
//! collects every one ([`ProblemCollector`]) before it fails with all of them ([`SceneProblems`]).

use std::fmt;

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
            write!(f, "`{}` = {} {}", self.key, self.value, self.reason)?;
        }
        if let Some(flag) = &self.flag {
            write!(f, " (set by `{flag}`)")?;
        }
        Ok(())
    }
}

/// Every problem found in a scene: never empty, by construction (a first problem is required), so that an
/// invalid scene always says what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneProblems {
    first: Problem,
    rest: Vec<Problem>,
}

impl SceneProblems {
    /// A list of one problem.
    #[must_use]
    pub fn new(first: Problem) -> Self {
        Self {
            first,
            rest: Vec::new(),
        }
    }

    /// The problems of `list`, or `None` when it is empty.
    #[must_use]
    pub fn from_vec(list: Vec<Problem>) -> Option<Self> {
        let mut list = list.into_iter();
        let first = list.next()?;
        Some(Self {
            first,
            rest: list.collect(),
        })
    }

    /// How many problems (at least one).
    #[must_use]
    pub fn count(&self) -> usize {
        1 + self.rest.len()
    }

    /// The problems, in the order found.
    pub fn iter(&self) -> impl Iterator<Item = &Problem> {
        std::iter::once(&self.first).chain(&self.rest)
    }
}

impl fmt::Display for SceneProblems {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.rest.is_empty() {
            return self.first.fmt(f);
        }
        write!(f, "{} problems:", self.count())?;
        for p in self.iter() {
            write!(f, "\n  {p}")?;
        }
        Ok(())
    }
}

/// Collects problems, naming the flag that set a key when one did.
pub(super) struct ProblemCollector<'a> {
    pub(super) list: Vec<Problem>,
    provenance: &'a [(&'static str, &'static str)],
}

impl<'a> ProblemCollector<'a> {
    pub(super) fn new(provenance: &'a [(&'static str, &'static str)]) -> Self {
        Self {
            list: Vec::new(),
            provenance,
        }
    }

    pub(super) fn push(&mut self, key: &str, value: String, reason: impl Into<String>) {
        let flag = self
            .provenance
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, f)| (*f).to_string());
        self.list.push(Problem {
            key: key.to_string(),
            value,
            reason: reason.into(),
            flag,
        });
    }

    pub(super) fn missing(&mut self, key: &str, reason: impl Into<String>) {
        self.push(key, String::new(), reason);
    }

    /// A required number that must be finite and > 0.
    pub(super) fn positive(&mut self, key: &str, value: f64) -> bool {
        let ok = value.is_finite() && value > 0.0;
        if !ok {
            self.push(
                key,
                number(value),
                "is outside (0, ∞): give a finite number > 0",
            );
        }
        ok
    }

    /// Any finite number.
    pub(super) fn finite(&mut self, key: &str, value: f64) -> bool {
        let ok = value.is_finite();
        if !ok {
            self.push(key, number(value), "is not a finite number");
        }
        ok
    }

    /// A vector of three finite numbers.
    pub(super) fn vector3(&mut self, key: &str, value: &[f64]) -> Option<[f64; 3]> {
        match value {
            [x, y, z] => {
                let ok = [*x, *y, *z].iter().all(|v| v.is_finite());
                if ok {
                    Some([*x, *y, *z])
                } else {
                    self.push(
                        key,
                        numbers(value),
                        "has a non-finite component: give three finite numbers",
                    );
                    None
                }
            }
            _ => {
                self.push(
                    key,
                    numbers(value),
                    format!(
                        "has {} components: give three, [ω_X, ω_Y, ω_Z]",
                        value.len()
                    ),
                );
                None
            }
        }
    }
}

/// A number as the user would write it (`-1`, `0.5`, `1e-9`, `NaN`, `inf`).
pub(super) fn number(value: f64) -> String {
    super::Short(value).to_string()
}

pub(super) fn numbers(values: &[f64]) -> String {
    let parts: Vec<String> = values.iter().map(|v| number(*v)).collect();
    format!("[{}]", parts.join(", "))
}
