//! Self-contained HTML reports: inline SVG figures, tables and text, no external resources.
use std::fmt::Write as _;

/// Escapes text for HTML element content and attribute values.
pub fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            _ => o.push(c),
        }
    }
    o
}

/// The colour of a [`HtmlReport::banner`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Banner {
    Ok,
    Bad,
    Synthetic,
    Info,
}

impl Banner {
    fn class(self) -> &'static str {
        match self {
            Banner::Ok => "ok",
            Banner::Bad => "bad",
            Banner::Synthetic => "synthetic",
            Banner::Info => "info",
        }
    }
}

/// A report built section by section.
#[derive(Debug, Clone)]
pub struct HtmlReport {
    title: String,
    body: String,
    /// (id, text) of every h2, for the table of contents.
    sections: Vec<(String, String)>,
}

/// Where [`HtmlReport::contents`] puts the table of contents (filled in by `finish`, once every
/// section is known).
const TOC_MARK: &str = "<!--toc-->";

/// An HTML id from a heading: lowercase letters and digits, the rest as single dashes.
pub fn slug(text: &str) -> String {
    let mut s = String::new();
    for c in text.chars() {
        if c.is_ascii_alphanumeric() {
            s.push(c.to_ascii_lowercase());
        } else if !s.ends_with('-') && !s.is_empty() {
            s.push('-');
        }
    }
    s.trim_end_matches('-').to_string()
}

impl HtmlReport {
    pub fn new(title: &str) -> Self {
        Self {
            title: title.into(),
            body: String::new(),
            sections: Vec::new(),
        }
    }

    /// A heading; an h2 gets an id (unique in the report) and an entry in the contents.
    pub fn heading(&mut self, level: u8, text: &str) -> &mut Self {
        let l = level.clamp(1, 6);
        if l == 2 {
            let base = slug(text);
            let mut id = base.clone();
            let mut k = 1;
            while self.sections.iter().any(|s| s.0 == id) {
                k += 1;
                id = format!("{base}-{k}");
            }
            let _ = writeln!(self.body, "<h2 id=\"{id}\">{}</h2>", escape(text));
            self.sections.push((id, text.to_string()));
        } else {
            let _ = writeln!(self.body, "<h{l}>{}</h{l}>", escape(text));
        }
        self
    }

    /// The table of contents goes here: links to every h2 of the report, before and after
    /// this call.
    pub fn contents(&mut self) -> &mut Self {
        self.body.push_str(TOC_MARK);
        self.body.push('\n');
        self
    }

    fn toc(&self) -> String {
        let mut o = String::from("<nav class=\"toc\"><p class=\"toc-title\">Contents</p><ol>");
        for (id, text) in &self.sections {
            let _ = write!(o, "<li><a href=\"#{id}\">{}</a></li>", escape(text));
        }
        o.push_str("</ol></nav>");
        o
    }

    pub fn paragraph(&mut self, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<p>{}</p>", escape(text));
        self
    }

    /// A highlighted notice (e.g. "synthetic data", "not converged").
    pub fn notice(&mut self, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<p class=\"notice\">{}</p>", escape(text));
        self
    }

    /// A full-width banner: `kind` sets the colour (green "ok", red "bad", amber "synthetic",
    /// grey "info").
    pub fn banner(&mut self, kind: Banner, text: &str) -> &mut Self {
        let _ = writeln!(
            self.body,
            "<div class=\"banner {}\">{}</div>",
            kind.class(),
            escape(text)
        );
        self
    }

    /// The boxed answer at the top of a report: a headline and supporting lines.
    pub fn verdict(&mut self, headline: &str, lines: &[String]) -> &mut Self {
        let _ = write!(
            self.body,
            "<div class=\"verdict\"><p class=\"headline\">{}</p>",
            escape(headline)
        );
        if !lines.is_empty() {
            self.body.push_str("<ul>");
            for l in lines {
                let _ = write!(self.body, "<li>{}</li>", escape(l));
            }
            self.body.push_str("</ul>");
        }
        self.body.push_str("</div>\n");
        self
    }

    pub fn list(&mut self, items: &[String]) -> &mut Self {
        self.body.push_str("<ul>\n");
        for i in items {
            let _ = writeln!(self.body, "<li>{}</li>", escape(i));
        }
        self.body.push_str("</ul>\n");
        self
    }

    /// Inlines an SVG document produced by [`crate::report::plot`] (trusted, not escaped).
    pub fn svg(&mut self, caption: &str, svg: &str) -> &mut Self {
        let start = svg.find("<svg").unwrap_or(0);
        let _ = writeln!(
            self.body,
            "<figure>{}<figcaption>{}</figcaption></figure>",
            &svg[start..],
            escape(caption)
        );
        self
    }

    pub fn table(&mut self, header: &[&str], rows: &[Vec<String>]) -> &mut Self {
        self.marked_table(header, rows, |_, _| false)
    }

    /// A table whose cells `(row, column)` for which `marked` holds are highlighted.
    pub fn marked_table(
        &mut self,
        header: &[&str],
        rows: &[Vec<String>],
        marked: impl Fn(usize, usize) -> bool,
    ) -> &mut Self {
        // A wide table scrolls in its own box, not the page.
        self.body
            .push_str("<div style=\"overflow-x:auto\"><table>\n<tr>");
        for h in header {
            let _ = write!(self.body, "<th>{}</th>", escape(h));
        }
        self.body.push_str("</tr>\n");
        for (i, r) in rows.iter().enumerate() {
            self.body.push_str("<tr>");
            for (j, c) in r.iter().enumerate() {
                let class = if marked(i, j) { " class=\"mark\"" } else { "" };
                let _ = write!(self.body, "<td{class}>{}</td>", escape(c));
            }
            self.body.push_str("</tr>\n");
        }
        self.body.push_str("</table></div>\n");
        self
    }

    /// Preformatted text (commands, JSON excerpts).
    pub fn pre(&mut self, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<pre>{}</pre>", escape(text));
        self
    }

    pub fn finish(&self) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{t}</title>\n<style>\
