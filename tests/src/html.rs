//! A strict reader of the HTML pages subfric writes (`report.html`, `fits/index.html`): it
//! checks that a page is well formed (every element closed in order, void elements not
//! closed, attributes quoted, entities known, one `html`, `head` and `body`), self-contained
//! (no script, nothing fetched: every image a PNG or SVG data URI, every link a file beside the page
//! or an anchor of the page) and made for small screens (a viewport), and returns what it
//! holds for the tests to compare with the files the job wrote.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Elements that have no end tag.
const VOID: [&str; 8] = ["meta", "img", "br", "hr", "link", "input", "col", "source"];

/// Entities the pages may use.
const ENTITIES: [&str; 5] = ["&amp;", "&lt;", "&gt;", "&quot;", "&#39;"];

/// What a well-formed page holds.
#[derive(Debug, Default)]
pub struct PageContent {
    /// The decoded bytes of every `<img>`'s data URI, in order.
    pub images: Vec<Vec<u8>>,
    /// Every `href`.
    pub links: Vec<String>,
    /// Every `id`.
    pub ids: BTreeSet<String>,
    /// Element names in order of appearance (start tags).
    pub elements: Vec<String>,
    /// The text outside tags (entities not decoded).
    pub text: String,
}

/// Decodes standard base64 (with padding).
pub fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    let value = |c: u8| -> Result<u32, String> {
        Ok(match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return Err(format!("`{}` is not base64", c as char)),
        })
    };
    let bytes = s.as_bytes();
    if !bytes.len().is_multiple_of(4) {
        return Err(format!("base64 of {} characters", bytes.len()));
    }
    let mut out = Vec::with_capacity(bytes.len() / 4 * 3);
    for chunk in bytes.chunks(4) {
        let pad = chunk.iter().rev().take_while(|&&c| c == b'=').count();
        let mut n = 0u32;
        for &c in &chunk[..4 - pad] {
            n = (n << 6) | value(c)?;
        }
        n <<= 6 * pad as u32;
        let b = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&b[..3 - pad]);
    }
    Ok(out)
}

/// Attributes of a start tag's inside (after the name): name="value" pairs.
fn attributes(inside: &str) -> Result<Vec<(String, String)>, String> {
    let mut out = Vec::new();
    let mut rest = inside.trim();
    while !rest.is_empty() {
        let eq = rest
            .find('=')
            .ok_or_else(|| format!("attribute without a value in `{inside}`"))?;
        let name = rest[..eq].trim().to_string();
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-') {
            return Err(format!("bad attribute name `{name}` in `{inside}`"));
        }
        let after = &rest[eq + 1..];
        let after = after
            .strip_prefix('"')
            .ok_or_else(|| format!("attribute `{name}` not double-quoted in `{inside}`"))?;
        let close = after
            .find('"')
            .ok_or_else(|| format!("attribute `{name}` not closed"))?;
        let value = after[..close].to_string();
        check_entities(&value)?;
        out.push((name, value));
        rest = after[close + 1..].trim_start();
    }
    Ok(out)
}

/// Every `&` starts a known entity.
fn check_entities(text: &str) -> Result<(), String> {
    for (i, _) in text.match_indices('&') {
        if !ENTITIES.iter().any(|e| text[i..].starts_with(e)) {
            let near: String = text[i..].chars().take(12).collect();
            return Err(format!("unknown entity or bare `&` at `{near}`"));
        }
    }
    Ok(())
}

/// Reads `html` as a page subfric writes; an error says what is wrong and where.
pub fn check_page(html: &str) -> Result<PageContent, String> {
    let html = html
        .strip_prefix("<!DOCTYPE html>")
        .ok_or("the page does not start with <!DOCTYPE html>")?;
    let mut page = PageContent::default();
    let mut stack: Vec<String> = Vec::new();
    let mut rest = html;
    let mut viewport = false;
    while let Some(open) = rest.find('<') {
        let text = &rest[..open];
        check_entities(text)?;
        if text.contains('>') {
            return Err(format!("a stray `>` in text `{}`", text.trim()));
        }
        page.text.push_str(text);
        let close = rest[open..].find('>').ok_or("a tag is not closed")? + open;
        let tag = &rest[open + 1..close];
        rest = &rest[close + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            let name = name.trim();
            match stack.pop() {
                Some(top) if top == name => {}
                Some(top) => return Err(format!("</{name}> closes <{top}>")),
                None => return Err(format!("</{name}> closes nothing")),
            }
            continue;
        }
        let (name, inside) = match tag.find(char::is_whitespace) {
            Some(i) => (&tag[..i], &tag[i..]),
            None => (tag, ""),
        };
        let name = name.to_ascii_lowercase();
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric()) {
            return Err(format!("bad tag `<{tag}>`"));
        }
        if name == "script" {
            return Err("the page holds a script".into());
        }
        let attrs = attributes(inside.trim_end_matches('/'))?;
        for (k, v) in &attrs {
            match k.as_str() {
                "href" => page.links.push(v.clone()),
                "id" if !page.ids.insert(v.clone()) => {
                    return Err(format!("id `{v}` twice"));
                }
                "src" => {
                    let data = v
                        .strip_prefix("data:image/png;base64,")
                        .or_else(|| v.strip_prefix("data:image/svg+xml;base64,"))
                        .ok_or_else(|| {
                            format!(
                                "an image that is not a PNG or SVG data URI: `{}`",
                                &v[..v.len().min(40)]
                            )
                        })?;
                    page.images.push(base64_decode(data)?);
                }
                _ => {}
            }
            if v.contains("http://") || v.contains("https://") {
                return Err(format!("`{k}` reaches the network: {v}"));
            }
        }
        if name == "meta" && attrs.iter().any(|(k, v)| k == "name" && v == "viewport") {
            viewport = true;
        }
        if name == "img" && !attrs.iter().any(|(k, _)| k == "src") {
            return Err("an image without a source".into());
        }
        page.elements.push(name.clone());
        if name == "style" {
            let end = rest.find("</style>").ok_or("<style> not closed")?;
            if rest[..end].contains("url(") || rest[..end].contains("@import") {
                return Err("the style fetches something".into());
            }
            rest = &rest[end + "</style>".len()..];
            continue;
        }
        if !VOID.contains(&name.as_str()) {
            stack.push(name);
        }
    }
    if !rest.trim().is_empty() {
        return Err(format!("text after the page: `{}`", rest.trim()));
    }
    if !stack.is_empty() {
        return Err(format!("elements not closed: {stack:?}"));
    }
    for once in ["html", "head", "body", "title"] {
        let n = page.elements.iter().filter(|e| *e == once).count();
        if n != 1 {
            return Err(format!("{n} <{once}> elements (expected one)"));
        }
    }
    if !viewport {
        return Err("no viewport meta tag (a phone would show the page zoomed out)".into());
    }
    Ok(page)
}

