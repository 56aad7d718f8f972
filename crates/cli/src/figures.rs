//! Overlay figures of a set: measured curve, published curve, fitted curve, residual below.

use anyhow::Result;
use std::path::{Path, PathBuf};
use subfric_fit::PreparedTest;
use subfric_model::{Control, Model};
use subfric_plot::{render_png, Figure, Panel, Series, Style};

/// The figure files `plot_set` writes for `tests`, relative to its output folder.
pub fn figure_files(tests: &[PreparedTest]) -> Vec<String> {
    tests
        .iter()
        .map(|p| format!("{}.png", sanitize(&p.fit.name)))
        .collect()
}

/// Renders one PNG per test under `out` (which must exist); returns the files written and a
/// note for every curve that could not be drawn (a model that runs away on a test).
pub fn plot_set(
    set_name: &str,
    tests: &[PreparedTest],
    published: Option<&Model>,
    fitted: Option<&Model>,
    out: &Path,
) -> Result<(Vec<PathBuf>, Vec<String>)> {
    let mut files = Vec::new();
    let mut notes = Vec::new();
    for p in tests {
        let t = &p.fit;
        let cycles = p.segmentation.cycles();
        let cycle = (cycles >= 1).then(|| {
            p.segmentation
                .cycle_of_row
                .iter()
                .map(|c| c + 1)
                .collect::<Vec<u32>>()
        });
        // Slip control: friction against slip. Traction control: slip against time.
        let slip_control = t.control == Control::Slip;
        let (x, x_label, y_label, res_label) = if slip_control {
            (
                t.imposed.clone(),
                "slip u [mm]",
                "friction τ/σ_n [-]",
                "fit − measured [-]",
            )
        } else {
            (
                t.time.clone(),
                "time t [s]",
                "slip u [mm]",
                "fit − measured [mm]",
            )
        };
        let to_y = |i: usize, v: f64| if slip_control { v / t.normal[i] } else { v };
        let measured: Vec<f64> = t
            .measured
            .iter()
            .enumerate()
            .map(|(i, v)| to_y(i, *v))
            .collect();
        let mut m = Series::new("measured", x.clone(), measured.clone(), Style::Measured);
        if let (Some(c), true) = (&cycle, cycles >= 2) {
            m = m.with_cycles(c.clone());
        }
        let mut main = vec![m];
        let mut residual = Vec::new();
        for (model, label, style) in [
            (published, "published parameters", Style::Published),
            (fitted, "fitted", Style::Fitted),
        ] {
            let Some(model) = model else { continue };
            let pred = match t.predict(model) {
                Ok(p) => p,
                Err(e) => {
                    notes.push(format!(
                        "{set_name}: test `{}`: the {label} curve is not drawn: {e} (row numbers count data rows from 0)",
                        t.name
                    ));
                    // The legend says so too ("(no data)" marks a series without points).
                    main.push(Series::new(
                        format!("{label}: model runs away"),
                        vec![f64::NAN],
                        vec![f64::NAN],
                        style,
                    ));
                    continue;
                }
            };
            let y: Vec<f64> = pred.iter().enumerate().map(|(i, v)| to_y(i, *v)).collect();
            residual.push(Series::new(
                label,
                x.clone(),
                y.iter().zip(&measured).map(|(a, b)| a - b).collect(),
                style,
            ));
            main.push(Series::new(label, x.clone(), y, style));
        }
        let title = format!("{set_name}: {} ({} kPa)", t.name, mean(&t.normal).round());
        let mut fig = Figure::new(title, x_label, Panel::new(y_label, main));
        if !residual.is_empty() {
            fig = fig.with_residual(Panel::new(res_label, residual).with_zero_line());
        }
        let file = out.join(format!("{}.png", sanitize(&t.name)));
        render_png(&fig, &file)?;
        files.push(file);
    }
    Ok((files, notes))
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// A file-name-safe version of a test name.
pub fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}
