//! `subfric`: calibrate the subloading-friction model of sand–metal interfaces and tell where
//! the model and the laboratory disagree, and why. The command line lives in the library
//! (`subfric::main`), so that the end-to-end tests build the very same program.

fn main() -> std::process::ExitCode {
    subfric::main()
}
