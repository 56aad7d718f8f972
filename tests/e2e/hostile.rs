//! Hostile sets and options, drawn by proptest (issue 42): numbers at the edges of the doubles,
//! odd encodings (a byte-order mark, UTF-16, CR and CRLF line ends), links and devices where
//! files are expected or written, keys given twice at any depth, short tests. Each drawn case
//! runs the program as a user does and checks its four promises:
//!
//! 1. no panic, and an end within a minute (no read without end, no blocked open);
//! 2. a refusal names where the trouble is: a file (with its line or field where it has one),
//!    or the flag;
//! 3. nothing written outside `--out`, nor through a link: the set, a victim file that links
//!    lead to, and the folder around are as they were;
//! 4. no interval where the data cannot carry one: a fit that shows an interval has tests that
//!    measure their noise (some 20 rows each); otherwise its parameters are "not determined"
//!    and its verdict "cannot judge".

use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use subfric_e2e::{subfric, text};

/// Every entry under `dir` with what it is: a file's bytes, a link's target, a folder, or
/// another kind (a FIFO is never opened).
fn snapshot(dir: &Path) -> Vec<(PathBuf, String)> {
    fn walk(root: &Path, d: &Path, out: &mut Vec<(PathBuf, String)>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            let rel = p.strip_prefix(root).unwrap().to_path_buf();
            let m = std::fs::symlink_metadata(&p).unwrap();
            let what = if m.file_type().is_symlink() {
                format!("link {}", std::fs::read_link(&p).unwrap().display())
            } else if m.is_dir() {
                walk(root, &p, out);
                "folder".into()
            } else if m.is_file() {
                format!("{:?}", std::fs::read(&p).unwrap())
            } else {
                "special".into()
            };
            out.push((rel, what));
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Numbers a record may hold, the edges of the doubles among them (as text).
fn cell() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (-500.0f64..500.0).prop_map(|x| format!("{x}")),
        1 => Just("0".to_string()),
        1 => Just("-0".to_string()),
        1 => Just("5e-324".to_string()),
        1 => Just("1e-320".to_string()),
        1 => Just("1e308".to_string()),
        1 => Just("-1.7976931348623157e308".to_string()),
        1 => Just("1e13".to_string()),
        1 => Just("NaN".to_string()),
        1 => Just("inf".to_string()),
        1 => Just(format!("1{}", "0".repeat(309))),
        1 => Just("".to_string()),
        1 => Just("1,5".to_string()),
    ]
}

/// How a text file is laid out on disk.
#[derive(Clone, Copy, Debug)]
enum Encoding {
    Plain,
    Bom,
    Utf16,
    Crlf,
    Cr,
}

fn encoding() -> impl Strategy<Value = Encoding> {
    prop_oneof![
        8 => Just(Encoding::Plain),
        1 => Just(Encoding::Bom),
        1 => Just(Encoding::Utf16),
        1 => Just(Encoding::Crlf),
        1 => Just(Encoding::Cr),
    ]
}

fn encode(text: &str, e: Encoding) -> Vec<u8> {
    match e {
        Encoding::Plain => text.as_bytes().to_vec(),
        Encoding::Bom => format!("\u{feff}{text}").into_bytes(),
        Encoding::Crlf => text.replace('\n', "\r\n").into_bytes(),
        Encoding::Cr => text.replace('\n', "\r").into_bytes(),
        Encoding::Utf16 => {
            let mut b = vec![0xFF, 0xFE];
            for u in text.encode_utf16() {
                b.extend(u.to_le_bytes());
            }
            b
        }
    }
}

/// What stands where a test's CSV is named.
#[derive(Clone, Copy, Debug)]
enum CsvPlace {
    File,
    LinkOutside,
    Fifo,
    DevZero,
    Folder,
}

fn csv_place() -> impl Strategy<Value = CsvPlace> {
    prop_oneof![
        24 => Just(CsvPlace::File),
        1 => Just(CsvPlace::LinkOutside),
        1 => Just(CsvPlace::Fifo),
        1 => Just(CsvPlace::DevZero),
        1 => Just(CsvPlace::Folder),
    ]
}

