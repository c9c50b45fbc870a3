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
//! [`merge`] refuses parts that do not belong together: different versions, suites, filters or
//! shard counts, a shard index given twice or missing, rows that are not exactly the shard's
//! share of the selection.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::suite::Suite;
use crate::suite::evaluate::Outcome;

/// Format tag written into every shard file; bumped when the layout changes.
pub const SHARD_FORMAT: &str = "flexverify-verify-shard/1";

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
}

impl ShardFile {
    pub fn new(
        suite: Suite,
        filter: Option<&str>,
        shard: Shard,
        selection: Vec<String>,
        outcomes: Vec<Outcome>,
    ) -> Self {
        ShardFile {
            format: SHARD_FORMAT.to_string(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            suite,
            filter: filter.map(str::to_string),
            shard,
            selection,
            outcomes,
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

/// Reads every `shard-*-of-*.json` in each folder (a folder may hold one shard or all of them).
pub fn read_dirs(dirs: &[PathBuf]) -> Result<Vec<(PathBuf, ShardFile)>, MergeError> {
    let mut files = Vec::new();
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
            let file: ShardFile =
                serde_json::from_str(&text).map_err(|e| MergeError::NotAShard {
                    path: path.clone(),
                    reason: e.to_string(),
                })?;
            if file.format != SHARD_FORMAT {
                return Err(MergeError::NotAShard {
                    path,
                    reason: format!("format `{}`, expected `{SHARD_FORMAT}`", file.format),
                });
            }
            files.push((path, file));
        }
    }
    Ok(files)
}

/// The rows of the whole selection, in selection order, from one file per shard.
pub fn merge(
    files: &[(PathBuf, ShardFile)],
) -> Result<(Suite, Option<String>, Vec<Outcome>), MergeError> {
    let Some((first_path, first)) = files.first() else {
        return Err(MergeError::NoShards("the given folders".into()));
    };
    let this_version = env!("CARGO_PKG_VERSION");
    if first.version != this_version {
        return Err(MergeError::Mismatch {
            first: first_path.clone(),
            second: PathBuf::from("this flexverify"),
            what: "versions",
            a: first.version.clone(),
            b: this_version.to_string(),
        });
    }
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
        let share = file.shard.share(&file.selection);
        if file.outcomes.len() != share.len()
            || file.outcomes.iter().zip(&share).any(|(o, id)| &o.id != id)
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
    Ok((first.suite, first.filter.clone(), outcomes))
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
