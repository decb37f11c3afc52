//! A small Markdown report: headings, paragraphs, tables and figures, written as
//! `report.md` and as `index.html` (the same Markdown rendered by pulldown-cmark, with SVG
//! figures found beside the report inlined so the page stands alone). The SVG figures
//! come from [`plot`]; [`fit`] adds the plots and table of fit results.
//!
//! ```no_run
//! # use hil_sim::report::Report;
//! let mut r = Report::new("Fit of ranran_50");
//! r.heading("Held-out error")
//!     .paragraph("Time-ordered split, last 15 % held out.")
//!     .table(&["model", "RMSE (N)"], &[vec!["spencer".to_owned(), "196.5".to_owned()]])
//!     .image("loop.svg", "Force against displacement");
//! r.write("target/report").unwrap();
//! ```

pub mod diagnose;
pub mod fit;
pub mod fit_page;
pub mod plot;
pub mod runs;
pub mod scores;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use pulldown_cmark::{html, CowStr, Event, Options, Parser, Tag, TagEnd};
use thiserror::Error;

use crate::io::output;

/// Why a report was not written.
#[derive(Debug, Error)]
pub enum ReportError {
    #[error("writing {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error(transparent)]
    Output(#[from] crate::io::output::OutputError),
}

/// A report under construction; see the module docs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    title: String,
    md: String,
}

impl Report {
    pub fn new(title: impl Into<String>) -> Self {
        let title = title.into();
        let md = format!("# {}\n\n", one_line(&title));
        Self { title, md }
    }

    pub fn title(&self) -> &str {
        &self.title
    }

    /// A section heading (`##`).
    pub fn heading(&mut self, text: &str) -> &mut Self {
        self.heading_level(2, text)
    }

    /// A heading of level 1–6 (clamped).
    pub fn heading_level(&mut self, level: usize, text: &str) -> &mut Self {
        let hashes = "#".repeat(level.clamp(1, 6));
        let _ = write!(self.md, "{hashes} {}\n\n", one_line(text));
        self
    }

    /// A paragraph of Markdown text (inline markup such as `*em*` or `` `code` `` is kept).
    pub fn paragraph(&mut self, text: &str) -> &mut Self {
        let text = text.trim();
        if !text.is_empty() {
            let _ = write!(self.md, "{text}\n\n");
        }
        self
    }

    /// A table; each row is padded or cut to the number of headers. `|` and line breaks in
    /// cells are escaped.
    pub fn table<H: AsRef<str>, C: AsRef<str>, R: AsRef<[C]>>(&mut self, headers: &[H], rows: &[R]) -> &mut Self {
        if headers.is_empty() {
            return self;
        }
        let line = |cells: &mut dyn Iterator<Item = String>| {
            let mut s = String::from("|");
            for c in cells {
                let _ = write!(s, " {c} |");
            }
            s.push('\n');
            s
        };
        self.md.push_str(&line(&mut headers.iter().map(|h| cell(h.as_ref()))));
        self.md.push_str(&line(&mut headers.iter().map(|_| "---".to_owned())));
        for r in rows {
            let r = r.as_ref();
            let mut cells = (0..headers.len()).map(|i| r.get(i).map(|c| cell(c.as_ref())).unwrap_or_default());
            self.md.push_str(&line(&mut cells));
        }
        self.md.push('\n');
        self
    }

    /// A figure: `rel_path` relative to the report's folder, with a caption under it.
    pub fn image(&mut self, rel_path: &str, caption: &str) -> &mut Self {
        let alt = one_line(caption).replace(['[', ']'], "");
        let dest = rel_path.replace(' ', "%20");
        let _ = write!(self.md, "![{alt}]({dest})\n\n*{}*\n\n", one_line(caption));
        self
    }

    /// The Markdown text as written to `report.md`: raw HTML in it (a file name such as
    /// `<img onerror=…>.csv` inside a title, cell or caption) is escaped so that a Markdown
    /// viewer shows it as text, and a link to anything but the web or a relative path is
    /// shown as its text, as the HTML page does ([`Report::html`]).
    pub fn markdown(&self) -> String {
        inert(&self.md)
    }

