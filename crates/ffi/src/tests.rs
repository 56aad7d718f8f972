use super::*;

#[test]
fn messages_are_truncated_at_a_character_boundary_and_terminated() {
    let mut buf = [1 as c_char; 6];
    // SAFETY: the buffer is valid for its length.
    unsafe { write_message(buf.as_mut_ptr(), buf.len(), "μ_k = 0.9") };
    // "μ_k =" is 6 bytes: 5 fit with the NUL, "μ" is two bytes.
    // SAFETY: write_message terminated the buffer.
    let s = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_str().unwrap();
    assert_eq!(s, "μ_k ");
    let mut buf = [1 as c_char; 2];
    // SAFETY: the buffer is valid for its length.
    unsafe { write_message(buf.as_mut_ptr(), buf.len(), "μ") };
    assert_eq!(buf[0], 0);
}

#[test]
fn json_errors_map_to_their_status() {
    let flat = r#"{"mu_s":0.45,"mu_k":0.3,"kappa":1.2,"xi":0.003,"u_tilde":15,"alpha_t":1000}"#;
    assert_eq!(model_from_json(flat).unwrap().params, Params::sample());
    let object = format!(r#"{{"params":{flat},"ext":{{"slip_hardening":{{"h":0.01,"s_h":1}}}}}}"#);
    assert!(!model_from_json(&object).unwrap().ext.terms.is_empty());
    let e = model_from_json(r#"{"mu_s":0.4}"#).unwrap_err();
    assert_eq!(e.0, SubfricStatus::InvalidJson);
    assert!(e.1.contains("`mu_k` is missing"), "{}", e.1);
    let e = model_from_json(&object.replace("slip_hardening", "slip_softening")).unwrap_err();
    assert_eq!(e.0, SubfricStatus::InvalidJson);
    assert!(
        e.1.contains("`ext.slip_softening` is not a known"),
        "{}",
        e.1
    );
    let e = model_from_json(&flat.replace("0.3", "0.9")).unwrap_err();
    assert_eq!(e.0, SubfricStatus::InvalidParameters);
    assert!(e.1.contains("mu_k = 0.9"), "{}", e.1);
    let e = model_from_json("{\"mu_s\": ").unwrap_err();
    assert_eq!(e.0, SubfricStatus::InvalidJson);
    assert!(e.1.contains("line 1"), "{}", e.1);
}

#[test]
fn reads_the_fit_json_files_that_reproduce_writes() {
    let fits = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fits");
    let mut read = 0;
    for entry in std::fs::read_dir(&fits).unwrap() {
        let file = entry.unwrap().path().join("fit.json");
        if let Ok(text) = std::fs::read_to_string(&file) {
            let m =
                model_from_json(&text).unwrap_or_else(|e| panic!("{}: {}", file.display(), e.1));
            let v: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert_eq!(
                m.params.mu_s,
                v["model"]["params"]["mu_s"].as_f64().unwrap()
            );
            read += 1;
        }
    }
    assert!(read >= 6, "{read} fit.json files under {}", fits.display());
}

#[test]
fn a_panic_becomes_an_internal_error() {
    let mut buf = [0 as c_char; 64];
    // SAFETY: the buffer is valid for its length.
    let status = unsafe { guard(buf.as_mut_ptr(), buf.len(), || panic!("boom")) };
    assert_eq!(status, SubfricStatus::Internal);
    // SAFETY: write_message terminated the buffer.
    let s = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_str().unwrap();
    assert_eq!(s, "internal error: boom");
}
