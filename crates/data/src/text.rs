//! Text as files hold it and as a terminal shows it: lines whatever their ends, names with
//! their control characters made visible, and the longest name a file system takes.

/// Longest set or test name accepted, in bytes: subfric names folders and files after them,
/// and 255 bytes is the longest file name of the common file systems (ext4, APFS, NTFS in
/// UTF-16 units, ...).
pub const MAX_NAME_BYTES: usize = 255;

/// The lines of `text`, whatever ends them: `\n`, `\r\n` or a lone `\r` (old Mac exports, some
/// lab loggers). The line ends are not part of the lines; a final line end gives no empty line
/// after it, but empty lines in between are kept, so that line numbers count as an editor does.
///
/// ```
/// let v: Vec<&str> = subfric_data::text::lines("a\r\nb\rc\n\nd").collect();
/// assert_eq!(v, ["a", "b", "c", "", "d"]);
/// assert_eq!(subfric_data::text::lines("a\r").count(), 1);
/// ```
pub fn lines(text: &str) -> impl Iterator<Item = &str> {
    let mut rest = Some(text);
    std::iter::from_fn(move || {
        let t = rest?;
        match t.find(['\n', '\r']) {
            Some(i) => {
                let end = if t[i..].starts_with("\r\n") {
                    i + 2
                } else {
                    i + 1
                };
                rest = Some(&t[end..]).filter(|r| !r.is_empty());
                Some(&t[..i])
            }
            None => {
                rest = None;
                (!t.is_empty()).then_some(t)
            }
        }
    })
}

/// A name (of a set, a test, a file) as shown on a terminal: control characters as escapes
/// (`\x1b`, `\n`, `\r`, `\t`, `\u{9b}`) and the characters that reorder text (bidirectional
/// overrides) as `\u{202e}`, so that a name cannot recolour the terminal, forge a line or hide
/// its own text. Other characters, accents included, are kept.
///
/// ```
/// use subfric_data::visible;
/// assert_eq!(visible("a\u{1b}[31mb\nc"), "a\\x1b[31mb\\nc");
/// assert_eq!(visible("Toyoura sand, µm"), "Toyoura sand, µm");
/// ```
pub fn visible(name: &str) -> String {
    let reorders = |c: char| matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
    let mut s = String::with_capacity(name.len());
    for c in name.chars() {
        match c {
            '\n' => s.push_str("\\n"),
            '\r' => s.push_str("\\r"),
            '\t' => s.push_str("\\t"),
            c if c.is_ascii_control() => s.push_str(&format!("\\x{:02x}", c as u32)),
            c if c.is_control() || reorders(c) => s.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => s.push(c),
        }
    }
    s
}

/// Why `name` (the value of `field`) is too long, if it is: more than [`MAX_NAME_BYTES`].
/// A number as a message shows it: plain when that is short (`0.3`, `-5`, `200000`), else in
/// scientific notation (`1e308`, not 309 digits; `1e-320`, not 321).
///
/// ```
/// use subfric_data::text::short_number;
/// assert_eq!(short_number(0.3), "0.3");
/// assert_eq!(short_number(-5.0), "-5");
/// assert_eq!(short_number(1e308), "1e308");
/// assert_eq!(short_number(1e-320), "1e-320");
/// assert_eq!(short_number(f64::INFINITY), "inf");
/// ```
pub fn short_number(x: f64) -> String {
    let plain = format!("{x}");
    if plain.len() <= 16 || !x.is_finite() {
        plain
    } else {
        format!("{x:e}")
    }
}

pub(crate) fn name_too_long(name: &str, what: &str) -> Option<String> {
    (name.len() > MAX_NAME_BYTES).then(|| {
        format!(
            "{what} of {} bytes is longer than {MAX_NAME_BYTES} (expected a shorter name: subfric names files and folders after it, and no common file system takes a longer file name)",
            name.len()
        )
    })
}

/// A hash of `s` that is the same on every machine and in every run (64-bit FNV-1a): for short
/// file-name suffixes that tell apart names a file name cannot hold whole.
///
/// ```
/// assert_eq!(subfric_data::text::stable_hash(""), 0xcbf29ce484222325);
/// assert_ne!(subfric_data::text::stable_hash("x y"), subfric_data::text::stable_hash("x_y"));
/// ```
pub fn stable_hash(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Formats a number with about 4 significant digits, without exponent for usual magnitudes.
pub fn num(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if !(1e-4..1e6).contains(&a) {
        return format!("{x:.3e}");
    }
    let decimals = (3 - a.log10().floor() as i32).clamp(0, 8) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}
