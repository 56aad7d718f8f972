//! Overlay figures of a set: measured curve, published curve, fitted curve, residual below
//! (`subfric plot`, and per set in `subfric reproduce`); and the figures of a diagnosis.

use crate::folders::io::load_model;
use crate::folders::output::{default_results_dir, holds_results_of, Destination, ResultsDir};
use crate::progress::Progress;
use anyhow::Result;
use std::path::{Path, PathBuf};
use subfric_data::load_set;
use subfric_model::{Control, Model};
use subfric_plot::{write_figure, Figure, Panel, Series, Style};
use subfric_reading::stats::upper_median;
use subfric_reading::{prepare_set, FitTest, PreparedTest};

/// Figures drawn.
pub struct Plotted {
    /// The PNG files written.
    pub files: Vec<PathBuf>,
    /// Curves that could not be drawn, and why (also given to the progress as warnings).
    pub notes: Vec<String>,
}

/// `subfric plot`: one figure per test of the set in `set_dir`, with the published curve
/// (when the set has reference parameters) and the curve of the model in `params` (a
/// params.json or fit.json; by default the set's `fits/<set name>/fit.json` when it exists
/// and is of this set folder, said as a note), into `fits/<set name>/plots` unless given. A
/// curve that cannot be drawn is reported, not dropped silently.
pub fn plot(
    set_dir: &Path,
    params: Option<&Path>,
    to: &Destination,
    progress: &dyn Progress,
) -> Result<Plotted> {
    let set = load_set(set_dir)?;
    let params = match params {
        Some(p) => Some(p.to_path_buf()),
        None => {
            let fit = default_results_dir(&set.meta.name).join("fit.json");
            let ours =
                fit.is_file() && holds_results_of(fit.parent().unwrap_or(Path::new(".")), set_dir);
            if ours {
                progress.note(&format!(
                    "drawing the fit in {} (give --params to draw another model)",
                    fit.display()
                ));
            }
            ours.then_some(fit)
        }
    };
    let fitted = params.as_deref().map(load_model).transpose()?;
    let prepared = prepare_set(&set, false);
    let published = crate::sets::published(&set)?;
    let dir = to
        .dir
        .clone()
        .unwrap_or_else(|| default_results_dir(&set.meta.name).join("plots"));
    let files = figure_files(&prepared);
    let claim = ResultsDir::claim(&dir, &[set_dir.to_path_buf()], &files, to.force)?;
    let (files, notes) = plot_set(
        &set.meta.name,
        &prepared,
        published.as_ref(),
        fitted.as_ref(),
        claim.path(),
    )?;
    for n in &notes {
        progress.warning(n);
    }
    claim.commit()?;
    Ok(Plotted { files, notes })
}

/// The figure files `plot_set` writes for `tests`, relative to its output folder: a PNG and
/// an SVG per test.
pub fn figure_files(tests: &[PreparedTest]) -> Vec<String> {
    stems_of(tests)
        .into_iter()
        .flat_map(|stem| [format!("{stem}.png"), format!("{stem}.svg")])
        .collect()
}

/// The figure stems of `tests` ([`figure_stems`]).
fn stems_of(tests: &[PreparedTest]) -> Vec<String> {
    let names: Vec<&str> = tests.iter().map(|p| p.fit.name.as_str()).collect();
    figure_stems(&names)
}

