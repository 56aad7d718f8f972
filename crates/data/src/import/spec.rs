//! The options an import reads a lab file with, and their problems before the file is read.

use std::path::Path;

use super::{ColumnRef, Delimiter, ImportFormat, Keep, LengthUnit, RateUnit, StressUnit, TimeUnit};
use crate::error::Problems;
use crate::meta::ControlColumn;
use crate::set::MAX_MAGNITUDE;

/// How to read a lab file.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportSpec {
    /// Cell delimiter.
    pub delimiter: Delimiter,
    /// Lines to skip at the top before the header (or the first data line).
    pub skip_lines: usize,
    /// Whether the first non-comment line after `skip_lines` is a header.
    pub has_header: bool,
    /// Time column.
    pub time: ColumnRef,
    /// Unit of the time column.
    pub time_unit: TimeUnit,
    /// Slip column.
    pub slip: ColumnRef,
    /// Unit of the slip column.
    pub slip_unit: LengthUnit,
    /// Shear column and its unit (or give `friction`).
    pub shear: Option<(ColumnRef, StressUnit)>,
    /// Friction (shear / normal) column, used when `shear` is `None`.
    pub friction: Option<ColumnRef>,
    /// Normal stress column and its unit.
    pub normal: Option<(ColumnRef, StressUnit)>,
    /// Constant normal stress, kPa, when there is no normal column.
    pub normal_stress_kpa: Option<f64>,
    /// Contact area [mm²] a force column (N, kN, lbf) is divided by (3600 for a 60 mm square
    /// shear box).
    pub area_mm2: Option<f64>,
    /// Which column the apparatus imposed.
    pub control: ControlColumn,
    /// Name of the test (unique within the set); the CSV is named after it.
    pub test_name: String,
    /// Name of the set (used when a new set is created).
    pub set_name: String,
    /// Title of a new set (default: the set name).
    pub title: Option<String>,
    /// Soil of a new set.
    pub soil: Option<String>,
    /// Surface of a new set.
    pub surface: Option<String>,
    /// Source of a new set (default: the lab file's name).
    pub source: Option<String>,
    /// The stretch of the record to keep (an aborted stage, the end-of-travel drop trimmed
    /// off); `None` keeps every row.
    pub keep: Option<Keep>,
    /// How the file is laid out: a delimited table read through the columns above, or a GDS
    /// export whose channels are mapped by their names; `Auto` tells them apart.
    pub format: ImportFormat,
    /// The stage to keep, by its number or name, when the file holds several (a stage
    /// column, or a GDS file's stages); `None` keeps the one with the longest shear travel and
    /// says so.
    pub stage: Option<String>,
    /// Further channels to carry with the test: a name of [`crate::CHANNEL_COLUMNS`] and the
    /// column holding it, in that name's unit (a delimited file; a GDS file's are found by
    /// their names).
    pub channels: Vec<(String, ColumnRef)>,
    /// Unit of the rate of shear displacement a GDS file states without one (the time is
    /// then the displacement over that rate).
    pub rate_unit: Option<RateUnit>,
}

impl Default for ImportSpec {
    /// Comma-or-auto file with a header `time_s, slip_mm, shear_kpa`, slip control.
    fn default() -> Self {
        ImportSpec {
            delimiter: Delimiter::Auto,
            skip_lines: 0,
            has_header: true,
            time: ColumnRef::Name("time_s".into()),
            time_unit: TimeUnit::S,
            slip: ColumnRef::Name("slip_mm".into()),
            slip_unit: LengthUnit::Mm,
            shear: Some((ColumnRef::Name("shear_kpa".into()), StressUnit::KPa)),
            friction: None,
            normal: None,
            normal_stress_kpa: None,
            area_mm2: None,
            control: ControlColumn::Slip,
            test_name: "test".into(),
            set_name: "imported".into(),
            title: None,
            soil: None,
            surface: None,
            source: None,
            keep: None,
            format: ImportFormat::Auto,
            stage: None,
            channels: Vec::new(),
            rate_unit: None,
        }
    }
}

