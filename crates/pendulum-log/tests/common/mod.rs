//! Shared fixtures: a synthetic run with the awkward values a real capture has (a 32-bit clock
//! wrap already unwrapped, encoder counts beyond i16, saturated accelerometer readings).
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::Path;

use pendulum_log::{
    AccelMsg, EncoderMsg, LogError, RunLogOptions, RunLogSummary, SimulatedMsg,
    METADATA_CAPTURE_HEADER, METADATA_RUN,
};

pub const FIRST_T_US: u64 = 4_294_000_000; // ~1 s before the board clock's 32-bit wrap
pub const STARTED: &str = "2026-03-14T10:22:05Z";

pub struct Fixture {
    pub encoder: Vec<EncoderMsg>,
    pub accel: Vec<AccelMsg>,
    pub simulated: Vec<SimulatedMsg>,
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    pub stats: serde_json::Value,
}

fn t_s(t_us: u64) -> f64 {
    (t_us - FIRST_T_US) as f64 / 1e6
}

/// `n_enc` encoder samples at 1 kHz, `n_enc / 5` accelerometer samples at 200 Hz (the first one
/// 300 µs after the first encoder sample), `n_sim` simulated samples at 100 Hz.
pub fn fixture(n_enc: usize, n_sim: usize) -> Fixture {
    let mut encoder = Vec::new();
    for i in 0..n_enc {
        let t_us = FIRST_T_US + i as u64 * 1000 + (i as u64 * 7) % 23; // jitter
        let count = (i as i64 * 97) - 20_000; // crosses the i16 range
        let theta_rad = count as f64 * std::f64::consts::TAU / 4096.0;
        encoder.push(EncoderMsg {
            t_s: t_s(t_us),
            t_us,
            count,
            count_raw: count as i16,
            theta_rad,
        });
    }
    let mut accel = Vec::new();
    for i in 0..n_enc / 5 {
        let t_us = FIRST_T_US + 300 + i as u64 * 5000;
        let phase = i as f64 * 0.3;
        let az_raw = (8192.0 + 30000.0 * phase.sin()).clamp(-32768.0, 32767.0) as i16;
        let ax_raw = if i % 50 == 0 {
            i16::MIN
        } else {
            (i as i16) - 300
        };
        let ay_raw = if i % 51 == 0 { i16::MAX } else { -(i as i16) };
        let k = 9.81 / 8192.0;
        accel.push(AccelMsg {
            t_s: t_s(t_us),
            t_us,
            ax_raw,
            ay_raw,
            az_raw,
            ax_m_s2: f64::from(ax_raw) * k,
            ay_m_s2: f64::from(ay_raw) * k,
            az_m_s2: f64::from(az_raw) * k,
        });
    }
    let simulated = (0..n_sim)
        .map(|i| {
            let t = i as f64 * 0.01;
            SimulatedMsg {
                t_s: t,
                theta_rad: (1.3 * t).sin() * 0.7,
                theta_dot_rad_s: (1.3 * t).cos() * 0.91,
                residual_rad: 1e-3 * (17.0 * t).sin() + 5e-324,
            }
        })
        .collect();
    let mut metadata = BTreeMap::new();
    metadata.insert(
        METADATA_RUN.to_string(),
        BTreeMap::from([
            ("id".to_string(), "r01".to_string()),
            ("file".to_string(), "r01.csv".to_string()),
            ("m_kg".to_string(), "1.46".to_string()),
            ("note".to_string(), "fresh grease, ünïcode ok".to_string()),
        ]),
    );
    metadata.insert(
        METADATA_CAPTURE_HEADER.to_string(),
        BTreeMap::from([
            ("firmware".to_string(), "serial-v1".to_string()),
            ("started".to_string(), STARTED.to_string()),
            ("x_unknown_key".to_string(), "kept".to_string()),
        ]),
    );
    let stats = serde_json::json!({
        "format": "serial-v1",
        "encoder_samples": n_enc,
        "accel_samples": n_enc / 5,
        "skipped": 2,
        "skipped_bytes": 57,
        "gaps": 1,
        "clock_wraps": 1,
        "encoder_wraps": 0,
        "truncated_tail_bytes": 0,
        "skips": [{"at": 17, "reason": "short line"}, {"at": 912, "reason": "bad field"}],
        "extra_float": 0.1
    });
    Fixture {
        encoder,
        accel,
        simulated,
        metadata,
        stats,
    }
}

/// Writes the fixture: all encoder samples, then all accelerometer samples (per-channel order is
/// what matters), then the replay, metadata first and stats last.
pub fn write(fx: &Fixture, path: &Path, opts: &RunLogOptions) -> Result<RunLogSummary, LogError> {
    let mut w = opts.create(path)?;
    for (name, map) in &fx.metadata {
        w.write_metadata(name, map.clone())?;
    }
    for m in &fx.encoder {
        w.write_encoder(m)?;
    }
    for m in &fx.accel {
        w.write_accel(m)?;
    }
    for m in &fx.simulated {
        w.write_simulated(m)?;
    }
    w.write_stats(&fx.stats)?;
    w.finish()
}

/// Offset and length of the records inside the first chunk (walking top-level records).
pub fn first_chunk_records(bytes: &[u8]) -> Option<(usize, usize)> {
    let u64_at = |o: usize| -> Option<u64> {
        Some(u64::from_le_bytes(bytes.get(o..o + 8)?.try_into().ok()?))
    };
    let mut at = 8;
    while at + 9 <= bytes.len() {
        let opcode = bytes[at];
        let len = usize::try_from(u64_at(at + 1)?).ok()?;
        let body = at + 9;
        if opcode == 0x06 {
            let clen = u32::from_le_bytes(bytes.get(body + 28..body + 32)?.try_into().ok()?);
            let records_len_at = body + 32 + clen as usize;
            let records_len = usize::try_from(u64_at(records_len_at)?).ok()?;
            return Some((records_len_at + 8, records_len));
        }
        at = body + len;
    }
    None
}
