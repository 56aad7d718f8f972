//! One self-contained HTML page: the figures embedded as data URIs (SVG where the figure has
//! one, crisp at any zoom; else PNG), the style inline, no
//! script and nothing fetched from the network, readable on a phone and on a desktop (a
//! viewport, images no wider than the page, tables that scroll sideways). The reports of
//! `fit`, `diagnose`, `plan` and `reproduce` are written with it (in the `report` module, above
//! this one).

use anyhow::{anyhow, Result};
use std::fmt::Write as _;
use std::path::Path;

/// The page's style: system fonts, a readable measure, figures and tables that fit a phone.
const STYLE: &str = "\
body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;line-height:1.45;\
margin:0 auto;padding:1rem;max-width:64rem;color:#1a1a1a;background:#fff}\
h1{font-size:1.5rem;margin:0.5rem 0 1rem}h2{font-size:1.2rem;margin-top:2rem;\
border-bottom:1px solid #ddd;padding-bottom:0.2rem}h3{font-size:1.05rem;margin-top:1.5rem}\
img{max-width:100%;height:auto;display:block;margin:0.5rem 0}\
figure{margin:1rem 0}figcaption{font-size:0.9rem;color:#555}\
.scroll{overflow-x:auto;-webkit-overflow-scrolling:touch;margin:0.5rem 0}\
table{border-collapse:collapse;font-size:0.9rem;min-width:100%}\
th,td{border:1px solid #ccc;padding:0.25rem 0.5rem;text-align:left;vertical-align:top;\
white-space:nowrap}th{background:#f3f3f3}td.num{text-align:right;font-variant-numeric:tabular-nums}\
.verdict{border-left:0.4rem solid;padding:0.5rem 0.9rem;margin:1rem 0;background:#f7f7f7}\
.verdict.ok{border-color:#2e7d32}.verdict.rough{border-color:#f9a825}\
.verdict.fails{border-color:#c62828}.verdict p{margin:0.3rem 0}\
pre{white-space:pre;overflow-x:auto;font-size:0.8rem;background:#f7f7f7;padding:0.5rem}\
.legend{font-size:0.9rem;color:#333}code{font-size:0.95em}";

/// How a verdict box is marked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// The model describes the data.
    Ok,
    /// Above the noise.
    Rough,
    /// The model does not describe the data.
    Fails,
}

impl Mark {
    /// The mark of an adequacy level.
    pub fn of(level: crate::outcome::adequacy::Level) -> Mark {
        match level {
            crate::outcome::adequacy::Level::AtNoise => Mark::Ok,
            crate::outcome::adequacy::Level::AboveNoise => Mark::Rough,
            crate::outcome::adequacy::Level::Fails => Mark::Fails,
            crate::outcome::adequacy::Level::CannotJudge => Mark::Rough,
        }
    }

    fn class(self) -> &'static str {
        match self {
            Mark::Ok => "ok",
            Mark::Rough => "rough",
            Mark::Fails => "fails",
        }
    }
}

/// A table cell: text, or a number (aligned right).
pub enum Cell {
    /// Text.
    Text(String),
    /// A number as text, aligned right.
    Num(String),
    /// Links to files beside the page: (label, href relative to the page).
    Links(Vec<(String, String)>),
}

impl From<String> for Cell {
    fn from(s: String) -> Cell {
        Cell::Text(s)
    }
}

impl From<&str> for Cell {
    fn from(s: &str) -> Cell {
        Cell::Text(s.to_string())
    }
}

/// A page being written.
pub struct Page {
    body: String,
    title: String,
}

/// `s` with the characters HTML gives a meaning escaped.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Text with `code spans` (between backticks) as `<code>`, everything escaped.
fn inline(s: &str) -> String {
    let mut out = String::new();
    for (i, part) in s.split('`').enumerate() {
        if i % 2 == 1 {
            let _ = write!(out, "<code>{}</code>", escape(part));
        } else {
            out.push_str(&escape(part));
        }
    }
    out
}

