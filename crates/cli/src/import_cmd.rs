//! `subfric import`: a laboratory export becomes a test of a set in the data format.

use crate::args::ImportArgs;
use anyhow::Result;
use subfric_data::{import, plausibility, summary, ColumnRef, ImportSpec};

/// The import specification the options describe.
fn spec_of(a: &ImportArgs) -> ImportSpec {
    let shear = match (&a.shear, &a.friction) {
        (Some(c), _) => Some((c.clone(), a.shear_unit.into())),
        (None, Some(_)) => None,
        (None, None) => Some((ColumnRef::Name("shear_kpa".into()), a.shear_unit.into())),
    };
    ImportSpec {
        delimiter: a.delimiter.into(),
        skip_lines: a.skip,
        has_header: !a.no_header,
        time: a.time.clone(),
        time_unit: a.time_unit.into(),
        slip: a.slip.clone(),
        slip_unit: a.slip_unit.into(),
        shear,
        friction: a.friction.clone(),
        normal: a.normal.clone().map(|c| (c, a.normal_unit.into())),
        normal_stress_kpa: a.normal_stress,
        control: a.control.into(),
        test_name: a.test_name.clone(),
        set_name: a.set_name.clone().unwrap_or_else(|| {
            a.out
                .file_name()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_else(|| "imported".into())
        }),
        title: a.title.clone(),
        soil: a.soil.clone(),
        surface: a.surface.clone(),
        source: Some(a.file.display().to_string()),
    }
}

/// `subfric import`: nothing in the output folder is overwritten, and the CSV and the set's
/// description are written all or nothing.
pub fn run(args: ImportArgs) -> Result<()> {
    let set = import(&args.file, &spec_of(&args), &args.out)?;
    println!("{}", summary(&set));
    crate::print_warnings(&plausibility(&set));
    Ok(())
}
