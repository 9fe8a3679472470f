//! Maps that outgrow one machine: a map split into `n` shards, each run as its own process (a
//! Slurm array task, a Kubernetes Indexed Job pod, or by hand), merged afterwards.
//!
//! * A map's **cells** are its independent units of work, numbered in the order the one-machine
//!   table lists them: for `bifurcate` one (sweep value, start) simulation in grid mode and one
//!   chain (start, up or down) in continuation mode; for `zones` one (x, y) cell with all its
//!   starts and all models; for `design` one (Ω, r, load) with all its starts and models. Shard
//!   `i` of `n` takes the cells `c` with `c mod n = i` (round-robin: neighbouring cells, which
//!   cost about the same, land on different shards, so the shards finish together). Every map
//!   command (`bifurcate`, `zones`, `design`) shares this module.
//! * A shard writes `OUT/shard=i/part.parquet` — the rows of its cells, with exactly the columns
//!   of the one-machine table, so DuckDB and polars read `OUT/shard=*/part.parquet` as one
//!   Hive-partitioned table with a `shard` column — and then `OUT/shard=i/manifest.json`
//!   ([`Manifest`]): the configuration hash, `n`, `i`, the cells, the part's SHA-256, the
//!   invocation and the version. Both are written atomically (a uniquely named temporary file
//!   beside the target, fsync, rename); the manifest last, so a shard folder without one is a
//!   shard that has not finished.
//! * [`read_shards`] checks a folder before a merge: every shard `0..n` present once, one
//!   configuration, each part the one its manifest names; the problems are listed together.
//! * `--shard I/N` names the shard; `--shard auto` (or `auto/N`) reads it from the scheduler's
//!   environment ([`ShardSpec::resolve`]).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use arrow_array::{Array, BooleanArray, Float64Array, Int64Array, StringArray};
use arrow_schema::DataType;
use pendulum_report::{Column, ColumnData, TableOptions};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::MapsError;

/// Name of a shard's table in its folder.
pub const PART: &str = "part.parquet";
/// Name of a shard's manifest in its folder.
pub const MANIFEST: &str = "manifest.json";
/// The manifest format this code writes and reads.
pub const FORMAT: &str = "pendulum-shard-1";
/// Most shards a map may be split into.
pub const MAX_SHARDS: usize = 100_000;

/// Shard `index` of `count` (0 ≤ index < count).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    pub fn new(index: usize, count: usize) -> Result<Self, MapsError> {
        if count == 0 || count > MAX_SHARDS {
            return Err(MapsError::Invalid(format!(
                "shard count {count}: expected 1 to {MAX_SHARDS}"
            )));
        }
        if index >= count {
            return Err(MapsError::Invalid(format!(
                "shard {index} of {count}: the index must be below the count (shards are numbered 0 to {})",
                count - 1
            )));
        }
        Ok(Self { index, count })
    }

    /// The cells of this shard among `total`: those with `c mod count = index`, ascending.
    pub fn cells(&self, total: usize) -> Vec<usize> {
        (self.index..total).step_by(self.count).collect()
    }

    /// `shard=i`, the Hive partition folder.
    pub fn dir_name(&self) -> String {
        format!("shard={}", self.index)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// What `--shard` says: a fixed shard, or `auto` (the index from the scheduler, the count from
/// the scheduler or given).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShardSpec {
    Fixed(Shard),
    Auto { count: Option<usize> },
}

const SPEC_EXPECTED: &str = "I/N (shard I of N, 0 ≤ I < N), auto (from SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT, or JOB_COMPLETION_INDEX and PENDULUM_SHARD_COUNT) or auto/N";

impl ShardSpec {
    /// Parses `I/N`, `auto` or `auto/N`.
    pub fn parse(text: &str) -> Result<Self, MapsError> {
        let bad = |why: &str| {
            MapsError::Invalid(format!("--shard {text:?}: {why}; expected {SPEC_EXPECTED}"))
        };
        let t = text.trim();
        let count = |s: &str| -> Result<usize, MapsError> {
            s.trim()
                .parse::<usize>()
                .map_err(|_| bad(&format!("cannot read {s:?} as a shard count")))
        };
        if t == "auto" {
            return Ok(ShardSpec::Auto { count: None });
        }
        let (a, b) = t.split_once('/').ok_or_else(|| bad("no '/'"))?;
        let n = count(b)?;
        if a.trim() == "auto" {
            Shard::new(0, n)?;
            return Ok(ShardSpec::Auto { count: Some(n) });
        }
        let i = a
            .trim()
            .parse::<usize>()
            .map_err(|_| bad(&format!("cannot read {a:?} as a shard index")))?;
        Ok(ShardSpec::Fixed(Shard::new(i, n)?))
    }

