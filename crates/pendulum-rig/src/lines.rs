//! Bounded line reading shared by the text readers. A damaged capture can hold a "line" of any
//! length (a lost newline, binary junk), so at most `max` bytes of it are kept and the rest is
//! counted and dropped: memory stays constant whatever the input.

use std::io::{self, BufRead};

/// One line as read: its content is in the caller's buffer (without `\n` / `\r\n`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LineInfo {
    /// 1-based line number.
    pub number: u64,
    /// 0-based byte offset of the line's first byte in the file.
    pub start: u64,
    /// Bytes in the file, line end included.
    pub bytes: u64,
    /// More than `max` bytes: the content was cut.
    pub overlong: bool,
    /// Ended by `\n` (false for a last line cut short).
    pub terminated: bool,
}

/// Reads the next line of `reader` into `line` (cleared first), keeping at most `max` bytes;
/// `line_no` counts lines, `pos` bytes. `None` at the end of input.
pub(crate) fn read_bounded_line<R: BufRead>(
    reader: &mut R,
    line: &mut Vec<u8>,
    line_no: &mut u64,
    pos: &mut u64,
    max: usize,
) -> io::Result<Option<LineInfo>> {
    line.clear();
    let mut bytes = 0u64;
    let mut overlong = false;
    let mut terminated = false;
    loop {
        let avail = match reader.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if avail.is_empty() {
            break;
        }
        let (chunk, used) = match avail.iter().position(|&b| b == b'\n') {
            Some(i) => {
                terminated = true;
                (&avail[..i], i + 1)
            }
            None => (avail, avail.len()),
        };
        let room = max.saturating_sub(line.len());
        if chunk.len() > room {
            overlong = true;
        }
        line.extend_from_slice(&chunk[..chunk.len().min(room)]);
        reader.consume(used);
        bytes += used as u64;
        if terminated {
            break;
        }
    }
    if bytes == 0 {
        return Ok(None);
    }
    if line.last() == Some(&b'\r') {
        line.pop();
    }
    *line_no += 1;
    let start = *pos;
    *pos += bytes;
    Ok(Some(LineInfo {
        number: *line_no,
        start,
        bytes,
        overlong,
        terminated,
    }))
}