/// Renders one figure per test under `out` (which must exist), as PNG and SVG; returns the
/// PNG files written (each with its SVG beside it) and a note for every curve that could not be drawn (a model that runs away on a test).
pub fn plot_set(
    set_name: &str,
    tests: &[PreparedTest],
    published: Option<&Model>,
    fitted: Option<&Model>,
    out: &Path,
) -> Result<(Vec<PathBuf>, Vec<String>)> {
    let mut files = Vec::new();
    let mut notes = Vec::new();
    for (p, stem) in tests.iter().zip(stems_of(tests)) {
        let t = &p.full;
        let slip_control = t.control == Control::Slip;
        let (x, x_label) = test_axis(p);
        let (y_label, res_label) = if slip_control {
            ("friction τ/σ_n [-]", "fit − measured [-]")
        } else {
            ("slip u [mm]", "fit − measured [mm]")
        };
        let to_y = |i: usize, v: f64| if slip_control { v / t.normal[i] } else { v };
        let measured: Vec<f64> = t
            .measured
            .iter()
            .enumerate()
            .map(|(i, v)| to_y(i, *v))
            .collect();
        // One colour for the data: the cycles of a cyclic test overlap, and colours that
        // cannot be told apart there would promise what the figure does not show.
        let mut main = vec![Series::new(
            "measured",
            x.clone(),
            measured.clone(),
            Style::Measured,
        )];
        let mut residual = Vec::new();
        for (model, label, style) in [
            (published, "published parameters", Style::Published),
            (fitted, "fitted", Style::Fitted),
        ] {
            let Some(model) = model else { continue };
            let pred = match t.predict(model) {
                Ok(p) => p,
                Err(e) => {
                    notes.push(format!(
                        "{set_name}: test `{}`: the {label} curve is not drawn: {e} (row numbers count data rows from 0)",
                        t.name
                    ));
                    // The legend says so too ("(no data)" marks a series without points).
                    main.push(Series::new(
                        format!("{label}: model runs away"),
                        vec![f64::NAN],
                        vec![f64::NAN],
                        style,
                    ));
                    continue;
                }
            };
            let y: Vec<f64> = pred.iter().enumerate().map(|(i, v)| to_y(i, *v)).collect();
            residual.push(Series::new(
                label,
                x.clone(),
                y.iter().zip(&measured).map(|(a, b)| a - b).collect(),
                style,
            ));
            main.push(Series::new(label, x.clone(), y, style));
        }
        let title = format!("{set_name}: {} ({} kPa)", t.name, mean(&t.normal).round());
        let mut fig = Figure::new(title, x_label, Panel::new(y_label, main));
        if !slip_control {
            // Traction control: what the rig imposed, beside the slip it measured.
            fig = fig.with_history(Panel::new(
                "imposed τ [kPa]",
                vec![Series::new(
                    "imposed traction",
                    t.time.clone(),
                    t.imposed.clone(),
                    Style::Other(0),
                )],
            ));
        }
        if let Some(end) = first_loading_window(p, &measured) {
            fig = fig.with_inset("zoom: first loading (peak and decay)", x[0], end);
        }
        if !residual.is_empty() {
            fig = fig.with_residual(Panel::new(res_label, residual).with_zero_line());
        }
        let file = out.join(format!("{stem}.png"));
        write_figure(&fig, &file)?;
        files.push(file);
    }
    Ok((files, notes))
}

/// Rows of the running median that tames the noise before the transient is looked for.
const SMOOTHING_ROWS: usize = 5;

/// Share of the largest departure from the final level below which the friction has settled.
const SETTLED_SHARE: f64 = 0.05;

/// The slip up to which a zoom shows the first loading of a monotonic test (slip control, no
/// reversal, no hold): twice the slip at which the friction last departs from its final level
/// by more than [`SETTLED_SHARE`] of its largest departure — the rise, the peak and the decay
/// that decide ũ and κ — or, when that decay is long, [`PEAK_SLIPS_SHOWN`] times the slip to
/// the peak; `None` for other tests, or when even that is much of the slip.
fn first_loading_window(p: &PreparedTest, friction: &[f64]) -> Option<f64> {
    let t = &p.full;
    let seg = &p.segmentation;
    if t.control != Control::Slip || !seg.reversals.is_empty() || !seg.holds.is_empty() {
        return None;
    }
    let n = friction.len();
    if n < 20 {
        return None;
    }
    let smooth: Vec<f64> = (0..n)
        .map(|i| {
            let a = i.saturating_sub(SMOOTHING_ROWS / 2);
            let mut w: Vec<f64> = friction[a..(a + SMOOTHING_ROWS).min(n)].to_vec();
            upper_median(&mut w).unwrap_or(f64::NAN)
        })
        .collect();
    let level = upper_median(&mut smooth[n - n / 3..].to_vec())?;
    let departure: Vec<f64> = smooth.iter().map(|v| (v - level).abs()).collect();
    let largest = departure.iter().copied().fold(0.0, f64::max);
    let last = departure
        .iter()
        .rposition(|&d| d > SETTLED_SHARE * largest)?;
    let peak = (0..n).max_by(|&a, &b| smooth[a].total_cmp(&smooth[b]))?;
    let (u0, u1) = (t.imposed[0], t.imposed[n - 1]);
    let zoom = |end: f64| (end > u0 && end - u0 < MAX_ZOOM_SHARE * (u1 - u0)).then_some(end);
    // The whole transient when it is short; else the rise and the peak with the start of
    // the decay.
    zoom(u0 + 2.0 * (t.imposed[last] - u0))
        .or_else(|| zoom(u0 + PEAK_SLIPS_SHOWN * (t.imposed[peak] - u0)))
}