    /// The shard, with `auto` read through `env` (a variable's value by name):
    /// * a Slurm job array: index `(SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN) /
    ///   SLURM_ARRAY_TASK_STEP` (min 0 and step 1 when unset, so `--array=1-8` gives shards 0–7),
    ///   count `SLURM_ARRAY_TASK_COUNT` (must agree with `auto/N` when both are given);
    /// * a Kubernetes Indexed Job: index `JOB_COMPLETION_INDEX`, count from `auto/N` or
    ///   `PENDULUM_SHARD_COUNT` (the Job's `completions`; Kubernetes does not pass it).
    pub fn resolve(&self, env: &dyn Fn(&str) -> Option<String>) -> Result<Shard, MapsError> {
        let given = match *self {
            ShardSpec::Fixed(s) => return Ok(s),
            ShardSpec::Auto { count } => count,
        };
        let num = |name: &str| -> Result<Option<usize>, MapsError> {
            match env(name) {
                None => Ok(None),
                Some(v) if v.trim().is_empty() => Ok(None),
                Some(v) => v.trim().parse::<usize>().map(Some).map_err(|_| {
                    MapsError::Invalid(format!(
                        "--shard auto: {name}={v:?} is not a non-negative integer"
                    ))
                }),
            }
        };
        if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
            let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let step = num("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1).max(1);
            let env_count = num("SLURM_ARRAY_TASK_COUNT")?;
            let count = match (given, env_count) {
                (Some(g), Some(e)) if g != e => {
                    return Err(MapsError::Invalid(format!(
                        "--shard auto/{g}: the Slurm array has SLURM_ARRAY_TASK_COUNT={e} tasks; give the same count or plain --shard auto"
                    )))
                }
                (Some(g), _) => g,
                (None, Some(e)) => e,
                (None, None) => {
                    return Err(MapsError::Invalid(
                        "--shard auto: SLURM_ARRAY_TASK_ID is set but not SLURM_ARRAY_TASK_COUNT; give the count as --shard auto/N".into(),
                    ))
                }
            };
            if id < min || (id - min) % step != 0 {
                return Err(MapsError::Invalid(format!(
                    "--shard auto: SLURM_ARRAY_TASK_ID={id} is not on the array's grid (min {min}, step {step}); submit a contiguous --array=MIN-MAX[:STEP]"
                )));
            }
            let index = (id - min) / step;
            return Shard::new(index, count).map_err(|e| {
                MapsError::Invalid(format!(
                    "--shard auto: SLURM_ARRAY_TASK_ID={id}, min {min}, step {step} gives shard {index}, but {e}; submit a contiguous --array=MIN-MAX[:STEP] (list arrays such as 1,5,7 cannot be mapped to shards)"
                ))
            });
        }
        if let Some(index) = num("JOB_COMPLETION_INDEX")? {
            let env_count = num("PENDULUM_SHARD_COUNT")?;
            let count = match (given, env_count) {
                (Some(g), Some(e)) if g != e => {
                    return Err(MapsError::Invalid(format!(
                        "--shard auto/{g} disagrees with PENDULUM_SHARD_COUNT={e}"
                    )))
                }
                (Some(c), _) | (None, Some(c)) => c,
                (None, None) => {
                    return Err(MapsError::Invalid(format!(
                        "--shard auto: JOB_COMPLETION_INDEX={index} gives the index but not the count; pass --shard auto/N or set PENDULUM_SHARD_COUNT=N (N = the Job's completions)"
                    )))
                }
            };
            return Shard::new(index, count);
        }
        Err(MapsError::Invalid(
            "--shard auto: neither SLURM_ARRAY_TASK_ID (a Slurm job array) nor JOB_COMPLETION_INDEX (a Kubernetes Indexed Job) is set; give the shard as --shard I/N".into(),
        ))
    }
}

