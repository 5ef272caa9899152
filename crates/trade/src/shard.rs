//! Sharded runs for map libraries: `--shard I/N` takes a deterministic share of the inputs, so
//! a Slurm array job (`--shard $SLURM_ARRAY_TASK_ID/N`) or a Kubernetes Indexed Job
//! (`--shard $JOB_COMPLETION_INDEX/N`) runs the same command on every node.

use std::fmt;
use std::str::FromStr;

/// Shard `index` of `count`, 0-based (Slurm's and Kubernetes' indices start at 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This shard, `0..count`.
    pub index: usize,
    /// How many shards the inputs are split into.
    pub count: usize,
}

/// A `--shard` value that is not `I/N` with 0 <= I < N.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("--shard {0:?}: expected I/N with 0 <= I < N (e.g. 0/4)")]
pub struct ShardError(pub String);

impl FromStr for Shard {
    type Err = ShardError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || ShardError(s.to_string());
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Self { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// The whole input as one shard.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// This shard's inputs: sorted by key and dealt round-robin, so every input lands in
    /// exactly one shard whatever order the inputs came in, and the shards' sizes differ by at
    /// most one.
    #[must_use]
    pub fn select<T: Clone>(&self, items: &[T], key: impl Fn(&T) -> String) -> Vec<T> {
        let mut keyed: Vec<(String, &T)> = items.iter().map(|t| (key(t), t)).collect();
        keyed.sort_by(|a, b| a.0.cmp(&b.0));
        keyed
            .into_iter()
            .enumerate()
            .filter(|(k, _)| k % self.count == self.index)
            .map(|(_, (_, t))| t.clone())
            .collect()
    }
}
