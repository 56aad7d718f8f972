//! Prints how the tests of sets are prepared for fitting: rows kept, start, stiffness.
//!
//! `cargo run -p subfric-fit --example prepare_info -- DIR...`
fn main() {
    for dir in std::env::args().skip(1) {
        let set = match subfric_data::load_set(std::path::Path::new(&dir)) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(1);
            }
        };
        let t0 = std::time::Instant::now();
        let prepared = subfric_reading::prepare_set(&set, false);
        println!("{} ({:.2} s)", set.meta.name, t0.elapsed().as_secs_f64());
        for p in &prepared {
            println!(
                "  {:<20} rows {:>6} fitted on {:>5}  start {:?} ({:?})  noise {:.4}  band {:.3e} mm",
                p.fit.name,
                p.full.len(),
                p.fit.len(),
                p.fit.initial,
                p.segmentation.start.kind,
                p.fit.noise_sd,
                p.segmentation.conditioned.band
            );
        }
        match subfric_reading::resolved_stiffness(&prepared) {
            Some(s) => println!("  stiffness: {}", s.evidence),
            None => println!("  stiffness: not resolved"),
        }
    }
}
