//! The model rows of `params.parquet` (written by `pendulum identify`: one row per model, with
//! `model`, the physical rig and damping values, the dimensionless set and any fitted effect
//! columns such as `coulomb_constant.T_c`), turned into `key=value` assignments that
//! [`pendulum_model::ParamSpec`] resolves exactly like `--param`.

use std::collections::BTreeMap;
use std::fs::File;
use std::path::Path;

use arrow_array::cast::AsArray;
use arrow_array::types::{Float32Type, Float64Type, Int32Type, Int64Type};
use arrow_array::Array;
use arrow_array::ArrayRef;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use pendulum_model::spec::{effect_keys, DIMENSIONLESS_KEYS, PHYSICAL_KEYS};

use crate::MapsError;

/// One model's row: its name and every numeric column that has a finite value.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamsRow {
    pub model: String,
    pub values: BTreeMap<String, f64>,
}

impl ParamsRow {
    pub fn get(&self, key: &str) -> Option<f64> {
        self.values.get(key).copied()
    }

    /// The row's parameters as `key=value` assignments: the physical keys and the effect
    /// columns, and with `dimensionless` also the dimensionless keys (which then override what
    /// the physical ones imply, as on the command line). Columns the model crate does not know
    /// (`f_obj`, `e_theta`, …) are left out.
    pub fn assignments(&self, dimensionless: bool) -> Vec<String> {
        let mut out = Vec::new();
        let mut push = |keys: &[&str]| {
            for k in keys {
                if let Some(v) = self.get(k) {
                    out.push(format!("{k}={v}"));
                }
            }
        };
        push(&PHYSICAL_KEYS);
        push(&effect_keys());
        if dimensionless {
            push(&DIMENSIONLESS_KEYS);
        }
        out
    }
}

fn numeric(col: &ArrayRef, i: usize) -> Option<f64> {
    if col.is_null(i) {
        return None;
    }
    let v = if let Some(a) = col.as_primitive_opt::<Float64Type>() {
        a.value(i)
    } else if let Some(a) = col.as_primitive_opt::<Float32Type>() {
        f64::from(a.value(i))
    } else if let Some(a) = col.as_primitive_opt::<Int64Type>() {
        a.value(i) as f64
    } else if let Some(a) = col.as_primitive_opt::<Int32Type>() {
        f64::from(a.value(i))
    } else {
        return None;
    };
    v.is_finite().then_some(v)
}

fn text(col: &ArrayRef, i: usize) -> Option<String> {
    if col.is_null(i) {
        return None;
    }
    if let Some(a) = col.as_string_opt::<i32>() {
        Some(a.value(i).to_string())
    } else if let Some(a) = col.as_string_opt::<i64>() {
        Some(a.value(i).to_string())
    } else {
        col.as_string_view_opt().map(|a| a.value(i).to_string())
    }
}