/// A shard's manifest, `OUT/shard=i/manifest.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`FORMAT`].
    pub format: String,
    /// The map command: `bifurcate`, `zones` or `design`.
    pub command: String,
    /// The pendulum version that computed the cells.
    pub version: String,
    /// `sha256:<hex>` over the command, the version, [`Manifest::job`] and
    /// [`Manifest::table_metadata`]: everything that decides the cells' values and the merged
    /// outputs (thread counts, the shard and the invocation excluded).
    pub config_hash: String,
    /// This shard's index and the shard count.
    pub shard: usize,
    pub shards: usize,
    /// How cells are dealt: `round_robin` (cell c to shard c mod shards).
    pub assignment: String,
    /// What one cell is, in words.
    pub cell: String,
    /// Cells of the whole map, and this shard's (ascending).
    pub cells_total: usize,
    pub cell_count: usize,
    pub cells: Vec<usize>,
    /// Rows of the part table.
    pub rows: usize,
    /// The part table's file name and SHA-256.
    pub part: String,
    pub part_sha256: String,
    /// The process that wrote the shard (`pendulum_report::invocation`), and its wall time.
    pub invocation_id: String,
    pub wall_s: f64,
    /// The key-value metadata of the one-machine table, in order.
    pub table_metadata: Vec<(String, String)>,
    /// The command's configuration: what the merge rebuilds the figures from.
    pub job: serde_json::Value,
}

/// SHA-256 of bytes, `sha256:<hex>`.
fn sha256_hex(bytes: &[u8]) -> String {
    let d = Sha256::digest(bytes);
    let mut s = String::with_capacity(7 + 64);
    s.push_str("sha256:");
    for b in d {
        s.push_str(&format!("{b:02x}"));
    }
    s
}

/// The configuration hash of a shard ([`Manifest::config_hash`]).
pub fn config_hash(
    command: &str,
    version: &str,
    job: &serde_json::Value,
    table_metadata: &[(String, String)],
) -> String {
    let text = serde_json::to_string(&(command, version, job, table_metadata)).unwrap_or_default();
    sha256_hex(text.as_bytes())
}

/// What a shard writes.
#[derive(Debug, Clone)]
pub struct ShardPart<'a> {
    pub command: &'a str,
    pub shard: Shard,
    /// What one cell is, in words.
    pub cell: &'a str,
    pub cells_total: usize,
    pub cells: &'a [usize],
    /// The rows of the shard's cells: the one-machine table's columns.
    pub columns: &'a [Column],
    /// The one-machine table's key-value metadata (without version and invocation, which the
    /// writer adds).
    pub table_metadata: &'a [(String, String)],
    pub job: serde_json::Value,
    pub wall_s: f64,
}

/// What [`write_shard`] wrote.
#[derive(Debug, Clone)]
pub struct ShardWritten {
    pub dir: PathBuf,
    pub part: PathBuf,
    pub manifest: PathBuf,
    pub rows: usize,
    pub config_hash: String,
}

/// A unique temporary name beside `path`, in the form the stale-temp sweep recognises.
fn tmp_beside(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}-{n}.tmp", std::process::id()))
}

/// Writes `bytes` to `path` atomically: a unique temporary file, fsync, rename.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), MapsError> {
    let tmp = tmp_beside(path);
    let io = |p: &Path| {
        let path = p.to_path_buf();
        move |source| MapsError::Io { path, source }
    };
    let mut f = File::create_new(&tmp).map_err(io(&tmp))?;
    let r = f
        .write_all(bytes)
        .and_then(|()| f.sync_all())
        .map_err(io(&tmp));
    drop(f);
    if let Err(e) = r {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, path).map_err(io(path))
}

