//! The `units` block of `experiment.json`: the units of a test's CSV columns, and their factors.

use serde::{Deserialize, Serialize};

/// The units a logger wrote a test's CSV columns in (the optional `units` block of
/// `experiment.json`, for the whole set or per test): stresses (`shear_kpa`, `normal_kpa`),
/// displacements (`slip_mm`) and time (`time_s`). Each is converted to the format's own unit
/// (kPa, mm, s) as the CSV is read; a unit not given is the format's own. The fields of
/// `experiment.json` itself keep the units their names carry (`normal_stress_kpa` is kPa).
///
/// ```
/// use subfric_data::meta::ColumnUnits;
/// let u: ColumnUnits = serde_json::from_str(r#"{"stress": "MPa", "time": "min"}"#).unwrap();
/// let s = u.scale().unwrap();
/// assert_eq!((s.stress, s.displacement, s.time), (1000.0, 1.0, 60.0));
/// let bad: ColumnUnits = serde_json::from_str(r#"{"stress": "N"}"#).unwrap();
/// assert!(bad.scale().is_err()); // a force is not a stress
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnUnits {
    /// Unit of the stress columns: kPa, MPa, Pa or psi.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress: Option<String>,
    /// Unit of the slip column: mm, um (µm), m or in.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<String>,
    /// Unit of the time column: s, ms, min or h.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<String>,
}

/// Factors that take a test's CSV columns to kPa, mm and s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnScale {
    /// kPa per unit of the stress columns.
    pub stress: f64,
    /// mm per unit of the slip column.
    pub displacement: f64,
    /// s per unit of the time column.
    pub time: f64,
}

impl ColumnScale {
    /// The format's own units: every factor 1.
    pub const OWN: ColumnScale = ColumnScale {
        stress: 1.0,
        displacement: 1.0,
        time: 1.0,
    };
}

/// The stress units a `units` block accepts (a force would need the contact area).
pub(crate) const STRESS_UNITS: &str = "kPa, MPa, Pa or psi";

/// kPa per unit of a stress unit `u` (a force is refused: it would need the contact area).
fn stress_factor(u: &str) -> Result<f64, String> {
    let unit: crate::import::StressUnit = u
        .parse()
        .map_err(|_| format!("unknown stress unit `{u}` (expected {STRESS_UNITS})"))?;
    if unit.is_force() {
        return Err(format!("`{u}` is a force, not a stress (expected {STRESS_UNITS}; `subfric import --area` divides a force column by the contact area)"));
    }
    Ok(unit.to_kpa())
}

/// mm per unit of a length unit `u`.
fn length_factor(u: &str) -> Result<f64, String> {
    u.parse::<crate::import::LengthUnit>().map(|l| l.to_mm())
}

/// s per unit of a time unit `u`.
fn time_factor(u: &str) -> Result<f64, String> {
    u.parse::<crate::import::TimeUnit>().map(|t| t.to_s())
}

/// Reads a unit: the factor to the format's own unit, or why it is not one.
type UnitReader = fn(&str) -> Result<f64, String>;

/// Each field of a `units` block with the function that reads its unit.
pub(super) const UNIT_FIELDS: [(&str, UnitReader); 3] = [
    ("stress", stress_factor),
    ("displacement", length_factor),
    ("time", time_factor),
];

impl ColumnUnits {
    /// The factors to kPa, mm and s, or (field, message) for the first unit that is unknown.
    pub fn scale(&self) -> Result<ColumnScale, (&'static str, String)> {
        let factor = |field: &'static str, unit: &Option<String>, read: UnitReader| {
            unit.as_deref()
                .map_or(Ok(1.0), read)
                .map_err(|e| (field, e))
        };
        Ok(ColumnScale {
            stress: factor("stress", &self.stress, stress_factor)?,
            displacement: factor("displacement", &self.displacement, length_factor)?,
            time: factor("time", &self.time, time_factor)?,
        })
    }

    /// Each declared unit with the factor its columns were converted by, in the words `check`,
    /// `fit` and `diagnose` print: "stress MPa → kPa ×1000". Empty when nothing is declared or
    /// a unit is unknown (the set is then refused where it is read).
    pub fn conversions(&self) -> Vec<String> {
        let Ok(scale) = self.scale() else {
            return Vec::new();
        };
        [
            ("stress", &self.stress, "kPa", scale.stress),
            ("displacement", &self.displacement, "mm", scale.displacement),
            ("time", &self.time, "s", scale.time),
        ]
        .into_iter()
        .filter_map(|(what, unit, own, factor)| {
            unit.as_ref()
                .map(|unit| format!("{what} {unit} → {own} ×{}", crate::text::num(factor)))
        })
        .collect()
    }
}
