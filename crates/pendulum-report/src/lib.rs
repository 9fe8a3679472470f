//! Parquet tables for dataframe analysis (pandas, polars, DuckDB): typed columns, units in field
//! metadata, the producing command and versions in the key-value metadata, zstd, written
//! atomically (a `.name.<pid>-<n>.tmp` beside the target, fsync, rename) so a crash never leaves a
//! half-written table under the final name.

use std::collections::HashMap;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::{SystemTime, UNIX_EPOCH};

use arrow_array::{ArrayRef, BooleanArray, Float64Array, Int64Array, RecordBatch, StringArray};
use arrow_schema::{DataType, Field, Schema};
use parquet::arrow::ArrowWriter;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::properties::WriterProperties;

/// Errors of the report crate.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: writing Parquet: {source}")]
    Parquet {
        path: PathBuf,
        #[source]
        source: parquet::errors::ParquetError,
    },
    #[error("{path}: building the table: {source}")]
    Arrow {
        path: PathBuf,
        #[source]
        source: arrow_schema::ArrowError,
    },
    #[error("{path}: column {column:?} has {got} rows, expected {expected}")]
    RaggedColumns {
        path: PathBuf,
        column: String,
        got: usize,
        expected: usize,
    },
}

/// The values of one column.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnData {
    F64(Vec<f64>),
    I64(Vec<i64>),
    Str(Vec<String>),
    Bool(Vec<bool>),
}

impl ColumnData {
    fn len(&self) -> usize {
        match self {
            ColumnData::F64(v) => v.len(),
            ColumnData::I64(v) => v.len(),
            ColumnData::Str(v) => v.len(),
            ColumnData::Bool(v) => v.len(),
        }
    }
}

/// A named column with its unit (stored as field metadata `unit`) and a short description.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    pub name: String,
    pub unit: Option<String>,
    pub description: Option<String>,
    pub data: ColumnData,
}

impl Column {
    pub fn new(name: &str, data: ColumnData) -> Self {
        Self {
            name: name.to_string(),
            unit: None,
            description: None,
            data,
        }
    }

    pub fn f64(name: &str, unit: &str, values: Vec<f64>) -> Self {
        Self::new(name, ColumnData::F64(values)).unit(unit)
    }

    pub fn unit(mut self, unit: &str) -> Self {
        self.unit = Some(unit.to_string());
        self
    }

    pub fn describe(mut self, text: &str) -> Self {
        self.description = Some(text.to_string());
        self
    }
}

/// One run of the program: an id every table it writes carries (key `invocation_id`), so that
/// tables of different runs of a command left in one folder (one killed over an earlier
/// result) can be told apart, and the instant it started (temporary files older than it
/// cannot be its own).
#[derive(Debug, Clone)]
pub struct Invocation {
    /// `<unix seconds>.<nanoseconds>-<pid>`: the start instant and the process, unique on one
    /// machine and sortable by start time.
    pub id: String,
    pub started: SystemTime,
}

/// This process's invocation, fixed at the first call: the binary calls it first thing so that
/// `started` is its start.
pub fn invocation() -> &'static Invocation {
    static INVOCATION: OnceLock<Invocation> = OnceLock::new();
    INVOCATION.get_or_init(|| {
        let started = SystemTime::now();
        let since = started.duration_since(UNIX_EPOCH).unwrap_or_default();
        Invocation {
            id: format!(
                "{}.{:09}-{}",
                since.as_secs(),
                since.subsec_nanos(),
                std::process::id()
            ),
            started,
        }
    })
}

/// Writer options with sensible defaults (zstd level 3, 64k rows per group).
#[derive(Debug, Clone)]
pub struct TableOptions {
    pub zstd_level: i32,
    pub row_group_rows: usize,
    pub metadata: Vec<(String, String)>,
}

impl Default for TableOptions {
    fn default() -> Self {
        Self {
            zstd_level: 3,
            row_group_rows: 65_536,
            metadata: vec![
                (
                    "pendulum_version".to_string(),
                    env!("CARGO_PKG_VERSION").to_string(),
                ),
                ("invocation_id".to_string(), invocation().id.clone()),
            ],
        }
    }
}

impl TableOptions {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a key-value pair to the file's footer metadata.
    pub fn meta(mut self, key: &str, value: impl Into<String>) -> Self {
        self.metadata.push((key.to_string(), value.into()));
        self
    }