/// Every PNG file under `dir`, recursively, sorted.
pub fn pngs_under(dir: &Path) -> Vec<PathBuf> {
    fn walk(d: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "png") {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, &mut out);
    out.sort();
    out
}

/// Checks the page `page` (a file in its output folder) and that it embeds every figure the job
/// wrote under `figures_root` (a PNG's SVG where it has one beside it) and nothing else, and that every link leads to a file beside it
/// or an anchor of it. Returns the page's content.
pub fn check_report(page: &Path, figures_root: &Path) -> PageContent {
    let html = std::fs::read_to_string(page).unwrap_or_else(|e| panic!("{}: {e}", page.display()));
    let content = check_page(&html).unwrap_or_else(|e| panic!("{}: {e}", page.display()));
    // A table without rows says nothing a sentence would not: reports say it in words.
    assert!(
        !html.contains("<tbody>\n</tbody>"),
        "{}: an empty table",
        page.display()
    );
    let written: Vec<(PathBuf, Vec<u8>)> = pngs_under(figures_root)
        .into_iter()
        .map(|p| {
            let svg = p.with_extension("svg");
            let shown = if svg.is_file() { svg } else { p };
            let b = std::fs::read(&shown).unwrap();
            (shown, b)
        })
        .collect();
    for (p, bytes) in &written {
        assert!(
            content.images.iter().any(|i| i == bytes),
            "{}: the figure {} is not in the page",
            page.display(),
            p.display()
        );
    }
    for i in &content.images {
        assert!(
            i.starts_with(b"\x89PNG\r\n\x1a\n") || i.starts_with(b"<svg "),
            "{}: an embedded image is neither a PNG nor an SVG",
            page.display()
        );
        assert!(
            written.iter().any(|(_, b)| b == i),
            "{}: an embedded image is none of the figures written",
            page.display()
        );
    }
    let dir = page.parent().unwrap();
    for l in &content.links {
        match l.strip_prefix('#') {
            Some(id) => assert!(
                content.ids.contains(id),
                "{}: no anchor #{id}",
                page.display()
            ),
            None => assert!(
                dir.join(l).exists(),
                "{}: the link {l} leads nowhere",
                page.display()
            ),
        }
    }
    content
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><meta name=\"viewport\" content=\"width=device-width\"><title>t</title><style>p{x:1}</style></head><body><p id=\"a\">x &amp; y</p><a href=\"#a\">a</a><img alt=\"\" src=\"data:image/png;base64,iVBORw0KGgo=\"></body></html>\n";

    #[test]
    fn a_good_page_reads() {
        let p = check_page(GOOD).unwrap();
        assert_eq!(p.images, vec![b"\x89PNG\r\n\x1a\n".to_vec()]);
        assert_eq!(p.links, vec!["#a".to_string()]);
    }

    #[test]
    fn broken_pages_are_refused() {
        let broken = [
            GOOD.replace("</p>", ""),
            GOOD.replace("&amp;", "&"),
            GOOD.replace(
                "<meta name=\"viewport\" content=\"width=device-width\">",
                "",
            ),
            GOOD.replace("data:image/png;base64,iVBORw0KGgo=", "https://x/y.png"),
            GOOD.replace("<body>", "<body><script>1</script>"),
            GOOD.replace("id=\"a\"", "id=a"),
            GOOD.replace("<title>t</title>", ""),
        ];
        for b in broken {
            assert!(check_page(&b).is_err(), "accepted:\n{b}");
        }
    }
}
