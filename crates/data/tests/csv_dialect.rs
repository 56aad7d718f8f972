//! What lab exports hold, read through the `csv` crate: a byte-order mark, CRLF and lone-CR line
//! ends, quoted cells (with the delimiter, a quote or a line break inside), comments, other
//! delimiters; errors still at the right file, line and column; written cells read back.

use subfric_data::{
    import, load_set, write_set, ColumnRef, Delimiter, ImportSpec, StressUnit, TestData,
};

const JSON_ONE: &str = r#"{"name": "s", "title": "t", "source": "unit test",
  "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}]}"#;

fn load(csv: &[u8]) -> Result<TestData, String> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("experiment.json"), JSON_ONE).unwrap();
    std::fs::write(dir.path().join("a.csv"), csv).unwrap();
    load_set(dir.path())
        .map(|s| s.tests[0].clone())
        .map_err(|e| e.to_string())
}

const PLAIN: &str =
    "# rig 2\ntime_s,slip_mm,shear_kpa,normal_kpa\n0,0,0,100\n1,0.01,12.5,100\n\n2,0.02,20.25,101\n";

#[test]
fn bom_crlf_and_lone_cr_read_the_same_numbers_as_plain() {
    let plain = load(PLAIN.as_bytes()).unwrap();
    assert_eq!(plain.shear_kpa, vec![0.0, 12.5, 20.25]);
    let crlf = format!("\u{feff}{}", PLAIN.replace('\n', "\r\n"));
    let cr = PLAIN.replace('\n', "\r");
    for (what, text) in [("BOM + CRLF", crlf), ("lone CR", cr)] {
        let t = load(text.as_bytes()).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(t.time_s, plain.time_s, "{what}");
        assert_eq!(t.slip_mm, plain.slip_mm, "{what}");
        assert_eq!(t.shear_kpa, plain.shear_kpa, "{what}");
        assert_eq!(t.normal_kpa, plain.normal_kpa, "{what}");
        assert_eq!(t.line_of_row, vec![3, 4, 6], "{what}");
        assert_eq!(t.comments, vec!["rig 2"], "{what}");
    }
}

#[test]
fn quoted_cells_are_one_cell_each() {
    // Quoted header names and numbers, a quote after a space, a comma inside quotes.
    let t = load(b"\"time_s\", \"slip_mm\",\"shear_kpa\"\n\"0\",0,0\n1,\"0.5\",\"20\"\n").unwrap();
    assert_eq!(t.shear_kpa, vec![0.0, 20.0]);
    // A decimal comma in quotes is one cell that is not a number (it was 4 cells, split by hand).
    let e = load(b"time_s,slip_mm,shear_kpa\n0,0,0\n1,\"0,5\",20\n").unwrap_err();
    assert!(
        e.contains("a.csv:3: field `slip_mm`: `0,5` is not a number (expected a decimal number)"),
        "{e}"
    );
    assert!(!e.contains("cells"), "{e}");
}

#[test]
fn a_bad_number_is_named_at_its_file_line_and_column() {
    // After a quoted cell holding a line break, in a CRLF file with a BOM, the lines still count
    // as an editor counts them.
    let csv = "\u{feff}# c\r\ntime_s,slip_mm,shear_kpa\r\n0,0,0\r\n\"1\r\n\",0.1,2\r\n\r\n2,abc,3\r\n3,0.3,x\ny\r\n";
    let e = load(csv.as_bytes()).unwrap_err();
    assert!(
        e.contains("a.csv:7: field `slip_mm`: `abc` is not a number"),
        "{e}"
    );
    // A cell that is not a number holding a line break is shown on one line.
    let e = load(b"time_s,slip_mm,shear_kpa\n0,0,0\n1,0.1,\"2\n3\"\n").unwrap_err();
    assert!(
        e.contains("a.csv:3: field `shear_kpa`: `2\\n3` is not a number"),
        "{e}"
    );
    // An unclosed quote takes the lines after it into its cell: the row says so.
    let e = load(b"time_s,slip_mm,shear_kpa\n0,0,0\n1,\"0.1,2\n2,0.2,3\n").unwrap_err();
    assert!(
        e.contains("a.csv:3: row has 2 cells (expected 3: time_s,slip_mm,shear_kpa); a quoted cell runs over several lines here: is a closing `\"` missing?"),
        "{e}"
    );
    // Lone CR line ends count as lines.
    let e = load(b"time_s,slip_mm,shear_kpa\r0,0,0\r\r1,0.1,inf\r").unwrap_err();
    assert!(
        e.contains("a.csv:4: field `shear_kpa`: `inf` is not a finite number"),
        "{e}"
    );
}

