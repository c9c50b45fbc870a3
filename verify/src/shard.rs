//! Splitting a verification suite over machines and merging the parts back.
//!
//! A run selects its cases (suite and filter) in catalog order, c_0 … c_{m-1}. Shard i of n
//! (1 ≤ i ≤ n) evaluates the cases c_k with k mod n = i − 1 and writes a [`ShardFile`]: the
//! selection it was cut from (suite, filter, the ids of all m cases, the program version) and
//! its own outcome rows. Each outcome depends only on its case (backend runs are
//! deterministic and run sequentially inside one solve), so [`merge`] of the n files gives the
//! rows of one unsharded run bit for bit, apart from wall times. The modulo split spreads the
//! expensive families (catalog order groups them) over all shards, with no cost model to keep.
//!
//! The full suite's refinement ladders (one study per scene, ids `ladder-<scene>`, selected by
//! the same filter) are split the same way, separately from the cases: shard i runs the
//! ladders at positions k with k mod n = i − 1 and stores its studies in its file; [`merge`]
//! returns them in selection order.
//!
//! `converge --shard I/N` splits the same way over the study's rungs (every backend's ladder,
//! in order, flattened): a [`ConvergeShardFile`] holds the rungs' measurements, and
//! [`merge_converge`] hands them to the study in place of fresh runs, so the merged study is
//! the unsharded one. A sharded ladder measures every rung; a rung after the ladder's end
//! (first failure after a success) is measured but not used, as in one run.
//!
//! [`merge`] refuses parts that do not belong together: different versions, suites, filters or
//! shard counts, a shard index given twice or missing, rows that are not exactly the shard's
//! share of the selection.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use data::{BackendKind, Settings};

use crate::study::ladder::Refine;
use crate::study::measure::RungMeasurement;
use crate::study::summary::Study;
use crate::study::survey::LadderSpec;
use crate::suite::Suite;
use crate::suite::evaluate::Outcome;

/// Format tag written into every `verify` shard file; bumped when the layout changes.
pub const SHARD_FORMAT: &str = "flexverify-verify-shard/2";
/// Format tag of `converge` shard files.
pub const CONVERGE_SHARD_FORMAT: &str = "flexverify-converge-shard/2";

/// Shard `index` of `count` (1-based: `--shard 1/3`, `2/3`, `3/3`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

#[derive(Debug, Error, PartialEq, Eq)]
#[error("--shard `{text}`: {reason}; expected I/N with 1 <= I <= N, e.g. --shard 2/4")]
pub struct ShardParseError {
    text: String,
    reason: &'static str,
}

