//! The records of the CSV input files (a heightfield terrain's heights, a heading series), read
//! with the `csv` crate: quoted fields, CRLF line ends, blank lines skipped, every field trimmed.

/// The records of `text`, each with the line it starts on (1-based) and its fields; lines of
/// white space are skipped, and lines whose first character is `#` when `comments` is true.
/// The error names the line.
pub(crate) fn csv_records(text: &str, comments: bool) -> Result<Vec<(usize, Vec<String>)>, (usize, String)> {
    let mut reader = csv::ReaderBuilder::new().has_headers(false).flexible(true).trim(csv::Trim::All).comment(comments.then_some(b'#')).from_reader(text.as_bytes());
    let line = |p: Option<&csv::Position>| p.map_or(0, |p| line_at(text, p.byte() as usize, comments));
    let mut records = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| (line(e.position()), e.to_string()))?;
        if record.iter().any(|field| !field.is_empty()) {
            records.push((line(record.position()), record.iter().map(str::to_string).collect()));
        }
    }
    Ok(records)
}

/// The line (1-based) of the first record at or after byte `start`: the reader's positions
/// are where it began reading, before the blank lines and the comments it skips.
fn line_at(text: &str, start: usize, comments: bool) -> usize {
    let mut start = start.min(text.len());
    while start < text.len() {
        let rest = &text[start..];
        let end = rest.find('\n').map_or(rest.len(), |i| i + 1);
        let line = &rest[..end];
        if !(line.trim().is_empty() || comments && line.starts_with('#')) {
            break;
        }
        start += end;
    }
    1 + text.as_bytes()[..start].iter().filter(|&&b| b == b'\n').count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Blank lines (of white space too) and comments are skipped, the fields trimmed and
    /// unquoted, each record with the line it starts on; a `#` is a comment only when asked.
    #[test]
    fn records_with_their_lines() {
        let text = "t, vx\n\n# a comment\n1,\"2.5\"\r\n   \n  3 ,4\n";
        let records = csv_records(text, true).unwrap();
        assert_eq!(records, vec![(1, vec!["t".into(), "vx".into()]), (4, vec!["1".into(), "2.5".into()]), (6, vec!["3".into(), "4".into()])]);
        assert_eq!(csv_records(text, false).unwrap()[1], (3, vec!["# a comment".to_string()]));
    }
}
