//! Which strings from a campaign (or a twin case, or an MCAP's metadata) may become file names
//! and paths.
//!
//! A campaign folder is data someone else may have written. A run's id names its output files
//! (`OUT/<id>.mcap`, `history_<model>_<id>.png`, the twin's `<id>.csv`), and a run's `file` key
//! is read from the campaign folder; neither may make the program read outside the campaign
//! folder or write (or delete) outside the output folder, and neither may carry terminal escape
//! codes into a message. These checks are the one place that decides what is safe: everything
//! that turns such a string into a path calls them.

use std::borrow::Cow;
use std::path::{Component, Path};

/// Longest run id, in bytes. Ids are embedded in longer file names (`.<id>.mcap.<pid>-<n>.tmp`,
/// `history_<model>_<id>.png`, `<id>-free`), which must stay under the usual 255-byte limit.
pub const MAX_ID_LEN: usize = 64;

/// Longest file name this program writes, in bytes (the limit of ext4, APFS, NTFS and most
/// others).
pub const MAX_FILE_NAME_LEN: usize = 255;

/// What a run id must look like, for error messages.
pub const ID_EXPECTED: &str = "1 to 64 ASCII letters, digits, '-', '_' or '.', not starting \
                               with '.' or '-' and not ending with '.' (the id names the run's \
                               output files)";

/// What a run's `file` key must look like, for error messages.
pub const FILE_EXPECTED: &str = "a path relative to the campaign folder that stays inside it \
                                 (no leading '/', no '..', no control characters)";

/// What the value of campaign key `key` (`id` or `file`) must look like.
pub fn expected(key: &str) -> &'static str {
    match key {
        "file" => FILE_EXPECTED,
        _ => ID_EXPECTED,
    }
}

/// Names Windows reserves for devices, with or without an extension (`NUL.mcap` is the device
/// too). Refused everywhere so that a campaign copied to such a system means the same thing.
const RESERVED: [&str; 22] = [
    "CON", "PRN", "AUX", "NUL", "COM1", "COM2", "COM3", "COM4", "COM5", "COM6", "COM7", "COM8",
    "COM9", "LPT1", "LPT2", "LPT3", "LPT4", "LPT5", "LPT6", "LPT7", "LPT8", "LPT9",
];

/// Checks that `id` can be used as (part of) a file name in any folder: ASCII letters, digits,
/// `-`, `_`, `.`, at most [`MAX_ID_LEN`] bytes. `Err` says what is wrong with it, in words that
/// go after "id {id:?}: ".
pub fn check_run_id(id: &str) -> Result<(), String> {
    check_name(id, MAX_ID_LEN)
}

/// The same rules as [`check_run_id`] for a whole file name this program is about to create
/// from parts it did not choose (a model name read from a params.parquet, an id read from an
/// MCAP), with the file-system limit [`MAX_FILE_NAME_LEN`].
pub fn check_file_name(name: &str) -> Result<(), String> {
    check_name(name, MAX_FILE_NAME_LEN)
}

fn check_name(name: &str, max_len: usize) -> Result<(), String> {
    if name.is_empty() {
        return Err("is empty".into());
    }
    if name.len() > max_len {
        return Err(format!("is {} bytes long (at most {max_len})", name.len()));
    }
    // Reported by what it is, not by the character itself: a control character or an escape
    // code must not reach the terminal (callers print the whole name with `{:?}`).
    if let Some(c) = name
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.')))
    {
        let what = match c {
            '/' | '\\' => "a path separator".to_string(),
            c if c.is_control() => format!("a control character ({:?})", c),
            c if !c.is_ascii() => format!("a non-ASCII character ({:?})", c),
            c => format!("the character {c:?}"),
        };
        return Err(format!("contains {what}"));
    }
    if name.starts_with('.') {
        // Also rules out "." and ".." (and hidden files, which dataset globs skip).
        return Err("starts with '.'".into());
    }
    if name.starts_with('-') {
        // Would read as an option to most command-line tools.
        return Err("starts with '-'".into());
    }
    if name.ends_with('.') {
        return Err("ends with '.'".into());
    }
    let stem = name.split('.').next().unwrap_or(name);
    if RESERVED.iter().any(|r| r.eq_ignore_ascii_case(stem)) {
        return Err(format!("is a reserved device name ({stem})"));
    }
    Ok(())
}

