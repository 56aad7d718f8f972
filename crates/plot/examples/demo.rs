//! Writes demo figures into the directory given as the first argument
//! (default: ./plot-demo) and prints their paths.

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::PathBuf;
use std::time::Instant;

use subfric_plot::{render_bars_png, render_png, Figure, Panel, Series, Style};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "plot-demo".into()),
    );
    std::fs::create_dir_all(&dir)?;

    let figures: Vec<(&str, Figure)> = vec![
        ("cyclic.png", common::cyclic_figure(3000)),
        ("monotonic.png", common::monotonic_figure()),
        ("long.png", {
            let x: Vec<f64> = (0..100_000).map(|i| i as f64 * 1e-4).collect();
            let y: Vec<f64> = x
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    if i == 61_234 {
                        140.0
                    } else {
                        60.0 * (1.0 - (-v * 3.0).exp()) + 3.0 * (v * 900.0).sin()
                    }
                })
                .collect();
            Figure::new(
                "100 000 points",
                "displacement (mm)",
                Panel::new(
                    "τ (kPa)",
                    vec![Series::new("measured", x, y, Style::Fitted)],
                ),
            )
        }),
        (
            "empty.png",
            Figure::new(
                "No data",
                "x (mm)",
                Panel::new(
                    "y (kPa)",
                    vec![Series::new(
                        "nan only",
                        vec![f64::NAN; 5],
                        vec![1.0; 5],
                        Style::Measured,
                    )],
                ),
            ),
        ),
        ("small.png", common::cyclic_figure(500).with_size(500, 375)),
    ];
    for (name, fig) in &figures {
        let path = dir.join(name);
        let t = Instant::now();
        render_png(fig, &path)?;
        println!(
            "{} ({:.1} ms)",
            path.display(),
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    let path = dir.join("bars.png");
    let t = Instant::now();
    render_bars_png(&common::bar_figure(), &path)?;
    println!(
        "{} ({:.1} ms)",
        path.display(),
        t.elapsed().as_secs_f64() * 1e3
    );
    Ok(())
}
