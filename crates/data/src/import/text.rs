//! A lab file as text: decoding, the lines after the header block, cells, and the hint at
//! `--skip` when the first lines are not numbers.

use std::path::Path;

use super::units::Delimiter;
use crate::csvio::{cells_of_line, Separator};
use crate::error::{DataError, InputProblem};
use crate::fsio::PathKind;

/// How the `csv` reader separates the cells for delimiter `d` (`Auto` as whitespace: resolve it
/// with [`detect`] first).
pub(super) fn separator(d: Delimiter) -> Separator {
    match d {
        Delimiter::Comma => Separator::Byte(b','),
        Delimiter::Tab => Separator::Byte(b'\t'),
        Delimiter::Semicolon => Separator::Byte(b';'),
        Delimiter::Whitespace | Delimiter::Auto => Separator::Whitespace,
    }
}

/// The delimiter of a header (or first data) line: tab, then `;`, then `,`, else whitespace,
/// looking only outside quotes (`time,"shear; kPa"` is comma-separated).
pub(super) fn detect(line: &str) -> Delimiter {
    let mut quoted = false;
    let line: String = line
        .chars()
        .filter(|&c| {
            quoted ^= c == '"';
            !quoted && c != '"'
        })
        .collect();
    if line.contains('\t') {
        Delimiter::Tab
    } else if line.contains(';') {
        Delimiter::Semicolon
    } else if line.contains(',') {
        Delimiter::Comma
    } else {
        Delimiter::Whitespace
    }
}

fn decode(bytes: Vec<u8>) -> String {
    match String::from_utf8(bytes) {
        Ok(s) => s,
        // Latin-1 (common in lab exports: `µm`, `°C`)
        Err(e) => e.into_bytes().iter().map(|&b| b as char).collect(),
    }
}

/// Reads the lab file as text (UTF-8, else Latin-1), refusing what is not a regular file, a
/// file beyond [`crate::fsio::MAX_DATA_FILE_BYTES`] and UTF-16 text (named as such).
pub(super) fn read_lab_text(lf: &Path) -> Result<String, DataError> {
    let kind = PathKind::of(lf);
    if kind != PathKind::File {
        return Err(DataError::Problems(vec![InputProblem::new(
            lf,
            None,
            None,
            format!("the lab file {} (expected a text file)", kind.describe()),
        )]));
    }
    let bytes = crate::fsio::read_user_file(lf, "the lab file", crate::fsio::MAX_DATA_FILE_BYTES)?;
    if let Some(encoding) = crate::fsio::utf16_encoding(&bytes) {
        return Err(DataError::Problems(vec![InputProblem::new(
            lf,
            Some(1),
            None,
            format!("the lab file is {encoding} text, not UTF-8 or Latin-1 (expected a text file of one byte per character: export it as UTF-8, or convert it with `iconv -f UTF-16 -t UTF-8`)"),
        )]));
    }
    let text = decode(bytes);
    Ok(match text.strip_prefix('\u{feff}') {
        Some(t) => t.to_string(),
        None => text,
    })
}

/// The non-empty, non-comment lines after `skip` lines, with their 1-based numbers: the lines
/// as written, for finding the delimiter ([`detect`]) and where the numbers start
/// ([`skip_hint`]), both of which look at each line alone.
pub(super) fn content_lines(text: &str, skip: usize) -> impl Iterator<Item = (usize, &str)> {
    // Lines end in \n, \r\n or a lone \r (old Mac exports, some loggers).
    crate::text::lines(text)
        .enumerate()
        .skip(skip)
        .map(|(i, line)| (i + 1, line))
        .filter(|(_, line)| {
            let t = line.trim();
            !t.is_empty() && !t.starts_with('#')
        })
}

/// The resolution of a number as written: the value of one unit in its last digit
/// (`4.93` → 0.01, `1.5e-3` → 1e-4, `120` → 1); `None` when it has no digits to count.
pub(super) fn resolution(text: &str) -> Option<f64> {
    let t = text.trim().trim_start_matches(['+', '-']);
    let (mantissa, exponent) = match t.find(['e', 'E']) {
        Some(i) => (&t[..i], t[i + 1..].parse::<i32>().ok()?),
        None => (t, 0),
    };
    if mantissa.is_empty() || !mantissa.chars().all(|c| c.is_ascii_digit() || c == '.') {
        return None;
    }
    let decimals = mantissa.find('.').map_or(0, |i| mantissa.len() - i - 1) as i32;
    Some(10f64.powi(exponent - decimals))
}

/// `x` (read with resolution `q`) times `factor`, rounded to the digits the reading carries:
/// as many decimals as the converted resolution needs, and one more when `factor` is not a
/// power of ten (so that the rounding loses less than a tenth of the lab's resolution). The
/// result is the double nearest that decimal, which is written back as that decimal.
pub(super) fn with_precision(x: f64, q: Option<f64>, factor: f64) -> f64 {
    let v = x * factor;
    let Some(q) = q else { return v };
    if factor == 1.0 || !v.is_finite() || v == 0.0 {
        return v;
    }
    let step = q * factor.abs();
    if !(step > 0.0 && step.is_finite()) {
        return v;
    }
    let exact = -step.log10();
    let power_of_ten = (factor.abs().log10() - factor.abs().log10().round()).abs() < 1e-9;
    let decimals = if power_of_ten && (exact - exact.round()).abs() < 1e-6 {
        exact.round()
    } else {
        exact.ceil() + 1.0
    };
    // Beyond 17 significant digits a double has nothing more to give.
    let decimals = decimals.clamp(0.0, (17.0 - v.abs().log10().ceil()).max(0.0)) as usize;
    format!("{v:.decimals$}").parse().unwrap_or(v)
}