/// Checks that a run's `file` key, joined to the campaign folder, names something inside that
/// folder: relative, no `..` component (even one that would come back: the rule stays simple to
/// check by eye), no control characters. Subfolders are fine (`sub/r02.bin`).
///
/// This is a check of the text; a symbolic link inside the campaign folder is followed (the
/// folder's owner put it there).
pub fn check_relative_file(file: &str) -> Result<(), String> {
    if file.is_empty() {
        return Err("is empty".into());
    }
    if let Some(c) = file.chars().find(|c| c.is_control()) {
        return Err(format!("contains a control character ({c:?})"));
    }
    // `Path::is_absolute` alone misses `\\server\share` and `C:x` on Windows; any root or
    // prefix component is refused on every platform.
    for comp in Path::new(file).components() {
        match comp {
            Component::Prefix(_) | Component::RootDir => {
                return Err("is an absolute path".into());
            }
            Component::ParentDir => return Err("contains '..'".into()),
            Component::CurDir | Component::Normal(_) => {}
        }
    }
    let drive = file.as_bytes().first().is_some_and(u8::is_ascii_alphabetic)
        && file.as_bytes().get(1) == Some(&b':');
    if file.starts_with('\\') || drive {
        // A Windows absolute path written on a Unix machine (`\data\r01.csv`, `C:\r01.csv`)
        // would be a relative file name here, and an escape there.
        return Err("is an absolute path".into());
    }
    if file.split(['/', '\\']).any(|part| part == "..") {
        return Err("contains '..'".into());
    }
    Ok(())
}

/// `s` as it may go to a terminal: unchanged when it holds no control or invisible formatting
/// character, else escaped the way `{:?}` escapes them. For strings from input files that are
/// printed but never used as names (a campaign's `name`), so that an escape code in a file
/// cannot move the cursor, recolour or retitle the user's terminal.
pub fn printable(s: &str) -> Cow<'_, str> {
    let harmless = |c: char| !c.is_control() && !is_format_char(c);
    if s.chars().all(harmless) {
        Cow::Borrowed(s)
    } else {
        let mut out = String::with_capacity(s.len() + 8);
        for c in s.chars() {
            if harmless(c) {
                out.push(c);
            } else {
                out.extend(c.escape_unicode());
            }
        }
        Cow::Owned(out)
    }
}

/// Bidirectional overrides and other zero-width formatting characters, which reorder or hide
/// what a terminal shows.
fn is_format_char(c: char) -> bool {
    matches!(c, '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{feff}')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn issue_13_ids_that_are_not_safe_file_names_are_refused() {
        for ok in ["r01", "R-01_a.b", "run.2026-03-14", "_x", &"a".repeat(64)] {
            assert_eq!(check_run_id(ok), Ok(()), "{ok:?}");
        }
        let bad: [(&str, &str); 16] = [
            ("", "empty"),
            ("../x", "path separator"),
            ("/tmp/victim/precious", "path separator"),
            ("a\\b", "path separator"),
            ("..", "starts with '.'"),
            (".", "starts with '.'"),
            (".hidden", "starts with '.'"),
            ("-rf", "starts with '-'"),
            ("r01.", "ends with '.'"),
            ("r\u{1b}[2Jx", "control character"),
            ("r01\n", "control character"),
            ("r\u{202e}01", "non-ASCII"),
            ("r 01", "' '"),
            ("nul", "reserved"),
            ("COM1.log", "reserved"),
            (&"a".repeat(65), "65 bytes"),
        ];
        for (id, why) in bad {
            let e = check_run_id(id).expect_err(id);
            assert!(e.contains(why), "{id:?}: {e}");
            // The reason never echoes a raw control character.
            assert!(!e.chars().any(char::is_control), "{id:?}: {e:?}");
        }
    }

    #[test]
    fn issue_13_printable_escapes_terminal_codes() {
        assert_eq!(printable("small-twin Läufer"), "small-twin Läufer");
        let p = printable("x\u{1b}[31mred\u{202e}");
        assert!(
            !p.chars().any(|c| c.is_control() || is_format_char(c)),
            "{p:?}"
        );
        assert_eq!(p, "x\\u{1b}[31mred\\u{202e}");
    }

    #[test]
    fn issue_13_run_files_stay_inside_the_campaign_folder() {
        for ok in [
            "r01.csv",
            "sub/r02.bin",
            "./r01.csv",
            "run 1.csv",
            "Läufer.csv",
        ] {
            assert_eq!(check_relative_file(ok), Ok(()), "{ok:?}");
        }
        for (file, why) in [
            ("", "empty"),
            ("/etc/passwd", "absolute"),
            ("../other/r01.csv", ".."),
            ("sub/../../r01.csv", ".."),
            ("sub\\..\\r01.csv", ".."),
            ("\\data\\r01.csv", "absolute"),
            ("C:\\r01.csv", "absolute"),
            ("r01\u{1b}]0;x\u{7}.csv", "control character"),
        ] {
            let e = check_relative_file(file).expect_err(file);
            assert!(e.contains(why), "{file:?}: {e}");
        }
    }
}
