//! Loads experiment-set folders and prints their summaries.
//!
//! `cargo run -p subfric-reading --example check -- DIR...`

fn main() {
    let mut failed = false;
    for dir in std::env::args().skip(1) {
        match subfric_data::load_set(std::path::Path::new(&dir)) {
            Ok(set) => println!("{}", subfric_reading::summary(&set)),
            Err(e) => {
                failed = true;
                eprintln!("{e}");
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}
