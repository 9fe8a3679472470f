//! `campaign.toml`: which captures make up a campaign, and each run's rig geometry.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use toml::Value;

use crate::error::RigError;
use crate::names;

/// The file name of a campaign description inside its folder.
pub const CAMPAIGN_FILE: &str = "campaign.toml";

/// What a run is used for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// The run takes part in fitting the damping parameters.
    Identify,
    /// The run only checks the fitted parameters.
    Validate,
}

impl Role {
    pub fn as_str(&self) -> &'static str {
        match self {
            Role::Identify => "identify",
            Role::Validate => "validate",
        }
    }
}

/// One run, with the rig-table defaults already applied.
///
/// The rig keys (`m_kg` … `r_b_m`) are NaN when a `format = "timeseries"` run leaves them out
/// (they are optional there); its file's description stays in `extra` (see
/// [`crate::timeseries`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSpec {
    pub id: String,
    /// The capture, resolved against the campaign folder.
    pub file: PathBuf,
    pub role: Role,
    pub m_kg: f64,
    pub l_m: f64,
    pub crank_r_m: f64,
    /// Key `rod_L_m`.
    pub rod_l_m: f64,
    pub r_b_m: f64,
    /// Crank speed set point (the accelerometer says what it really was).
    pub omega_hz: Option<f64>,
    /// `"serial-v1"` or `"sd-v2"`, if the experimenter said (readers detect it anyway), or
    /// `"timeseries"` (a generic CSV/TSV described by the run's keys).
    pub format: Option<String>,
    /// Every key not listed above, from the rig table and the run (the run wins).
    pub extra: BTreeMap<String, Value>,
}

/// A campaign folder's description.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Campaign {
    /// The folder holding `campaign.toml` and the captures.
    pub dir: PathBuf,
    /// `name`, or the folder's name when absent.
    pub name: String,
    /// `g_m_s2`, default 9.81.
    pub g_m_s2: f64,
    /// The `[rig]` table as written (defaults for every run).
    pub rig: BTreeMap<String, Value>,
    pub runs: Vec<RunSpec>,
    /// Unknown top-level keys.
    pub extra: BTreeMap<String, Value>,
    /// Unknown keys so close to a known one that they are probably a misspelling of it (see
    /// [`suggest_key`]), each naming the file, the run (or `[rig]`) and the suggestion. The key
    /// is still kept as metadata, as rig.md requires; the user is told.
    pub warnings: Vec<String>,
}

/// Top-level keys the program reads.
const TOP_KEYS: [&str; 4] = ["name", "g_m_s2", "rig", "run"];

/// The known key an unknown `key` is probably a misspelling of: at most 2 edits away (a
/// transposition counts as one: `omgea_hz`), 1 for keys of 4 characters or fewer so that
/// ordinary short metadata keys are not taken for one (rig.md's own `note` is 2 edits from
/// `role`). `None` when no known key is that close, or the key is itself known.
pub fn suggest_key<'a>(key: &str, known: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let mut best: Option<(usize, &str)> = None;
    for k in known {
        if k == key {
            return None;
        }
        let d = edit_distance(key, k);
        let limit = if k.chars().count().min(key.chars().count()) <= 4 {
            1
        } else {
            2
        };
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, k));
        }
    }
    best.map(|(_, k)| k)
}

/// Optimal-string-alignment distance: insertions, deletions, substitutions and transpositions
/// of neighbours each count 1.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[a.len()][b.len()]
}

const RUN_KEYS: [&str; 10] = [
    "id",
    "file",
    "role",
    "m_kg",
    "l_m",
    "crank_r_m",
    "rod_L_m",
    "r_b_m",
    "omega_hz",
    "format",
];
const FORMATS: [&str; 3] = ["serial-v1", "sd-v2", crate::timeseries::FORMAT];

