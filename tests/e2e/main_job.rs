//! End-to-end tests of the main job and of every subcommand a user runs on the bundled data
//! (reproduce, simulate, fit, plot, import, check, help), each run as a separate process of
//! the subfric program on copies of `experiments/` in temporary folders.
//!
//! A whole `bench` or `selfcheck` run is too slow for a test: `bench` is run on its quick parts
//! (`--only`, in `bench.rs`), `selfcheck` is only checked through `--help`.

use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;
use subfric_e2e::{
    args, assert_mentions, bundled_sets, column, copy_set, experiments, read_data_csv, read_json,
    relative_rms, repo, snapshot, subfric, text,
};
use subfric_plot::{inspect_png, read_rgb, FITTED_RGB};

fn run(a: &[&OsStr]) -> Output {
    subfric!().run(a)
}

fn run_ok(a: &[&OsStr]) -> String {
    subfric!().ok(a)
}

fn run_err(a: &[&OsStr]) -> String {
    subfric!().err(a)
}

/// Checks a figure file: a decodable 8-bit PNG of sane size that is not blank. Returns the
/// number of pixels of the fitted-curve colour.
fn check_png(p: &Path) -> usize {
    // Decode with the png crate itself, independently of subfric-plot's reader.
    let file = std::fs::File::open(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let mut reader = decoder
        .read_info()
        .unwrap_or_else(|e| panic!("{}: not a PNG: {e}", p.display()));
    let mut buf = vec![0; reader.output_buffer_size().expect("a PNG of sane size")];
    let info = reader
        .next_frame(&mut buf)
        .unwrap_or_else(|e| panic!("{}: truncated PNG: {e}", p.display()));
    assert_eq!(info.bit_depth, png::BitDepth::Eight, "{}", p.display());
    assert!(
        (400..=4000).contains(&info.width) && (300..=4000).contains(&info.height),
        "{}: size {}x{}",
        p.display(),
        info.width,
        info.height
    );
    let c = inspect_png(p).unwrap();
    assert_eq!((c.width, c.height), (info.width, info.height));
    assert!(
        c.inked_fraction > 0.01 && c.inked_fraction < 0.6 && c.distinct_colors > 5,
        "{}: blank or flooded figure: {c:?}",
        p.display()
    );
    let img = read_rgb(p).unwrap();
    img.pixels().filter(|(_, _, c)| *c == FITTED_RGB).count()
}

/// The fitted curve's pixels lie inside the plotting areas (none in the margins).
fn assert_curve_inside_axes(p: &Path) {
    let img = read_rgb(p).unwrap();
    let (mut left, mut right, mut top, mut bottom) = (u32::MAX, 0, u32::MAX, 0);
    for (x, y, c) in img.pixels() {
        if c == FITTED_RGB {
            left = left.min(x);
            right = right.max(x);
            top = top.min(y);
            bottom = bottom.max(y);
        }
    }
    assert!(
        left > 40 && right < img.width - 10 && top > 30 && bottom < img.height - 40,
        "{}: curve outside the axes",
        p.display()
    );
}

/// PNG files directly in `dir`.
fn pngs_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .collect();
    v.sort();
    v
}

/// The file name `subfric` gives a test's figure.
fn png_name(test: &str) -> String {
    let s: String = test
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{s}.png")
}

const BASE_PARAMS: [&str; 6] = ["mu_s", "mu_k", "kappa", "xi", "u_tilde", "alpha_t"];

// ---------------------------------------------------------------------------------------------
// reproduce
// ---------------------------------------------------------------------------------------------

