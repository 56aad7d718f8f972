//! The stretch of a lab record to keep on import: the rest — an aborted stage before the real
//! one, the end-of-travel drop of a shear box — is trimmed off, and the test's comments say
//! which lines went.

use std::fmt;
use std::str::FromStr;

/// The column a stretch to keep is read on, in the imported units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KeepColumn {
    /// Time [s].
    Time,
    /// Slip [mm].
    Slip,
}

impl KeepColumn {
    /// The column's name in a test CSV.
    pub(crate) fn name(self) -> &'static str {
        match self {
            KeepColumn::Time => "time_s",
            KeepColumn::Slip => "slip_mm",
        }
    }
}

/// One contiguous stretch of the record: from the first row whose value on `column` reaches
/// `from`, up to the row before the first later row whose value passes `to` (a slip that
/// reaches the travel's end and drops back is cut where it first passes). Open ends are
/// infinite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keep {
    /// The column read.
    pub column: KeepColumn,
    /// Lowest value kept (s or mm).
    pub from: f64,
    /// Highest value kept (s or mm).
    pub to: f64,
}

impl Keep {
    /// Rows `[first, end)` of `values` (the column, in the imported units) the stretch keeps;
    /// empty when no row reaches `from`.
    pub fn rows(&self, values: &[f64]) -> std::ops::Range<usize> {
        let Some(first) = values.iter().position(|&v| v >= self.from) else {
            return 0..0;
        };
        let end = values[first..]
            .iter()
            .position(|&v| v > self.to)
            .map_or(values.len(), |k| first + k);
        first..end
    }
}

impl FromStr for Keep {
    type Err = String;

    /// `time=10:500` (seconds), `slip=:4.5` (millimetres); either end may be left open.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let expected = "expected `time=FROM:TO` in s or `slip=FROM:TO` in mm, either end open, e.g. `time=120:` or `slip=:9.5`";
        let (name, range) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}` names no column ({expected})"))?;
        let column = match name.trim().to_ascii_lowercase().as_str() {
            "time" | "time_s" => KeepColumn::Time,
            "slip" | "slip_mm" => KeepColumn::Slip,
            other => return Err(format!("unknown column `{other}` ({expected})")),
        };
        let (lo, hi) = range
            .split_once(':')
            .ok_or_else(|| format!("`{range}` is no range ({expected})"))?;
        let end = |t: &str, open: f64| -> Result<f64, String> {
            let t = t.trim();
            if t.is_empty() {
                return Ok(open);
            }
            match t.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(format!("`{t}` is not a finite number ({expected})")),
            }
        };
        let (from, to) = (end(lo, f64::NEG_INFINITY)?, end(hi, f64::INFINITY)?);
        if from >= to {
            return Err(format!(
                "the range {from}:{to} keeps nothing (expected FROM below TO)"
            ));
        }
        if from.is_infinite() && to.is_infinite() {
            return Err(format!(
                "both ends are open: nothing is trimmed ({expected})"
            ));
        }
        Ok(Keep { column, from, to })
    }
}

impl fmt::Display for Keep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let end = |x: f64| {
            if x.is_finite() {
                crate::text::short_number(x)
            } else {
                String::new()
            }
        };
        let column = match self.column {
            KeepColumn::Time => "time",
            KeepColumn::Slip => "slip",
        };
        write!(f, "{column}={}:{}", end(self.from), end(self.to))
    }
}

/// The note for rows trimmed off: `lines` of every row read, `kept` the rows kept.
/// `place` is what a row's place counts (`line`, or `value` of a file of channel lists).
pub(crate) fn trim_note(
    keep: &Keep,
    lines: &[usize],
    kept: &std::ops::Range<usize>,
    place: &str,
) -> String {
    let before = &lines[..kept.start];
    let after = &lines[kept.end..];
    let unit = match keep.column {
        KeepColumn::Time => "s",
        KeepColumn::Slip => "mm",
    };
    let span = |l: &[usize]| match (l.first(), l.last()) {
        (Some(a), Some(b)) if a == b => Some(format!("{place} {a}")),
        (Some(a), Some(b)) => Some(format!("{place}s {a}–{b}")),
        _ => None,
    };
    let name = keep.column.name();
    let mut parts = Vec::new();
    if let Some(s) = span(before) {
        parts.push(format!("{s} before {name} reached {} {unit}", keep.from));
    }
    if let Some(s) = span(after) {
        parts.push(format!("{s} from where {name} passed {} {unit}", keep.to));
    }
    format!(
        "trimmed as asked (--keep {keep}): {} of {} rows kept; {} left out",
        kept.len(),
        lines.len(),
        if parts.is_empty() {
            "no row".to_string()
        } else {
            parts.join(" and ")
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_with_open_ends_and_refuse_what_keeps_nothing() {
        let k: Keep = "time=10:500".parse().unwrap();
        assert_eq!((k.column, k.from, k.to), (KeepColumn::Time, 10.0, 500.0));
        let k: Keep = "slip=:9.5".parse().unwrap();
        assert_eq!(k.column, KeepColumn::Slip);
        assert!(k.from.is_infinite() && k.to == 9.5);
        assert_eq!(k.to_string(), "slip=:9.5");
        for bad in [
            "time",
            "force=1:2",
            "time=5",
            "time=5:1",
            "time=:",
            "time=a:2",
        ] {
            let e = bad.parse::<Keep>().unwrap_err();
            assert!(e.contains("expected"), "{bad}: {e}");
        }
    }

    #[test]
    fn a_shear_box_drop_at_the_end_of_travel_is_cut_where_the_slip_first_passes() {
        // Slip rises to 10 mm, then the box's end-of-travel drop reads back 9.8 and 10.2.
        let slip = [0.0, 2.0, 5.0, 9.0, 10.5, 9.8, 10.2];
        let k: Keep = "slip=:10".parse().unwrap();
        assert_eq!(k.rows(&slip), 0..4);
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        assert_eq!("time=1.5:".parse::<Keep>().unwrap().rows(&t), 2..5);
        assert_eq!("time=9:".parse::<Keep>().unwrap().rows(&t), 0..0);
    }

    #[test]
    fn the_note_names_the_lines_trimmed_off() {
        let k: Keep = "time=1.5:3.5".parse().unwrap();
        let lines = [2, 3, 4, 5, 6];
        let note = trim_note(&k, &lines, &(2..4), "line");
        assert_eq!(
            note,
            "trimmed as asked (--keep time=1.5:3.5): 2 of 5 rows kept; lines 2–3 before time_s reached 1.5 s and line 6 from where time_s passed 3.5 s left out"
        );
    }
}
