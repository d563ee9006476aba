//! Deterministic shards: asset `a` belongs to shard `h(a) mod N`, where
//! `h(a)` is the first 8 bytes (big-endian u64) of
//! `SHA-256("modal-batch-shard-v1" ‖ bank name)` and the bank name is the
//! asset's output path inside the batch directory (unique per manifest).
//!
//! Shards are numbered 0..N−1 (`--shard 0/3`, `--shard 1/3`, `--shard 2/3`).
//! The assignment depends only on the bank name and N: not on the manifest's
//! order, the other assets, the machine or the material, so editing an
//! asset's options never moves it to another shard, and a re-run of one
//! shard finds its own finished banks again.
//!
//! Without `--shard`, the shard comes from the scheduler's environment
//! ([`Shard::from_env`]):
//! - Slurm job arrays: index `(SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN)
//!   / SLURM_ARRAY_TASK_STEP` (`MIN` 0 and `STEP` 1 when unset; `--array=0-14:2`
//!   runs shards 0..7), count `SLURM_ARRAY_TASK_COUNT`; an index list
//!   (`--array=3,5,7`) has no such mapping and is refused;
//! - Kubernetes Indexed Jobs: index `JOB_COMPLETION_INDEX`, count from
//!   `--shard-count` or `MODAL_SHARD_COUNT` (Kubernetes does not export it);
//! - otherwise the whole manifest (shard 0 of 1); a shard count without
//!   an index (`MODAL_SHARD_COUNT` alone: an Indexed Job without
//!   `completionMode: Indexed`) is an error, not the whole manifest on
//!   every pod.
//!
//! At most [`MAX_SHARDS`] shards.
//!
//! `--shard-count`, when given, overrides any count from the environment.

use sha2::{Digest, Sha256};

use crate::BatchError;

/// Shard `index` of `count` (0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This shard, `0..count`.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

/// Where a shard selection came from (for messages).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardEnv {
    /// The `--shard I/N` flag.
    Flag,
    /// `SLURM_ARRAY_TASK_ID` / `SLURM_ARRAY_TASK_COUNT`.
    Slurm,
    /// `JOB_COMPLETION_INDEX` (Kubernetes Indexed Job).
    Kubernetes,
    /// No selection: the whole manifest.
    Whole,
}

/// Environment variable giving the shard count to Kubernetes Indexed Jobs.
pub const SHARD_COUNT_ENV: &str = "MODAL_SHARD_COUNT";

/// The most shards a batch may be split into: more than a library's assets
/// leaves shards empty, and a merge lists every missing shard (10¹⁷ shards
/// ran a merge out of memory).
pub const MAX_SHARDS: usize = 100_000;

impl Shard {
    /// The whole manifest: shard 0 of 1.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// A checked shard.
    pub fn new(index: usize, count: usize) -> Result<Shard, BatchError> {
        if count == 0 {
            return Err(BatchError::Shard("the shard count must be at least 1".into()));
        }
        if count > MAX_SHARDS {
            return Err(BatchError::Shard(format!("{count} shards: at most {MAX_SHARDS} are supported")));
        }
        if index >= count {
            return Err(BatchError::Shard(format!(
                "shard index {index} is out of range for {count} shards (indices are 0-based: 0..{})",
                count - 1
            )));
        }
        Ok(Shard { index, count })
    }

    /// Parses `I/N` (0-based index, e.g. `0/3`).
    pub fn parse(text: &str) -> Result<Shard, BatchError> {
        let bad =
            || BatchError::Shard(format!("--shard must be I/N with 0 <= I < N (e.g. 0/3), got '{text}'"));
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let i: usize = i.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        Shard::new(i, n)
    }

    /// The shard selected by the flags (`flag`: `--shard`, `count`:
    /// `--shard-count`) or, without `--shard`, by the environment read
    /// through `var` (see the module doc for the precedence).
    pub fn select(
        flag: Option<&str>,
        count: Option<usize>,
        var: impl Fn(&str) -> Option<String>,
    ) -> Result<(Shard, ShardEnv), BatchError> {
        if let Some(text) = flag {
            let shard = Shard::parse(text)?;
            if count.is_some_and(|c| c != shard.count) {
                return Err(BatchError::Shard(format!(
                    "--shard {text} and --shard-count {} disagree",
                    count.unwrap_or(0)
                )));
            }
            return Ok((shard, ShardEnv::Flag));
        }
        Shard::from_env(count, var)
    }