/// What is planted in the output folder before the command runs.
#[derive(Clone, Copy, Debug)]
enum OutPlant {
    Nothing,
    LockLink,
    LockFifo,
    OutIsLink,
}

fn out_plant() -> impl Strategy<Value = OutPlant> {
    prop_oneof![
        6 => Just(OutPlant::Nothing),
        1 => Just(OutPlant::LockLink),
        1 => Just(OutPlant::LockFifo),
        1 => Just(OutPlant::OutIsLink),
    ]
}

/// Where a key is given twice in experiment.json, if anywhere.
#[derive(Clone, Copy, Debug)]
enum Twice {
    Nowhere,
    Top,
    Interface,
    Reference,
    Test,
    Deep,
}

fn twice() -> impl Strategy<Value = Twice> {
    prop_oneof![
        12 => Just(Twice::Nowhere),
        1 => Just(Twice::Top),
        1 => Just(Twice::Interface),
        1 => Just(Twice::Reference),
        1 => Just(Twice::Test),
        1 => Just(Twice::Deep),
    ]
}

#[derive(Clone, Debug)]
struct Test {
    rows: usize,
    /// Noise of the shear, kPa.
    noise: f64,
    /// Cells replacing a generated one: (row, column, text).
    hostile: Vec<(usize, usize, String)>,
    place: CsvPlace,
    encoding: Encoding,
}

fn test() -> impl Strategy<Value = Test> {
    (
        prop_oneof![3 => 0usize..5, 3 => 5usize..25, 2 => 25usize..80],
        0.0f64..2.0,
        prop_oneof![
            3 => Just(Vec::new()),
            1 => prop::collection::vec((0usize..80, 0usize..3, cell()), 1..3),
        ],
        csv_place(),
        encoding(),
    )
        .prop_map(|(rows, noise, hostile, place, encoding)| Test {
            rows,
            noise,
            hostile,
            place,
            encoding,
        })
}

#[derive(Clone, Debug)]
struct Case {
    tests: Vec<Test>,
    normal: String,
    reference: Option<String>,
    twice: Twice,
    json_encoding: Encoding,
    command: usize,
    plant: OutPlant,
    seed: u64,
}

