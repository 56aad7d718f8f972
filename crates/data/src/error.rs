//! Errors and validation problems.

use std::fmt;
use std::path::{Path, PathBuf};

/// One problem found while validating an experiment set, a test file or a lab file.
///
/// Every problem names the file, and where it makes sense the 1-based line and the field
/// (column name or JSON path). The message says what is wrong and what was expected.
///
/// ```
/// use subfric_data::InputProblem;
/// let p = InputProblem::new("set/a.csv", Some(7), Some("time_s"), "`x` is not a number (expected a decimal number)");
/// assert_eq!(p.to_string(), "set/a.csv:7: field `time_s`: `x` is not a number (expected a decimal number)");
/// ```
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct InputProblem {
    /// File the problem is in.
    pub file: PathBuf,
    /// 1-based line number in that file, when the problem is tied to a line.
    pub line: Option<usize>,
    /// Field concerned: a CSV column name or a JSON path such as `tests[0].control`.
    pub field: Option<String>,
    /// What is wrong, followed by what was expected.
    pub message: String,
}

impl InputProblem {
    /// Builds a problem.
    pub fn new(
        file: impl AsRef<Path>,
        line: Option<usize>,
        field: Option<&str>,
        message: impl Into<String>,
    ) -> Self {
        InputProblem {
            file: file.as_ref().to_path_buf(),
            line,
            field: field.map(str::to_string),
            message: message.into(),
        }
    }
}

impl fmt::Display for InputProblem {
    /// One line, whatever the names and cells quoted in it hold (see [`crate::visible`]).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut s = self.file.display().to_string();
        if let Some(line) = self.line {
            s.push_str(&format!(":{line}"));
        }
        s.push_str(": ");
        if let Some(field) = &self.field {
            s.push_str(&format!("field `{field}`: "));
        }
        s.push_str(&self.message);
        f.write_str(&crate::visible(&s))
    }
}

/// Joins problems into one line each.
fn list_problems(problems: &[InputProblem]) -> String {
    let mut s = format!(
        "{} problem{} in the experiment data:",
        problems.len(),
        if problems.len() == 1 { "" } else { "s" }
    );
    for p in problems {
        s.push_str("\n  ");
        s.push_str(&p.to_string());
    }
    s
}

/// Errors of this crate.
#[derive(Debug, thiserror::Error)]
pub enum DataError {
    /// A file or folder could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// `experiment.json` is not valid JSON or does not have the expected shape.
    ///
    /// Shape problems (missing or mistyped fields) are reported as [`DataError::Problems`]
    /// naming the JSON path of each field; this variant is for text that is not JSON at all.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Json {
        /// The JSON file.
        path: PathBuf,
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error.
        column: usize,
        /// What is wrong and what was expected.
        message: String,
    },
    /// Validation found problems (all of them are listed).
    #[error("{}", list_problems(.0))]
    Problems(Vec<InputProblem>),
}

impl DataError {
    /// The problems, if this is [`DataError::Problems`]; empty otherwise.
    pub fn problems(&self) -> &[InputProblem] {
        match self {
            DataError::Problems(p) => p,
            _ => &[],
        }
    }

    pub(crate) fn io(path: impl AsRef<Path>, source: std::io::Error) -> Self {
        DataError::Io {
            path: path.as_ref().to_path_buf(),
            source,
        }
    }
}

/// Collects problems of one file, capping their number so that a file with thousands of bad
/// rows gives a readable report.
#[derive(Debug, Default)]
pub(crate) struct Problems {
    list: Vec<InputProblem>,
    dropped: usize,
    file_of_dropped: Option<PathBuf>,
}

/// At most this many problems are kept per collector; the rest are counted.
pub(crate) const MAX_PROBLEMS: usize = 60;

impl Problems {
    pub(crate) fn push(&mut self, p: InputProblem) {
        if self.list.len() < MAX_PROBLEMS {
            self.list.push(p);
        } else {
            self.dropped += 1;
            if self.file_of_dropped.is_none() {
                self.file_of_dropped = Some(p.file.clone());
            }
        }
    }

    pub(crate) fn add(
        &mut self,
        file: &Path,
        line: Option<usize>,
        field: Option<&str>,
        message: impl Into<String>,
    ) {
        self.push(InputProblem::new(file, line, field, message));
    }

    pub(crate) fn extend(&mut self, ps: Vec<InputProblem>) {
        for p in ps {
            self.push(p);
        }
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.list.is_empty() && self.dropped == 0
    }

    pub(crate) fn into_vec(mut self) -> Vec<InputProblem> {
        if self.dropped > 0 {
            let file = self.file_of_dropped.take().unwrap_or_default();
            self.list.push(InputProblem::new(
                file,
                None,
                None,
                format!(
                    "{} more problem{} not shown (fix the ones above first)",
                    self.dropped,
                    if self.dropped == 1 { "" } else { "s" }
                ),
            ));
        }
        self.list
    }

    pub(crate) fn into_result<T>(self, value: T) -> Result<T, DataError> {
        if self.is_empty() {
            Ok(value)
        } else {
            Err(DataError::Problems(self.into_vec()))
        }
    }
}
