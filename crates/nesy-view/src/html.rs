//! Building HTML pages that stand alone: every piece of text is escaped on the way in, pictures
//! travel inside the page as `data:` URIs, and the page carries no script and fetches nothing
//! from the network (its content security policy says so to the browser).

use std::fmt::Write as _;

use base64::Engine as _;

/// A piece of HTML that is safe to place in a page: built from escaped text or from this
/// module's helpers, never from raw input.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Html(String);

impl Html {
    /// Text, escaped (`<`, `>`, `&`, `"` and `'`), so that a model's reply or a file name
    /// cannot add markup.
    pub fn text(text: &str) -> Html {
        Html(escape(text))
    }

    /// Nothing.
    pub fn empty() -> Html {
        Html(String::new())
    }

    /// A fixed fragment of markup written in nesy's own source (a tag name, a separator).
    /// The argument is `'static` so that no runtime text can arrive this way.
    pub fn markup(markup: &'static str) -> Html {
        Html(markup.to_owned())
    }

    /// `inner` inside `<tag class="class">…</tag>` (no class attribute when `class` is empty).
    pub fn tag(tag: &'static str, class: &str, inner: Html) -> Html {
        if class.is_empty() {
            Html(format!("<{tag}>{}</{tag}>", inner.0))
        } else {
            Html(format!("<{tag} class=\"{}\">{}</{tag}>", escape(class), inner.0))
        }
    }

    /// The fragments one after another.
    pub fn concat(parts: impl IntoIterator<Item = Html>) -> Html {
        Html(parts.into_iter().map(|p| p.0).collect())
    }

    /// A link to `href` (a relative path in the run directory, or an anchor) showing `text`.
    pub fn link(href: &str, text: &str) -> Html {
        Html(format!("<a href=\"{}\">{}</a>", escape_href(href), escape(text)))
    }

    /// Preformatted text (code, action blocks), escaped.
    pub fn pre(text: &str) -> Html {
        Html(format!("<pre>{}</pre>", escape(text)))
    }

    /// A picture embedded in the page: `bytes` as a `data:` URI of type `mime`
    /// (`image/png`, `image/jpeg`), with `alt` as its description and `title` shown on hover.
    pub fn image(bytes: &[u8], mime: &str, alt: &str) -> Html {
        let data = base64::engine::general_purpose::STANDARD.encode(bytes);
        Html(format!(
            "<img src=\"data:{};base64,{data}\" alt=\"{}\" title=\"{}\">",
            escape(mime),
            escape(alt),
            escape(alt)
        ))
    }

    /// A picture file next to the page (a relative path), shown with `alt`.
    pub fn image_file(href: &str, alt: &str) -> Html {
        Html(format!(
            "<img src=\"{}\" alt=\"{}\" title=\"{}\">",
            escape_href(href),
            escape(alt),
            escape(alt)
        ))
    }

    /// A video file next to the page, with the browser's own controls.
    pub fn video_file(href: &str, label: &str) -> Html {
        Html(format!(
            "<video src=\"{}\" controls preload=\"metadata\" title=\"{}\"></video>",
            escape_href(href),
            escape(label)
        ))
    }

    /// A collapsible block: `summary` always shown, `inner` on demand (open at first when
    /// `open`).
    pub fn details(summary: &str, inner: Html, open: bool) -> Html {
        Html(format!(
            "<details{}><summary>{}</summary>{}</details>",
            if open { " open" } else { "" },
            escape(summary),
            inner.0
        ))
    }

    /// A table: `header` as its column names, then one row per entry of `rows`.
    pub fn table(header: &[&str], rows: impl IntoIterator<Item = Vec<Html>>) -> Html {
        let mut out = String::from("<table><thead><tr>");
        for name in header {
            let _ = write!(out, "<th>{}</th>", escape(name));
        }
        out.push_str("</tr></thead><tbody>");
        for row in rows {
            out.push_str("<tr>");
            for cell in row {
                let _ = write!(out, "<td>{}</td>", cell.0);
            }
            out.push_str("</tr>");
        }
        out.push_str("</tbody></table>");
        Html(out)
    }

    /// A table of two columns without a header: a name and its value on each row.
    pub fn key_values(rows: impl IntoIterator<Item = (String, Html)>) -> Html {
        let mut out = String::from("<table><tbody>");
        for (key, value) in rows {
            let _ = write!(out, "<tr><th>{}</th><td>{}</td></tr>", escape(&key), value.0);
        }
        out.push_str("</tbody></table>");
        Html(out)
    }

    /// A bulleted list.
    pub fn list(items: impl IntoIterator<Item = Html>) -> Html {
        let mut out = String::from("<ul>");
        for item in items {
            let _ = write!(out, "<li>{}</li>", item.0);
        }
        out.push_str("</ul>");
        Html(out)
    }

    /// The markup.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// Whether there is no markup at all.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// A page: a title, sections in order, and the style sheet inside it.
#[derive(Debug, Clone)]
pub struct Page {
    title: String,
    body: String,
}

impl Page {
    /// An empty page titled `title` (shown as its first heading too).
    pub fn new(title: &str) -> Page {
        Page {
            title: title.to_owned(),
            body: String::new(),
        }
    }