impl Campaign {
    /// Loads `dir/campaign.toml`, or the given `.toml` file (its folder is the campaign's).
    pub fn load(dir_or_toml: impl AsRef<Path>) -> Result<Self, RigError> {
        let p = dir_or_toml.as_ref();
        let toml_path = if p.is_dir() {
            p.join(CAMPAIGN_FILE)
        } else {
            p.to_path_buf()
        };
        // Read at most one byte past the limit: a hostile campaign.toml of gigabytes is refused
        // without being held in memory (a 19 MB `name` used to take 170 MB).
        let file = std::fs::File::open(&toml_path).map_err(|e| RigError::io(&toml_path, e))?;
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(
            &mut std::io::Read::take(file, MAX_CAMPAIGN_BYTES + 1),
            &mut bytes,
        )
        .map_err(|e| RigError::io(&toml_path, e))?;
        if bytes.len() as u64 > MAX_CAMPAIGN_BYTES {
            return Err(RigError::TooLarge {
                path: toml_path,
                at: format!("more than {MAX_CAMPAIGN_BYTES} bytes"),
                what: "a campaign description is a few KB (about 150 bytes a run): not read".into(),
            });
        }
        let text = String::from_utf8(bytes).map_err(|e| {
            RigError::io(
                &toml_path,
                std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
                ),
            )
        })?;
        Self::parse(&text, &toml_path)
    }

    /// Parses campaign text; `toml_path` names the file in messages and its folder resolves
    /// the run files.
    pub fn parse(text: &str, toml_path: impl AsRef<Path>) -> Result<Self, RigError> {
        let path = toml_path.as_ref();
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        check_line_lengths(text, path)?;
        let mut table: toml::Table = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((1, 1));
            RigError::CampaignSyntax {
                path: path.to_path_buf(),
                line,
                column,
                message: e.message().trim().to_string(),
            }
        })?;
        let key_err = |run: Option<String>, key: &str, expected: &str| RigError::CampaignKey {
            path: path.to_path_buf(),
            run,
            key: key.to_string(),
            expected: expected.to_string(),
        };

        let name = match table.remove("name") {
            None => dir
                .canonicalize()
                .ok()
                .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
                .unwrap_or_else(|| "campaign".to_string()),
            Some(Value::String(s)) => s,
            Some(_) => return Err(key_err(None, "name", "a string")),
        };
        let g_m_s2 = match table.remove("g_m_s2") {
            None => 9.81,
            Some(v) => positive(&v).ok_or_else(|| key_err(None, "g_m_s2", "a positive number"))?,
        };
        let rig: BTreeMap<String, Value> = match table.remove("rig") {
            None => BTreeMap::new(),
            Some(Value::Table(t)) => t.into_iter().collect(),
            Some(_) => return Err(key_err(None, "rig", "a table [rig]")),
        };
        let run_values = match table.remove("run") {
            None => Vec::new(),
            Some(Value::Array(a)) => a,
            Some(_) => return Err(key_err(None, "run", "an array of tables [[run]]")),
        };
        let extra: BTreeMap<String, Value> = table.into_iter().collect();
        let run_keys = || {
            RUN_KEYS
                .iter()
                .chain(crate::timeseries::TIMESERIES_KEYS.iter())
                .copied()
        };
        let mut warnings = Vec::new();
        let mut warn = |scope: &str, key: &str, known: &str| {
            warnings.push(format!(
                "{}: {scope}unknown key `{}` (kept as metadata): did you mean `{known}`?",
                path.display(),
                names::printable(key)
            ));
        };
        for k in extra.keys() {
            if let Some(known) = suggest_key(k, TOP_KEYS.iter().copied().chain(run_keys())) {
                warn("", k, known);
            }
        }
        for k in rig.keys() {
            if let Some(known) = suggest_key(k, run_keys()) {
                warn("[rig]: ", k, known);
            }
        }
        for (i, v) in run_values.iter().enumerate() {
            let Value::Table(t) = v else { continue };
            let label = match t.get("id") {
                Some(Value::String(s)) if names::check_run_id(s).is_ok() => s.clone(),
                _ => format!("run #{}", i + 1),
            };
            for k in t.keys() {
                if let Some(known) = suggest_key(k, run_keys()) {
                    warn(&format!("run `{label}`: "), k, known);
                }
            }
        }

        let mut runs = Vec::with_capacity(run_values.len());
        let mut ids = BTreeSet::new();
        for (i, v) in run_values.into_iter().enumerate() {
            let Value::Table(t) = v else {
                return Err(key_err(
                    Some(format!("run #{}", i + 1)),
                    "run",
                    "a table [[run]]",
                ));
            };
            let run = Self::parse_run(path, &dir, &rig, t, i)?;
            if !ids.insert(run.id.clone()) {
                return Err(RigError::DuplicateRunId {
                    path: path.to_path_buf(),
                    run_id: run.id,
                });
            }
            runs.push(run);
        }
        Ok(Campaign {
            dir,
            name,
            g_m_s2,
            rig,
            runs,
            extra,
            warnings,
        })
    }

    fn parse_run(
        path: &Path,
        dir: &Path,
        rig: &BTreeMap<String, Value>,
        run: toml::Table,
        index: usize,
    ) -> Result<RunSpec, RigError> {
        let mut merged: BTreeMap<String, Value> = rig.clone();
        merged.extend(run);
        let mut label = format!("run #{}", index + 1);
        let key_err = |label: &str, key: &str, expected: &str| RigError::CampaignKey {
            path: path.to_path_buf(),
            run: Some(label.to_string()),
            key: key.to_string(),
            expected: expected.to_string(),
        };
        let unsafe_name =
            |label: &str, key: &'static str, value: &str, problem: String| RigError::UnsafeName {
                path: path.to_path_buf(),
                run: label.to_string(),
                key,
                value: value.to_string(),
                problem,
            };
        let id = match merged.get("id") {
            Some(Value::String(s)) if !s.is_empty() => s.clone(),
            _ => return Err(key_err(&label, "id", "a non-empty string")),
        };
        // The id becomes output file names (and appears in messages): refused before it is
        // used for anything, including as the label of later errors.
        names::check_run_id(&id).map_err(|p| unsafe_name(&label, "id", &id, p))?;
        label = id.clone();
        let file = match merged.get("file") {
            Some(Value::String(s)) if !s.is_empty() => {
                // Captures are read from the campaign folder only.
                names::check_relative_file(s).map_err(|p| unsafe_name(&label, "file", s, p))?;
                dir.join(s)
            }
            _ => {
                return Err(key_err(
                    &label,
                    "file",
                    "a non-empty string (capture file name)",
                ))
            }
        };
        let role = match merged.get("role") {
            Some(Value::String(s)) => match s.as_str() {
                "identify" => Role::Identify,
                "validate" => Role::Validate,
                _ => {
                    return Err(RigError::BadRole {
                        path: path.to_path_buf(),
                        run: label,
                        value: s.clone(),
                    })
                }
            },
            _ => return Err(key_err(&label, "role", "\"identify\" or \"validate\"")),
        };
        let num = |key: &str| -> Result<f64, RigError> {
            merged
                .get(key)
                .and_then(positive)
                .ok_or_else(|| key_err(&label, key, "a positive number"))
        };
        // A time-series run from another rig may leave the rig keys out (NaN = unknown).
        let timeseries = matches!(merged.get("format"), Some(Value::String(s)) if s == crate::timeseries::FORMAT);
        let rig_num = |key: &str| -> Result<f64, RigError> {
            if timeseries && !merged.contains_key(key) {
                Ok(f64::NAN)
            } else {
                num(key)
            }
        };
        let m_kg = rig_num("m_kg")?;
        let l_m = rig_num("l_m")?;
        let crank_r_m = rig_num("crank_r_m")?;
        let rod_l_m = rig_num("rod_L_m")?;
        let r_b_m = rig_num("r_b_m")?;
        let omega_hz = match merged.get("omega_hz") {
            None => None,
            Some(_) => Some(num("omega_hz")?),
        };
        let format = match merged.get("format") {
            None => None,
            Some(Value::String(s)) if FORMATS.contains(&s.as_str()) => Some(s.clone()),
            Some(_) => {
                return Err(key_err(
                    &label,
                    "format",
                    "\"serial-v1\", \"sd-v2\" or \"timeseries\"",
                ))
            }
        };
        if timeseries {
            // Checked here so that a bad key names campaign.toml; the keys stay in `extra`.
            crate::timeseries::TimeseriesSpec::from_keys(&merged, path, &label)?;
        }
        let extra = merged
            .into_iter()
            .filter(|(k, _)| !RUN_KEYS.contains(&k.as_str()))
            .collect();
        Ok(RunSpec {
            id,
            file,
            role,
            m_kg,
            l_m,
            crank_r_m,
            rod_l_m,
            r_b_m,
            omega_hz,
            format,
            extra,
        })
    }

    /// The path of `campaign.toml`.
    pub fn toml_path(&self) -> PathBuf {
        self.dir.join(CAMPAIGN_FILE)
    }

    /// Fails with [`RigError::MissingRunFile`] for the first run whose capture is absent.
    pub fn check_files(&self) -> Result<(), RigError> {
        match self.runs.iter().find(|r| !r.file.is_file()) {
            Some(r) => Err(RigError::MissingRunFile {
                path: r.file.clone(),
                run_id: r.id.clone(),
            }),
            None => Ok(()),
        }
    }

    /// The runs with this role.
    pub fn runs_with_role(&self, role: Role) -> impl Iterator<Item = &RunSpec> {
        self.runs.iter().filter(move |r| r.role == role)
    }

    /// TOML text that [`Campaign::load`] reads back into an equal campaign (when it sits in
    /// the same folder). Run files inside the folder are written relative to it; every run
    /// key is written explicitly, so the `[rig]` table is kept only as metadata-and-defaults.
    pub fn to_toml_string(&self) -> Result<String, RigError> {
        let mut top = toml::Table::new();
        top.insert("name".into(), Value::String(self.name.clone()));
        top.insert("g_m_s2".into(), Value::Float(self.g_m_s2));
        for (k, v) in &self.extra {
            top.insert(k.clone(), v.clone());
        }
        if !self.rig.is_empty() {
            top.insert(
                "rig".into(),
                Value::Table(self.rig.clone().into_iter().collect()),
            );
        }
        let runs = self
            .runs
            .iter()
            .map(|r| Value::Table(self.run_table(r)))
            .collect();
        top.insert("run".into(), Value::Array(runs));
        toml::to_string(&top).map_err(|e| RigError::CampaignWrite {
            path: self.toml_path(),
            message: e.to_string(),
        })
    }

    fn run_table(&self, r: &RunSpec) -> toml::Table {
        let mut t = toml::Table::new();
        for (k, v) in &r.extra {
            t.insert(k.clone(), v.clone());
        }
        let file = r.file.strip_prefix(&self.dir).unwrap_or(&r.file);
        t.insert("id".into(), Value::String(r.id.clone()));
        t.insert(
            "file".into(),
            Value::String(file.to_string_lossy().into_owned()),
        );
        t.insert("role".into(), Value::String(r.role.as_str().into()));
        for (k, v) in [
            ("m_kg", r.m_kg),
            ("l_m", r.l_m),
            ("crank_r_m", r.crank_r_m),
            ("rod_L_m", r.rod_l_m),
            ("r_b_m", r.r_b_m),
        ] {
            // NaN: left out by a time-series run.
            if !v.is_nan() {
                t.insert(k.into(), Value::Float(v));
            }
        }
        if let Some(w) = r.omega_hz {
            t.insert("omega_hz".into(), Value::Float(w));
        }
        if let Some(f) = &r.format {
            t.insert("format".into(), Value::String(f.clone()));
        }
        t
    }

    /// Writes [`Campaign::to_toml_string`] to `path`: a folder (then `campaign.toml` in it) or
    /// a file path.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<(), RigError> {
        let p = path.as_ref();
        let target = if p.is_dir() {
            p.join(CAMPAIGN_FILE)
        } else {
            p.to_path_buf()
        };
        let text = self.to_toml_string()?;
        std::fs::write(&target, text).map_err(|e| RigError::io(&target, e))
    }
}

