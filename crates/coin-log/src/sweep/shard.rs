//! Which runs one process takes (format.md: Shards): shard K of N takes the runs whose index is K
//! modulo N, so that N shards on N machines together make every run exactly once. The shard is a value
//! here; the CLI reads it from `--shard K/N` or from the scheduler's environment through
//! [`Shard::from_environment`], to which it lends the environment.

use std::fmt;

// Slurm's job-array variables, and the index of a Kubernetes Indexed Job's pod (its count is the Job's
// `completions`, given by a flag).
const SLURM_TASK_ID: &str = "SLURM_ARRAY_TASK_ID";
const SLURM_TASK_COUNT: &str = "SLURM_ARRAY_TASK_COUNT";
const SLURM_TASK_MIN: &str = "SLURM_ARRAY_TASK_MIN";
const SLURM_TASK_MAX: &str = "SLURM_ARRAY_TASK_MAX";
const KUBERNETES_INDEX: &str = "JOB_COMPLETION_INDEX";

/// Shard `index` of `count`: the runs with run index ≡ `index` (mod `count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Shard {
    index: u64,
    count: u64,
}

/// A shard that cannot be taken.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct ShardError(String);

impl Shard {
    /// Every run: shard 0 of 1.
    pub const ALL: Self = Self { index: 0, count: 1 };

    /// Shard `index` of `count`, refused unless 0 ≤ index < count.
    pub fn new(index: u64, count: u64) -> Result<Self, ShardError> {
        if count == 0 {
            return Err(ShardError(format!(
                "shard {index}/0: N must be at least 1 (the number of shards)"
            )));
        }
        if index >= count {
            return Err(ShardError(format!(
                "shard {index}/{count}: K must be 0 … N − 1 = {} (number a Slurm array from 0: --array=0-{0})",
                count - 1
            )));
        }
        Ok(Self { index, count })
    }

    /// K.
    #[must_use]
    pub fn index(self) -> u64 {
        self.index
    }

    /// N.
    #[must_use]
    pub fn count(self) -> u64 {
        self.count
    }

    /// True for the whole sweep (N = 1).
    #[must_use]
    pub fn is_all(self) -> bool {
        self.count == 1
    }

    /// Whether run `run` is this shard's.
    #[must_use]
    pub fn takes(self, run: u64) -> bool {
        run % self.count == self.index
    }

    /// Whether some run is both this shard's and `other`'s: K ≡ K' (mod gcd(N, N')).
    #[must_use]
    pub fn overlaps(self, other: Self) -> bool {
        let (mut a, mut b) = (self.count, other.count);
        while b != 0 {
            (a, b) = (b, a % b);
        }
        self.index % a == other.index % a
    }

    /// How many of a sweep's `runs` are this shard's.
    #[must_use]
    pub fn len(self, runs: u64) -> u64 {
        runs.saturating_sub(self.index).div_ceil(self.count)
    }

    /// This shard's runs of a sweep of `runs`, in index order.
    pub fn runs(self, runs: u64) -> impl Iterator<Item = u64> {
        (self.index..runs).step_by(usize::try_from(self.count).unwrap_or(usize::MAX))
    }