    /// A section: a second-level heading with the anchor `id` (so a report can link to it),
    /// then `content`.
    pub fn section(&mut self, id: &str, heading: &str, content: Html) -> &mut Page {
        let _ = write!(
            self.body,
            "<section id=\"{}\"><h2>{}</h2>{}</section>",
            escape(id),
            escape(heading),
            content.0
        );
        self
    }

    /// Markup placed directly under the title.
    pub fn push(&mut self, content: Html) -> &mut Page {
        self.body.push_str(&content.0);
        self
    }

    /// The whole document.
    pub fn finish(&self) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
             <meta http-equiv=\"Content-Security-Policy\" content=\"{CSP}\">\
             <title>{title}</title><style>{STYLE}</style></head>\n<body><h1>{title}</h1>{body}</body></html>\n",
            title = escape(&self.title),
            body = self.body
        )
    }
}

/// What a report may load: its own embedded pictures and style, and files beside it; no
/// script at all, nothing from the network.
const CSP: &str = "default-src 'none'; img-src data: 'self'; media-src 'self'; style-src 'unsafe-inline'";

/// The style sheet every page embeds.
const STYLE: &str = "body{font:14px/1.45 system-ui,sans-serif;margin:1.5em auto;max-width:1200px;padding:0 1em;color:#1d1d1f}\
h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ddd;padding-bottom:.2em;margin-top:1.6em}\
h3{font-size:1.05em}\
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ccc;padding:.25em .5em;text-align:left;vertical-align:top}\
th{background:#f3f3f3}pre{background:#f6f6f6;padding:.6em;overflow-x:auto;font-size:12px;margin:.3em 0}\
img{max-width:100%;border:1px solid #ccc}video{max-width:100%;width:384px}\
.frames img{width:192px;margin-right:4px}.card .frames img{width:124px}.thumb img{width:160px}\
.ok{color:#176f2c;font-weight:600}.bad{color:#b3261e;font-weight:600}.muted{color:#666}\
.violation{background:#fde7e7}.patched{background:#e5f4e8}\
.grid{display:flex;flex-wrap:wrap;gap:10px}.card{border:1px solid #ccc;padding:.4em;width:262px}.card h3{margin:.1em 0 .3em}.card p{margin:.3em 0}\
.columns{display:grid;grid-template-columns:1fr 1fr;gap:12px}\
details{margin:.3em 0}summary{cursor:pointer}";

/// `text` with the five characters that HTML reads as markup replaced by entities.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// A relative link, percent-encoded where a path character is not URL-safe, and kept
/// relative: a scheme (`javascript:`) or a protocol-relative `//host` would leave the page,
/// so such a target becomes `#`.
fn escape_href(href: &str) -> String {
    let leaves = href.starts_with("//")
        || href
            .split(['/', '?', '#'])
            .next()
            .is_some_and(|first| first.contains(':'));
    if leaves {
        return "#".to_owned();
    }
    let mut out = String::with_capacity(href.len());
    for byte in href.bytes() {
        match byte {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' | b'/' | b'#' => {
                out.push(byte as char)
            }
            _ => {
                let _ = write!(out, "%{byte:02X}");
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_from_a_model_cannot_add_markup() {
        let reply = "<script>alert('x')</script> & \"quoted\"";
        let html = Html::tag("p", "", Html::text(reply));
        assert_eq!(
            html.as_str(),
            "<p>&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &quot;quoted&quot;</p>"
        );
        let page = Page::new("<b>run</b>").finish();
        assert!(page.contains("<title>&lt;b&gt;run&lt;/b&gt;</title>"), "{page}");
    }

    #[test]
    fn links_stay_relative_and_encoded() {
        assert_eq!(
            Html::link("units/a b/policy.py", "x").as_str(),
            "<a href=\"units/a%20b/policy.py\">x</a>"
        );
        assert_eq!(
            Html::link("javascript:alert(1)", "x").as_str(),
            "<a href=\"#\">x</a>"
        );
        assert_eq!(Html::link("//example.com/x", "x").as_str(), "<a href=\"#\">x</a>");
        assert_eq!(Html::link("#gallery", "x").as_str(), "<a href=\"#gallery\">x</a>");
    }

    #[test]
    fn pictures_travel_inside_the_page() {
        let img = Html::image(&[0x89, b'P', b'N', b'G'], "image/png", "top view");
        assert_eq!(
            img.as_str(),
            "<img src=\"data:image/png;base64,iVBORw==\" alt=\"top view\" title=\"top view\">"
        );
    }

    #[test]
    fn a_page_loads_nothing_from_the_network_and_runs_no_script() {
        let mut page = Page::new("t");
        page.section(
            "a",
            "A",
            Html::table(&["k", "v"], [vec![Html::text("1"), Html::text("2")]]),
        );
        let doc = page.finish();
        assert!(doc.contains("default-src 'none'"));
        assert!(!doc.contains("<script"));
        assert!(doc.contains("<section id=\"a\"><h2>A</h2><table>"), "{doc}");
    }
}
