//! The committed header `include/subfric.h` is what cbindgen generates from `src/lib.rs` with
//! `cbindgen.toml`. After changing the interface, regenerate it with
//! `SUBFRIC_BLESS=1 cargo test -p subfric-ffi --test header`.

use std::path::Path;

#[test]
fn committed_header_is_up_to_date() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut generated);
    let generated = String::from_utf8(generated).expect("UTF-8 header");
    let path = dir.join("include/subfric.h");
    if std::env::var_os("SUBFRIC_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write include/subfric.h");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is out of date with src/lib.rs: regenerate it with \
         `SUBFRIC_BLESS=1 cargo test -p subfric-ffi --test header`",
        path.display()
    );
    for name in [
        "subfric_model_new",
        "subfric_model_from_json",
        "subfric_model_from_file",
        "subfric_model_free",
        "subfric_model_params",
        "subfric_state_init",
        "subfric_step",
        "subfric_version",
        "SUBFRIC_STATUS_NO_CONVERGENCE",
        "#define SUBFRIC_STATE_LEN 17",
        "#define SUBFRIC_STATE_SLOTS 5",
        "double slots[SUBFRIC_STATE_SLOTS];",
        "double dshear_dslip[3][3];",
    ] {
        assert!(generated.contains(name), "the header lacks {name}");
    }
}
