//! The subfric program, built for the end-to-end tests (see Cargo.toml).

fn main() -> std::process::ExitCode {
    subfric::main()
}