/// Reads every model row of a `params.parquet`.
pub fn read_params(path: &Path) -> Result<Vec<ParamsRow>, MapsError> {
    let file = File::open(path).map_err(|source| MapsError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let pq = |source| MapsError::Parquet {
        path: path.to_path_buf(),
        source,
    };
    let reader = ParquetRecordBatchReaderBuilder::try_new(file)
        .map_err(pq)?
        .build()
        .map_err(pq)?;
    let mut rows = Vec::new();
    for batch in reader {
        let batch = batch.map_err(|e| MapsError::Parquet {
            path: path.to_path_buf(),
            source: parquet::errors::ParquetError::ArrowError(e.to_string()),
        })?;
        let schema = batch.schema();
        let model_idx = schema.index_of("model").map_err(|_| {
            MapsError::Invalid(format!(
                "{}: no `model` column: not a params table written by pendulum identify? (columns: {})",
                path.display(),
                schema
                    .fields()
                    .iter()
                    .map(|f| f.name().as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        let model_col = batch.column(model_idx);
        for i in 0..batch.num_rows() {
            let Some(model) = text(model_col, i) else {
                continue;
            };
            let mut values = BTreeMap::new();
            for (f, col) in schema.fields().iter().zip(batch.columns()) {
                if let Some(v) = numeric(col, i) {
                    values.insert(f.name().clone(), v);
                }
            }
            rows.push(ParamsRow { model, values });
        }
    }
    Ok(rows)
}

/// The row of model `name`; the error lists the models the file has.
pub fn find_model(path: &Path, rows: Vec<ParamsRow>, name: &str) -> Result<ParamsRow, MapsError> {
    let names: Vec<String> = rows.iter().map(|r| r.model.clone()).collect();
    rows.into_iter().find(|r| r.model == name).ok_or_else(|| {
        MapsError::Invalid(format!(
            "{}: no model {name:?}; the file has {}",
            path.display(),
            if names.is_empty() {
                "no model rows".to_string()
            } else {
                names.join(", ")
            }
        ))
    })
}

/// Reads `path` and returns the row of model `name`.
pub fn load_model(path: &Path, name: &str) -> Result<ParamsRow, MapsError> {
    find_model(path, read_params(path)?, name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pendulum_model::{ParamSpec, Physical};
    use pendulum_report::{Column, ColumnData, TableOptions};

    #[test]
    fn rows_resolve_like_params() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("params.parquet");
        let f = |name: &str, v: Vec<f64>| Column::f64(name, "1", v);
        let cols = vec![
            Column::new(
                "model",
                ColumnData::Str(vec!["reference".into(), "linear".into()]),
            ),
            f("a", vec![0.0, 0.0]),
            f("b", vec![0.5, 0.3]),
            f("mu", vec![0.15, 0.0]),
            f("coulomb_constant.T_c", vec![0.004, f64::NAN]),
            f("beta", vec![0.109, 0.066]),
            f("M", vec![0.007, 0.0]),
            f("R", vec![0.7, 0.7]),
            f("lambda", vec![0.126, 0.126]),
            f("f_obj", vec![1.0, 2.0]),
        ];
        TableOptions::new().write(&path, &cols).unwrap();
        let row = load_model(&path, "reference").unwrap();
        assert_eq!(row.get("b"), Some(0.5));
        let a = row.assignments(true);
        assert!(
            a.contains(&"coulomb_constant.T_c=0.004".to_string()),
            "{a:?}"
        );
        assert!(!a.iter().any(|s| s.starts_with("f_obj")));
        let (_, d) = ParamSpec::parse(&a)
            .unwrap()
            .resolve(&Physical::default())
            .unwrap();
        assert_eq!(
            (d.beta, d.m_coulomb, d.r, d.lambda),
            (0.109, 0.007, 0.7, 0.126)
        );
        assert!(d.c > 0.0);
        let lin = load_model(&path, "linear").unwrap();
        assert!(lin.get("coulomb_constant.T_c").is_none());
        let e = load_model(&path, "quadratic").unwrap_err().to_string();
        assert!(e.contains("reference, linear"), "{e}");
    }

    /// A params.parquet someone opened in pandas and saved again comes back snappy-compressed
    /// (pandas', pyarrow's and DuckDB's default; we write zstd): it reads the same.
    #[test]
    fn a_table_saved_by_pandas_reads_the_same() {
        use parquet::arrow::ArrowWriter;
        use parquet::basic::Compression;
        use parquet::file::properties::WriterProperties;
        let dir = tempfile::tempdir().unwrap();
        let ours = dir.path().join("params.parquet");
        let cols = vec![
            Column::new("model", ColumnData::Str(vec!["reference".into()])),
            Column::f64("b", "N·s/m", vec![0.5]),
            Column::f64("mu", "1", vec![0.15]),
            Column::f64("coulomb_constant.T_c", "N·m", vec![0.004]),
        ];
        TableOptions::new().write(&ours, &cols).unwrap();
        let batches: Vec<_> = ParquetRecordBatchReaderBuilder::try_new(File::open(&ours).unwrap())
            .unwrap()
            .build()
            .unwrap()
            .map(Result::unwrap)
            .collect();
        let theirs = dir.path().join("edited.parquet");
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .build();
        let mut w = ArrowWriter::try_new(
            File::create(&theirs).unwrap(),
            batches[0].schema(),
            Some(props),
        )
        .unwrap();
        for b in &batches {
            w.write(b).unwrap();
        }
        w.close().unwrap();
        assert_eq!(
            load_model(&theirs, "reference").unwrap(),
            load_model(&ours, "reference").unwrap()
        );
    }
}