    /// The shard from a scheduler's environment (see the module doc).
    pub fn from_env(
        count: Option<usize>,
        var: impl Fn(&str) -> Option<String>,
    ) -> Result<(Shard, ShardEnv), BatchError> {
        let get = |name: &str| var(name).map(|v| v.trim().to_string()).filter(|v| !v.is_empty());
        let number = |name: &str| -> Result<Option<usize>, BatchError> {
            get(name)
                .map(|v| {
                    v.parse::<usize>().map_err(|_| {
                        BatchError::Shard(format!("{name}={v} is not a non-negative whole number"))
                    })
                })
                .transpose()
        };
        let count_from_env = number(SHARD_COUNT_ENV)?;
        if let Some(id) = number("SLURM_ARRAY_TASK_ID")? {
            let min = number("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let tasks = number("SLURM_ARRAY_TASK_COUNT")?;
            if let Some((shards, tasks)) = count.zip(tasks).filter(|(c, t)| c != t) {
                // The range check below would blame an index list that was never used.
                return Err(BatchError::Shard(format!(
                    "--shard-count {shards} disagrees with the Slurm array's SLURM_ARRAY_TASK_COUNT {tasks}: \
                     one task per shard needs the same count (drop --shard-count, or submit --array with \
                     {shards} tasks)"
                )));
            }
            let n = match count.or(tasks).or(count_from_env) {
                Some(n) => n,
                None => {
                    return Err(BatchError::Shard(
                        "SLURM_ARRAY_TASK_ID is set but not SLURM_ARRAY_TASK_COUNT: give --shard-count N"
                            .into(),
                    ))
                }
            };
            let offset = id.checked_sub(min).ok_or_else(|| {
                BatchError::Shard(format!("SLURM_ARRAY_TASK_ID {id} is below SLURM_ARRAY_TASK_MIN {min}"))
            })?;
            let step = number("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1).max(1);
            // A range's last id is MIN + (COUNT − 1)·STEP; a list's (3,5,7: COUNT 3,
            // STEP unset) is not, and no task of it can tell its shard.
            let range_end =
                n.checked_sub(1).and_then(|k| k.checked_mul(step)).and_then(|k| k.checked_add(min));
            if let Some(max) = number("SLURM_ARRAY_TASK_MAX")?.filter(|&max| Some(max) != range_end) {
                return Err(BatchError::Shard(format!(
                    "SLURM_ARRAY_TASK_MIN {min}, MAX {max} and COUNT {n} (STEP {step}) are not a range: an \
                     array given as a list of indices has no shard mapping; use a range (--array=0-N or \
                     0-N:S) or --shard I/N"
                )));
            }
            if offset % step != 0 {
                return Err(BatchError::Shard(format!(
                    "SLURM_ARRAY_TASK_ID {id} is not SLURM_ARRAY_TASK_MIN {min} plus a multiple of \
                     SLURM_ARRAY_TASK_STEP {step}: an array given as a list of indices has no shard \
                     mapping; use a range (--array=0-N or 0-N:S) or --shard I/N"
                )));
            }
            let index = offset / step;
            if index >= n {
                return Err(BatchError::Shard(format!(
                    "SLURM_ARRAY_TASK_ID {id} is shard {index} of SLURM_ARRAY_TASK_COUNT {n}: an array given \
                     as a list of indices has no shard mapping; use a range (--array=0-N or 0-N:S) or --shard I/N"
                )));
            }
            return Ok((Shard::new(index, n)?, ShardEnv::Slurm));
        }
        if let Some(index) = number("JOB_COMPLETION_INDEX")? {
            let n = count.or(count_from_env).ok_or_else(|| {
                BatchError::Shard(format!(
                    "JOB_COMPLETION_INDEX is set: give the shard count (the Job's completions) \
                     with --shard-count N or {SHARD_COUNT_ENV}"
                ))
            })?;
            return Ok((Shard::new(index, n)?, ShardEnv::Kubernetes));
        }
        match (count, count_from_env) {
            (Some(n), _) if n != 1 => Err(BatchError::Shard(format!(
                "--shard-count {n} needs a shard index: --shard I/{n}, SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX"
            ))),
            (None, Some(n)) if n != 1 => Err(BatchError::Shard(format!(
                "{SHARD_COUNT_ENV}={n} needs a shard index (JOB_COMPLETION_INDEX: a Kubernetes Job with \
                 completionMode: Indexed, SLURM_ARRAY_TASK_ID, or --shard I/{n}); without one every \
                 worker would run the whole manifest"
            ))),
            _ => Ok((Shard::WHOLE, ShardEnv::Whole)),
        }
    }

    /// The shard (0..`count`) that owns the asset whose bank is `bank_name`.
    pub fn of(bank_name: &str, count: usize) -> usize {
        let mut h = Sha256::new();
        h.update(b"modal-batch-shard-v1");
        h.update(bank_name.as_bytes());
        let digest = h.finalize();
        let mut first = [0u8; 8];
        first.copy_from_slice(&digest[..8]);
        (u64::from_be_bytes(first) % count.max(1) as u64) as usize
    }

    /// True when this shard owns the asset whose bank is `bank_name`.
    pub fn owns(&self, bank_name: &str) -> bool {
        Shard::of(bank_name, self.count) == self.index
    }

    /// True for the whole manifest (one shard).
    pub fn is_whole(&self) -> bool {
        self.count == 1
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |name| pairs.iter().find(|(k, _)| *k == name).map(|(_, v)| v.to_string())
    }

    #[test]
    fn flags_parse_and_reject_nonsense() {
        assert_eq!(Shard::parse("0/3").unwrap(), Shard { index: 0, count: 3 });
        assert_eq!(Shard::parse(" 2 / 3 ").unwrap(), Shard { index: 2, count: 3 });
        for bad in ["3/3", "1/0", "-1/3", "a/3", "1", "1/2/3", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        assert!(Shard::select(Some("1/3"), Some(4), env(&[])).is_err());
        assert_eq!(Shard::select(Some("1/3"), Some(3), env(&[])).unwrap().0, Shard { index: 1, count: 3 });
    }

    #[test]
    fn the_flag_wins_over_the_environment() {
        let vars = [("SLURM_ARRAY_TASK_ID", "2"), ("SLURM_ARRAY_TASK_COUNT", "4")];
        let (shard, from) = Shard::select(Some("0/2"), None, env(&vars)).unwrap();
        assert_eq!((shard, from), (Shard { index: 0, count: 2 }, ShardEnv::Flag));
    }

    #[test]
    fn slurm_arrays_are_rebased_to_their_minimum() {
        let vars = [("SLURM_ARRAY_TASK_ID", "2"), ("SLURM_ARRAY_TASK_COUNT", "4")];
        assert_eq!(
            Shard::select(None, None, env(&vars)).unwrap(),
            (Shard::new(2, 4).unwrap(), ShardEnv::Slurm)
        );
        // --array=1-4: ids 1..=4 become shards 0..=3.
        let vars =
            [("SLURM_ARRAY_TASK_ID", "4"), ("SLURM_ARRAY_TASK_MIN", "1"), ("SLURM_ARRAY_TASK_COUNT", "4")];
        assert_eq!(Shard::select(None, None, env(&vars)).unwrap().0, Shard::new(3, 4).unwrap());
        let vars = [("SLURM_ARRAY_TASK_ID", "4"), ("SLURM_ARRAY_TASK_COUNT", "4")];
        assert!(Shard::select(None, None, env(&vars)).is_err(), "id 4 of 4 without MIN is out of range");
        assert!(Shard::select(None, None, env(&[("SLURM_ARRAY_TASK_ID", "0")])).is_err());
        assert!(Shard::select(None, None, env(&[("SLURM_ARRAY_TASK_ID", "x")])).is_err());
    }

    #[test]
    fn slurm_steps_are_followed_and_index_lists_refused() {
        // --array=0-14:2: ids 0, 2, ..., 14 are shards 0..=7 of 8.
        let stepped = |id: &'static str| {
            [
                ("SLURM_ARRAY_TASK_ID", id),
                ("SLURM_ARRAY_TASK_MIN", "0"),
                ("SLURM_ARRAY_TASK_STEP", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "8"),
            ]
        };
        assert_eq!(Shard::select(None, None, env(&stepped("6"))).unwrap().0, Shard::new(3, 8).unwrap());
        assert_eq!(Shard::select(None, None, env(&stepped("14"))).unwrap().0, Shard::new(7, 8).unwrap());
        assert!(Shard::select(None, None, env(&stepped("5"))).is_err(), "not on the step");
        // --array=3,5,7: MIN 3, COUNT 3, no step: id 7 would be shard 4 of 3.
        let list =
            [("SLURM_ARRAY_TASK_ID", "7"), ("SLURM_ARRAY_TASK_MIN", "3"), ("SLURM_ARRAY_TASK_COUNT", "3")];
        let err = Shard::select(None, None, env(&list)).unwrap_err().to_string();
        assert!(err.contains("list of indices"), "{err}");
        // With MAX (Slurm exports it), every task of the list is refused, id 5 too.
        let list = [
            ("SLURM_ARRAY_TASK_ID", "5"),
            ("SLURM_ARRAY_TASK_MIN", "3"),
            ("SLURM_ARRAY_TASK_MAX", "7"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ];
        let err = Shard::select(None, None, env(&list)).unwrap_err().to_string();
        assert!(err.contains("not a range"), "{err}");
        let mut range = stepped("6").to_vec();
        range.push(("SLURM_ARRAY_TASK_MAX", "14"));
        assert_eq!(Shard::select(None, None, env(&range)).unwrap().0, Shard::new(3, 8).unwrap());
        // --shard-count against the array's own count: said as such, not as an index list.
        let err = Shard::select(None, Some(5), env(&range)).unwrap_err().to_string();
        assert!(
            err.starts_with("--shard-count 5 disagrees with the Slurm array's SLURM_ARRAY_TASK_COUNT 8"),
            "{err}"
        );
        assert_eq!(Shard::select(None, Some(8), env(&range)).unwrap().0, Shard::new(3, 8).unwrap());
    }

    #[test]
    fn a_shard_count_alone_is_an_error_and_absurd_counts_are_refused() {
        let err = Shard::select(None, None, env(&[(SHARD_COUNT_ENV, "8")])).unwrap_err().to_string();
        assert!(err.contains("needs a shard index"), "{err}");
        assert_eq!(Shard::select(None, None, env(&[(SHARD_COUNT_ENV, "1")])).unwrap().0, Shard::WHOLE);
        assert!(Shard::parse("0/99999999999999999").is_err());
        assert!(Shard::new(0, MAX_SHARDS).is_ok() && Shard::new(0, MAX_SHARDS + 1).is_err());
    }

    #[test]
    fn kubernetes_needs_a_count() {
        let vars = [("JOB_COMPLETION_INDEX", "1")];
        assert!(Shard::select(None, None, env(&vars)).is_err());
        assert_eq!(
            Shard::select(None, Some(3), env(&vars)).unwrap(),
            (Shard::new(1, 3).unwrap(), ShardEnv::Kubernetes)
        );
        let vars = [("JOB_COMPLETION_INDEX", "1"), (SHARD_COUNT_ENV, "2")];
        assert_eq!(Shard::select(None, None, env(&vars)).unwrap().0, Shard::new(1, 2).unwrap());
        // The flag's count overrides the variable's.
        assert_eq!(Shard::select(None, Some(5), env(&vars)).unwrap().0, Shard::new(1, 5).unwrap());
    }

    #[test]
    fn no_selection_is_the_whole_manifest() {
        assert_eq!(Shard::select(None, None, env(&[])).unwrap(), (Shard::WHOLE, ShardEnv::Whole));
        assert_eq!(Shard::select(None, Some(1), env(&[])).unwrap().0, Shard::WHOLE);
        assert!(Shard::select(None, Some(3), env(&[])).is_err());
        assert_eq!(Shard::select(None, None, env(&[("SLURM_ARRAY_TASK_ID", "")])).unwrap().0, Shard::WHOLE);
    }

    #[test]
    fn every_asset_has_exactly_one_shard_and_shards_are_balanced() {
        let names: Vec<String> = (0..3000).map(|i| format!("props/asset_{i:04}.bank")).collect();
        for count in [1, 2, 3, 7] {
            let mut sizes = vec![0usize; count];
            for name in &names {
                let owners: Vec<usize> =
                    (0..count).filter(|&i| Shard::new(i, count).unwrap().owns(name)).collect();
                assert_eq!(owners.len(), 1);
                sizes[owners[0]] += 1;
            }
            // A fair split: each shard within 5 standard deviations of N/count.
            let mean = names.len() as f64 / count as f64;
            let sd = (mean * (1.0 - 1.0 / count as f64)).sqrt();
            assert!(sizes.iter().all(|&s| (s as f64 - mean).abs() <= 5.0 * sd + 1e-9), "{sizes:?}");
        }
        // Pinned against Python's hashlib (the assignment is part of the contract:
        // re-runs must find their banks): int.from_bytes(sha256(b"modal-batch-shard-v1"
        // b"props/cup.bank").digest()[:8], "big") % 3, % 7, % 1000 = 2, 4, 911.
        assert_eq!(Shard::of("props/cup.bank", 1), 0);
        assert_eq!(Shard::of("props/cup.bank", 3), 2);
        assert_eq!(Shard::of("props/cup.bank", 7), 4);
        assert_eq!(Shard::of("props/cup.bank", 1000), 911);
    }
}
