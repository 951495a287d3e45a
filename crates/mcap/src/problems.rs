//! A bounded list of findings: the first few in full, the rest counted.

/// How many findings are kept in full.
const KEPT: usize = 8;

/// Findings of one check, bounded in memory whatever the file holds.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Problems {
    first: Vec<String>,
    total: u64,
}

impl Problems {
    /// Records a finding; `describe` runs only while the list has room.
    pub fn push_with(&mut self, describe: impl FnOnce() -> String) {
        self.total += 1;
        if self.first.len() < KEPT {
            self.first.push(describe());
        }
    }

    /// Number of findings.
    #[must_use]
    pub fn total(&self) -> u64 {
        self.total
    }

    /// True when there is none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.total == 0
    }

    /// Appends the other list's findings.
    pub fn extend(&mut self, other: &Problems) {
        for p in &other.first {
            if self.first.len() < KEPT {
                self.first.push(p.clone());
            }
        }
        self.total += other.total;
    }

    /// The findings as one line: the first few, then how many more.
    #[must_use]
    pub fn summary(&self) -> String {
        let mut s = self.first.join("; ");
        let more = self.total - self.first.len() as u64;
        if more > 0 {
            s.push_str(&format!("; and {more} more"));
        }
        s
    }
}