#[test]
fn lab_export_with_semicolons_quotes_and_a_bom() {
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("export.csv");
    let text = "\u{feff}\"Exported; rig 2\"\r\n\"Time; s\";\"Slip, mm\";\"Shear \"\"kPa\"\"\"\r\n0;0;0\r\n1;0,05;12,5\r\n2;0,1;\"20,25\"\r\n";
    std::fs::write(&lab, text).unwrap();
    let spec = ImportSpec {
        delimiter: Delimiter::Semicolon,
        skip_lines: 1,
        time: ColumnRef::Name("Time; s".into()),
        slip: ColumnRef::Name("Slip, mm".into()),
        shear: Some((ColumnRef::Name("Shear \"kPa\"".into()), StressUnit::KPa)),
        normal_stress_kpa: Some(100.0),
        ..ImportSpec::default()
    };
    let out = dir.path().join("set");
    let set = import(&lab, &spec, &out).unwrap_or_else(|e| panic!("{e}"));
    let t = &set.tests[0];
    assert_eq!(t.slip_mm, vec![0.0, 0.05, 0.1]);
    assert_eq!(t.shear_kpa, vec![0.0, 12.5, 20.25]);
    // Detected, the delimiter is the same (the header's `;`), and a bad cell is named at its line.
    std::fs::write(&lab, text.replace("12,5", "12,5x")).unwrap();
    let auto = ImportSpec {
        delimiter: Delimiter::Auto,
        ..spec
    };
    let e = import(&lab, &auto, &dir.path().join("set2")).unwrap_err();
    assert!(
        e.to_string()
            .contains("export.csv:4: field `Shear \"kPa\"`: `12,5x` is not a number"),
        "{e}"
    );
}

#[test]
fn a_header_name_with_the_delimiter_inside_quotes_is_one_column() {
    let dir = tempfile::tempdir().unwrap();
    let lab = dir.path().join("export.csv");
    std::fs::write(
        &lab,
        "t,\"slip, mm\",\"shear, kPa\"\n0,0,0\n1,0.1,5\n2,0.2,9\n",
    )
    .unwrap();
    let spec = ImportSpec {
        time: ColumnRef::Name("t".into()),
        slip: ColumnRef::Name("slip, mm".into()),
        shear: Some((ColumnRef::Index(3), StressUnit::KPa)),
        normal_stress_kpa: Some(100.0),
        ..ImportSpec::default()
    };
    let set = import(&lab, &spec, &dir.path().join("set")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(set.tests[0].shear_kpa, vec![0.0, 5.0, 9.0]);
}

#[test]
fn written_comments_and_numbers_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir(&src).unwrap();
    std::fs::write(src.join("experiment.json"), JSON_ONE).unwrap();
    std::fs::write(src.join("a.csv"), PLAIN).unwrap();
    let mut set = load_set(&src).unwrap();
    // A comment holding a line break (an imported file's name may) stays comments.
    set.tests[0].comments = vec!["from `a,\"b\"\nc.txt`".into(), String::new()];
    let out = dir.path().join("out");
    write_set(&set, &out).unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(out.join("a.csv")).unwrap();
    assert!(
        text.starts_with(
            "# from `a,\"b\"\n# c.txt`\n#\ntime_s,slip_mm,shear_kpa,normal_kpa\n0,0,0,100\n"
        ),
        "{text}"
    );
    let back = load_set(&out).unwrap();
    assert_eq!(back.tests[0].shear_kpa, set.tests[0].shear_kpa);
    assert_eq!(back.tests[0].comments, vec!["from `a,\"b\"", "c.txt`", ""]);
}