fn case() -> impl Strategy<Value = Case> {
    (
        prop::collection::vec(test(), 1..4),
        prop_oneof![8 => Just("100".to_string()), 1 => cell()],
        prop_oneof![
            8 => Just(None),
            1 => Just(Some(r#"{"mu_s": 0.6, "mu_k": 0.5, "kappa": 2, "xi": 0.01, "u_tilde": 15, "alpha_t": 2000}"#.to_string())),
            1 => cell().prop_map(|c| Some(format!(r#"{{"mu_s": {}, "mu_k": 0.5, "kappa": 2, "xi": 0.01, "u_tilde": 15, "alpha_t": 2000}}"#, if c.is_empty() { "\"x\"".into() } else { c }))),
            1 => Just(Some("[0.6, 0.5]".to_string())),
        ],
        twice(),
        encoding(),
        0usize..4,
        out_plant(),
        any::<u64>(),
    )
        .prop_map(
            |(tests, normal, reference, twice, json_encoding, command, plant, seed)| Case {
                tests,
                normal,
                reference,
                twice,
                json_encoding,
                command,
                plant,
                seed,
            },
        )
}

/// A deterministic noise in [-1, 1].
fn noise(i: usize, seed: u64) -> f64 {
    let mut x = (i as u64)
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(seed.wrapping_mul(0xD1B5_4A32_D192_ED03));
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// Writes the drawn set into `set`; `victim` is the file outside that links lead to.
fn write_case(c: &Case, set: &Path, victim: &Path) {
    std::fs::create_dir_all(set).unwrap();
    let mut specs = Vec::new();
    for (k, t) in c.tests.iter().enumerate() {
        let file = format!("t{k}.csv");
        let normal = if k == 0 {
            c.normal.clone()
        } else {
            "200".into()
        };
        let normal = if normal.is_empty() {
            "\"\"".into()
        } else {
            normal
        };
        let dup = if matches!(c.twice, Twice::Test) && k == 0 {
            r#""control": "shear", "#
        } else {
            ""
        };
        specs.push(format!(
            r#"{{"name": "t{k}", "file": "{file}", {dup}"control": "slip", "normal_stress_kpa": {normal}}}"#
        ));
        let path = set.join(&file);
        match t.place {
            CsvPlace::LinkOutside => {
                std::os::unix::fs::symlink(victim, &path).unwrap();
                continue;
            }
            CsvPlace::Fifo => {
                assert!(Command::new("mkfifo")
                    .arg(&path)
                    .status()
                    .unwrap()
                    .success());
                continue;
            }
            CsvPlace::DevZero => {
                std::os::unix::fs::symlink("/dev/zero", &path).unwrap();
                continue;
            }
            CsvPlace::Folder => {
                std::fs::create_dir(&path).unwrap();
                continue;
            }
            CsvPlace::File => {}
        }
        let mut rows: Vec<[String; 3]> = (0..t.rows)
            .map(|i| {
                let u = 2.0 * i as f64 / (t.rows.max(2) - 1) as f64;
                let mu = 0.5 + 0.1 * (-(u - 0.3f64).powi(2) / 0.02).exp() - 0.5 * (-u / 0.05).exp();
                [
                    format!("{}", 50.0 * u),
                    format!("{u}"),
                    format!("{}", 100.0 * mu + t.noise * noise(i, c.seed ^ k as u64)),
                ]
            })
            .collect();
        for (r, col, v) in &t.hostile {
            if let Some(row) = rows.get_mut(*r) {
                row[*col] = v.clone();
            }
        }
        let mut csv = String::from("time_s,slip_mm,shear_kpa\n");
        for r in rows {
            csv.push_str(&format!("{},{},{}\n", r[0], r[1], r[2]));
        }
        std::fs::write(&path, encode(&csv, t.encoding)).unwrap();
    }
    let interface = if matches!(c.twice, Twice::Interface) {
        r#""interface": {"soil": "a", "soil": "b"},"#
    } else {
        r#""interface": {"soil": "Toyoura"},"#
    };
    let reference = match (&c.reference, c.twice) {
        (_, Twice::Reference) => r#""reference_parameters": {"mu_s": 0.6, "mu_s": 0.7, "mu_k": 0.5, "kappa": 2, "xi": 0.01, "u_tilde": 15, "alpha_t": 2000},"#.to_string(),
        (Some(r), _) => format!(r#""reference_parameters": {r},"#),
        (None, _) => String::new(),
    };
    let top = match c.twice {
        Twice::Top => r#""title": "again","#,
        Twice::Deep => r#""lab": {"rig": {"cell": 1, "cell": 2}},"#,
        _ => "",
    };
    let json = format!(
        "{{\n  \"name\": \"hostile\",\n  \"title\": \"hostile\",\n  \"source\": \"drawn\",\n  {top}\n  {interface}\n  {reference}\n  \"tests\": [\n    {}\n  ]\n}}\n",
        specs.join(",\n    ")
    );
    std::fs::write(set.join("experiment.json"), encode(&json, c.json_encoding)).unwrap();
}

/// Runs the program; panics past a minute (a read without end, a blocked open).
fn run(exe: &Path, a: &[OsString]) -> (Option<i32>, String) {
    let mut child = Command::new(exe)
        .args(a)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            let _ = child.wait();
            panic!("subfric {a:?} did not end within a minute");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let o = child.wait_with_output().unwrap();
    (o.status.code(), text(&o.stderr))
}

fn check_case(c: &Case) {
    let s = subfric!();
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let victim = root.join("victim.txt");
    std::fs::write(&victim, "precious\n").unwrap();
    let set = root.join("set");
    write_case(c, &set, &victim);
    let params = root.join("params.json");
    std::fs::write(
        &params,
        r#"{"mu_s": 0.6, "mu_k": 0.5, "kappa": 2, "xi": 0.01, "u_tilde": 15, "alpha_t": 1000}"#,
    )
    .unwrap();
    let out = root.join("out");
    let elsewhere = root.join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    match c.plant {
        OutPlant::Nothing => {}
        OutPlant::LockLink => {
            std::fs::create_dir(&out).unwrap();
            std::os::unix::fs::symlink(&victim, out.join(".subfric-lock")).unwrap();
        }
        OutPlant::LockFifo => {
            std::fs::create_dir(&out).unwrap();
            assert!(Command::new("mkfifo")
                .arg(out.join(".subfric-lock"))
                .status()
                .unwrap()
                .success());
        }
        OutPlant::OutIsLink => std::os::unix::fs::symlink(&elsewhere, &out).unwrap(),
    }
    let o = |x: &Path| x.as_os_str().to_os_string();
    let a: Vec<OsString> = match c.command {
        0 => vec!["check".into(), o(&set)],
        1 => [
            "fit",
            "",
            "--out",
            "",
            "--global-evals",
            "100",
            "--starts",
            "2",
            "--no-profiles",
        ]
        .iter()
        .enumerate()
        .map(|(i, x)| match i {
            1 => o(&set),
            3 => o(&out),
            _ => OsString::from(x),
        })
        .collect(),
        2 => vec!["plot".into(), o(&set), "--out".into(), o(&out)],
        _ => vec![
            "simulate".into(),
            o(&set),
            "--params".into(),
            o(&params),
            "--out".into(),
            o(&out),
        ],
    };
    let set_before = snapshot(&set);
    let outside = |r: &Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(r)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        v.sort();
        v
    };
    let root_before = outside(root);
    let (code, err) = run(s.exe(), &a);
    // 1. No panic; exit codes 0, 1 (refused) or 2 (usage).
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "{a:?} panicked:\n{err}"
    );
    assert!(matches!(code, Some(0..=2)), "{a:?}: exit {code:?}\n{err}");
    // 2. A refusal names the file (and its line or field) or the flag.
    if code != Some(0) {
        let named = err.contains(&*root.to_string_lossy()) || err.contains("--");
        assert!(named, "{a:?}: a refusal that names no file or flag:\n{err}");
    }
    // 3. Nothing written outside --out or through a link.
    assert_eq!(
        std::fs::read_to_string(&victim).unwrap(),
        "precious\n",
        "{a:?}"
    );
    assert_eq!(snapshot(&set), set_before, "{a:?} changed the set");
    assert_eq!(outside(root), {
        let mut v = root_before.clone();
        if !v.contains(&"out".to_string()) && out.exists() {
            v.push("out".into());
            v.sort();
        }
        v
    });
    assert_eq!(
        std::fs::read_dir(&elsewhere).unwrap().count(),
        0,
        "{a:?} wrote through the linked output folder"
    );
    // 4. No interval where the data cannot carry one.
    if c.command == 1 && code == Some(0) {
        let fit = subfric_e2e::read_json(&out.join("fit.json"));
        let shown = fit["report"]["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .any(|p| !p["interval"].is_null() || !p["std_error"].is_null());
        // A test measures its noise with 0.367 × (rows − 2) degrees of freedom at most.
        let fewest = fit["report"]["tests"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["rows"].as_u64().unwrap_or(0))
            .min()
            .unwrap_or(0);
        if fewest < 19 {
            assert!(!shown, "{a:?}: an interval from a test of {fewest} rows");
            assert_eq!(
                fit["verdict"]["level"], "cannot-judge",
                "{}",
                fit["verdict"]
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn hostile_sets_and_options_keep_the_four_promises(c in case()) {
        check_case(&c);
    }
}

#[test]
fn a_drawn_case_is_written_as_drawn() {
    // The writer itself: a plain case reads back as a set the program accepts.
    let c = Case {
        tests: vec![Test {
            rows: 40,
            noise: 0.5,
            hostile: Vec::new(),
            place: CsvPlace::File,
            encoding: Encoding::Plain,
        }],
        normal: "100".into(),
        reference: None,
        twice: Twice::Nowhere,
        json_encoding: Encoding::Plain,
        command: 0,
        plant: OutPlant::Nothing,
        seed: 1,
    };
    let tmp = tempfile::tempdir().unwrap();
    let set = tmp.path().join("set");
    write_case(&c, &set, &tmp.path().join("victim"));
    let o = Command::new(env!("CARGO_BIN_EXE_subfric-e2e"))
        .args([OsStr::new("check"), set.as_os_str()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let _: PathBuf = set;
}
