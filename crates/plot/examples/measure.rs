//! Times the two figure kinds and reports their PNG and SVG sizes; the numbers in
//! `docs/plot-rasteriser.md` come from this program.
//!
//! `cargo run -p subfric-plot --release --example measure -- [DIR] [RUNS] [WHICH]`
//! writes `overlay.png` and `bars.png` into DIR (default ./plot-measure)
//! and prints, per figure, the fastest and the median of RUNS renders to PNG
//! (default 20, after one warm-up render), the PNG's size and the size of the
//! SVG written beside it (`write_figure`, once, untimed). WHICH
//! (`overlay` or `bars`) renders only one of them, e.g. to count
//! instructions with `perf stat -e instructions`, which unlike wall time
//! does not depend on what else the machine is doing.

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use subfric_plot::{
    render_bars_png, render_png, write_figure, Chart, Figure, Panel, PlotError, Series, Style,
};

/// The figure `subfric plot` writes for a long cyclic test: a 20 000-point
/// measured curve coloured by cycle, the published and the fitted model on
/// the same 20 000 points, and both residuals below.
fn overlay() -> Figure {
    let n = 20_000;
    let (x, measured, cycles) = common::cyclic(n, 5, 60.0, 0.08, 2.5, 7);
    let (_, fitted, _) = common::cyclic(n, 5, 58.0, 0.085, 0.0, 7);
    let (_, published, _) = common::cyclic(n, 5, 66.0, 0.05, 0.0, 7);
    let minus = |a: &[f64]| -> Vec<f64> { a.iter().zip(&measured).map(|(m, d)| m - d).collect() };
    let residual = Panel::new(
        "fit − measured (kPa)",
        vec![
            Series::new(
                "published parameters",
                x.clone(),
                minus(&published),
                Style::Published,
            ),
            Series::new("fitted", x.clone(), minus(&fitted), Style::Fitted),
        ],
    )
    .with_zero_line();
    let main = Panel::new(
        "shear stress τ (kPa)",
        vec![
            Series::new("measured", x.clone(), measured.clone(), Style::Measured)
                .with_cycles(cycles),
            Series::new(
                "published parameters",
                x.clone(),
                published,
                Style::Published,
            ),
            Series::new("fitted", x, fitted, Style::Fitted),
        ],
    );
    Figure::new(
        "table4-two-way: two-way-cyclic (100 kPa)",
        "tangential displacement δ (mm)",
        main,
    )
    .with_residual(residual)
}

fn time(
    runs: usize,
    mut render: impl FnMut() -> Result<(), PlotError>,
) -> Result<(f64, f64), PlotError> {
    render()?;
    let mut ms = Vec::with_capacity(runs);
    for _ in 0..runs {
        let t = Instant::now();
        render()?;
        ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    ms.sort_by(f64::total_cmp);
    Ok((ms[0], ms[ms.len() / 2]))
}

fn report(
    name: &str,
    fig: &impl Chart,
    path: &Path,
    (best, median): (f64, f64),
) -> Result<(), Box<dyn std::error::Error>> {
    let bytes = std::fs::metadata(path)?.len();
    let svg = write_figure(fig, path)?.svg;
    let svg_bytes = std::fs::metadata(&svg)?.len();
    println!(
        "{name:8} best {best:7.2} ms  median {median:7.2} ms  {bytes:7} bytes PNG  {svg_bytes:7} bytes SVG  {}",
        path.display()
    );
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = PathBuf::from(args.next().unwrap_or_else(|| "plot-measure".into()));
    let runs: usize = args.next().map_or(Ok(20), |a| a.parse())?.max(1);
    let which = args.next().unwrap_or_default();
    std::fs::create_dir_all(&dir)?;

    if which != "bars" {
        let fig = overlay();
        let path = dir.join("overlay.png");
        report(
            "overlay",
            &fig,
            &path,
            time(runs, || render_png(&fig, &path))?,
        )?;
    }
    if which != "overlay" {
        let bars = common::bar_figure();
        let path = dir.join("bars.png");
        report(
            "bars",
            &bars,
            &path,
            time(runs, || render_bars_png(&bars, &path))?,
        )?;
    }
    Ok(())
}
