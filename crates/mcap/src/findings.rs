//! A bounded list of findings: the first few in full, the rest counted.

/// How many findings are kept in full.
const KEPT: usize = 8;
/// Longest finding kept \[bytes\]: a finding may quote a name from the file, which may be megabytes.
const LONGEST: usize = 1024;

/// Findings of one check, bounded in memory whatever the file holds.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BoundedFindings {
    first: Vec<String>,
    total: u64,
}

impl BoundedFindings {
    /// Records a finding; `describe` runs only while the list has room.
    pub fn push_with(&mut self, describe: impl FnOnce() -> String) {
        self.total += 1;
        if self.first.len() < KEPT {
            let mut finding = describe();
            if finding.len() > LONGEST {
                let end = (0..=LONGEST).rfind(|&i| finding.is_char_boundary(i));
                finding.truncate(end.unwrap_or(0));
                finding.push('…');
            }
            self.first.push(finding);
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
    pub fn extend(&mut self, other: &BoundedFindings) {
        let room = KEPT.saturating_sub(self.first.len());
        self.first.extend(other.first.iter().take(room).cloned());
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_finding_is_cut_and_the_rest_counted() {
        let mut f = BoundedFindings::default();
        for _ in 0..10 {
            f.push_with(|| "é".repeat(LONGEST));
        }
        assert_eq!(f.total(), 10);
        assert!(f.first.iter().all(|s| s.len() <= LONGEST + '…'.len_utf8()));
        assert!(f.summary().ends_with("; and 2 more"));
    }
}
