//! The embedded JSON Schemas parse, are draft 2020-12, and describe exactly what the writer
//! serializes. Checked by a small hand-written validator for the keywords the schemas use.

mod common;

use pendulum_log::{schemas, AccelMsg, EncoderMsg, SimulatedMsg};
use serde_json::{json, Value};

/// Validates `value` against `schema` for the keywords our schemas use: type, properties,
/// required, additionalProperties (false), items, minimum, maximum.
fn validate(schema: &Value, value: &Value, at: &str) -> Result<(), String> {
    if let Some(ty) = schema.get("type").and_then(Value::as_str) {
        let ok = match ty {
            "object" => value.is_object(),
            "array" => value.is_array(),
            "string" => value.is_string(),
            "boolean" => value.is_boolean(),
            "number" => value.is_number(),
            "integer" => value.is_i64() || value.is_u64(),
            other => return Err(format!("{at}: schema uses unsupported type {other}")),
        };
        if !ok {
            return Err(format!("{at}: expected {ty}, found {value}"));
        }
    }
    if let Some(min) = schema.get("minimum") {
        if as_i128(value)? < as_i128(min)? {
            return Err(format!("{at}: {value} < minimum {min}"));
        }
    }
    if let Some(max) = schema.get("maximum") {
        if as_i128(value)? > as_i128(max)? {
            return Err(format!("{at}: {value} > maximum {max}"));
        }
    }
    if let Some(obj) = value.as_object() {
        let props = schema.get("properties").and_then(Value::as_object);
        for key in schema
            .get("required")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            let key = key.as_str().ok_or("required entry not a string")?;
            if !obj.contains_key(key) {
                return Err(format!("{at}: missing required key {key}"));
            }
        }
        for (k, v) in obj {
            match props.and_then(|p| p.get(k)) {
                Some(sub) => validate(sub, v, &format!("{at}.{k}"))?,
                None if schema.get("additionalProperties") == Some(&Value::Bool(false)) => {
                    return Err(format!("{at}: unexpected key {k}"))
                }
                None => {}
            }
        }
    }
    if let (Some(items), Some(arr)) = (schema.get("items"), value.as_array()) {
        for (i, v) in arr.iter().enumerate() {
            validate(items, v, &format!("{at}[{i}]"))?;
        }
    }
    Ok(())
}

fn as_i128(v: &Value) -> Result<i128, String> {
    v.as_i64()
        .map(i128::from)
        .or_else(|| v.as_u64().map(i128::from))
        .ok_or_else(|| format!("{v} is not an integer"))
}

fn parse(text: &str, name: &str) -> Value {
    let schema: Value = serde_json::from_str(text).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(
        schema["$schema"], "https://json-schema.org/draft/2020-12/schema",
        "{name}: draft 2020-12"
    );
    assert_eq!(schema["type"], "object", "{name}");
    schema
}

/// Flat numeric message schemas: every property is a number or integer (Foxglove plots them by
/// path), all of them required, and their names are exactly the serialized fields.
fn check_flat(schema: &Value, sample: &Value, name: &str) {
    let props = schema["properties"].as_object().unwrap();
    for (k, p) in props {
        assert!(
            matches!(p["type"].as_str(), Some("number" | "integer")),
            "{name}.{k} must be numeric"
        );
    }
    let mut required: Vec<_> = schema["required"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect();
    let mut keys: Vec<_> = sample.as_object().unwrap().keys().cloned().collect();
    let mut prop_keys: Vec<_> = props.keys().cloned().collect();
    required.sort();
    keys.sort();
    prop_keys.sort();
    assert_eq!(required, keys, "{name}: required = serialized fields");
    assert_eq!(prop_keys, keys, "{name}: properties = serialized fields");
    validate(schema, sample, name).unwrap();

    // The validator is not vacuous.
    let mut missing = sample.clone();
    missing.as_object_mut().unwrap().remove(&keys[0]);
    assert!(validate(schema, &missing, name).is_err());
    let mut wrong = sample.clone();
    wrong[&keys[0]] = json!("text");
    assert!(validate(schema, &wrong, name).is_err());
    let mut extra = sample.clone();
    extra["bogus"] = json!(1);
    assert!(validate(schema, &extra, name).is_err());
}

#[test]
fn encoder_schema_matches_messages() {
    let schema = parse(schemas::ENCODER, "encoder.json");
    let fx = common::fixture(50, 0);
    for m in &fx.encoder {
        check_flat(&schema, &serde_json::to_value(m).unwrap(), "encoder");
    }
    let extreme = EncoderMsg {
        t_s: 0.0,
        t_us: u64::MAX,
        count: i64::MIN,
        count_raw: i16::MIN,
        theta_rad: -1e300,
    };
    validate(&schema, &serde_json::to_value(extreme).unwrap(), "encoder").unwrap();
    let too_big = json!({"t_s": 0.0, "t_us": 0, "count": 0, "count_raw": 32768, "theta_rad": 0.0});
    assert!(
        validate(&schema, &too_big, "encoder").is_err(),
        "count_raw is i16"
    );
    let negative = json!({"t_s": 0.0, "t_us": -1, "count": 0, "count_raw": 0, "theta_rad": 0.0});
    assert!(
        validate(&schema, &negative, "encoder").is_err(),
        "t_us is u64"
    );
}

#[test]
fn accel_schema_matches_messages() {
    let schema = parse(schemas::ACCEL, "accel.json");
    let fx = common::fixture(500, 0);
    for m in &fx.accel {
        check_flat(&schema, &serde_json::to_value(m).unwrap(), "accel");
    }
    let extreme = AccelMsg {
        t_s: 1e9,
        t_us: u64::MAX,
        ax_raw: i16::MIN,
        ay_raw: i16::MAX,
        az_raw: 0,
        ax_m_s2: -39.24,
        ay_m_s2: 39.24,
        az_m_s2: 0.0,
    };
    validate(&schema, &serde_json::to_value(extreme).unwrap(), "accel").unwrap();
}

#[test]
fn simulated_schema_matches_messages() {
    let schema = parse(schemas::SIMULATED, "simulated.json");
    let m = SimulatedMsg {
        t_s: 1.5,
        theta_rad: 0.25,
        theta_dot_rad_s: -3.0,
        residual_rad: 1e-4,
    };
    check_flat(&schema, &serde_json::to_value(m).unwrap(), "simulated");
}

#[test]
fn ingest_stats_schema_documents_the_fields() {
    let schema = parse(schemas::INGEST_STATS, "ingest_stats.json");
    let props = schema["properties"].as_object().unwrap();
    for key in [
        "format",
        "encoder_samples",
        "accel_samples",
        "skipped",
        "skipped_bytes",
        "gaps",
        "clock_wraps",
        "encoder_wraps",
        "truncated_tail_bytes",
        "skips",
    ] {
        let p = &props[key];
        assert!(
            p["description"].as_str().is_some_and(|d| !d.is_empty()),
            "{key} is documented"
        );
    }
    let fx = common::fixture(10, 0);
    validate(&schema, &fx.stats, "stats").unwrap();
    validate(&schema, &json!({}), "stats").unwrap(); // free-form
    assert!(validate(
        &schema,
        &json!({"skips": [{"at": "x", "reason": "r"}]}),
        "stats"
    )
    .is_err());
    assert!(validate(&schema, &json!({"skips": [{"at": 1}]}), "stats").is_err());
    assert!(validate(&schema, &json!({"gaps": -1}), "stats").is_err());
    assert!(validate(&schema, &json!([]), "stats").is_err());
}