impl FromStr for Shard {
    type Err = ShardParseError;
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let fail = |reason| ShardParseError {
            text: text.to_string(),
            reason,
        };
        let (i, n) = text.split_once('/').ok_or_else(|| fail("no `/`"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| fail("I is not a whole number"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| fail("N is not a whole number"))?;
        if count == 0 {
            return Err(fail("N must be at least 1"));
        }
        if index == 0 {
            return Err(fail("shards are numbered from 1"));
        }
        if index > count {
            return Err(fail("I is larger than N"));
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// Whether the item at `position` of the sorted selection belongs to this shard.
    pub fn owns(self, position: usize) -> bool {
        position % self.count == self.index - 1
    }

    /// This shard's share of `items` (kept in order).
    pub fn share<T: Clone>(self, items: &[T]) -> Vec<T> {
        items
            .iter()
            .enumerate()
            .filter(|(k, _)| self.owns(*k))
            .map(|(_, x)| x.clone())
            .collect()
    }

    /// The file a shard writes into its output folder.
    pub fn file_name(self) -> String {
        format!("shard-{}-of-{}.json", self.index, self.count)
    }
}

/// One shard's partial result of `flexverify verify`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShardFile {
    pub format: String,
    /// Version of the program that wrote the file; parts of different versions never merge.
    pub version: String,
    pub suite: Suite,
    pub filter: Option<String>,
    pub shard: Shard,
    /// Ids of every case of the selection, in order (not only this shard's).
    pub selection: Vec<String>,
    /// This shard's rows, in selection order.
    pub outcomes: Vec<Outcome>,
    /// Every ladder of the selection (full suite), in order (not only this shard's).
    pub ladder_selection: Vec<LadderSpec>,
    /// This shard's ladder studies, in selection order.
    pub ladders: Vec<Study>,
}

impl ShardFile {
    pub fn new(
        suite: Suite,
        filter: Option<&str>,
        shard: Shard,
        selection: Vec<String>,
        outcomes: Vec<Outcome>,
        ladder_selection: Vec<LadderSpec>,
        ladders: Vec<Study>,
    ) -> Self {
        ShardFile {
            format: SHARD_FORMAT.to_string(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            suite,
            filter: filter.map(str::to_string),
            shard,
            selection,
            outcomes,
            ladder_selection,
            ladders,
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("serializable shard file")
    }
}

/// Why shard outputs cannot be merged.
#[derive(Debug, Error)]
pub enum MergeError {
    #[error("cannot read {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path} is not a flexverify shard file: {reason}")]
    NotAShard { path: PathBuf, reason: String },
    #[error("no shard files (shard-I-of-N.json) in {0}")]
    NoShards(String),
    #[error("{first} and {second} come from different runs: {what} differ ({a} vs {b})")]
    Mismatch {
        first: PathBuf,
        second: PathBuf,
        what: &'static str,
        a: String,
        b: String,
    },
    #[error("shard {shard} appears twice: {first} and {second}")]
    Duplicate {
        shard: Shard,
        first: PathBuf,
        second: PathBuf,
    },
    #[error("shard(s) {missing} of {count} missing")]
    Missing { missing: String, count: usize },
    #[error("{path}: its rows are not shard {shard}'s share of the selection")]
    WrongRows { path: PathBuf, shard: Shard },
}

/// The shard files found by [`read_dirs`]: all of `verify` or all of `converge`.
pub enum Parts {
    Verify(Vec<(PathBuf, ShardFile)>),
    Converge(Vec<(PathBuf, ConvergeShardFile)>),
}

/// Reads every `shard-*.json` in each folder (a folder may hold one shard or all of them).
pub fn read_dirs(dirs: &[PathBuf]) -> Result<Parts, MergeError> {
    let mut verify = Vec::new();
    let mut converge = Vec::new();
    for dir in dirs {
        let entries = std::fs::read_dir(dir).map_err(|source| MergeError::Read {
            path: dir.clone(),
            source,
        })?;
        let mut paths: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with("shard-") && n.ends_with(".json"))
            })
            .collect();
        if paths.is_empty() {
            return Err(MergeError::NoShards(dir.display().to_string()));
        }
        paths.sort();
        for path in paths {
            let text = std::fs::read_to_string(&path).map_err(|source| MergeError::Read {
                path: path.clone(),
                source,
            })?;
            let not_a_shard = |reason: String| MergeError::NotAShard {
                path: path.clone(),
                reason,
            };
            let value: serde_json::Value =
                serde_json::from_str(&text).map_err(|e| not_a_shard(e.to_string()))?;
            match value.get("format").and_then(|f| f.as_str()) {
                Some(SHARD_FORMAT) => verify.push((
                    path.clone(),
                    serde_json::from_str(&text).map_err(|e| not_a_shard(e.to_string()))?,
                )),
                Some(CONVERGE_SHARD_FORMAT) => converge.push((
                    path.clone(),
                    serde_json::from_str(&text).map_err(|e| not_a_shard(e.to_string()))?,
                )),
                other => {
                    return Err(not_a_shard(format!(
                        "format {other:?}, expected `{SHARD_FORMAT}` or `{CONVERGE_SHARD_FORMAT}`"
                    )));
                }
            }
        }
    }
    match (verify.is_empty(), converge.is_empty()) {
        (false, true) => Ok(Parts::Verify(verify)),
        (true, false) => Ok(Parts::Converge(converge)),
        _ => Err(MergeError::Mismatch {
            first: verify[0].0.clone(),
            second: converge[0].0.clone(),
            what: "commands",
            a: "verify".into(),
            b: "converge".into(),
        }),
    }
}

/// Refuses a part written by another version of flexverify.
fn same_version(path: &Path, version: &str) -> Result<(), MergeError> {
    let this_version = env!("CARGO_PKG_VERSION");
    if version == this_version {
        return Ok(());
    }
    Err(MergeError::Mismatch {
        first: path.to_path_buf(),
        second: PathBuf::from("this flexverify"),
        what: "versions",
        a: version.to_string(),
        b: this_version.to_string(),
    })
}

/// What the shards of one `verify` selection give together.
pub struct Merged {
    pub suite: Suite,
    pub filter: Option<String>,
    /// The rows of the whole selection, in selection order.
    pub outcomes: Vec<Outcome>,
    /// The ladder studies of the whole selection, in selection order.
    pub ladders: Vec<Study>,
}

/// The rows and ladders of the whole selection, in selection order, from one file per shard.
pub fn merge(files: &[(PathBuf, ShardFile)]) -> Result<Merged, MergeError> {
    let Some((first_path, first)) = files.first() else {
        return Err(MergeError::NoShards("the given folders".into()));
    };
    same_version(first_path, &first.version)?;
    let mut by_index: BTreeMap<usize, (&PathBuf, &ShardFile)> = BTreeMap::new();
    for (path, file) in files {
        let differ = |what, a: String, b: String| MergeError::Mismatch {
            first: first_path.clone(),
            second: path.clone(),
            what,
            a,
            b,
        };
        if file.version != first.version {
            return Err(differ(
                "versions",
                first.version.clone(),
                file.version.clone(),
            ));
        }
        if file.suite != first.suite {
            return Err(differ(
                "suites",
                format!("{:?}", first.suite),
                format!("{:?}", file.suite),
            ));
        }
        if file.filter != first.filter {
            return Err(differ(
                "filters",
                format!("{:?}", first.filter),
                format!("{:?}", file.filter),
            ));
        }
        if file.shard.count != first.shard.count {
            return Err(differ(
                "shard counts",
                first.shard.count.to_string(),
                file.shard.count.to_string(),
            ));
        }
        if file.selection != first.selection {
            return Err(differ(
                "case selections",
                format!("{} cases", first.selection.len()),
                format!("{} cases", file.selection.len()),
            ));
        }
        if file.ladder_selection != first.ladder_selection {
            return Err(differ(
                "ladder selections",
                format!("{} ladders", first.ladder_selection.len()),
                format!("{} ladders", file.ladder_selection.len()),
            ));
        }
        let share = file.shard.share(&file.selection);
        let ladder_share = file.shard.share(&file.ladder_selection);
        if file.outcomes.len() != share.len()
            || file.outcomes.iter().zip(&share).any(|(o, id)| &o.id != id)
            || file.ladders.len() != ladder_share.len()
            || file
                .ladders
                .iter()
                .zip(&ladder_share)
                .any(|(study, spec)| study.scene != spec.scene || study.quantity != spec.quantity)
        {
            return Err(MergeError::WrongRows {
                path: path.clone(),
                shard: file.shard,
            });
        }
        if let Some((other, _)) = by_index.insert(file.shard.index, (path, file)) {
            return Err(MergeError::Duplicate {
                shard: file.shard,
                first: other.clone(),
                second: path.clone(),
            });
        }
    }
    let count = first.shard.count;
    let missing: Vec<String> = (1..=count)
        .filter(|i| !by_index.contains_key(i))
        .map(|i| i.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(MergeError::Missing {
            missing: missing.join(", "),
            count,
        });
    }
    // Row k of the selection is row k / n of shard (k mod n) + 1.
    let outcomes = (0..first.selection.len())
        .map(|k| by_index[&(k % count + 1)].1.outcomes[k / count].clone())
        .collect();
    let ladders = (0..first.ladder_selection.len())
        .map(|k| by_index[&(k % count + 1)].1.ladders[k / count].clone())
        .collect();
    Ok(Merged {
        suite: first.suite,
        filter: first.filter.clone(),
        outcomes,
        ladders,
    })
}

/// One rung of a sharded study: its place in the flattened ladders and its measurement.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MeasuredRung {
    /// Index in the flattened ladders (backend order, then rung order).
    pub position: usize,
    pub backend: BackendKind,
    /// Index of the rung in its backend's ladder.
    pub rung: usize,
    pub measurement: RungMeasurement,
}