body{{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}}\
table{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #bbb;padding:3px 8px;text-align:right}}td.mark{{background:#ffe08a;font-weight:bold}}\
th{{background:#eee}}figure{{margin:1em 0}}figcaption{{font-size:90%;color:#555}}\
.notice{{background:#fff3cd;border:1px solid #e0c060;padding:6px 10px}}pre{{background:#f6f6f6;padding:8px}}\
.banner{{padding:8px 12px;margin:6px 0;font-weight:bold;border-radius:4px}}\
.banner.ok{{background:#dff0d8;border:1px solid #3c763d;color:#2b542c}}\
.banner.bad{{background:#c9302c;border:1px solid #8b1f1c;color:#fff;font-size:120%}}\
.banner.synthetic{{background:#f0ad4e;border:1px solid #b06d0f;color:#222;font-size:120%}}\
.banner.info{{background:#eef;border:1px solid #99b;color:#223}}\
.verdict{{border:2px solid #333;border-radius:6px;padding:6px 14px;margin:10px 0 18px;background:#fafafa}}\
.verdict .headline{{font-size:130%;font-weight:bold;margin:6px 0}}\
.toc{{border:1px solid #ccc;background:#f8f8f8;padding:4px 14px;margin:10px 0 18px}}\
.toc-title{{font-weight:bold;margin:4px 0}}.toc ol{{columns:2;margin:4px 0}}\
figure svg{{max-width:100%;height:auto}}\
</style></head><body>\n<h1>{t}</h1>\n{b}</body></html>\n",
            t = escape(&self.title),
            b = self.body.replacen(TOC_MARK, &self.toc(), 1)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_text_and_inlines_svg() {
        let mut r = HtmlReport::new("a<b");
        r.paragraph("x & y")
            .notice("SYNTHETIC data")
            .table(
                &["model", "rms_N"],
                &[vec!["<linear>".into(), "1.5".into()]],
            )
            .svg("fig", "<?xml version=\"1.0\"?><svg width=\"1\"></svg>");
        let h = r.finish();
        assert!(h.contains("<title>a&lt;b</title>"));
        assert!(h.contains("x &amp; y"));
        assert!(h.contains("&lt;linear&gt;"));
        assert!(h.contains("<figure><svg width=\"1\"></svg>"));
        assert!(!h.contains("<?xml"));
        assert!(!h.contains("http"), "self-contained");
    }

    #[test]
    fn contents_link_every_section_with_unique_ids() {
        let mut r = HtmlReport::new("t");
        r.heading(2, "Intro").contents();
        r.heading(2, "Loops (Fig. 16)")
            .heading(2, "Loops (Fig. 16)");
        let h = r.finish();
        for id in ["intro", "loops-fig-16", "loops-fig-16-2"] {
            assert!(h.contains(&format!("<h2 id=\"{id}\">")), "{id}");
            assert!(h.contains(&format!("<a href=\"#{id}\">")), "{id}");
        }
        assert!(!h.contains(TOC_MARK));
    }
}