#[test]
fn reproduce_twice_writes_the_same_tables_fits_and_figures() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = tmp.path().join("experiments");
    let sets = bundled_sets();
    assert!(sets.len() >= 6, "bundled sets: {sets:?}");
    for s in &sets {
        copy_set(s, &exp);
    }
    // Not a set: ignored by reproduce (no experiment.json).
    std::fs::create_dir_all(exp.join("notes")).unwrap();
    std::fs::write(exp.join("notes/readme.txt"), "not a set").unwrap();
    let out = tmp.path().join("fits");
    let stdout = run_ok(args!["reproduce", "--experiments", &exp, "--out", &out]);
    assert!(
        stdout.contains(&format!("wrote {} sets", sets.len())),
        "{stdout}"
    );
    assert!(!out.join("notes").exists());

    // What is tracked under fits/ is a pure function of the data, the code and the seed: a
    // second run (as on a clean checkout, into the folder the first one wrote) gives the same
    // files, byte for byte. Only the wall times differ, and they go to the one untracked file.
    let tracked = |dir: &Path| -> Vec<(PathBuf, Vec<u8>)> {
        snapshot(dir)
            .into_iter()
            .filter(|(p, _)| p != Path::new("timings.txt"))
            .collect()
    };
    let first = tracked(&out);
    assert!(out.join("timings.txt").is_file());
    let gitignore = std::fs::read_to_string(repo().join(".gitignore")).unwrap();
    assert!(
        gitignore.lines().any(|l| l.trim() == "/fits/timings.txt"),
        "timings.txt must not be tracked:\n{gitignore}"
    );
    run_ok(args!["reproduce", "--experiments", &exp, "--out", &out]);
    let second = tracked(&out);
    let names = |s: &[(PathBuf, Vec<u8>)]| s.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>();
    assert_eq!(
        names(&first),
        names(&second),
        "the two runs wrote different files"
    );
    for ((path, a), (_, b)) in first.iter().zip(&second) {
        assert!(a == b, "{} differs between two runs", path.display());
        let name = path.to_string_lossy();
        assert!(!name.contains("subfric-tmp"), "temporary file left: {name}");
        if name.ends_with("fit.json") {
            assert!(!text(a).contains("elapsed"), "{name} holds a wall time");
        }
    }

    // Which tables the sets belong to, from their experiment.json.
    let mut tables: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for s in &sets {
        let meta = read_json(&exp.join(s).join("experiment.json"));
        let table = meta["reference_parameters"]["source"]
            .as_str()
            .unwrap_or("other sets")
            .to_lowercase()
            .replace(' ', "");
        tables.entry(table).or_default().push(s.clone());
    }
    // The paper's four tables are all there.
    for t in ["table1", "table2", "table3", "table4"] {
        assert!(tables.contains_key(t), "{tables:?}");
    }

    let readme = std::fs::read_to_string(out.join("README.md")).unwrap();
    for (table, members) in &tables {
        for ext in ["md", "csv"] {
            let f = out.join(format!("{table}.{ext}"));
            assert!(f.is_file(), "{} missing", f.display());
            assert!(readme.contains(&format!("({table}.{ext})")), "{readme}");
        }
        let md = std::fs::read_to_string(out.join(format!("{table}.md"))).unwrap();
        for s in members {
            assert!(md.contains(&format!("## {s}")), "{table}.md lacks {s}");
        }
        // For a skimming engineer: an undetermined parameter shows the bound the data set,
        // with no difference from the published value; the notation has its legend.
        for row in md
            .lines()
            .filter(|l| l.starts_with("| ") && l.contains("not determined"))
        {
            let cells: Vec<&str> = row.split('|').map(str::trim).collect();
            assert!(
                cells[2].starts_with("not determined ("),
                "{table}.md: {row}"
            );
            assert!(cells[7].is_empty(), "{table}.md: a difference for {row}");
        }
        assert!(
            md.contains("95 % interval [a, b]"),
            "{table}.md has no legend"
        );
    }
    assert!(
        readme.contains("not determined (≤ b)"),
        "README has no legend"
    );

    // The one page: every figure of the job, each set's verdict and table.
    let page = subfric_e2e::html::check_report(&out.join("index.html"), &out);
    assert_eq!(
        page.images.len(),
        subfric_e2e::html::pngs_under(&out).len(),
        "index.html does not hold every figure once"
    );
    for s in &sets {
        assert!(page.text.contains(s.as_str()), "index.html lacks {s}");
    }
    assert!(page.text.contains("the model describes these data"));

    // Per set: fit.json, one PNG per test, all linked from the README.
    let mut fitted: BTreeMap<String, Value> = BTreeMap::new();
    for s in &sets {
        let meta = read_json(&exp.join(s).join("experiment.json"));
        let tests: Vec<String> = meta["tests"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["name"].as_str().unwrap().to_string())
            .collect();
        let dir = out.join(s);
        let fit = read_json(&dir.join("fit.json"));
        assert_eq!(fit["set"], Value::from(s.as_str()));
        assert_eq!(fit["tests"], serde_json::json!(tests), "{s}");
        let params = &fit["params"];
        assert_eq!(
            params, &fit["model"]["params"],
            "{s}: params and model.params differ"
        );
        for k in BASE_PARAMS {
            let v = params[k].as_f64().unwrap_or_else(|| panic!("{s}: {k}"));
            assert!(v.is_finite() && v >= 0.0, "{s}: {k} = {v}");
        }
        let (mu_s, mu_k) = (
            params["mu_s"].as_f64().unwrap(),
            params["mu_k"].as_f64().unwrap(),
        );
        assert!(mu_k <= mu_s, "{s}: mu_k {mu_k} > mu_s {mu_s}");
        // These curves were computed from the published parameters: μ_s, which every test
        // determines, comes back within 5 %.
        let published = meta["reference_parameters"]["mu_s"].as_f64().unwrap();
        assert!(
            (mu_s - published).abs() / published < 0.05,
            "{s}: mu_s {mu_s} vs published {published}"
        );
        assert!(dir.join("fit.txt").is_file());

        let pngs = pngs_in(&dir);
        assert_eq!(pngs.len(), tests.len(), "{s}: one PNG per test: {pngs:?}");
        for t in &tests {
            let f = dir.join(png_name(t));
            assert!(pngs.contains(&f), "{s}: {} missing", f.display());
            let red = check_png(&f);
            assert!(red > 2000, "{s}/{t}: fitted curve not drawn ({red} pixels)");
            assert_curve_inside_axes(&f);
            assert!(
                readme.contains(&format!("({s}/{})", png_name(t))),
                "README does not show {s}/{t}"
            );
        }
        assert!(readme.contains(&format!("({s}/fit.json)")));
        fitted.insert(s.clone(), fit);
    }
    let medium = &fitted["table1-medium"]["params"]["mu_s"];
    assert!(
        (medium.as_f64().unwrap() - 0.37).abs() / 0.37 < 0.05,
        "{medium}"
    );

    // The CSV tables: one row per parameter, consistent with fit.json, intervals that hold both
    // the fitted and the published value; no interval exactly for fixed parameters.
    let header = "table,set,parameter,unit,value,std_error,lower,upper,lower_open,upper_open,status,published,difference_percent";
    let mut seen = 0;
    for (table, members) in &tables {
        let csv = std::fs::read_to_string(out.join(format!("{table}.csv"))).unwrap();
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some(header));
        let mut rows_per_set: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for line in lines {
            let c: Vec<&str> = line.split(',').collect();
            assert_eq!(c.len(), 13, "{table}.csv: {line}");
            let (set, name) = (c[1], c[2]);
            assert!(members.iter().any(|m| m == set), "{table}.csv: {line}");
            rows_per_set
                .entry(set.to_string())
                .or_default()
                .push(name.to_string());
            let value: f64 = c[4].parse().unwrap();
            let in_fit = fitted[set]["params"][name].as_f64().unwrap();
            assert!(
                (value - in_fit).abs() <= 1e-9 * in_fit.abs().max(1.0),
                "{table}.csv {set} {name}: {value} but fit.json has {in_fit}"
            );
            let published: f64 = c[11]
                .parse()
                .unwrap_or_else(|_| panic!("{table}.csv: no published value: {line}"));
            let fixed = c[10] == "fixed";
            assert_eq!(
                c[6].is_empty() && c[7].is_empty(),
                fixed,
                "{table}.csv: empty interval iff fixed: {line}"
            );
            if fixed {
                continue;
            }
            let (lo, hi): (f64, f64) = (c[6].parse().unwrap(), c[7].parse().unwrap());
            assert!(lo <= value && value <= hi, "{table}.csv: {line}");
            assert!(
                lo <= published && published <= hi,
                "{table}.csv: published {published} outside [{lo}, {hi}]: {line}"
            );
            seen += 1;
        }
        for s in members {
            let mut names = rows_per_set.remove(s).unwrap_or_default();
            names.sort();
            let mut want: Vec<String> = BASE_PARAMS.iter().map(|s| s.to_string()).collect();
            want.sort();
            assert_eq!(names, want, "{table}.csv rows of {s}");
        }
    }
    assert!(seen >= 5 * sets.len(), "{seen} intervals checked");
}