    /// The shard a scheduler gave this process, from its environment (`var` looks a variable up), or
    /// `None` outside a job array. Slurm: K = `SLURM_ARRAY_TASK_ID` − `SLURM_ARRAY_TASK_MIN` (0 when not
    /// set), N = `SLURM_ARRAY_TASK_MAX` − `SLURM_ARRAY_TASK_MIN` + 1, or `SLURM_ARRAY_TASK_COUNT`; an
    /// array with a step or a list, whose ids are not K = 0 … N − 1 apart from MIN, is refused. Kubernetes:
    /// K = `JOB_COMPLETION_INDEX`, N = `kubernetes_count` (the Job's `completions`). An error for a
    /// variable that is no number, an array that does not number its tasks densely, or a Kubernetes index
    /// without its count (or a count without an index).
    pub fn from_environment(
        var: impl Fn(&str) -> Option<String>,
        kubernetes_count: Option<u64>,
    ) -> Result<Option<Self>, ShardError> {
        let number = |name: &str| -> Result<Option<u64>, ShardError> {
            var(name)
                .map(|v| {
                    v.trim()
                        .parse::<u64>()
                        .map_err(|_| ShardError(format!("{name}={v} is not a whole number ≥ 0")))
                })
                .transpose()
        };
        if let Some(id) = number(SLURM_TASK_ID)? {
            let shard = slurm(
                id,
                number(SLURM_TASK_MIN)?,
                number(SLURM_TASK_MAX)?,
                number(SLURM_TASK_COUNT)?,
            )?;
            // --shard-count is Kubernetes' count; in a job array the array's size is N, and a count
            // given beside it that differs was silently ignored (the sweep cut in other shards than asked).
            return match kubernetes_count {
                Some(count) if count != shard.count => Err(ShardError(format!(
                    "--shard-count {count} does not match this Slurm job array of {} tasks, whose size is the \
                     number of shards: submit --array=0-{} for {count} shards, or leave --shard-count out",
                    shard.count,
                    count.saturating_sub(1)
                ))),
                _ => Ok(Some(shard)),
            };
        }
        match (number(KUBERNETES_INDEX)?, kubernetes_count) {
            (Some(index), Some(count)) if index >= count => Err(ShardError(format!(
                "{KUBERNETES_INDEX}={index} is not below --shard-count {count}: give --shard-count the \
                 Job's completions (its pods are indexed 0 … completions − 1)"
            ))),
            (Some(index), Some(count)) => Self::new(index, count).map(Some),
            (Some(index), None) => Err(ShardError(format!(
                "{KUBERNETES_INDEX}={index} is set (a Kubernetes Indexed Job) but not the number of shards: \
                 pass --shard-count N with N the Job's completions, or --shard K/N"
            ))),
            (None, Some(count)) => Err(ShardError(format!(
                "--shard-count {count} needs {KUBERNETES_INDEX} (set in each pod of a Kubernetes Indexed Job); \
                 elsewhere pass --shard K/N"
            ))),
            (None, None) => Ok(None),
        }
    }
}

fn slurm(
    id: u64,
    min: Option<u64>,
    max: Option<u64>,
    count: Option<u64>,
) -> Result<Shard, ShardError> {
    let min = min.unwrap_or(0);
    let dense = max.map(|max| max.saturating_sub(min) + 1);
    let n = match (dense, count) {
        (Some(d), Some(c)) if d != c => {
            return Err(ShardError(format!(
                "this job array's {c} tasks are not numbered densely ({SLURM_TASK_MIN} = {min}, {SLURM_TASK_MAX} = \
                 {}): an array with a step or a list leaves shards out; submit --array=0-{} (or pass --shard K/N)",
                max.unwrap_or_default(),
                c - 1
            )))
        }
        (Some(n), _) | (None, Some(n)) => n,
        (None, None) => {
            return Err(ShardError(format!(
                "{SLURM_TASK_ID} = {id} is set without {SLURM_TASK_COUNT} or {SLURM_TASK_MAX}: pass --shard K/N"
            )))
        }
    };
    let index = id.checked_sub(min).ok_or_else(|| {
        ShardError(format!(
            "{SLURM_TASK_ID} = {id} is below {SLURM_TASK_MIN} = {min}"
        ))
    })?;
    Shard::new(index, n)
}

impl std::str::FromStr for Shard {
    type Err = ShardError;

    /// `K/N`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let parsed = s
            .split_once('/')
            .and_then(|(k, n)| Some((k.trim().parse().ok()?, n.trim().parse().ok()?)));
        let (k, n) = parsed.ok_or_else(|| {
            ShardError(format!(
                "`{s}` is not K/N, e.g. 0/4 for the first of four shards"
            ))
        })?;
        Self::new(k, n)
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}