    /// Writes `columns` to `path` atomically.
    pub fn write(&self, path: &Path, columns: &[Column]) -> Result<TableSummary, ReportError> {
        write_table(path, columns, self)
    }
}

/// What a write produced.
#[derive(Debug, Clone, PartialEq)]
pub struct TableSummary {
    pub path: PathBuf,
    pub rows: usize,
    pub columns: usize,
    pub bytes: u64,
}

/// `.NAME.<pid>-<n>.tmp` beside `path`: unique to this process and call, so that two processes
/// writing the same table into one folder never share, truncate or delete each other's
/// temporary file (issue 13).
fn tmp_path(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "table.parquet".into());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}-{n}.tmp", std::process::id()))
}

/// The writer's process id when `name` is one of this program's temporary file names:
/// `.NAME.<pid>-<n>.tmp` (tables here, MCAP logs in `pendulum-log`) or `.NAME.<pid>-<n>.tmp.png`
/// (plots in `pendulum-plot`, whose encoder picks the format from the extension). Anything else,
/// a user's own dot-file included, is `None`.
pub fn temp_writer_pid(name: &str) -> Option<u32> {
    let stem = name
        .strip_suffix(".tmp.png")
        .or_else(|| name.strip_suffix(".tmp"))?;
    let (base, tag) = stem.strip_prefix('.')?.rsplit_once('.')?;
    let (pid, n) = tag.split_once('-')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if base.is_empty() || !digits(pid) || !digits(n) {
        return None;
    }
    pid.parse().ok()
}