// ---------------------------------------------------------------------------------------------
// simulate
// ---------------------------------------------------------------------------------------------

/// Simulates `set` with its published parameters; returns (input rows, output rows) of its
/// only test after checking the output is a valid set.
fn simulate_published(set: &str, tmp: &Path) -> (Vec<Vec<f64>>, Vec<Vec<f64>>, String) {
    let dir = experiments().join(set);
    let out = tmp.join(format!("sim-{set}"));
    let stdout = run_ok(args![
        "simulate",
        &dir,
        "--params",
        &dir.join("experiment.json"),
        "--out",
        &out
    ]);
    let meta = read_json(&dir.join("experiment.json"));
    let test = &meta["tests"][0];
    let file = test["file"].as_str().unwrap();
    assert!(stdout.contains(file), "{stdout}");
    // The output is a set `check` accepts, of the same shape.
    let summary = run_ok(args!["check", &out]);
    assert!(
        summary.contains(test["name"].as_str().unwrap()),
        "{summary}"
    );
    let meta_out = read_json(&out.join("experiment.json"));
    assert_eq!(meta_out["tests"], meta["tests"]);
    let (h_in, rows_in) = read_data_csv(&dir.join(file));
    let (h_out, rows_out) = read_data_csv(&out.join(file));
    assert_eq!(h_in, h_out);
    assert_eq!(h_in[..3], ["time_s", "slip_mm", "shear_kpa"]);
    assert_eq!(rows_in.len(), rows_out.len());
    (
        rows_in,
        rows_out,
        test["control"].as_str().unwrap().to_string(),
    )
}

