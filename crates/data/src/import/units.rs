//! The units, delimiters and column references an import reads a lab file with.

use std::fmt;
use std::str::FromStr;

/// Cell delimiter of a lab file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Delimiter {
    /// `,`
    Comma,
    /// tab
    Tab,
    /// runs of spaces or tabs
    Whitespace,
    /// `;` (a decimal comma is then accepted)
    Semicolon,
    /// detected from the header (or first data) line: tab, then `;`, then `,`, else whitespace
    Auto,
}

impl FromStr for Delimiter {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "," | "comma" | "csv" => Ok(Delimiter::Comma),
            "\\t" | "\t" | "tab" | "tsv" => Ok(Delimiter::Tab),
            "whitespace" | "space" | "ws" | " " => Ok(Delimiter::Whitespace),
            ";" | "semicolon" => Ok(Delimiter::Semicolon),
            "auto" | "" => Ok(Delimiter::Auto),
            other => Err(format!(
                "unknown delimiter `{other}` (expected comma, tab, whitespace, semicolon or auto)"
            )),
        }
    }
}

/// A column of a lab file: by header name or by 1-based index.
///
/// ```
/// use subfric_data::ColumnRef;
/// assert_eq!("3".parse::<ColumnRef>().unwrap(), ColumnRef::Index(3));
/// assert_eq!("Shear (MPa)".parse::<ColumnRef>().unwrap(), ColumnRef::Name("Shear (MPa)".into()));
/// assert!("0".parse::<ColumnRef>().is_err());
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ColumnRef {
    /// Header name (matched ignoring case and surrounding spaces).
    Name(String),
    /// 1-based column index.
    Index(usize),
}

impl FromStr for ColumnRef {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        if s.is_empty() {
            return Err(
                "empty column reference (expected a header name or a 1-based index)".into(),
            );
        }
        if s.chars().all(|c| c.is_ascii_digit()) {
            match s.parse::<usize>() {
                Ok(0) | Err(_) => Err(format!(
                    "column index `{s}` is invalid (expected 1, 2, 3, …)"
                )),
                Ok(i) => Ok(ColumnRef::Index(i)),
            }
        } else {
            Ok(ColumnRef::Name(s.to_string()))
        }
    }
}

impl fmt::Display for ColumnRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ColumnRef::Name(n) => write!(f, "{n}"),
            ColumnRef::Index(i) => write!(f, "column {i}"),
        }
    }
}

impl From<&str> for ColumnRef {
    fn from(s: &str) -> Self {
        s.parse().unwrap_or_else(|_| ColumnRef::Name(s.to_string()))
    }
}

/// Time unit of a lab file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeUnit {
    /// seconds
    S,
    /// minutes
    Min,
    /// hours
    H,
    /// milliseconds
    Ms,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn to_s(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Min => 60.0,
            TimeUnit::H => 3600.0,
            TimeUnit::Ms => 1e-3,
        }
    }
}

impl FromStr for TimeUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "s" | "sec" | "second" | "seconds" => Ok(TimeUnit::S),
            "min" | "minute" | "minutes" => Ok(TimeUnit::Min),
            "h" | "hr" | "hour" | "hours" => Ok(TimeUnit::H),
            "ms" | "millisecond" | "milliseconds" => Ok(TimeUnit::Ms),
            other => Err(format!(
                "unknown time unit `{other}` (expected s, min, h or ms)"
            )),
        }
    }
}

/// Length unit of a lab file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LengthUnit {
    /// millimetres
    Mm,
    /// micrometres
    Um,
    /// metres
    M,
    /// inches
    In,
}

impl LengthUnit {
    /// Millimetres per unit.
    pub fn to_mm(self) -> f64 {
        match self {
            LengthUnit::Mm => 1.0,
            LengthUnit::Um => 1e-3,
            LengthUnit::M => 1e3,
            LengthUnit::In => 25.4,
        }
    }
}

impl FromStr for LengthUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_lowercase().as_str() {
            "mm" => Ok(LengthUnit::Mm),
            "um" | "µm" | "μm" | "micron" | "microns" => Ok(LengthUnit::Um),
            "m" => Ok(LengthUnit::M),
            "in" | "inch" | "inches" => Ok(LengthUnit::In),
            other => Err(format!(
                "unknown length unit `{other}` (expected mm, um, m or in)"
            )),
        }
    }
}

/// Unit of a shear or normal column of a lab file: a stress, or a force that the import
/// divides by the contact area (`ImportSpec::area_mm2`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StressUnit {
    /// kilopascals
    KPa,
    /// megapascals
    MPa,
    /// pascals
    Pa,
    /// pounds per square inch
    Psi,
    /// newtons (a force: divided by the area)
    N,
    /// kilonewtons (a force: divided by the area)
    KN,
    /// pounds-force (a force: divided by the area)
    Lbf,
}