/// Standard base64 with padding (RFC 4648), for data URIs.
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(char::from(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

impl Page {
    /// A page titled `title` (also its first heading).
    pub fn new(title: &str) -> Page {
        Page {
            body: format!("<h1>{}</h1>\n", escape(title)),
            title: title.to_string(),
        }
    }

    /// A section heading, with an anchor `id`.
    pub fn h2(&mut self, id: &str, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<h2 id=\"{}\">{}</h2>", escape(id), inline(text));
        self
    }

    /// A sub-heading.
    pub fn h3(&mut self, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<h3>{}</h3>", inline(text));
        self
    }

    /// A paragraph (`code` between backticks).
    pub fn p(&mut self, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<p>{}</p>", inline(text));
        self
    }

    /// A verdict box: one paragraph per line, marked by `mark`.
    pub fn verdict(&mut self, mark: Mark, lines: &[String]) -> &mut Self {
        let _ = writeln!(self.body, "<div class=\"verdict {}\">", mark.class());
        for l in lines {
            let _ = writeln!(self.body, "<p>{}</p>", inline(l));
        }
        self.body.push_str("</div>\n");
        self
    }

    /// A bulleted list (`code` between backticks), with the class `class` (empty: none).
    pub fn list(&mut self, class: &str, items: &[String]) -> &mut Self {
        if items.is_empty() {
            return self;
        }
        if class.is_empty() {
            self.body.push_str("<ul>\n");
        } else {
            let _ = writeln!(self.body, "<ul class=\"{}\">", escape(class));
        }
        for i in items {
            let _ = writeln!(self.body, "<li>{}</li>", inline(i));
        }
        self.body.push_str("</ul>\n");
        self
    }

    /// A table that scrolls sideways on a narrow screen.
    pub fn table(&mut self, header: &[&str], rows: Vec<Vec<Cell>>) -> &mut Self {
        self.body
            .push_str("<div class=\"scroll\"><table>\n<thead><tr>");
        for h in header {
            let _ = write!(self.body, "<th>{}</th>", escape(h));
        }
        self.body.push_str("</tr></thead>\n<tbody>\n");
        for r in rows {
            self.body.push_str("<tr>");
            for c in r {
                match c {
                    Cell::Text(t) => {
                        let _ = write!(self.body, "<td>{}</td>", inline(&t));
                    }
                    Cell::Num(t) => {
                        let _ = write!(self.body, "<td class=\"num\">{}</td>", escape(&t));
                    }
                    Cell::Links(links) => {
                        let parts: Vec<String> = links
                            .iter()
                            .map(|(label, href)| {
                                format!("<a href=\"{}\">{}</a>", escape(href), escape(label))
                            })
                            .collect();
                        let _ = write!(self.body, "<td>{}</td>", parts.join(" · "));
                    }
                }
            }
            self.body.push_str("</tr>\n");
        }
        self.body.push_str("</tbody>\n</table></div>\n");
        self
    }

    /// Preformatted text (a readable report as the terminal shows it).
    pub fn pre(&mut self, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<pre>{}</pre>", escape(text));
        self
    }

    /// A link to a file beside the page (`href` relative to it).
    pub fn link_line(&mut self, text: &str, links: &[(&str, String)]) -> &mut Self {
        let parts: Vec<String> = links
            .iter()
            .map(|(label, href)| format!("<a href=\"{}\">{}</a>", escape(href), escape(label)))
            .collect();
        let _ = writeln!(self.body, "<p>{}{}</p>", inline(text), parts.join(" · "));
        self
    }

    /// The figure `file` (a PNG), embedded as a data URI with a caption: the SVG beside it
    /// (same name, `.svg`) when there is one, else the PNG.
    pub fn figure(&mut self, file: &Path, caption: &str) -> Result<&mut Self> {
        let svg = file.with_extension("svg");
        let (kind, file) = if svg.is_file() {
            ("svg+xml", svg.as_path())
        } else {
            ("png", file)
        };
        let bytes = std::fs::read(file).map_err(|e| {
            anyhow!(
                "{}: cannot read the figure for the report: {e}",
                file.display()
            )
        })?;
        let _ = writeln!(
            self.body,
            "<figure><img alt=\"{}\" src=\"data:image/{kind};base64,{}\"><figcaption>{}</figcaption></figure>",
            escape(caption),
            base64(&bytes),
            inline(caption)
        );
        Ok(self)
    }

    /// The whole document.
    pub fn finish(&self) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n{}</body>\n</html>\n",
            escape(&self.title),
            self.body
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
        assert_eq!(base64(&[0xff, 0xfe, 0x00]), "//4A");
    }

    #[test]
    fn text_is_escaped_and_code_marked() {
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        assert_eq!(
            inline("run `subfric plan <set>` now"),
            "run <code>subfric plan &lt;set&gt;</code> now"
        );
    }
}