    /// A standalone HTML page for the report in `dir`: SVG images that exist under `dir`
    /// are inlined, other images are linked.
    pub fn html(&self, dir: &Path) -> String {
        let mut opts = Options::empty();
        opts.insert(Options::ENABLE_TABLES);
        let mut events = Vec::new();
        let mut skip_image = false;
        let mut skipped_links = 0usize;
        for ev in Parser::new_ext(&self.md, opts) {
            match ev {
                Event::Start(Tag::Image { ref dest_url, .. }) => match inline_svg(dir, dest_url) {
                    Some(svg) => {
                        events.push(Event::Html(CowStr::from(format!("<span class=\"figure\">{svg}</span>"))));
                        skip_image = true;
                    }
                    None => events.push(ev),
                },
                Event::End(TagEnd::Image) if skip_image => skip_image = false,
                _ if skip_image => {}
                // Text is never markup: raw HTML in a title, cell or caption (a file name such
                // as `<img onerror=…>.csv`) is shown as text, and links only go to the web.
                Event::Html(s) | Event::InlineHtml(s) => events.push(Event::Text(s)),
                Event::Start(Tag::Link { ref dest_url, .. }) if !safe_link(dest_url) => skipped_links += 1,
                Event::End(TagEnd::Link) if skipped_links > 0 => skipped_links -= 1,
                _ => events.push(ev),
            }
        }
        name_headings(&mut events);
        let mut body = String::new();
        html::push_html(&mut body, events.into_iter());
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n<style>\n{CSS}</style>\n</head>\n<body>\n{body}</body>\n</html>\n",
            escape_html(&self.title)
        )
    }

    /// Write `report.md` and `index.html` into `dir` (created if missing); returns the
    /// path of `index.html`.
    pub fn write(&self, dir: impl AsRef<Path>) -> Result<PathBuf, ReportError> {
        let dir = dir.as_ref();
        output::create_dir(dir)?;
        output::write(&dir.join("report.md"), self.markdown())?;
        let index = dir.join("index.html");
        output::write(&index, self.html(dir))?;
        Ok(index)
    }
}