/// Newtons per pound-force.
const NEWTONS_PER_LBF: f64 = 4.448_221_615_260_5;

impl StressUnit {
    /// Kilopascals per unit of a stress; for a force, kilopascals per unit on one square
    /// millimetre (divide by the area in mm²): see [`StressUnit::kpa_per_unit`].
    pub fn to_kpa(self) -> f64 {
        match self {
            StressUnit::KPa => 1.0,
            StressUnit::MPa => 1e3,
            StressUnit::Pa => 1e-3,
            StressUnit::Psi => 6.894_757_293_168_361,
            // 1 N / 1 mm² = 1 MPa.
            StressUnit::N => 1e3,
            StressUnit::KN => 1e6,
            StressUnit::Lbf => 1e3 * NEWTONS_PER_LBF,
        }
    }

    /// A force, which needs the contact area.
    pub fn is_force(self) -> bool {
        matches!(self, StressUnit::N | StressUnit::KN | StressUnit::Lbf)
    }

    /// Kilopascals per unit, a force divided by `area_mm2`; `None` for a force without an
    /// area.
    pub fn kpa_per_unit(self, area_mm2: Option<f64>) -> Option<f64> {
        match (self.is_force(), area_mm2) {
            (false, _) => Some(self.to_kpa()),
            (true, Some(a)) => Some(self.to_kpa() / a),
            (true, None) => None,
        }
    }

    /// The unit as written.
    pub fn name(self) -> &'static str {
        match self {
            StressUnit::KPa => "kPa",
            StressUnit::MPa => "MPa",
            StressUnit::Pa => "Pa",
            StressUnit::Psi => "psi",
            StressUnit::N => "N",
            StressUnit::KN => "kN",
            StressUnit::Lbf => "lbf",
        }
    }
}

impl FromStr for StressUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "kpa" => Ok(StressUnit::KPa),
            "mpa" => Ok(StressUnit::MPa),
            "pa" => Ok(StressUnit::Pa),
            "psi" => Ok(StressUnit::Psi),
            "n" => Ok(StressUnit::N),
            "kn" => Ok(StressUnit::KN),
            "lbf" => Ok(StressUnit::Lbf),
            other => Err(format!(
                "unknown stress or force unit `{other}` (expected kPa, MPa, Pa, psi, or a force with the area: N, kN, lbf)"
            )),
        }
    }
}

/// How a lab file is laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImportFormat {
    /// A GDS export when the file is one (an `.ini` channel file, or a table under a
    /// `Stage Number` header), else a delimited table.
    Auto,
    /// A delimited table read through the columns the import names.
    Delimited,
    /// A GDS direct- or interface-shear export (the `.ini` channel file or the tabular
    /// GDSLAB export): channels mapped by their names.
    Gds,
}

impl FromStr for ImportFormat {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(ImportFormat::Auto),
            "delimited" | "csv" => Ok(ImportFormat::Delimited),
            "gds" => Ok(ImportFormat::Gds),
            other => Err(format!(
                "unknown file format `{other}` (expected auto, delimited or gds)"
            )),
        }
    }
}

/// Unit of a rate of displacement: a length per time (`mm/min`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RateUnit {
    /// The length.
    pub length: LengthUnit,
    /// Per this time.
    pub per: TimeUnit,
}

impl RateUnit {
    /// Millimetres per second per unit.
    pub fn to_mm_per_s(self) -> f64 {
        self.length.to_mm() / self.per.to_s()
    }
}

impl FromStr for RateUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let expected = "expected a length per time such as mm/min, mm/s or um/s";
        let (l, t) = s
            .split_once('/')
            .ok_or_else(|| format!("`{s}` is no rate unit ({expected})"))?;
        let length = l
            .parse::<LengthUnit>()
            .map_err(|e| format!("{e}; {expected}"))?;
        let per = t
            .parse::<TimeUnit>()
            .map_err(|e| format!("{e}; {expected}"))?;
        Ok(RateUnit { length, per })
    }
}

impl fmt::Display for RateUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let l = match self.length {
            LengthUnit::Mm => "mm",
            LengthUnit::Um => "µm",
            LengthUnit::M => "m",
            LengthUnit::In => "in",
        };
        let t = match self.per {
            TimeUnit::S => "s",
            TimeUnit::Min => "min",
            TimeUnit::H => "h",
            TimeUnit::Ms => "ms",
        };
        write!(f, "{l}/{t}")
    }
}