/// Rows of numbers that must follow for a line to count as where the data start.
const NUMERIC_RUN: usize = 3;

/// A row of at least two cells that are all numbers.
fn numeric_row(line: &str, delimiter: Delimiter) -> bool {
    let d = match delimiter {
        Delimiter::Auto => detect(line),
        d => d,
    };
    let cells = cells_of_line(line, separator(d));
    cells.len() >= 2
        && cells.iter().all(|c| {
            let c = if d != Delimiter::Comma && c.contains(',') && !c.contains('.') {
                c.replace(',', ".")
            } else {
                c.clone()
            };
            crate::set::parse_number(&c).is_ok()
        })
}

/// When the first lines after the `skip` skipped ones are not rows of numbers (a header
/// block of a lab export: specimen, date, operator), where the rows of numbers start, as a
/// hint: "line 1 `Specimen: A` is not a number; is it a header block? try --skip 3" (the
/// header line of the columns kept when `has_header`). `None` when there is nothing more to
/// skip or no rows of numbers at all.
pub(super) fn skip_hint(
    text: &str,
    skip: usize,
    has_header: bool,
    delimiter: Delimiter,
) -> Option<String> {
    let lines: Vec<(usize, &str)> = content_lines(text, skip).collect();
    let numeric: Vec<bool> = lines
        .iter()
        .map(|(_, l)| numeric_row(l, delimiter))
        .collect();
    let start = (0..lines.len()).find(|&k| {
        let end = (k + NUMERIC_RUN).min(lines.len());
        numeric[k..end].iter().all(|&n| n)
    })?;
    let first_kept = if has_header {
        start.checked_sub(1)?
    } else {
        start
    };
    let suggested = lines[first_kept].0 - 1;
    if first_kept == 0 || suggested <= skip {
        return None;
    }
    let (line_no, first) = lines[0];
    let shown: String = first.trim().chars().take(40).collect();
    Some(format!(
        "line {line_no} `{shown}` is not a number; is it a header block? try --skip {suggested} ({} at line {}{})",
        if has_header {
            "the column header would then be read"
        } else {
            "the rows of numbers would then start"
        },
        lines[first_kept].0,
        if has_header {
            format!(", the numbers from line {}", lines[start].0)
        } else {
            String::new()
        }
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_counts_the_last_digit() {
        assert_eq!(resolution("4.93"), Some(0.01));
        assert_eq!(resolution("120"), Some(1.0));
        assert_eq!(resolution("-1.5e-3"), Some(1e-4));
        assert_eq!(resolution("inf"), None);
    }

    #[test]
    fn conversions_keep_the_digits_of_the_input() {
        let um = |t: &str| with_precision(t.parse().unwrap(), resolution(t), 1e-3);
        assert_eq!(um("4.93").to_string(), "0.00493");
        assert_eq!(um("0.1").to_string(), "0.0001");
        // 1.23 in = 31.242 mm: one guard digit beyond the input's resolution (0.254 mm).
        let inch = with_precision(1.23, resolution("1.23"), 25.4);
        assert_eq!(inch.to_string(), "31.24");
        // A force over an area: 123.4 N on 3600 mm² is 34.2777… kPa, resolution 0.028 kPa.
        let kpa = with_precision(123.4, resolution("123.4"), 1e3 / 3600.0);
        assert_eq!(kpa.to_string(), "34.278");
        // No factor: the number as read.
        assert_eq!(with_precision(0.1, resolution("0.1"), 1.0), 0.1);
    }

    #[test]
    fn the_delimiter_is_found_outside_quotes() {
        assert_eq!(detect("time,\"shear; kPa\""), Delimiter::Comma);
        assert_eq!(detect("\"t, s\";u"), Delimiter::Semicolon);
        assert_eq!(detect("a\t\"b;c\""), Delimiter::Tab);
        assert_eq!(detect("\"a,b\" c"), Delimiter::Whitespace);
    }

    #[test]
    fn a_header_block_gets_a_hint_at_skip() {
        let text = "Specimen: A\nDate: 2024-05-01\nOperator: JK\ntime,disp,force\n0,0,0\n1,0.1,5\n2,0.2,9\n3,0.3,12\n";
        let hint = skip_hint(text, 0, true, Delimiter::Auto).unwrap();
        assert!(
            hint.starts_with(
                "line 1 `Specimen: A` is not a number; is it a header block? try --skip 3"
            ),
            "{hint}"
        );
        // Skipped already, or a plain file: nothing to say.
        assert_eq!(skip_hint(text, 3, true, Delimiter::Auto), None);
        assert_eq!(
            skip_hint("t,u,s\n0,0,0\n1,1,1\n2,2,2\n", 0, true, Delimiter::Auto),
            None
        );
        // Without a header line the numbers themselves start the kept lines.
        let hint = skip_hint(text, 0, false, Delimiter::Auto).unwrap();
        assert!(hint.contains("try --skip 4"), "{hint}");
        // No rows of numbers at all: no guess.
        assert_eq!(skip_hint("a: b\nc: d\n", 0, true, Delimiter::Auto), None);
    }
}