fn write_table(
    path: &Path,
    columns: &[Column],
    opts: &TableOptions,
) -> Result<TableSummary, ReportError> {
    let rows = columns.first().map_or(0, |c| c.data.len());
    let mut fields = Vec::with_capacity(columns.len());
    let mut arrays: Vec<ArrayRef> = Vec::with_capacity(columns.len());
    for c in columns {
        if c.data.len() != rows {
            return Err(ReportError::RaggedColumns {
                path: path.to_path_buf(),
                column: c.name.clone(),
                got: c.data.len(),
                expected: rows,
            });
        }
        let (dt, arr): (DataType, ArrayRef) = match &c.data {
            ColumnData::F64(v) => (DataType::Float64, Arc::new(Float64Array::from(v.clone()))),
            ColumnData::I64(v) => (DataType::Int64, Arc::new(Int64Array::from(v.clone()))),
            ColumnData::Str(v) => (DataType::Utf8, Arc::new(StringArray::from(v.clone()))),
            ColumnData::Bool(v) => (DataType::Boolean, Arc::new(BooleanArray::from(v.clone()))),
        };
        let mut md = HashMap::new();
        if let Some(u) = &c.unit {
            md.insert("unit".to_string(), u.clone());
        }
        if let Some(d) = &c.description {
            md.insert("description".to_string(), d.clone());
        }
        fields.push(Field::new(&c.name, dt, false).with_metadata(md));
        arrays.push(arr);
    }
    // The pairs go both into the Arrow schema (pyarrow/polars show them as `schema.metadata`)
    // and into the Parquet footer (any Parquet reader).
    let schema_md: HashMap<String, String> = opts.metadata.iter().cloned().collect();
    let schema = Arc::new(Schema::new(fields).with_metadata(schema_md));
    let batch =
        RecordBatch::try_new(schema.clone(), arrays).map_err(|source| ReportError::Arrow {
            path: path.to_path_buf(),
            source,
        })?;
    let level = ZstdLevel::try_new(opts.zstd_level).map_err(|source| ReportError::Parquet {
        path: path.to_path_buf(),
        source,
    })?;
    let props = WriterProperties::builder()
        .set_compression(Compression::ZSTD(level))
        .set_max_row_group_row_count(Some(opts.row_group_rows.max(1)))
        .build();
    let tmp = tmp_path(path);
    let io = |source| ReportError::Io {
        path: tmp.clone(),
        source,
    };
    // `create_new`: never truncate a file this call did not create.
    let file = File::create_new(&tmp).map_err(io)?;
    let pq = |source| ReportError::Parquet {
        path: path.to_path_buf(),
        source,
    };
    let result = (|| {
        let mut w = ArrowWriter::try_new(file, schema, Some(props)).map_err(pq)?;
        for (k, v) in &opts.metadata {
            w.append_key_value_metadata(parquet::file::metadata::KeyValue::new(
                k.clone(),
                v.clone(),
            ));
        }
        w.write(&batch).map_err(pq)?;
        let file = w.into_inner().map_err(pq)?;
        file.sync_all().map_err(io)?;
        Ok(())
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, path).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    Ok(TableSummary {
        path: path.to_path_buf(),
        rows,
        columns: columns.len(),
        bytes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use parquet::file::reader::{FileReader, SerializedFileReader};

    /// Two writers of one table never share a temporary name (two identify runs into one
    /// folder, issue 13); before, both used `.t.parquet.tmp`.
    #[test]
    fn issue_13_temporary_names_are_unique_per_writer() {
        let p = Path::new("/out/t.parquet");
        let (a, b) = (tmp_path(p), tmp_path(p));
        assert_ne!(a, b);
        for t in [&a, &b] {
            let name = t.file_name().unwrap().to_string_lossy().into_owned();
            assert!(
                name.starts_with(".t.parquet.") && name.ends_with(".tmp"),
                "{name}"
            );
            assert!(name.contains(&std::process::id().to_string()), "{name}");
            assert_eq!(t.parent(), p.parent());
        }
    }

    /// The temporary names the writers make are recognised, and nothing else is: a stale-temp
    /// sweep must never take a user's file.
    #[test]
    fn issue_13_temporary_names_are_recognised() {
        let own = tmp_path(Path::new("/out/params.parquet"));
        let own = own.file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(temp_writer_pid(&own), Some(std::process::id()));
        assert_eq!(temp_writer_pid(".r01.mcap.123-4.tmp"), Some(123));
        assert_eq!(
            temp_writer_pid(".history_reference_r01.png.77-0.tmp.png"),
            Some(77)
        );
        for other in [
            "params.parquet",
            ".params.parquet.tmp",
            ".r01.mcap.12a-4.tmp",
            ".r01.mcap.123-.tmp",
            ".123-4.tmp",
            "notes.123-4.tmp",
            ".bashrc",
            "campaign.tmp",
        ] {
            assert_eq!(temp_writer_pid(other), None, "{other}");
        }
    }

    #[test]
    fn round_trip_with_units_and_metadata() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.parquet");
        let cols = vec![
            Column::f64("t", "1", vec![0.0, 0.5, 1.0]),
            Column::new("class", ColumnData::Str(vec!["rest".into(); 3])),
            Column::new("k", ColumnData::I64(vec![1, 2, 3])),
            Column::new("ok", ColumnData::Bool(vec![true, false, true])),
        ];
        let s = TableOptions::new()
            .meta("steady_state", "rest")
            .write(&path, &cols)
            .unwrap();
        assert_eq!((s.rows, s.columns), (3, 4));
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, ["t.parquet"], "temporary file left behind");
        let r = SerializedFileReader::new(File::open(&path).unwrap()).unwrap();
        let kv = r.metadata().file_metadata().key_value_metadata().unwrap();
        assert!(kv
            .iter()
            .any(|k| k.key == "steady_state" && k.value.as_deref() == Some("rest")));
        assert!(kv
            .iter()
            .any(|k| k.key == "invocation_id" && k.value.as_deref() == Some(&invocation().id)));
        let batches: Vec<_> =
            parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(
                File::open(&path).unwrap(),
            )
            .unwrap()
            .build()
            .unwrap()
            .collect::<Result<_, _>>()
            .unwrap();
        let b = &batches[0];
        assert_eq!(
            b.schema()
                .field(0)
                .metadata()
                .get("unit")
                .map(String::as_str),
            Some("1")
        );
        let t = b.column(0).as_any().downcast_ref::<Float64Array>().unwrap();
        assert_eq!(t.values().to_vec(), vec![0.0, 0.5, 1.0]);
    }

    #[test]
    fn ragged_columns_are_an_error_and_leave_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.parquet");
        let cols = vec![
            Column::f64("a", "1", vec![0.0]),
            Column::f64("b", "1", vec![]),
        ];
        let e = TableOptions::new()
            .write(&path, &cols)
            .unwrap_err()
            .to_string();
        assert!(e.contains("\"b\"") && e.contains("expected 1"), "{e}");
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
    }
}