/// Writes a shard into `out/shard=i/`: the part table, then the manifest (both atomic). A
/// manifest already there is removed first, so that the folder never pairs an old manifest
/// with a new part.
pub fn write_shard(out: &Path, p: &ShardPart<'_>) -> Result<ShardWritten, MapsError> {
    let dir = out.join(p.shard.dir_name());
    std::fs::create_dir_all(&dir).map_err(|source| MapsError::Io {
        path: dir.clone(),
        source,
    })?;
    let manifest_path = dir.join(MANIFEST);
    match std::fs::remove_file(&manifest_path) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(source) => {
            return Err(MapsError::Io {
                path: manifest_path,
                source,
            })
        }
    }
    let version = env!("CARGO_PKG_VERSION");
    let hash = config_hash(p.command, version, &p.job, p.table_metadata);
    let part_path = dir.join(PART);
    let mut opts = TableOptions::new();
    for (k, v) in p.table_metadata {
        opts = opts.meta(k, v.clone());
    }
    opts = opts
        .meta("shard", p.shard.index.to_string())
        .meta("shards", p.shard.count.to_string())
        .meta("config_hash", hash.clone());
    let written = opts.write(&part_path, p.columns)?;
    let bytes = std::fs::read(&part_path).map_err(|source| MapsError::Io {
        path: part_path.clone(),
        source,
    })?;
    let m = Manifest {
        format: FORMAT.to_string(),
        command: p.command.to_string(),
        version: version.to_string(),
        config_hash: hash.clone(),
        shard: p.shard.index,
        shards: p.shard.count,
        assignment: "round_robin".to_string(),
        cell: p.cell.to_string(),
        cells_total: p.cells_total,
        cell_count: p.cells.len(),
        cells: p.cells.to_vec(),
        rows: written.rows,
        part: PART.to_string(),
        part_sha256: sha256_hex(&bytes),
        invocation_id: pendulum_report::invocation().id.clone(),
        wall_s: p.wall_s,
        table_metadata: p.table_metadata.to_vec(),
        job: p.job.clone(),
    };
    let text = serde_json::to_string_pretty(&m)
        .map_err(|e| MapsError::Invalid(format!("cannot encode the shard manifest: {e}")))?;
    write_atomic(&manifest_path, text.as_bytes())?;
    Ok(ShardWritten {
        dir,
        part: part_path,
        manifest: manifest_path,
        rows: written.rows,
        config_hash: hash,
    })
}

/// A folder of complete, consistent shards ([`read_shards`]).
#[derive(Debug, Clone)]
pub struct ShardSet {
    pub dir: PathBuf,
    /// By shard index, 0..n.
    pub manifests: Vec<Manifest>,
    /// Each shard's rows, by shard index.
    pub parts: Vec<Vec<Column>>,
}

impl ShardSet {
    pub fn first(&self) -> &Manifest {
        &self.manifests[0]
    }

    /// That the shards deal `total` cells, the number the run being merged has (`what`: "the
    /// map", "the sweep", "the search").
    pub fn check_cells(&self, total: usize, what: &str) -> Result<(), MapsError> {
        let dealt = self.first().cells_total;
        if dealt != total {
            return Err(MapsError::Invalid(format!(
                "the shards deal {dealt} cells, {what} has {total}"
            )));
        }
        Ok(())
    }

    /// For each cell of the map, the shard holding it and its position among that shard's cells.
    pub fn cell_owner(&self) -> Vec<(usize, usize)> {
        let mut owner = vec![(usize::MAX, 0); self.first().cells_total];
        for (s, m) in self.manifests.iter().enumerate() {
            for (j, &c) in m.cells.iter().enumerate() {
                owner[c] = (s, j);
            }
        }
        owner
    }
}

/// The shard index in a folder name `shard=I`, `None` for other names.
fn shard_dir_index(name: &str) -> Option<Result<usize, String>> {
    let v = name.strip_prefix("shard=")?;
    Some(
        v.parse::<usize>()
            .map_err(|_| format!("{name}: {v:?} is not a shard index")),
    )
}

