//! Positions of the values of a JSON text, by JSON path, so that problems found after parsing
//! can name the line they come from.

use std::collections::HashMap;

/// Maps a JSON path (`""` for the root, `tests[0].control`, ...) to the 1-based line and column
/// where its value starts. Never panics; on malformed input it returns what it found so far.
pub(crate) fn value_positions(text: &str) -> HashMap<String, (usize, usize)> {
    let mut s = Scanner::new(text);
    s.value(String::new(), 0);
    s.out
}

/// Where the value at `field` ends in `text`: the index (in chars) just past its last char.
/// `None` when the text is not JSON or has no such field.
pub(crate) fn value_end(text: &str, field: &str) -> Option<usize> {
    let mut s = Scanner::new(text);
    s.end_of = Some((field.to_string(), None));
    s.value(String::new(), 0);
    s.end_of.and_then(|(_, end)| end)
}

/// The keys given twice in one object, at any depth, with the line and column of the second:
/// a JSON reader keeps one of the two silently (serde_json the last), so which value was meant
/// is not known. Paths as in [`value_positions`]; never panics.
pub(crate) fn duplicate_keys(text: &str) -> Vec<(String, usize, usize)> {
    let mut s = Scanner::new(text);
    s.value(String::new(), 0);
    s.duplicates
}

impl Scanner {
    /// A scanner at the first value of `text` (leading white space skipped).
    fn new(text: &str) -> Scanner {
        let mut s = Scanner {
            chars: text.chars().collect(),
            pos: 0,
            line: 1,
            col: 1,
            out: HashMap::new(),
            duplicates: Vec::new(),
            end_of: None,
        };
        s.skip_ws();
        s
    }
}

struct Scanner {
    chars: Vec<char>,
    pos: usize,
    line: usize,
    col: usize,
    out: HashMap<String, (usize, usize)>,
    duplicates: Vec<(String, usize, usize)>,
    /// A path whose value's end is wanted, and that end once found.
    end_of: Option<(String, Option<usize>)>,
}

const MAX_DEPTH: usize = 200;

impl Scanner {
    fn peek(&self) -> Option<char> {
        self.chars.get(self.pos).copied()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.peek()?;
        self.pos += 1;
        if c == '\n' {
            self.line += 1;
            self.col = 1;
        } else {
            self.col += 1;
        }
        Some(c)
    }

    fn skip_ws(&mut self) {
        while matches!(self.peek(), Some(c) if c.is_whitespace()) {
            self.bump();
        }
    }

    /// Parses one value at the current position; returns false on malformed input.
    fn value(&mut self, path: String, depth: usize) -> bool {
        if depth > MAX_DEPTH {
            return false;
        }
        self.out.insert(path.clone(), (self.line, self.col));
        let ok = self.value_inner(&path, depth);
        if ok {
            if let Some((want, end)) = &mut self.end_of {
                if *want == path {
                    *end = Some(self.pos);
                }
            }
        }
        ok
    }

    fn value_inner(&mut self, path: &str, depth: usize) -> bool {
        match self.peek() {
            Some('{') => {
                self.bump();
                self.skip_ws();
                if self.peek() == Some('}') {
                    self.bump();
                    return true;
                }
                let mut keys = std::collections::HashSet::new();
                loop {
                    self.skip_ws();
                    let at = (self.line, self.col);
                    let Some(key) = self.string() else {
                        return false;
                    };
                    let again = !keys.insert(key.clone());
                    self.skip_ws();
                    if self.bump() != Some(':') {
                        return false;
                    }
                    self.skip_ws();
                    let child = if path.is_empty() {
                        key
                    } else {
                        format!("{path}.{key}")
                    };
                    if again {
                        self.duplicates.push((child.clone(), at.0, at.1));
                    }
                    if !self.value(child, depth + 1) {
                        return false;
                    }
                    self.skip_ws();
                    match self.bump() {
                        Some(',') => continue,
                        Some('}') => return true,
                        _ => return false,
                    }
                }
            }
            Some('[') => {
                self.bump();
                self.skip_ws();
                if self.peek() == Some(']') {
                    self.bump();
                    return true;
                }
                let mut i = 0usize;
                loop {
                    self.skip_ws();
                    if !self.value(format!("{path}[{i}]"), depth + 1) {
                        return false;
                    }
                    i += 1;
                    self.skip_ws();
                    match self.bump() {
                        Some(',') => continue,
                        Some(']') => return true,
                        _ => return false,
                    }
                }
            }
            Some('"') => self.string().is_some(),
            Some(_) => {
                // number, true, false, null
                let mut any = false;
                while matches!(self.peek(), Some(c) if !c.is_whitespace() && !matches!(c, ',' | ']' | '}'))
                {
                    self.bump();
                    any = true;
                }
                any
            }
            None => false,
        }
    }

    fn string(&mut self) -> Option<String> {
        if self.bump() != Some('"') {
            return None;
        }
        let mut s = String::new();
        loop {
            match self.bump()? {
                '"' => return Some(s),
                '\\' => {
                    let c = self.bump()?;
                    match c {
                        'n' => s.push('\n'),
                        't' => s.push('\t'),
                        'r' => s.push('\r'),
                        'b' => s.push('\u{8}'),
                        'f' => s.push('\u{c}'),
                        'u' => {
                            let mut code = 0u32;
                            for _ in 0..4 {
                                code = code * 16 + self.bump()?.to_digit(16)?;
                            }
                            s.push(char::from_u32(code).unwrap_or('\u{fffd}'));
                        }
                        other => s.push(other),
                    }
                }
                c => s.push(c),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_nested_paths() {
        let text = "{\n  \"a\": 1,\n  \"tests\": [\n    {\"name\": \"x\",\n     \"control\": \"slip\"}\n  ]\n}";
        let p = value_positions(text);
        assert_eq!(p["a"], (2, 8));
        assert_eq!(p["tests[0].name"].0, 4);
        assert_eq!(p["tests[0].control"].0, 5);
    }

    #[test]
    fn finds_keys_given_twice_at_any_depth() {
        let text = "{\"a\": {\"b\": 1,\n \"b\": 2}, \"c\": [{\"d\": 0, \"d\": 1}], \"e\": 1, \"f.g\": 1, \"f\": {\"g\": 2}}";
        let d = duplicate_keys(text);
        assert_eq!(
            d,
            vec![("a.b".to_string(), 2, 2), ("c[0].d".to_string(), 2, 26)]
        );
    }

    #[test]
    fn malformed_input_does_not_panic() {
        for t in ["", "{", "{\"a\"", "[1,", "\"\\u12", "{\"a\":[{]}", "}}}"] {
            let _ = value_positions(t);
        }
    }
}