/// A positive finite number; TOML integers are accepted (`m_kg = 1`).
fn positive(v: &Value) -> Option<f64> {
    let x = match v {
        Value::Float(f) => *f,
        Value::Integer(i) => *i as f64,
        _ => return None,
    };
    (x.is_finite() && x > 0.0).then_some(x)
}

/// 1-based line and column (in characters) of a byte offset.
/// The largest `campaign.toml` read: 1 MiB is some 7,000 runs.
pub const MAX_CAMPAIGN_BYTES: u64 = 1024 * 1024;

/// The longest line of a `campaign.toml`: keys, ids, notes and file names are short; a longer
/// line is damage or a hostile file (the TOML parser would copy it more than once).
pub const MAX_CAMPAIGN_LINE_BYTES: usize = 64 * 1024;

/// Refuses a line longer than [`MAX_CAMPAIGN_LINE_BYTES`], naming its line and byte offset.
fn check_line_lengths(text: &str, path: &Path) -> Result<(), RigError> {
    let mut start = 0usize;
    for (i, line) in text.split('\n').enumerate() {
        if line.len() > MAX_CAMPAIGN_LINE_BYTES {
            return Err(RigError::TooLarge {
                path: path.to_path_buf(),
                at: format!("line {}, byte {start}", i + 1),
                what: format!(
                    "a line of {} bytes, longer than the {MAX_CAMPAIGN_LINE_BYTES} a campaign \
                     line may hold",
                    line.len()
                ),
            });
        }
        start += line.len() + 1;
    }
    Ok(())
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut off = offset.min(text.len());
    while !text.is_char_boundary(off) {
        off -= 1;
    }
    let before = &text[..off];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXAMPLE: &str = r#"
name = "damping-2026-03"
g_m_s2 = 9.81
operator = "ann"

[rig]                 # shared by every run unless a run overrides a key
r_b_m = 0.01225
rod_L_m = 0.575
bearing = "P203"

[[run]]
id = "r01"
file = "r01.csv"
m_kg = 1.46
l_m = 0.265
crank_r_m = 0.0725
omega_hz = 1.54
role = "identify"
note = "fresh grease"

[[run]]
id = "r02"
file = "sub/r02.bin"
m_kg = 1
l_m = 0.17
crank_r_m = 0.205
r_b_m = 0.02
role = "validate"
format = "sd-v2"
"#;

    #[test]
    fn parses_defaults_overrides_and_unknown_keys() {
        let c = Campaign::parse(EXAMPLE, "/data/c1/campaign.toml").unwrap();
        assert_eq!(c.name, "damping-2026-03");
        assert_eq!(c.dir, PathBuf::from("/data/c1"));
        assert_eq!(c.extra["operator"].as_str(), Some("ann"));
        let r1 = &c.runs[0];
        assert_eq!(r1.file, PathBuf::from("/data/c1/r01.csv"));
        assert_eq!(r1.r_b_m, 0.01225);
        assert_eq!(r1.rod_l_m, 0.575);
        assert_eq!(r1.omega_hz, Some(1.54));
        assert_eq!(r1.role, Role::Identify);
        assert_eq!(r1.extra["note"].as_str(), Some("fresh grease"));
        assert_eq!(r1.extra["bearing"].as_str(), Some("P203"));
        let r2 = &c.runs[1];
        assert_eq!(r2.r_b_m, 0.02);
        assert_eq!(r2.m_kg, 1.0);
        assert_eq!(r2.omega_hz, None);
        assert_eq!(r2.format.as_deref(), Some("sd-v2"));
        assert_eq!(r2.role, Role::Validate);
    }

    #[test]
    fn errors_name_file_run_and_key() {
        let text = EXAMPLE.replace("l_m = 0.265\n", "");
        let e = Campaign::parse(&text, "c/campaign.toml").unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, RigError::CampaignKey { .. }));
        assert!(
            msg.contains("c/campaign.toml") && msg.contains("r01") && msg.contains("l_m"),
            "{msg}"
        );

        let text = EXAMPLE.replace("m_kg = 1.46", "m_kg = \"heavy\"");
        let msg = Campaign::parse(&text, "c/campaign.toml")
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("r01") && msg.contains("m_kg") && msg.contains("number"),
            "{msg}"
        );

        let text = EXAMPLE.replace("id = \"r02\"\n", "");
        let msg = Campaign::parse(&text, "c/campaign.toml")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("run #2") && msg.contains("`id`"), "{msg}");

        let text = EXAMPLE.replace("role = \"validate\"", "role = \"check\"");
        let e = Campaign::parse(&text, "c/campaign.toml").unwrap_err();
        assert!(matches!(e, RigError::BadRole { .. }), "{e}");

        let text = EXAMPLE.replace("id = \"r02\"", "id = \"r01\"");
        let e = Campaign::parse(&text, "c/campaign.toml").unwrap_err();
        assert!(matches!(e, RigError::DuplicateRunId { .. }), "{e}");

        let text = EXAMPLE.replace("m_kg = 1.46", "m_kg = = 1.46");
        match Campaign::parse(&text, "c/campaign.toml").unwrap_err() {
            RigError::CampaignSyntax { line, .. } => assert_eq!(line, 14),
            e => panic!("{e}"),
        }
    }

    #[test]
    fn suggests_close_known_keys_only() {
        let known = || RUN_KEYS.iter().copied();
        assert_eq!(suggest_key("omgea_hz", known()), Some("omega_hz"));
        assert_eq!(suggest_key("omega_Hz", known()), Some("omega_hz"));
        assert_eq!(suggest_key("crank_rm", known()), Some("crank_r_m"));
        assert_eq!(suggest_key("omega_hz", known()), None);
        // rig.md's own metadata keys are not misspellings.
        for k in ["note", "operator", "bearing", "shaker", "lab", "seed"] {
            assert_eq!(suggest_key(k, known()), None, "{k}");
        }
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("ab", "ba"), 1);
    }

    #[test]
    fn round_trips_through_text() {
        let c = Campaign::parse(EXAMPLE, "/data/c1/campaign.toml").unwrap();
        let text = c.to_toml_string().unwrap();
        let back = Campaign::parse(&text, "/data/c1/campaign.toml").unwrap();
        assert_eq!(back, c, "{text}");
    }
}