/// A force column needs the contact area, and an area is only for a force column (given
/// without one, the force would likely be read as a stress).
fn area_problems(lf: &Path, spec: &ImportSpec, pr: &mut Problems) {
    let forces: Vec<(&str, StressUnit)> = [("shear", &spec.shear), ("normal", &spec.normal)]
        .into_iter()
        .filter_map(|(what, c)| c.as_ref().map(|(_, u)| (what, *u)))
        .filter(|(_, u)| u.is_force())
        .collect();
    match spec.area_mm2 {
        None => {
            for (what, u) in &forces {
                pr.add(
                    lf,
                    None,
                    Some(what),
                    format!(
                        "the {what} column is a force in {} (expected the contact area in mm² to turn it into a stress: --area, e.g. 3600 for a 60 mm square shear box)",
                        u.name()
                    ),
                );
            }
        }
        Some(a) if !(a > 0.0 && a.is_finite()) => pr.add(
            lf,
            None,
            Some("area"),
            format!(
                "contact area {} mm² is {} (expected the area in mm², a finite number > 0)",
                crate::text::short_number(a),
                if a.is_nan() { "not a number" } else if a <= 0.0 { "not positive" } else { "infinite" }
            ),
        ),
        Some(a) if forces.iter().any(|(_, u)| !u.kpa_per_unit(Some(a)).is_some_and(|k| k.is_finite() && k > 0.0)) => pr.add(
            lf,
            None,
            Some("area"),
            format!(
                "contact area {} mm² is so small that a force over it is beyond the doubles (expected the area in mm², e.g. 3600 for a 60 mm square shear box)",
                crate::text::short_number(a)
            ),
        ),
        Some(a) if forces.is_empty() => pr.add(
            lf,
            None,
            Some("area"),
            format!(
                "a contact area of {a} mm² was given but no column is a force (expected --shear-unit or --normal-unit N, kN or lbf with --area; a stress needs no area)"
            ),
        ),
        Some(_) => {}
    }
}

/// Problems of the import options themselves, before the file is read.
pub(super) fn spec_problems(lf: &Path, spec: &ImportSpec) -> Problems {
    let mut pr = Problems::default();
    if spec.test_name.trim().is_empty() {
        pr.add(
            lf,
            None,
            Some("test_name"),
            "empty test name (expected a name for the test)",
        );
    }
    if spec.shear.is_some() && spec.friction.is_some() {
        pr.add(
            lf,
            None,
            Some("friction"),
            "both a shear and a friction column were given (expected one of them: the test is written with the one given, and the other would be dropped)",
        );
    }
    if spec.shear.is_none() && spec.friction.is_none() {
        pr.add(
            lf,
            None,
            Some("shear"),
            "neither a shear nor a friction column was given (expected one of them)",
        );
    }
    if spec.normal.is_none() && spec.normal_stress_kpa.is_none() {
        pr.add(
            lf,
            None,
            Some("normal"),
            "the normal stress is unknown (expected a normal column or a constant normal stress in kPa)",
        );
    }
    for (name, field, what) in [
        (&spec.test_name, "test_name", "a test name"),
        (&spec.set_name, "set_name", "a set name"),
    ] {
        if let Some(msg) = crate::text::name_too_long(name.trim(), what) {
            pr.add(lf, None, Some(field), msg);
        }
    }
    area_problems(lf, spec, &mut pr);
    if let Some(x) = spec.normal_stress_kpa {
        if x > MAX_MAGNITUDE {
            pr.add(
                lf,
                None,
                Some("normal_stress_kpa"),
                format!("normal stress {x:e} kPa is beyond {MAX_MAGNITUDE:e} kPa (expected a measured normal stress in kPa)"),
            );
        } else if !(x > 0.0 && x.is_finite()) {
            pr.add(
                lf,
                None,
                Some("normal_stress_kpa"),
                format!("normal stress {x} kPa is not positive (expected > 0)"),
            );
        }
    }
    pr
}
