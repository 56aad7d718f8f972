//! Printing that never panics and never stops the work. `println!` panics when stdout cannot be
//! written (a reader that went away: `subfric fit s | head -1`; a full device: `> /dev/full`),
//! and `eprintln!` likewise for stderr. The results are files, written before anything is
//! printed about them; so a write error on the terminal's streams is remembered, never raised:
//!
//! - stdout: the first error is kept and later lines are dropped; [`stdout_problem`] tells
//!   `main` about it once the command is done (a closed pipe ends quietly, with the command's
//!   own exit code; any other error is one line on stderr and exit code 1);
//! - stderr: errors are ignored (there is nowhere left to report them).
//!
//! Every line is shown with its control characters made visible ([`visible`]): a set or test
//! name holding an escape sequence or a newline cannot recolour the terminal or forge a line.

use std::fmt::Display;
use std::io::{self, Write};
use std::sync::Mutex;

/// The first error writing stdout, if any.
static STDOUT_ERROR: Mutex<Option<io::Error>> = Mutex::new(None);

/// Prints a line (or several) on stdout; see the module documentation for errors.
pub fn out(text: impl Display) {
    let Ok(mut failed) = STDOUT_ERROR.lock() else {
        return;
    };
    if failed.is_some() {
        return;
    }
    let text = visible_lines(&text.to_string());
    let mut stdout = io::stdout().lock();
    if let Err(e) = writeln!(stdout, "{text}").and_then(|()| stdout.flush()) {
        *failed = Some(e);
    }
}

/// Prints a line (or several) on stderr, ignoring errors.
pub fn err(text: impl Display) {
    let text = visible_lines(&text.to_string());
    let mut stderr = io::stderr().lock();
    let _ = writeln!(stderr, "{text}").and_then(|()| stderr.flush());
}

/// The error that stopped stdout, if one did.
pub fn stdout_problem() -> Option<io::Error> {
    STDOUT_ERROR.lock().ok().and_then(|mut e| e.take())
}

/// `text` with its control characters shown as escapes (`\x1b`, `\r`, `\u{9b}`), line breaks
/// and tabs kept: the text of a report is many lines, but a name never is.
pub fn visible_lines(text: &str) -> String {
    text.split('\n')
        .map(|line| {
            line.split('\t')
                .map(subfric_app::visible)
                .collect::<Vec<_>>()
                .join("\t")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_shown_and_line_breaks_kept() {
        assert_eq!(visible_lines("plain\ttext\n"), "plain\ttext\n");
        assert_eq!(
            visible_lines("a\u{1b}[31mred\rb\nc\u{9b}"),
            "a\\x1b[31mred\\rb\nc\\u{9b}"
        );
    }
}
