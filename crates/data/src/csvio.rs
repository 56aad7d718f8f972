//! CSV as every file of the project reads and writes it, through the `csv` crate: records
//! (quoted fields, commas and line breaks inside quotes, doubled quotes), `#` comment lines kept
//! with their text, and the 1-based line on which each record starts.
//!
//! Reading accepts what lab exports contain: lines ending in `\n`, `\r\n` or a lone `\r`, blank
//! lines, spaces around cells, a cell quoted after a space (` "time_s"`), and a delimiter other
//! than the comma (a lab file's `;` or tab, or runs of spaces). A UTF-8 byte-order mark is dropped
//! by whoever reads the file ([`crate::fsio::read_user_text`]).
//!
//! Writing ([`writer`], [`text_of`]) quotes a cell only when it must (a delimiter, a quote or a
//! line break in it), ends records in `\n`, and writes numbers as given: an ordinary table is the
//! same bytes as `join(",")` would make, and any cell reads back as written.

use std::borrow::Cow;

/// How the cells of a line are separated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Separator {
    /// One byte: `,`, `;` or tab.
    Byte(u8),
    /// Runs of spaces or tabs (a column-aligned text export).
    Whitespace,
}

/// One thing a CSV text holds, in the file's order.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Item<'a> {
    /// A `#` comment line: its 1-based line and its text as written (the `#` included, the
    /// line end not).
    Comment(usize, String),
    /// A record: the 1-based line it starts on and its cells, trimmed of surrounding spaces and
    /// unquoted (borrowed: the cells' buffers are used again for the next record).
    Record(usize, &'a [String]),
}

/// A cell as read, written into `out`: surrounding spaces trimmed, and the quotes of a cell
/// quoted after a space (` "a, b"`) removed, which the `csv` crate keeps as written since the
/// quote does not open the field. (In that case a delimiter inside the quotes has already split
/// the cell.)
fn cell_text(raw: &[u8], out: &mut String) {
    out.clear();
    let raw = String::from_utf8_lossy(raw);
    let t = raw.trim();
    if raw.starts_with(char::is_whitespace)
        && t.len() >= 2
        && t.starts_with('"')
        && t.ends_with('"')
    {
        out.push_str(&t[1..t.len() - 1].replace("\"\"", "\""));
    } else {
        out.push_str(t);
    }
}

/// The bytes the `csv` reader is given: a lone `\r` made a `\n` (one byte for one, so every byte
/// offset stays the same), and for [`Separator::Whitespace`] tabs made spaces.
fn normalised(text: &str, sep: Separator) -> Cow<'_, [u8]> {
    let b = text.as_bytes();
    let lone_cr = |i: usize| b[i] == b'\r' && b.get(i + 1) != Some(&b'\n');
    let tabs = sep == Separator::Whitespace && b.contains(&b'\t');
    if !tabs && !(0..b.len()).any(lone_cr) {
        return Cow::Borrowed(b);
    }
    Cow::Owned(
        (0..b.len())
            .map(|i| match b[i] {
                _ if lone_cr(i) => b'\n',
                b'\t' if tabs => b' ',
                c => c,
            })
            .collect(),
    )
}

/// Counts lines up to a byte offset, moving forward only.
struct LineCounter<'a> {
    bytes: &'a [u8],
    at: usize,
    line: usize,
}

impl LineCounter<'_> {
    /// The 1-based line of byte `to` (not before the last one asked).
    fn line_at(&mut self, to: usize) -> usize {
        let to = to.min(self.bytes.len());
        if to > self.at {
            self.line += self.bytes[self.at..to]
                .iter()
                .filter(|&&c| c == b'\n')
                .count();
            self.at = to;
        }
        self.line
    }
}