#[test]
fn simulate_with_published_parameters_reproduces_a_slip_controlled_curve() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b, control) = simulate_published("table1-medium", tmp.path());
    assert_eq!(control, "slip");
    // Time and the imposed slip are passed through unchanged.
    assert_eq!(column(&a, 0), column(&b, 0));
    assert_eq!(column(&a, 1), column(&b, 1));
    // The shear is the model's: close to the measured one (0.3 % noise) but not a copy of it.
    let rms = relative_rms(&column(&a, 2), &column(&b, 2));
    assert!(rms < 0.005, "relative RMS {rms}");
    assert!(rms > 1e-4, "the measured column was copied (RMS {rms})");
}

#[test]
fn simulate_drives_a_shear_controlled_test_with_the_shear_column() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b, control) = simulate_published("table3-pulsating", tmp.path());
    assert_eq!(control, "shear");
    // Under traction control the shear is imposed and kept; the slip is the model's.
    assert_eq!(column(&a, 0), column(&b, 0));
    assert_eq!(column(&a, 2), column(&b, 2));
    let rms = relative_rms(&column(&a, 1), &column(&b, 1));
    assert!(rms < 0.005, "relative RMS of slip {rms}");
    assert!(rms > 1e-4, "the measured column was copied (RMS {rms})");
}

// ---------------------------------------------------------------------------------------------
// fit and plot
// ---------------------------------------------------------------------------------------------