/// One shard's rungs of `flexverify converge`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ConvergeShardFile {
    pub format: String,
    pub version: String,
    /// The scene argument (catalog name or path; `merge` loads it again).
    pub scene: String,
    pub quantity: String,
    pub refine: Refine,
    pub backends: Vec<BackendKind>,
    pub base: Settings,
    pub shard: Shard,
    /// Rungs of all ladders together.
    pub rungs_total: usize,
    pub measurements: Vec<MeasuredRung>,
}

impl ConvergeShardFile {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        scene: &str,
        quantity: &str,
        refine: Refine,
        backends: &[BackendKind],
        base: &Settings,
        shard: Shard,
        rungs_total: usize,
        measurements: Vec<MeasuredRung>,
    ) -> Self {
        ConvergeShardFile {
            format: CONVERGE_SHARD_FORMAT.to_string(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene: scene.to_string(),
            quantity: quantity.to_string(),
            refine,
            backends: backends.to_vec(),
            base: base.clone(),
            shard,
            rungs_total,
            measurements,
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("serializable shard file")
    }
}

/// The measurements of every rung, keyed by (backend, rung index), from one file per shard;
/// also the first file (its scene, quantity, refine, backends and base settings).
#[allow(clippy::type_complexity)]
pub fn merge_converge(
    files: &[(PathBuf, ConvergeShardFile)],
) -> Result<
    (
        ConvergeShardFile,
        BTreeMap<(BackendKind, usize), RungMeasurement>,
    ),
    MergeError,
> {
    let Some((first_path, first)) = files.first() else {
        return Err(MergeError::NoShards("the given folders".into()));
    };
    same_version(first_path, &first.version)?;
    let mut by_index: BTreeMap<usize, &PathBuf> = BTreeMap::new();
    let mut rungs = BTreeMap::new();
    for (path, file) in files {
        let fields = |f: &ConvergeShardFile| {
            [
                ("versions", f.version.clone()),
                ("scenes", f.scene.clone()),
                ("quantities", f.quantity.clone()),
                ("refinements", format!("{:?}", f.refine)),
                ("backends", format!("{:?}", f.backends)),
                ("settings", format!("{:?}", f.base)),
                ("shard counts", f.shard.count.to_string()),
                ("rung counts", f.rungs_total.to_string()),
            ]
        };
        for ((what, a), (_, b)) in fields(first).into_iter().zip(fields(file)) {
            if a != b {
                return Err(MergeError::Mismatch {
                    first: first_path.clone(),
                    second: path.clone(),
                    what,
                    a,
                    b,
                });
            }
        }
        let positions: Vec<usize> = file.measurements.iter().map(|m| m.position).collect();
        let share: Vec<usize> = (0..file.rungs_total)
            .filter(|&p| file.shard.owns(p))
            .collect();
        if positions != share {
            return Err(MergeError::WrongRows {
                path: path.clone(),
                shard: file.shard,
            });
        }
        if let Some(other) = by_index.insert(file.shard.index, path) {
            return Err(MergeError::Duplicate {
                shard: file.shard,
                first: other.clone(),
                second: path.clone(),
            });
        }
        for m in &file.measurements {
            rungs.insert((m.backend, m.rung), m.measurement.clone());
        }
    }
    let count = first.shard.count;
    let missing: Vec<String> = (1..=count)
        .filter(|i| !by_index.contains_key(i))
        .map(|i| i.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(MergeError::Missing {
            missing: missing.join(", "),
            count,
        });
    }
    Ok((first.clone(), rungs))
}

/// Copies the plots (`*.svg`, `*.png`) the shards drew into `out`.
pub fn copy_plots(dirs: &[PathBuf], out: &Path) -> std::io::Result<usize> {
    let mut copied = 0;
    for dir in dirs {
        for entry in std::fs::read_dir(dir)? {
            let path = entry?.path();
            if path.extension().is_some_and(|e| e == "svg" || e == "png")
                && let Some(name) = path.file_name()
            {
                std::fs::copy(&path, out.join(name))?;
                copied += 1;
            }
        }
    }
    Ok(copied)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_accepts_valid_and_rejects_bad_shards() {
        assert_eq!("2/3".parse(), Ok(Shard { index: 2, count: 3 }));
        assert_eq!("1/1".parse(), Ok(Shard { index: 1, count: 1 }));
        for bad in ["0/3", "4/3", "1/0", "0/0", "x/3", "2", "-1/3", "2/3/4", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn shares_partition_the_selection() {
        let items: Vec<usize> = (0..10).collect();
        let n = 3;
        let mut all: Vec<usize> = (1..=n)
            .flat_map(|i| Shard { index: i, count: n }.share(&items))
            .collect();
        all.sort();
        assert_eq!(all, items);
        assert_eq!(Shard { index: 2, count: 3 }.share(&items), vec![1, 4, 7]);
    }
}