/// The page's style: fits a 1400 px window without sideways scrolling; a table wider than
/// the page scrolls inside itself rather than pushing the page wider.
const CSS: &str = "body { font-family: sans-serif; max-width: 1280px; margin: 1.5em auto; padding: 0 1em; color: #222; line-height: 1.4; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.88em; display: block; max-width: 100%; overflow-x: auto; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; text-align: left; vertical-align: top; }
th { background: #f3f3f3; vertical-align: bottom; }
td { font-variant-numeric: tabular-nums; }
img, .figure svg { max-width: 100%; height: auto; display: block; }
.figure svg { max-width: 1000px; }
code { background: #f3f3f3; padding: 0 0.2em; }
td code { white-space: nowrap; }
pre { overflow-x: auto; white-space: pre-wrap; }
p { overflow-wrap: anywhere; }
";

/// Give every heading an `id` made of its words (`## Closed loop` → `closed-loop`), so a
/// section can be linked to and screenshotted; repeated names get `-2`, `-3`, ….
fn name_headings(events: &mut [Event<'_>]) {
    let mut seen = std::collections::HashMap::<String, usize>::new();
    for i in 0..events.len() {
        if !matches!(events[i], Event::Start(Tag::Heading { .. })) {
            continue;
        }
        let mut words = String::new();
        for ev in &events[i + 1..] {
            match ev {
                Event::End(TagEnd::Heading(_)) => break,
                Event::Text(t) | Event::Code(t) => words.push_str(t),
                _ => {}
            }
        }
        let mut slug = String::new();
        for c in words.chars().flat_map(char::to_lowercase) {
            if c.is_alphanumeric() {
                slug.push(c);
            } else if !slug.is_empty() && !slug.ends_with('-') {
                slug.push('-');
            }
        }
        let slug = slug.trim_end_matches('-').to_owned();
        let n = seen.entry(slug.clone()).or_insert(0);
        *n += 1;
        let id = if *n == 1 { slug } else { format!("{slug}-{n}") };
        if let Event::Start(Tag::Heading { id: slot, .. }) = &mut events[i] {
            *slot = Some(CowStr::from(id));
        }
    }
}

/// The SVG at `dir/rel` without any XML prolog, if `rel` is a relative `.svg` path that
/// stays inside `dir` and can be read.
fn inline_svg(dir: &Path, rel: &str) -> Option<String> {
    let rel = rel.replace("%20", " ");
    let p = Path::new(&rel);
    let inside = p.is_relative() && p.components().all(|c| matches!(c, std::path::Component::Normal(_)));
    if !inside || p.extension().is_none_or(|e| !e.eq_ignore_ascii_case("svg")) {
        return None;
    }
    let text = std::fs::read_to_string(dir.join(p)).ok()?;
    let start = text.find("<svg")?;
    Some(text[start..].trim_end().to_owned())
}

/// How a report names a file: its name only, never the folders of the user's machine.
pub fn file_label(path: &Path) -> String {
    path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
}

/// A message about `path` as a report shows it: the file's folders left out.
pub fn relabel(msg: &str, path: &Path) -> String {
    let full = path.display().to_string();
    if full.is_empty() {
        return msg.to_owned();
    }
    msg.replace(&full, &file_label(path))
}

/// A link the page may carry: to the web or relative (no `javascript:`, `data:`, …).
/// `md` with every raw HTML span or block escaped (`<` as `&lt;`, which Markdown shows as
/// the character) and the brackets of every unsafe link escaped (the link becomes its text):
/// the places are those the CommonMark parser itself finds, so intended markup (emphasis,
/// code, tables, images) is untouched.
fn inert(md: &str) -> String {
    let mut opts = Options::empty();
    opts.insert(Options::ENABLE_TABLES);
    // (byte offset, what replaces the one byte there)
    let mut edits: Vec<(usize, &str)> = Vec::new();
    for (ev, range) in Parser::new_ext(md, opts).into_offset_iter() {
        match ev {
            Event::Html(_) | Event::InlineHtml(_) => {
                edits.extend(md[range.clone()].match_indices('<').map(|(i, _)| (range.start + i, "&lt;")));
            }
            Event::Start(Tag::Link { ref dest_url, .. })
                if !safe_link(dest_url) && md[range.clone()].starts_with('[') =>
            {
                edits.push((range.start, "\\["));
            }
            _ => {}
        }
    }
    edits.sort_unstable_by_key(|e| e.0);
    edits.dedup_by_key(|e| e.0);
    let mut out = String::with_capacity(md.len() + 4 * edits.len());
    let mut at = 0;
    for (i, with) in edits {
        out.push_str(&md[at..i]);
        out.push_str(with);
        at = i + 1;
    }
    out.push_str(&md[at..]);
    out
}

fn safe_link(dest: &str) -> bool {
    let d = dest.trim_start().to_ascii_lowercase();
    d.starts_with("https://") || d.starts_with("http://") || !d.contains(':')
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn cell(s: &str) -> String {
    one_line(s).replace('|', "\\|")
}

fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("hil-sim-report-{}-{name}", std::process::id()))
    }

    fn sample() -> Report {
        let mut r = Report::new("Fit <report>");
        r.heading("Held-out error")
            .paragraph("Last 15 % of the *recording* held out.")
            .table(&["model", "RMSE (N)", "note"], &[vec!["spencer", "196.5", "a|b"], vec!["algebraic", "250.1"]])
            .image("loop.svg", "Force against displacement")
            .image("missing.png", "Not there");
        r
    }

    #[test]
    fn markdown_has_every_block() {
        let md = sample().markdown().to_owned();
        assert!(md.starts_with("# Fit &lt;report>\n\n## Held-out error\n\n"), "{md}");
        assert!(md.contains("| model | RMSE (N) | note |\n| --- | --- | --- |\n| spencer | 196.5 | a\\|b |\n"));
        assert!(md.contains("| algebraic | 250.1 |  |\n"));
        assert!(md.contains("![Force against displacement](loop.svg)\n\n*Force against displacement*"));
    }

    /// A recording's name is text in `report.md` as in `index.html`: no raw HTML and no
    /// unsafe link survives for a Markdown viewer to render.
    #[test]
    fn markdown_carries_no_raw_html_or_unsafe_link() {
        let name = "<img src=x onerror=alert(1)>.csv";
        let mut r = Report::new(format!("Fit of {name}"));
        r.paragraph(&format!("Fitted on {name}; see [the docs](javascript:alert(2)) and *this*."))
            .paragraph("<div onclick=\"x()\">block</div>")
            .table(&["run"], &[vec![name.to_owned()]])
            .image("loop.svg", name);
        let md = r.markdown();
        let mut opts = Options::empty();
        opts.insert(Options::ENABLE_TABLES);
        for ev in Parser::new_ext(&md, opts) {
            assert!(!matches!(ev, Event::Html(_) | Event::InlineHtml(_)), "{ev:?} in {md}");
            if let Event::Start(Tag::Link { dest_url, .. }) = &ev {
                assert!(safe_link(dest_url), "{dest_url} in {md}");
            }
        }
        // What is shown is still the name, and the intended markup is kept.
        let mut html = String::new();
        html::push_html(&mut html, Parser::new_ext(&md, opts));
        assert!(html.contains("Fit of &lt;img src=x onerror=alert(1)&gt;.csv"), "{html}");
        assert!(html.contains("<em>this</em>") && html.contains("<table>"), "{html}");
    }

    #[test]
    fn writes_md_and_html_with_inlined_svg() {
        let dir = tmp("out");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("loop.svg"), "<svg width=\"10\" height=\"10\"><text>LOOPMARK</text></svg>\n").unwrap();
        let index = sample().write(&dir).unwrap();
        assert_eq!(index, dir.join("index.html"));
        let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
        assert_eq!(md, sample().markdown());
        let html = std::fs::read_to_string(&index).unwrap();
        assert!(html.starts_with("<!DOCTYPE html>"));
        assert!(html.contains("<title>Fit &lt;report&gt;</title>"));
        assert!(html.contains("<h2 id=\"held-out-error\">Held-out error</h2>"), "{html}");
        assert!(html.contains("<table>") && html.contains("<th>RMSE (N)</th>") && html.contains("<td>a|b</td>"));
        assert!(html.contains("<em>recording</em>"));
        assert!(html.contains("LOOPMARK"), "SVG not inlined");
        assert!(!html.contains("src=\"loop.svg\""));
        assert!(html.contains("<img src=\"missing.png\" alt=\"Not there\""));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn svg_outside_the_folder_is_linked_not_read() {
        let mut r = Report::new("t");
        r.image("../secret.svg", "up").image("/etc/x.svg", "abs");
        let html = r.html(Path::new("/nonexistent"));
        assert!(html.contains("<img src=\"../secret.svg\""));
        assert!(html.contains("<img src=\"/etc/x.svg\""));
    }

    #[test]
    fn raw_html_and_script_links_are_text() {
        let mut r = Report::new("<script>x</script>");
        r.paragraph("a <img src=x onerror=\"y\"> b [go](javascript:alert(1)) [ok](https://example.org)")
            .table(&["<b>h</b>"], &[vec!["<svg onload=z>"]]);
        let html = r.html(Path::new("/nonexistent"));
        assert!(!html.contains("<script>") && !html.contains("<img") && !html.contains("<b>"));
        assert!(!html.contains("<svg") && !html.contains("javascript:"));
        assert!(html.contains("&lt;img src=x") && html.contains("<a href=\"https://example.org\">ok</a>"));
    }

    #[test]
    fn empty_table_and_blank_paragraph_are_skipped() {
        let mut r = Report::new("t");
        let none: [&str; 0] = [];
        let rows: [Vec<&str>; 0] = [];
        r.table(&none, &rows).paragraph("   ");
        assert_eq!(r.markdown(), "# t\n\n");
        assert_eq!(r.title(), "t");
    }
}