/// Reads the records and comment lines of `text` from line `skip + 1` on, handing each to
/// `each` in the file's order. Blank lines are left out. A line whose first non-blank character
/// is `#` is a comment (the `csv` crate's own rule is the `#` as the line's first byte; a comment
/// indented by spaces is recognised here, from its first cell).
///
/// Errors (none are expected of text in memory) give the line and the `csv` crate's message.
pub(crate) fn read(
    text: &str,
    skip: usize,
    sep: Separator,
    mut each: impl FnMut(Item),
) -> Result<(), (usize, String)> {
    let bytes = normalised(text, sep);
    let bytes: &[u8] = &bytes;
    // Byte offset of line `skip + 1`: after the `skip`-th `\n` (every line end has one now).
    let start = if skip == 0 {
        0
    } else {
        bytes
            .iter()
            .enumerate()
            .filter(|(_, &c)| c == b'\n')
            .nth(skip - 1)
            .map_or(bytes.len(), |(i, _)| i + 1)
    };
    let mut lines = LineCounter {
        bytes,
        at: 0,
        line: 1,
    };
    let delimiter = match sep {
        Separator::Byte(d) => d,
        Separator::Whitespace => b' ',
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .delimiter(delimiter)
        .comment(Some(b'#'))
        .from_reader(&bytes[start..]);
    let mut record = csv::ByteRecord::new();
    let mut cells: Vec<String> = Vec::new();
    // Where the text not yet handed out starts: blank and comment lines before a record are
    // consumed by the reader along with the record, and are found again here.
    let mut from = start;
    loop {
        let more = reader
            .read_byte_record(&mut record)
            .map_err(|e| (lines.line_at(from), e.to_string()))?;
        let end = if more {
            start + reader.position().byte() as usize
        } else {
            bytes.len()
        };
        let record_start = gap(bytes, from, end, |at, comment| {
            each(Item::Comment(lines.line_at(at), comment));
        });
        from = end;
        if !more {
            return Ok(());
        }
        let raw = &bytes[record_start..end];
        if raw.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let line = lines.line_at(record_start);
        let mut n = 0;
        for raw_cell in &record {
            if n == cells.len() {
                cells.push(String::new());
            }
            cell_text(raw_cell, &mut cells[n]);
            // Between runs of spaces the cells are empty: not cells.
            if !(sep == Separator::Whitespace && cells[n].is_empty()) {
                n += 1;
            }
        }
        if raw.iter().find(|c| !c.is_ascii_whitespace()) == Some(&b'#') {
            let first_line = raw.split(|&c| c == b'\n').next().unwrap_or_default();
            let comment = String::from_utf8_lossy(first_line);
            each(Item::Comment(line, comment.trim().to_string()));
        } else {
            each(Item::Record(line, &cells[..n]));
        }
    }
}

/// Walks the blank and `#` comment lines from `from` as the `csv` reader skips them before a
/// record (line ends, then a `#` line up to its `\n`, again), handing each comment with its byte
/// offset to `comment`; returns where the record itself starts.
fn gap(bytes: &[u8], from: usize, to: usize, mut comment: impl FnMut(usize, String)) -> usize {
    let mut i = from;
    loop {
        while i < to && matches!(bytes[i], b'\r' | b'\n') {
            i += 1;
        }
        if i >= to || bytes[i] != b'#' {
            return i;
        }
        let stop = bytes[i..to]
            .iter()
            .position(|&c| c == b'\n')
            .map_or(to, |k| i + k);
        let text = String::from_utf8_lossy(&bytes[i..stop]);
        comment(i, text.trim_end_matches('\r').trim().to_string());
        i = stop;
    }
}

/// The cells of one line of text split by `sep`, as [`read`] reads them (for looking at single
/// lines, e.g. the hint at `--skip`).
pub(crate) fn cells_of_line(line: &str, sep: Separator) -> Vec<String> {
    let mut cells = Vec::new();
    let _ = read(line, 0, sep, |item| {
        if let (Item::Record(_, c), true) = (item, cells.is_empty()) {
            cells = c.to_vec();
        }
    });
    cells
}

/// A CSV writer of the project's dialect over `out`: `,` between cells, `\n` after each record,
/// a cell quoted only when it holds a `,`, a `"` (doubled) or a line break.
///
/// ```
/// let mut w = subfric_data::csvio::writer(Vec::new());
/// w.write_record(["set", "note"]).unwrap();
/// w.write_record(["a", "say \"x\", then\nmore"]).unwrap();
/// let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
/// assert_eq!(text, "set,note\na,\"say \"\"x\"\", then\nmore\"\n");
/// ```
pub fn writer<W: std::io::Write>(out: W) -> csv::Writer<W> {
    csv::WriterBuilder::new()
        .delimiter(b',')
        .quote_style(csv::QuoteStyle::Necessary)
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(out)
}

/// The CSV text of `records` (see [`writer`]).
///
/// ```
/// let text = subfric_data::csvio::text_of([vec!["a", "b"], vec!["1", "x,y"]]);
/// assert_eq!(text, "a,b\n1,\"x,y\"\n");
/// ```
pub fn text_of<R, C>(records: impl IntoIterator<Item = R>) -> String
where
    R: IntoIterator<Item = C>,
    C: AsRef<[u8]>,
{
    let mut w = writer(Vec::new());
    for r in records {
        // Writing to memory cannot fail.
        let _ = w.write_record(r);
    }
    let bytes = w.into_inner().unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `read` hands out, owned: a comment's line and text, or a record's line and cells.
    #[derive(Debug, PartialEq)]
    enum Owned {
        Comment(usize, String),
        Record(usize, Vec<String>),
    }

    fn items(text: &str, skip: usize, sep: Separator) -> Vec<Owned> {
        let mut v = Vec::new();
        read(text, skip, sep, |i| {
            v.push(match i {
                Item::Comment(l, c) => Owned::Comment(l, c),
                Item::Record(l, c) => Owned::Record(l, c.to_vec()),
            })
        })
        .unwrap();
        v
    }

    fn rec(line: usize, cells: &[&str]) -> Owned {
        Owned::Record(line, cells.iter().map(|c| c.to_string()).collect())
    }

    #[test]
    fn line_ends_comments_and_blank_lines() {
        let comma = Separator::Byte(b',');
        let want = vec![
            Owned::Comment(1, "# c1".into()),
            rec(2, &["a", "b"]),
            rec(4, &["1", "2"]),
            Owned::Comment(5, "# c2".into()),
            rec(6, &["3", "4"]),
        ];
        for text in [
            "# c1\na,b\n\n1,2\n# c2\n3,4\n",
            "# c1\r\na,b\r\n\r\n1,2\r\n# c2\r\n3,4\r\n",
            "# c1\ra,b\r\r1,2\r# c2\r3,4",
            "# c1\ra,b\r\n  \n1, 2\n  # c2\n3,4",
        ] {
            assert_eq!(items(text, 0, comma), want, "{text:?}");
        }
    }

    #[test]
    fn quoted_cells_hold_delimiters_quotes_and_line_breaks() {
        let v = items(
            "\"a, b\",\"say \"\"x\"\"\"\n1, \"2\"\n\"two\nlines\",3\n4,5\n",
            0,
            Separator::Byte(b','),
        );
        assert_eq!(
            v,
            vec![
                rec(1, &["a, b", "say \"x\""]),
                rec(2, &["1", "2"]),
                rec(3, &["two\nlines", "3"]),
                rec(5, &["4", "5"]),
            ]
        );
    }

    #[test]
    fn skipped_lines_other_delimiters_and_whitespace() {
        let text = "Specimen: A; B\nDate\r\nt;u\n0,5;1\n";
        assert_eq!(
            items(text, 2, Separator::Byte(b';')),
            vec![rec(3, &["t", "u"]), rec(4, &["0,5", "1"])]
        );
        assert_eq!(
            items("t \t  u\n 1   2\t3\n", 0, Separator::Whitespace),
            vec![rec(1, &["t", "u"]), rec(2, &["1", "2", "3"])]
        );
        assert_eq!(items("a\nb\n", 5, Separator::Byte(b',')), vec![]);
        assert_eq!(
            cells_of_line("x\t\"y\"", Separator::Byte(b'\t')),
            ["x", "y"]
        );
    }

    #[test]
    fn written_cells_read_back_as_they_were() {
        let cells = [
            "plain",
            "a,b",
            "say \"x\"",
            "two\nlines",
            "cr\rlf",
            "",
            "# not a comment",
        ];
        let text = text_of([cells]);
        assert!(
            text.starts_with("plain,\"a,b\",\"say \"\"x\"\"\",\"two\nlines\""),
            "{text}"
        );
        let v = items(&text, 0, Separator::Byte(b','));
        // The `#` cell is not the record's first, so no comment; a lone \r inside quotes is
        // read as a line end, as every line end.
        let mut want: Vec<String> = cells.iter().map(|c| c.to_string()).collect();
        want[4] = "cr\nlf".into();
        assert_eq!(v, vec![Owned::Record(1, want)]);
        assert_eq!(text_of([["1", "2.5"], ["3", "-4e-7"]]), "1,2.5\n3,-4e-7\n");
    }
}