fn list(v: &[usize]) -> String {
    v.iter()
        .map(|i| i.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Reads and checks the shards in `dir`. Refused, with every problem named: no shard folders;
/// a shard folder without manifest (unfinished or failed); a shard index missing, or claimed by
/// two folders; a folder whose manifest names another index; manifests of different
/// configurations (which shards have which hash, and the first setting that differs) or shard
/// counts; a part whose bytes or rows are not the ones its manifest names.
pub fn read_shards(dir: &Path) -> Result<ShardSet, MapsError> {
    let entries = std::fs::read_dir(dir).map_err(|source| MapsError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut problems: Vec<String> = Vec::new();
    // index → folder names
    let mut folders: BTreeMap<usize, Vec<String>> = BTreeMap::new();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        match shard_dir_index(&name) {
            None => {}
            Some(Err(p)) => problems.push(p),
            Some(Ok(i)) if e.path().is_dir() => folders.entry(i).or_default().push(name),
            Some(Ok(_)) => problems.push(format!("{name} is not a folder")),
        }
    }
    if folders.is_empty() && problems.is_empty() {
        return Err(MapsError::Invalid(format!(
            "{}: no shard=I folders: nothing to merge (run the map with --shard I/N and --out {} first)",
            dir.display(),
            dir.display()
        )));
    }
    let mut manifests: BTreeMap<usize, Manifest> = BTreeMap::new();
    for (i, names) in &folders {
        if names.len() > 1 {
            problems.push(format!(
                "duplicated shard {i}: folders {} all claim it",
                names.join(" and ")
            ));
            continue;
        }
        let path = dir.join(&names[0]).join(MANIFEST);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                problems.push(format!(
                    "shard {i} is incomplete: {} has no {MANIFEST} (still running, failed or killed; run it again)",
                    names[0]
                ));
                continue;
            }
            Err(e) => {
                problems.push(format!("{}: {e}", path.display()));
                continue;
            }
        };
        let m: Manifest = match serde_json::from_str(&text) {
            Ok(m) => m,
            Err(e) => {
                problems.push(format!(
                    "{}: not a shard manifest ({e}); expected {FORMAT}",
                    path.display()
                ));
                continue;
            }
        };
        if m.format != FORMAT {
            problems.push(format!(
                "{}: format {:?}, this pendulum reads {FORMAT:?}",
                path.display(),
                m.format
            ));
            continue;
        }
        if m.shard != *i {
            problems.push(format!(
                "{}/{MANIFEST} says it is shard {} of {}, not {i}: a copied or renamed folder",
                names[0], m.shard, m.shards
            ));
            continue;
        }
        let again = config_hash(&m.command, &m.version, &m.job, &m.table_metadata);
        if again != m.config_hash {
            problems.push(format!(
                "{}: the configuration does not hash to the manifest's config_hash (edited or damaged)",
                path.display()
            ));
            continue;
        }
        manifests.insert(*i, m);
    }
    // One configuration, one shard count.
    let mut by_hash: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (i, m) in &manifests {
        by_hash.entry(&m.config_hash).or_default().push(*i);
    }
    if by_hash.len() > 1 {
        let groups: Vec<String> = by_hash
            .iter()
            .map(|(h, v)| {
                let m = &manifests[&v[0]];
                format!(
                    "shard(s) {} have {} ({} {})",
                    list(v),
                    &h[..h.len().min(19)],
                    m.command,
                    m.table_metadata
                        .iter()
                        .find(|(k, _)| k == "sweep" || k == "x")
                        .map_or(String::new(), |(_, v)| v.clone())
                )
            })
            .collect();
        let hashes: Vec<&&str> = by_hash.keys().collect();
        let a = &manifests[&by_hash[hashes[0]][0]];
        let b = &manifests[&by_hash[hashes[1]][0]];
        problems.push(format!(
            "mixed configurations: {}; {}: the folder holds shards of different maps (remove the stale shard folders or give each map its own --out)",
            groups.join("; "),
            first_difference(a, b)
        ));
    }
    let mut by_count: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (i, m) in &manifests {
        by_count.entry(m.shards).or_default().push(*i);
    }
    if by_count.len() > 1 {
        let groups: Vec<String> = by_count
            .iter()
            .map(|(n, v)| format!("shard(s) {} say {n} shards", list(v)))
            .collect();
        problems.push(format!(
            "mixed shard counts: {} (a map split twice into one folder)",
            groups.join("; ")
        ));
    }
    let n = by_count.keys().next_back().copied().unwrap_or(0);
    if by_count.len() == 1 {
        let missing: Vec<usize> = (0..n).filter(|i| !folders.contains_key(i)).collect();
        if !missing.is_empty() {
            problems.push(format!(
                "missing shard(s) {} of {n}: no {} folder",
                list(&missing),
                missing
                    .iter()
                    .map(|i| format!("shard={i}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        let beyond: Vec<usize> = folders.keys().copied().filter(|&i| i >= n).collect();
        if !beyond.is_empty() {
            problems.push(format!(
                "shard folder(s) {} are beyond the {n} shards the manifests name",
                list(&beyond)
            ));
        }
    }
    if !problems.is_empty() {
        return Err(MapsError::Invalid(format!(
            "cannot merge {}: {}",
            dir.display(),
            problems.join("; ")
        )));
    }
    // Cells dealt as the manifests say, every cell once; parts as named.
    let mut parts = Vec::with_capacity(n);
    let list_m: Vec<Manifest> = manifests.into_values().collect();
    let total = list_m[0].cells_total;
    for m in &list_m {
        let expect = Shard::new(m.shard, m.shards)?.cells(total);
        if m.cells_total != total || m.cells != expect || m.cell_count != m.cells.len() {
            problems.push(format!(
                "shard {}: its cells are not the round-robin share {} of {total} cells",
                m.shard,
                Shard::new(m.shard, m.shards)?
            ));
            continue;
        }
        let path = dir.join(format!("shard={}", m.shard)).join(&m.part);
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) => {
                problems.push(format!(
                    "{}: {e} (the manifest names it: the shard folder is damaged)",
                    path.display()
                ));
                continue;
            }
        };
        if sha256_hex(&bytes) != m.part_sha256 {
            problems.push(format!(
                "{}: not the table its manifest names (SHA-256 differs): rewritten by another run; run shard {} again",
                path.display(),
                m.shard
            ));
            continue;
        }
        let cols = read_columns(&path)?;
        let rows = cols.first().map_or(0, |c| column_len(&c.data));
        if rows != m.rows {
            problems.push(format!(
                "{}: {rows} rows, the manifest says {}",
                path.display(),
                m.rows
            ));
            continue;
        }
        parts.push(cols);
    }
    if !problems.is_empty() {
        return Err(MapsError::Invalid(format!(
            "cannot merge {}: {}",
            dir.display(),
            problems.join("; ")
        )));
    }
    Ok(ShardSet {
        dir: dir.to_path_buf(),
        manifests: list_m,
        parts,
    })
}

/// The first setting in which two manifests' configurations differ, in words.
fn first_difference(a: &Manifest, b: &Manifest) -> String {
    if a.command != b.command {
        return format!("one is {}, the other {}", a.command, b.command);
    }
    if a.version != b.version {
        return format!("versions {} and {}", a.version, b.version);
    }
    let ma: BTreeMap<&str, &str> = a
        .table_metadata
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    let mb: BTreeMap<&str, &str> = b
        .table_metadata
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    for (k, va) in &ma {
        match mb.get(k) {
            Some(vb) if vb == va => {}
            Some(vb) => return format!("first difference: {k} = {va:?} vs {vb:?}"),
            None => return format!("first difference: {k} only in shard {}", a.shard),
        }
    }
    if let (Some(ja), Some(jb)) = (a.job.as_object(), b.job.as_object()) {
        for (k, va) in ja {
            if jb.get(k) != Some(va) {
                return format!("first difference: the job's {k}");
            }
        }
    }
    "the configurations differ".to_string()
}

fn column_len(d: &ColumnData) -> usize {
    match d {
        ColumnData::F64(v) => v.len(),
        ColumnData::I64(v) => v.len(),
        ColumnData::Str(v) => v.len(),
        ColumnData::Bool(v) => v.len(),
    }
}

/// Reads a table written by `pendulum_report` back into columns (units and descriptions from
/// the field metadata).
pub fn read_columns(path: &Path) -> Result<Vec<Column>, MapsError> {
    use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
    let pq = |source| MapsError::Parquet {
        path: path.to_path_buf(),
        source,
    };
    let file = File::open(path).map_err(|source| MapsError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let builder = ParquetRecordBatchReaderBuilder::try_new(file).map_err(pq)?;
    let schema = builder.schema().clone();
    let reader = builder.build().map_err(pq)?;
    let mut cols: Vec<Column> = schema
        .fields()
        .iter()
        .map(|f| {
            let data = match f.data_type() {
                DataType::Float64 => Ok(ColumnData::F64(Vec::new())),
                DataType::Int64 => Ok(ColumnData::I64(Vec::new())),
                DataType::Utf8 => Ok(ColumnData::Str(Vec::new())),
                DataType::Boolean => Ok(ColumnData::Bool(Vec::new())),
                other => Err(MapsError::Invalid(format!(
                    "{}: column {} has type {other}, not one pendulum writes",
                    path.display(),
                    f.name()
                ))),
            }?;
            let md = f.metadata();
            Ok(Column {
                name: f.name().clone(),
                unit: md.get("unit").cloned(),
                description: md.get("description").cloned(),
                data,
            })
        })
        .collect::<Result<_, MapsError>>()?;
    for batch in reader {
        let batch = batch
            .map_err(|e| MapsError::Invalid(format!("{}: reading Parquet: {e}", path.display())))?;
        for (c, arr) in cols.iter_mut().zip(batch.columns()) {
            let bad = || {
                MapsError::Invalid(format!(
                    "{}: column {} is not of the type its schema says",
                    path.display(),
                    c.name
                ))
            };
            match &mut c.data {
                ColumnData::F64(v) => {
                    let a = arr
                        .as_any()
                        .downcast_ref::<Float64Array>()
                        .ok_or_else(bad)?;
                    v.extend(a.values().iter().copied());
                }
                ColumnData::I64(v) => {
                    let a = arr.as_any().downcast_ref::<Int64Array>().ok_or_else(bad)?;
                    v.extend(a.values().iter().copied());
                }
                ColumnData::Str(v) => {
                    let a = arr.as_any().downcast_ref::<StringArray>().ok_or_else(bad)?;
                    v.extend((0..a.len()).map(|i| a.value(i).to_string()));
                }
                ColumnData::Bool(v) => {
                    let a = arr
                        .as_any()
                        .downcast_ref::<BooleanArray>()
                        .ok_or_else(bad)?;
                    v.extend((0..a.len()).map(|i| a.value(i)));
                }
            }
            if arr.null_count() > 0 {
                return Err(MapsError::Invalid(format!(
                    "{}: column {} has nulls; pendulum tables have none",
                    path.display(),
                    c.name
                )));
            }
        }
    }
    Ok(cols)
}

/// Builds a table from rows of the shards' parts: row `k` of the result is row `order[k].1` of
/// part `order[k].0`. The parts must have the same columns (names, types, units).
pub fn gather(parts: &[Vec<Column>], order: &[(usize, usize)]) -> Result<Vec<Column>, MapsError> {
    let Some(first) = parts.first() else {
        return Err(MapsError::Invalid("no shard tables to merge".into()));
    };
    for (s, p) in parts.iter().enumerate() {
        let same = p.len() == first.len()
            && p.iter().zip(first).all(|(a, b)| {
                a.name == b.name
                    && a.unit == b.unit
                    && std::mem::discriminant(&a.data) == std::mem::discriminant(&b.data)
            });
        if !same {
            return Err(MapsError::Invalid(format!(
                "shard {s}'s table has other columns than shard 0's"
            )));
        }
    }
    let mut out = Vec::with_capacity(first.len());
    for (j, c) in first.iter().enumerate() {
        let data = match &c.data {
            ColumnData::F64(_) => ColumnData::F64(
                order
                    .iter()
                    .map(|&(s, r)| match &parts[s][j].data {
                        ColumnData::F64(v) => v[r],
                        _ => unreachable!("checked above"),
                    })
                    .collect(),
            ),
            ColumnData::I64(_) => ColumnData::I64(
                order
                    .iter()
                    .map(|&(s, r)| match &parts[s][j].data {
                        ColumnData::I64(v) => v[r],
                        _ => unreachable!("checked above"),
                    })
                    .collect(),
            ),
            ColumnData::Str(_) => ColumnData::Str(
                order
                    .iter()
                    .map(|&(s, r)| match &parts[s][j].data {
                        ColumnData::Str(v) => v[r].clone(),
                        _ => unreachable!("checked above"),
                    })
                    .collect(),
            ),
            ColumnData::Bool(_) => ColumnData::Bool(
                order
                    .iter()
                    .map(|&(s, r)| match &parts[s][j].data {
                        ColumnData::Bool(v) => v[r],
                        _ => unreachable!("checked above"),
                    })
                    .collect(),
            ),
        };
        out.push(Column {
            name: c.name.clone(),
            unit: c.unit.clone(),
            description: c.description.clone(),
            data,
        });
    }
    Ok(out)
}

/// A column's values by name, for rebuilding results from rows.
pub(crate) fn col<'a>(cols: &'a [Column], name: &str) -> Result<&'a ColumnData, MapsError> {
    cols.iter()
        .find(|c| c.name == name)
        .map(|c| &c.data)
        .ok_or_else(|| MapsError::Invalid(format!("shard table has no column {name:?}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env_of(pairs: &[(&str, &str)]) -> impl Fn(&str) -> Option<String> {
        let m: BTreeMap<String, String> = pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        move |k: &str| m.get(k).cloned()
    }

    #[test]
    fn fixed_shards_parse_and_deal_round_robin() {
        assert_eq!(
            ShardSpec::parse("2/5").unwrap(),
            ShardSpec::Fixed(Shard { index: 2, count: 5 })
        );
        assert_eq!(Shard::new(2, 5).unwrap().cells(13), vec![2, 7, 12]);
        let mut all: Vec<usize> = (0..4)
            .flat_map(|i| Shard::new(i, 4).unwrap().cells(10))
            .collect();
        all.sort_unstable();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
        for bad in ["5/5", "1/0", "x/3", "3", "1/y", "-1/3"] {
            let e = ShardSpec::parse(bad).unwrap_err().to_string();
            assert!(e.contains("shard"), "{bad}: {e}");
        }
    }

    #[test]
    fn slurm_arrays_may_start_anywhere() {
        let auto = ShardSpec::parse("auto").unwrap();
        // --array=1-3: ids 1..3 are shards 0..2.
        for id in 1..=3 {
            let s = auto
                .resolve(&env_of(&[
                    ("SLURM_ARRAY_TASK_ID", &id.to_string()),
                    ("SLURM_ARRAY_TASK_MIN", "1"),
                    ("SLURM_ARRAY_TASK_COUNT", "3"),
                ]))
                .unwrap();
            assert_eq!((s.index, s.count), (id - 1, 3));
        }
        // --array=10-16:2 → ids 10, 12, 14, 16 are shards 0..3.
        let s = auto
            .resolve(&env_of(&[
                ("SLURM_ARRAY_TASK_ID", "14"),
                ("SLURM_ARRAY_TASK_MIN", "10"),
                ("SLURM_ARRAY_TASK_STEP", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "4"),
            ]))
            .unwrap();
        assert_eq!((s.index, s.count), (2, 4));
        // A list array (1,5,7): id 7 − min 1 = 6 is beyond 3 tasks.
        let e = auto
            .resolve(&env_of(&[
                ("SLURM_ARRAY_TASK_ID", "7"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("contiguous"), "{e}");
        // auto/N must agree with the array.
        let e = ShardSpec::parse("auto/4")
            .unwrap()
            .resolve(&env_of(&[
                ("SLURM_ARRAY_TASK_ID", "0"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("SLURM_ARRAY_TASK_COUNT=3"), "{e}");
    }

    #[test]
    fn kubernetes_indexed_jobs_need_the_count() {
        let e = ShardSpec::parse("auto")
            .unwrap()
            .resolve(&env_of(&[("JOB_COMPLETION_INDEX", "3")]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("PENDULUM_SHARD_COUNT"), "{e}");
        let s = ShardSpec::parse("auto/8")
            .unwrap()
            .resolve(&env_of(&[("JOB_COMPLETION_INDEX", "3")]))
            .unwrap();
        assert_eq!((s.index, s.count), (3, 8));
        let s = ShardSpec::parse("auto")
            .unwrap()
            .resolve(&env_of(&[
                ("JOB_COMPLETION_INDEX", "7"),
                ("PENDULUM_SHARD_COUNT", "8"),
            ]))
            .unwrap();
        assert_eq!((s.index, s.count), (7, 8));
        let e = ShardSpec::parse("auto")
            .unwrap()
            .resolve(&env_of(&[
                ("JOB_COMPLETION_INDEX", "8"),
                ("PENDULUM_SHARD_COUNT", "8"),
            ]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("below the count"), "{e}");
        let e = ShardSpec::parse("auto")
            .unwrap()
            .resolve(&env_of(&[]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("--shard I/N"), "{e}");
    }

    #[test]
    fn columns_round_trip_and_gather() {
        let dir = tempfile::tempdir().unwrap();
        let cols = vec![
            Column::f64("x", "m", vec![1.0, f64::NAN, -0.0]),
            Column::new("n", ColumnData::I64(vec![1, 2, 3])).describe("count"),
            Column::new(
                "s",
                ColumnData::Str(vec!["a".into(), "b".into(), "c".into()]),
            ),
            Column::new("b", ColumnData::Bool(vec![true, false, true])),
        ];
        let p = dir.path().join("t.parquet");
        TableOptions::new().write(&p, &cols).unwrap();
        let back = read_columns(&p).unwrap();
        assert_eq!(back.len(), 4);
        assert_eq!(back[0].unit.as_deref(), Some("m"));
        assert_eq!(back[1].description.as_deref(), Some("count"));
        match &back[0].data {
            ColumnData::F64(v) => {
                assert_eq!(v[0], 1.0);
                assert!(v[1].is_nan());
                assert!(v[2] == 0.0 && v[2].is_sign_negative());
            }
            other => panic!("{other:?}"),
        }
        let g = gather(&[back.clone(), back], &[(1, 2), (0, 0)]).unwrap();
        assert_eq!(g[1].data, ColumnData::I64(vec![3, 1]));
        assert_eq!(
            g[2].data,
            ColumnData::Str(vec!["c".to_string(), "a".to_string()])
        );
    }
}