/// A zoom shows at most this share of the slip (beyond, the main panel shows it as well).
const MAX_ZOOM_SHARE: f64 = 0.35;

/// When the decay is long, the zoom shows this many times the slip to the peak.
const PEAK_SLIPS_SHOWN: f64 = 4.0;

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Longest test name used as a figure's file name as it is.
const MAX_PLAIN_STEM: usize = 64;

/// Characters of a name kept in front of the hash of a figure's file name.
const HASHED_SLUG: usize = 48;

/// The file-name stems of the figures of tests named `names` (one set's tests, in order):
/// different for different names, also where case is ignored (macOS, Windows), and never a
/// stem followed by `-event-NN` (the zooms of [`diagnosis_figures`]) of another.
///
/// A name of at most 64 of `[A-Za-z0-9_-]` that no other name matches but for case, and that
/// does not end like a zoom (`-event-3`), is its own stem. Any other name is shown readably,
/// its other characters as `_` and cut at 48, followed by `.` and a hash of the whole name
/// (8 hexadecimal digits, 16 if two would meet): `x y` → `x_y.` and its hash, while `x_y`
/// stays `x_y`; `é` → `_.` and its hash, while `_` stays `_`.
///
/// ```
/// use subfric_app::render::figures::figure_stems;
/// let s = figure_stems(&["monotonic", "x y", "x_y", "a/b", "a_b", "é", "_"]);
/// assert_eq!(&s[..1], ["monotonic"]);
/// assert_eq!(s[2], "x_y");
/// assert!(s[1].starts_with("x_y."));
/// let mut unique = s.clone();
/// unique.sort();
/// unique.dedup();
/// assert_eq!(unique.len(), s.len());
/// ```
pub fn figure_stems(names: &[&str]) -> Vec<String> {
    let slug = |n: &str| -> String {
        n.chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect()
    };
    let looks_like_zoom = |n: &str| {
        n.rsplit_once("-event-")
            .is_some_and(|(_, k)| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
    };
    let candidate =
        |n: &str| !n.is_empty() && n.len() <= MAX_PLAIN_STEM && slug(n) == n && !looks_like_zoom(n);
    // Hashed stems hold a `.`, plain ones never: only plain ones can meet.
    let plain = |i: usize, n: &str| {
        candidate(n)
            && !names
                .iter()
                .enumerate()
                .any(|(j, m)| j != i && candidate(m) && m.eq_ignore_ascii_case(n))
    };
    for hex_digits in [8, 16] {
        let stems: Vec<String> = names
            .iter()
            .enumerate()
            .map(|(i, n)| {
                if plain(i, n) {
                    return n.to_string();
                }
                let mut s = slug(n);
                if let Some((cut, _)) = s.char_indices().nth(HASHED_SLUG) {
                    s.truncate(cut);
                }
                let h = subfric_data::text::stable_hash(n);
                let h = format!("{h:016x}");
                format!("{s}.{}", &h[..hex_digits])
            })
            .collect();
        let mut folded: Vec<String> = stems.iter().map(|s| s.to_lowercase()).collect();
        folded.sort();
        folded.dedup();
        if folded.len() == stems.len() {
            return stems;
        }
    }
    // Two names with the same 64-bit hash and slug: numbered, in order.
    names
        .iter()
        .enumerate()
        .map(|(i, n)| {
            format!(
                "{}.{}",
                slug(n).chars().take(HASHED_SLUG).collect::<String>(),
                i + 1
            )
        })
        .collect()
}

/// The x axis a whole test is drawn against, the same in every report (the fit's, the
/// diagnosis's): time under traction control, and where a slip-controlled test holds (a hold
/// has no slip, and against slip it would be a vertical line); slip otherwise, as the paper
/// draws its curves (a cyclic test's loops, a velocity step's transient over its slip).
fn test_axis(p: &PreparedTest) -> (Vec<f64>, &'static str) {
    let t = &p.full;
    let holds = p.segmentation.holds.iter().any(|&(s, _)| s > 1);
    if t.control == Control::Slip && !holds {
        (t.imposed.clone(), "slip u [mm]")
    } else {
        (t.time.clone(), "time t [s]")
    }
}

/// The figures of a diagnosis: per test the measured curve, the base model and the model with
/// the named effects (against the test's axis, [`test_axis`]), and one zoom
/// per velocity step and per hold, against slip from the event, so that a specialist can read
/// the transients; then the figures `more` (drawn by the caller, written into `out` too).
pub fn diagnosis_figures(
    set_name: &str,
    tests: &[PreparedTest],
    base: &Model,
    with_effects: Option<(&Model, &str)>,
    more: Vec<(Figure, PathBuf)>,
    out: &Path,
) -> Result<Vec<PathBuf>> {
    use rayon::prelude::*;
    claim_folder(out)?;
    // Each test's curves are simulated on all its rows, two models per test: in parallel, one
    // test per core (a long record spends a second on them serially).
    let curves: Vec<Option<FrictionCurves>> = tests
        .par_iter()
        .map(|p| {
            (p.full.control == Control::Slip)
                .then(|| FrictionCurves::of(&p.full, base, with_effects))
        })
        .collect();
    // The figures are drawn first and rendered in parallel (a long record has dozens).
    let mut jobs: Vec<(Figure, PathBuf)> = Vec::new();
    for ((p, stem), curves) in tests.iter().zip(stems_of(tests)).zip(curves) {
        let t = &p.full;
        let Some(curves) = curves else {
            continue;
        };
        let all = 0..t.len();
        let (x, x_label) = test_axis(p);
        let fig = Figure::new(
            format!("{set_name}: {} ({} kPa)", t.name, mean(&t.normal).round()),
            x_label,
            Panel::new("friction τ/σ_n [-]", curves.series(&x, all)),
        );
        jobs.push((fig, out.join(format!("{stem}.png"))));
        let events = events_of(p);
        for (k, (row, what)) in events.iter().enumerate() {
            let Some((a, b)) = event_window(t, &events, k) else {
                continue;
            };
            let (xs, xlabel) = if what.starts_with("hold") {
                // A hold has no slip: against time from its start.
                (
                    t.time.iter().map(|v| v - t.time[*row]).collect::<Vec<_>>(),
                    "time from the start of the hold [s]",
                )
            } else {
                let u0 = t.imposed[*row];
                (
                    t.imposed.iter().map(|u| 1e3 * (u - u0)).collect(),
                    "slip from the step [µm]",
                )
            };
            let fig = Figure::new(
                format!("{}: {} at t = {:.0} s", t.name, what, t.time[*row]),
                xlabel,
                Panel::new("friction τ/σ_n [-]", curves.series(&xs, a..b)),
            );
            jobs.push((fig, out.join(format!("{stem}-event-{:02}.png", k + 1))));
        }
    }
    jobs.extend(more);
    jobs.par_iter()
        .map(|(fig, file)| Ok(write_figure(fig, file).map(|_| file.clone())?))
        .collect()
}

/// Creates `out` and removes its PNG and SVG files: the folder is claimed with the results, and
/// figures of an earlier diagnosis (other events, other tests) would be read as this one's.
fn claim_folder(out: &Path) -> Result<()> {
    std::fs::create_dir_all(out)?;
    crate::folders::io::remove_earlier_files(out, "svg")?;
    crate::folders::io::remove_earlier_files(out, "png")
}

/// The friction of one test: measured, of the base model and of the model with the effects.
struct FrictionCurves {
    measured: Vec<f64>,
    base: Option<Vec<f64>>,
    effects: Option<Vec<f64>>,
    /// Name of the effects, for the legend.
    label: String,
}

impl FrictionCurves {
    fn of(t: &FitTest, base: &Model, with_effects: Option<(&Model, &str)>) -> Self {
        let friction =
            |v: &[f64]| -> Vec<f64> { v.iter().zip(&t.normal).map(|(a, n)| a / n).collect() };
        let (base, effects) = rayon::join(
            || t.predict(base).ok().map(|v| friction(&v)),
            || with_effects.and_then(|(m, _)| t.predict(m).ok().map(|v| friction(&v))),
        );
        FrictionCurves {
            measured: friction(&t.measured),
            base,
            effects,
            label: with_effects.map_or("", |(_, l)| l).to_string(),
        }
    }

    /// The curves over rows `range`, against `x`.
    fn series(&self, x: &[f64], range: std::ops::Range<usize>) -> Vec<Series> {
        let mut v = vec![Series::new(
            "measured",
            x[range.clone()].to_vec(),
            self.measured[range.clone()].to_vec(),
            Style::Measured,
        )];
        if let Some(b) = &self.base {
            v.push(Series::new(
                "base model",
                x[range.clone()].to_vec(),
                b[range.clone()].to_vec(),
                Style::Published,
            ));
        }
        if let Some(e) = &self.effects {
            v.push(Series::new(
                format!("with {}", self.label),
                x[range.clone()].to_vec(),
                e[range.clone()].to_vec(),
                Style::Fitted,
            ));
        }
        v
    }
}

/// The velocity steps and holds (except a rest at the start) of a test: (row, what), in
/// order.
fn events_of(p: &PreparedTest) -> Vec<(usize, String)> {
    let t = &p.full;
    let seg = &p.segmentation;
    let mut events: Vec<(usize, String)> = seg
        .rate_changes
        .iter()
        .zip(seg.step_rates())
        .map(|(&c, (a, b))| {
            (
                c,
                format!("velocity step {} → {} µm/s", rate_text(a), rate_text(b)),
            )
        })
        .collect();
    for &(s, e) in &seg.holds {
        if s > 1 {
            let d = t.time[(e - 1).min(t.len() - 1)] - t.time[s - 1];
            events.push((s - 1, format!("hold of {d:.0} s")));
        }
    }
    events.sort_by_key(|e| e.0);
    events
}

/// Slip shown before an event [mm]: a stretch of the level it leaves.
const SLIP_BEFORE_EVENT_MM: f64 = 0.1;

/// Slip shown after an event [mm]: the transient and the start of the level it settles to.
const SLIP_AFTER_EVENT_MM: f64 = 0.3;

/// Rows a..b of the figure of event `k`: from [`SLIP_BEFORE_EVENT_MM`] of slip before it to
/// [`SLIP_AFTER_EVENT_MM`] after (or the next event); `None` when fewer than two rows follow.
fn event_window(t: &FitTest, events: &[(usize, String)], k: usize) -> Option<(usize, usize)> {
    let row = events[k].0;
    let u0 = t.imposed[row];
    let next = events.get(k + 1).map_or(t.len(), |e| e.0 + 1);
    let mut a = row;
    while a > 0 && (u0 - t.imposed[a - 1]).abs() <= SLIP_BEFORE_EVENT_MM {
        a -= 1;
    }
    let mut b = row + 1;
    while b < next.min(t.len()) && (t.imposed[b] - u0).abs() <= SLIP_AFTER_EVENT_MM {
        b += 1;
    }
    (b > row + 2).then_some((a, b))
}

/// A rate in µm/s with three significant digits.
fn rate_text(mm_per_s: f64) -> String {
    let v = 1e3 * mm_per_s.abs();
    let decimals = (2 - v.log10().floor() as i32).clamp(0, 6) as usize;
    format!("{v:.decimals$}")
}
