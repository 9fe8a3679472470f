//! A small RFC 3339 parser for the capture header's `started` key.
//!
//! Only this one conversion is needed (to anchor MCAP log times to wall-clock time), which does
//! not justify a date-time dependency.

use crate::LogError;

/// Parses an RFC 3339 timestamp such as `2026-03-14T10:22:05Z` into nanoseconds since the Unix
/// epoch (UTC).
///
/// Accepts `T`, `t` or a space between date and time, optional fractional seconds (up to
/// nanoseconds; more digits are truncated), and `Z`/`z` or a numeric offset `±HH:MM`. Rejects
/// leap seconds (`:60`) and times before 1970, which MCAP's unsigned log time cannot hold.
pub fn parse_rfc3339_utc_ns(value: &str) -> Result<u64, LogError> {
    let bad = |why: &'static str| LogError::BadTimestamp {
        value: value.to_string(),
        why,
    };
    let b = value.trim().as_bytes();
    if b.len() < 20 {
        return Err(bad("too short"));
    }
    let num = |range: std::ops::Range<usize>, what: &'static str| -> Result<i64, LogError> {
        let digits = &b[range];
        if !digits.iter().all(u8::is_ascii_digit) {
            return Err(bad(what));
        }
        Ok(digits
            .iter()
            .fold(0i64, |acc, d| acc * 10 + i64::from(d - b'0')))
    };
    let year = num(0..4, "year is not 4 digits")?;
    if b[4] != b'-' || b[7] != b'-' {
        return Err(bad("date is not YYYY-MM-DD"));
    }
    let month = num(5..7, "month is not 2 digits")?;
    let day = num(8..10, "day is not 2 digits")?;
    if !matches!(b[10], b'T' | b't' | b' ') {
        return Err(bad("no T between date and time"));
    }
    if b[13] != b':' || b[16] != b':' {
        return Err(bad("time is not HH:MM:SS"));
    }
    let hour = num(11..13, "hour is not 2 digits")?;
    let minute = num(14..16, "minute is not 2 digits")?;
    let second = num(17..19, "second is not 2 digits")?;

    let mut i = 19;
    let mut frac_ns: i64 = 0;
    if b[i] == b'.' {
        i += 1;
        let start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            if i - start < 9 {
                frac_ns = frac_ns * 10 + i64::from(b[i] - b'0');
            }
            i += 1;
        }
        let n = i - start;
        if n == 0 {
            return Err(bad("no digits after the decimal point"));
        }
        for _ in n..9 {
            frac_ns *= 10;
        }
    }
    let offset_s: i64 = match &b[i..] {
        [b'Z' | b'z'] => 0,
        [sign @ (b'+' | b'-'), h1, h2, b':', m1, m2] => {
            let digits = [*h1, *h2, *m1, *m2];
            if !digits.iter().all(u8::is_ascii_digit) {
                return Err(bad("offset is not ±HH:MM"));
            }
            let h = i64::from(h1 - b'0') * 10 + i64::from(h2 - b'0');
            let m = i64::from(m1 - b'0') * 10 + i64::from(m2 - b'0');
            if h > 23 || m > 59 {
                return Err(bad("offset out of range"));
            }
            let s = (h * 60 + m) * 60;
            if *sign == b'-' {
                -s
            } else {
                s
            }
        }
        [] => return Err(bad("no time zone (Z or ±HH:MM)")),
        _ => return Err(bad("unexpected characters after the seconds")),
    };

    if !(1..=12).contains(&month) {
        return Err(bad("month out of range"));
    }
    if day < 1 || day > days_in_month(year, month) {
        return Err(bad("day out of range for the month"));
    }
    if hour > 23 || minute > 59 {
        return Err(bad("hour or minute out of range"));
    }
    if second == 60 {
        return Err(bad("leap seconds are not supported"));
    }
    if second > 59 {
        return Err(bad("second out of range"));
    }

    let secs =
        days_from_civil(year, month, day) * 86_400 + hour * 3600 + minute * 60 + second - offset_s;
    if secs < 0 {
        return Err(bad("before 1970-01-01T00:00:00Z"));
    }
    let ns = i128::from(secs) * 1_000_000_000 + i128::from(frac_ns);
    u64::try_from(ns).map_err(|_| bad("too far in the future for u64 nanoseconds"))
}

fn is_leap(year: i64) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

fn days_in_month(year: i64, month: i64) -> i64 {
    match month {
        2 if is_leap(year) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's `days_from_civil`).
fn days_from_civil(year: i64, month: i64, day: i64) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (month + 9) % 12;
    let doy = (153 * mp + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        let cases = [
            ("2026-03-14T10:22:05Z", 1_773_483_725_000_000_000),
            ("1970-01-01T00:00:00Z", 0),
            ("2000-02-29T23:59:59.123456789Z", 951_868_799_123_456_789),
            ("2000-02-29t23:59:59.5z", 951_868_799_500_000_000),
            ("2026-03-14T12:22:05+02:00", 1_773_483_725_000_000_000),
            ("2026-03-14 10:22:05-00:30", 1_773_485_525_000_000_000),
            ("2026-03-14T10:22:05.1234567891Z", 1_773_483_725_123_456_789),
        ];
        for (s, ns) in cases {
            assert_eq!(parse_rfc3339_utc_ns(s).unwrap(), ns, "{s}");
        }
    }

    #[test]
    fn rejects_bad_input() {
        for s in [
            "",
            "2026-03-14",
            "2026-03-14T10:22:05",
            "2026-13-14T10:22:05Z",
            "2026-02-29T10:22:05Z",
            "2026-03-14T24:00:00Z",
            "2026-03-14T10:22:60Z",
            "2026-03-14T10:22:05.Z",
            "2026-03-14T10:22:05+0200",
            "1969-12-31T23:59:59Z",
            "2026-03-14T10:22:05Zjunk",
            "２026-03-14T10:22:05Z",
            "20x6-03-14T10:22:05Z",
        ] {
            assert!(
                matches!(parse_rfc3339_utc_ns(s), Err(LogError::BadTimestamp { .. })),
                "{s:?} should be rejected"
            );
        }
    }
}