#[test]
fn fit_with_chosen_free_and_fixed_parameters_then_plot_it() {
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let out = tmp.path().join("fit");
    let stdout = run_ok(args![
        "fit",
        &set,
        "--free",
        "mu_s,u_tilde",
        "--fix",
        "kappa=33,xi=0.027,mu_k=0.3",
        "--no-profiles",
        "--out",
        &out
    ]);
    let fit_json = out.join("fit.json");
    assert!(
        stdout.contains(&format!("wrote {}", fit_json.display())),
        "{stdout}"
    );
    let fit = read_json(&fit_json);
    let p = &fit["params"];
    let mu_s = p["mu_s"].as_f64().unwrap();
    assert!((mu_s - 0.37).abs() < 0.37 * 0.02, "mu_s {mu_s}");
    let u = p["u_tilde"].as_f64().unwrap();
    assert!((u - 3000.0).abs() < 3000.0 * 0.3, "u_tilde {u}");
    // Fixed values are kept exactly.
    assert_eq!(p["kappa"].as_f64(), Some(33.0));
    assert_eq!(p["xi"].as_f64(), Some(0.027));
    assert_eq!(p["mu_k"].as_f64(), Some(0.3));
    assert_eq!(fit["tests"], serde_json::json!(["monotonic"]));
    let status: BTreeMap<String, String> = fit["report"]["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["name"].as_str().unwrap().to_string(),
                r["status"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    for k in ["mu_k", "kappa", "xi", "alpha_t"] {
        assert_eq!(status[k], "fixed", "{k}: {status:?}");
    }
    for k in ["mu_s", "u_tilde"] {
        assert_ne!(status[k], "fixed", "{k}: {status:?}");
    }

    // plot with the fit: the fitted curve is drawn.
    let plots = tmp.path().join("plots");
    let stdout = run_ok(args!["plot", &set, "--params", &fit_json, "--out", &plots]);
    let png = plots.join("monotonic.png");
    assert!(
        stdout.contains(&format!("wrote {}", png.display())),
        "{stdout}"
    );
    assert_eq!(pngs_in(&plots), vec![png.clone()]);
    let red = check_png(&png);
    assert!(red > 2000, "fitted curve not drawn ({red} pixels)");

    // plot without a fit: no fitted-curve colour anywhere (nor in the legend).
    let bare = tmp.path().join("bare");
    run_ok(args!["plot", &set, "--out", &bare]);
    let red = check_png(&bare.join("monotonic.png"));
    assert_eq!(red, 0, "a fitted curve drawn without a fit");
}

// ---------------------------------------------------------------------------------------------
// import
// ---------------------------------------------------------------------------------------------

#[test]
fn import_converts_units_of_a_tab_delimited_lab_file() {
    let tmp = tempfile::tempdir().unwrap();
    let lab = tmp.path().join("export.txt");
    // 0.5 min rows, slip in µm, shear in MPa, a comment line, CRLF line ends.
    let mut t = String::from("# lab export\r\nTime [min]\tSlip [µm]\tShear [MPa]\r\n");
    for i in 0..40 {
        let slip_um = 25.0 * i as f64;
        let shear_mpa = 0.030 * (1.0 - (-(i as f64) / 5.0).exp());
        t.push_str(&format!(
            "{}\t{slip_um}\t{shear_mpa:.6}\r\n",
            0.5 * i as f64
        ));
    }
    std::fs::write(&lab, t).unwrap();
    let out = tmp.path().join("lab-set");
    let stdout = run_ok(args![
        "import",
        &lab,
        "--out",
        &out,
        "--time",
        "Time [min]",
        "--time-unit",
        "min",
        "--slip",
        "Slip [µm]",
        "--slip-unit",
        "um",
        "--shear",
        "Shear [MPa]",
        "--shear-unit",
        "MPa",
        "--normal-stress",
        "50",
        "--test-name",
        "first run",
    ]);
    assert!(stdout.contains("first run"), "{stdout}");
    run_ok(args!["check", &out]);
    let meta = read_json(&out.join("experiment.json"));
    assert_eq!(meta["name"], "lab-set");
    let test = &meta["tests"][0];
    assert_eq!(test["name"], "first run");
    assert_eq!(test["control"], "slip");
    assert_eq!(test["normal_stress_kpa"].as_f64(), Some(50.0));
    let file = out.join(test["file"].as_str().unwrap());
    let (header, rows) = read_data_csv(&file);
    assert_eq!(header, ["time_s", "slip_mm", "shear_kpa"]);
    assert_eq!(rows.len(), 40);
    // Row 3: 1.5 min = 90 s, 75 µm = 0.075 mm, MPa × 1000 = kPa.
    let want_shear = (0.030 * (1.0 - (-3.0f64 / 5.0).exp()) * 1e6).round() / 1e3;
    let r = &rows[3];
    assert!((r[0] - 90.0).abs() < 1e-9, "{r:?}");
    assert!((r[1] - 0.075).abs() < 1e-12, "{r:?}");
    assert!((r[2] - want_shear).abs() < 1e-9, "{r:?} vs {want_shear}");
    let last = rows.last().unwrap();
    assert!((last[0] - 39.0 * 30.0).abs() < 1e-9 && (last[1] - 0.975).abs() < 1e-12);

    // A second test (another record: the same rows twice are refused) joins the same set; a
    // duplicate name is refused and names the set file.
    let lab2 = tmp.path().join("export2.txt");
    let text = std::fs::read_to_string(&lab).unwrap();
    std::fs::write(&lab2, text.replace("\t0.0", "\t0.1")).unwrap();
    let second = |name: &str| {
        args![
            "import",
            &lab2,
            "--out",
            &out,
            "--time",
            "1",
            "--time-unit",
            "min",
            "--slip",
            "2",
            "--slip-unit",
            "um",
            "--shear",
            "3",
            "--shear-unit",
            "MPa",
            "--normal-stress",
            "50",
            "--test-name",
            name,
        ]
        .iter()
        .map(|s| s.to_os_string())
        .collect::<Vec<_>>()
    };
    let a = second("second");
    run_ok(&a.iter().map(|s| s.as_os_str()).collect::<Vec<_>>());
    let meta = read_json(&out.join("experiment.json"));
    assert_eq!(meta["tests"].as_array().unwrap().len(), 2);
    let b = second("second");
    let err = run_err(&b.iter().map(|s| s.as_os_str()).collect::<Vec<_>>());
    assert_mentions(&err, &["experiment.json", "second", "expected"]);
    run_ok(args!["check", &out]);
}

// ---------------------------------------------------------------------------------------------
// help
// ---------------------------------------------------------------------------------------------

/// Every option of a `--help` text that takes a value, with the text describing it.
fn options_with_values(help: &str) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    let mut in_options = false;
    for line in help.lines() {
        if line.starts_with("Options:") || line.starts_with("Arguments:") {
            in_options = line.starts_with("Options:");
            continue;
        }
        if !in_options {
            continue;
        }
        let t = line.trim_start();
        // An option line starts with `-x` or `--x`; a listed possible value with `- `.
        if t.starts_with('-') && !t.starts_with("- ") {
            let head = t.split("  ").next().unwrap_or(t);
            let takes_value = head.contains('<');
            out.push((
                if takes_value {
                    head.to_string()
                } else {
                    String::new()
                },
                t.to_string(),
            ));
        } else if let Some(last) = out.last_mut() {
            last.1.push(' ');
            last.1.push_str(t);
        }
    }
    out.retain(|(h, _)| !h.is_empty());
    out
}

#[test]
fn help_lists_every_subcommand_and_every_option_with_its_default() {
    let help = run_ok(args!["--help"]);
    let commands = [
        "reproduce",
        "simulate",
        "check",
        "import",
        "fit",
        "plot",
        "diagnose",
        "selfcheck",
        "plan",
        "bench",
        "campaign",
    ];
    for c in commands {
        assert!(
            help.lines().any(|l| l.trim_start().starts_with(c)),
            "`subfric --help` does not list {c}:\n{help}"
        );
    }
    let mut checked = 0;
    for c in commands {
        let help = run_ok(args![c, "--help"]);
        assert!(help.contains(&format!("Usage: subfric {c}")), "{help}");
        let usage = help.lines().find(|l| l.starts_with("Usage:")).unwrap();
        for (head, description) in options_with_values(&help) {
            // A required option has no default: it is in the usage line without brackets.
            let flag = head
                .split([' ', ','])
                .find(|w| w.starts_with("--"))
                .unwrap();
            let required =
                usage.contains(&format!(" {flag} ")) && !usage.contains(&format!("[{flag}"));
            assert!(
                required || description.contains("[default:"),
                "`subfric {c} --help`: {head} shows no default:\n{description}"
            );
            checked += 1;
        }
    }
    assert!(checked > 40, "{checked} options checked");
    // The values an option takes are listed.
    let help = run_ok(args!["import", "--help"]);
    assert_mentions(
        &help,
        &["kPa", "MPa", "psi", "semicolon", "whitespace", "min", "um"],
    );
    let help = run_ok(args!["fit", "--help"]);
    assert_mentions(
        &help,
        &[
            "--free",
            "--fix",
            "--bounds",
            "--weight",
            "--no-profiles",
            "--out",
            "--force",
            "lsq",
            "nm",
        ],
    );
    let help = run_ok(args!["selfcheck", "--help"]);
    assert_mentions(&help, &["--per-class", "--seed", "--sets", "--json"]);
    let help = run_ok(args!["bench", "--help"]);
    assert_mentions(&help, &["--json", "--experiments", "--only", "many-tests"]);
    // An unknown subcommand is a usage error (clap's exit code 2), not a panic.
    let o = run(args!["frobnicate"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!text(&o.stderr).contains("panicked"));
}

#[test]
fn check_summarises_a_bundled_set_without_warnings() {
    for s in bundled_sets() {
        let o = run(args!["check", &experiments().join(&s)]);
        assert!(o.status.success(), "{s}: {}", text(&o.stderr));
        assert!(text(&o.stdout).contains(&s), "{s}");
        assert!(
            !text(&o.stderr).contains("warning"),
            "{s}: a bundled set is flagged implausible:\n{}",
            text(&o.stderr)
        );
    }
    let golden = subfric_e2e::golden().join("pair-01");
    let o = run(args!["check", &golden]);
    assert!(
        o.status.success() && text(&o.stderr).is_empty(),
        "{}",
        text(&o.stderr)
    );
}
