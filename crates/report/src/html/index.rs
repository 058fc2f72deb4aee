//! The batch page, `index.html`: one row per sample (verdict, η, σ′s and σa per channel, a link to
//! its page), sortable by any column with a few lines of inline JavaScript (no network; without
//! JavaScript the table is still there, in the command's order), and the samples that failed with
//! their message.

use std::fmt::Write as _;

use scatterfit_io::result_json::MeasurementResult;

use super::markup::{badge, head_with, href, name, text};
use super::view::ResultView;

/// One measured sample on the index.
#[derive(Debug, Clone)]
pub struct IndexEntry<'a> {
    /// Its result.
    pub result: &'a MeasurementResult,
    /// Its folder as the reader knows it (shown).
    pub folder: String,
    /// Its page relative to the index (`pink/report.html`), `None` when it has none.
    pub page: Option<String>,
    /// Further links relative to the index: (label, path), e.g. ("Figure 6", "pink/compare.svg").
    pub links: Vec<(String, String)>,
}

/// A batch's index page.
#[derive(Debug, Clone, Default)]
pub struct IndexPage<'a> {
    /// The page title, e.g. `scatterfit batch`.
    pub title: String,
    /// A paragraph under the title (plain text; escaped).
    pub intro: String,
    /// The measured samples, in the command's order.
    pub samples: Vec<IndexEntry<'a>>,
    /// The samples that failed: (folder, message).
    pub failures: Vec<(String, String)>,
    /// The summary files beside the index, relative names (linked).
    pub files: Vec<String>,
}

/// Sorts the tables with class `sortable` by the clicked column (or Enter/Space on it): numbers by
/// their `data-sort` value, text otherwise; a second click reverses. Marks the page
/// `data-ready="1"` when it has run (the browser test checks it).
pub(crate) const SORT_JS: &str = r#"
(function () {
  "use strict";
  function key(td) {
    var v = td.getAttribute("data-sort");
    if (v !== null && v !== "" && !isNaN(Number(v))) { return Number(v); }
    return td.textContent.trim().toLowerCase();
  }
  function sortBy(table, i, th) {
    var asc = th.getAttribute("aria-sort") !== "ascending";
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (c) { c.removeAttribute("aria-sort"); });
    th.setAttribute("aria-sort", asc ? "ascending" : "descending");
    var body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    rows.sort(function (a, b) {
      var x = key(a.cells[i]), y = key(b.cells[i]);
      var d = (typeof x === "number" && typeof y === "number") ? x - y : String(x).localeCompare(String(y));
      return asc ? d : -d;
    });
    rows.forEach(function (r) { body.appendChild(r); });
  }
  Array.prototype.forEach.call(document.querySelectorAll("table.sortable"), function (table) {
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (th, i) {
      th.classList.add("sortable");
      th.tabIndex = 0;
      th.title = "sort by this column";
      th.addEventListener("click", function () { sortBy(table, i, th); });
      th.addEventListener("keydown", function (e) {
        if (e.key === "Enter" || e.key === " ") { e.preventDefault(); sortBy(table, i, th); }
      });
    });
  });
  document.body.setAttribute("data-ready", "1");
})();
"#;

fn num_cell(v: Option<f64>, err: Option<f64>) -> String {
    let shown = v.map_or("—".into(), scatterfit_io::result_table::sig4);
    let e = err.map_or(String::new(), |e| {
        format!(
            "<br><span class=\"err\">± {}</span>",
            scatterfit_io::result_table::sig4(e)
        )
    });
    let key = v.map_or(String::new(), |v| format!("{v:e}"));
    format!("<td class=\"num\" data-sort=\"{key}\">{shown}{e}</td>")
}

/// Most characters of a reason shown in the index's row (the whole is its tooltip and on the
/// sample's page).
const WHY_CHARS: usize = 140;

fn verdict_rank(v: &str) -> u8 {
    match v {
        "ok" => 0,
        "suspect" => 1,
        _ => 2,
    }
}

/// The index page.
pub(crate) fn index_page(page: &IndexPage<'_>) -> String {
    let mut p = head_with(&page.title, "wide");
    let views: Vec<ResultView> = page
        .samples
        .iter()
        .map(|e| ResultView::new(e.result))
        .collect();
    let count = |v: &str| views.iter().filter(|r| r.verdict == v).count();
    let _ = writeln!(
        p,
        "<header><h1>{}</h1><p>{}</p><p class=\"meta\">{} sample(s): {} ok, {} suspect, {} \
         failed in a channel; {} could not be measured.</p></header>",
        name(&page.title),
        text(&page.intro),
        views.len() + page.failures.len(),
        count("ok"),
        count("suspect"),
        count("failed"),
        page.failures.len()
    );
    p.push_str(
        "<section id=\"samples\"><h2>Samples</h2><p class=\"muted\">Click a column's header to \
         sort by it. ± : the fit's standard error and the spectrophotometer's part in \
         quadrature.</p><div class=\"scroll\"><table class=\"sortable\" id=\"samples-table\"><thead><tr>\
         <th>sample</th><th>verdict</th><th>per channel</th><th>η</th><th>σ′s R [mm⁻¹]</th>\
         <th>σ′s G</th><th>σ′s B</th><th>σa R [mm⁻¹]</th><th>σa G</th><th>σa B</th>\
         <th>method / model</th><th>links</th></tr></thead><tbody>\n",
    );
    for (e, v) in page.samples.iter().zip(&views) {
        let sample = match &e.page {
            Some(h) => format!("<a href=\"{}\">{}</a>", href(h), name(&v.name)),
            None => name(&v.name),
        };
        let channels: Vec<String> = v
            .channels
            .iter()
            .map(|c| format!("{} {}", c.name, c.verdict))
            .collect();
        // The reasons, each once (the same check often speaks for every channel), shortened.
        let mut why: Vec<&str> = Vec::new();
        for r in v.channels.iter().flat_map(|c| &c.reasons) {
            if !why.contains(&r.message.as_str()) {
                why.push(&r.message);
            }
        }
        let why: String = why
            .iter()
            .map(|m| {
                let short: String = m.chars().take(WHY_CHARS).collect();
                let more = if m.chars().count() > WHY_CHARS {
                    "…"
                } else {
                    ""
                };
                format!(
                    "<span class=\"why\" title=\"{}\">{}{more}</span>",
                    name(m),
                    name(&short)
                )
            })
            .collect();
        let _ = write!(
            p,
            "<tr><td class=\"sample\" data-sort=\"{}\">{sample}<br><span class=\"path muted\">{}\
             </span></td><td data-sort=\"{}\">{}</td><td class=\"rgbv\"><span class=\"nowrap\">{}\
             </span>{why}</td>{}",
            name(&v.name),
            name(&e.folder),
            verdict_rank(v.verdict),
            badge(v.verdict),
            channels.join(" · "),
            num_cell(v.eta.value(), v.eta.total_error())
        );
        for c in &v.channels {
            p.push_str(&num_cell(
                c.sigma_s_prime.value(),
                c.sigma_s_prime.total_error(),
            ));
        }
        for c in &v.channels {
            p.push_str(&num_cell(c.sigma_a.value(), c.sigma_a.total_error()));
        }
        let links: Vec<String> = e
            .page
            .iter()
            .flat_map(|h| {
                [
                    format!("<a href=\"{}\">report</a>", href(h)),
                    format!("<a href=\"{}#evidence\">evidence</a>", href(h)),
                ]
            })
            .chain(
                e.links
                    .iter()
                    .map(|(l, h)| format!("<a href=\"{}\">{}</a>", href(h), name(l))),
            )
            .collect();
        let _ = writeln!(
            p,
            "<td>{} / {}</td><td class=\"links\">{}</td></tr>",
            name(&v.method),
            name(&v.model),
            links.join("<br>")
        );
    }
    p.push_str("</tbody></table></div></section>\n");
    p.push_str("<section id=\"failures\"><h2>Failures</h2>");
    if page.failures.is_empty() {
        p.push_str("<p>none: every sample was measured.</p>");
    } else {
        p.push_str("<table><thead><tr><th>sample folder</th><th>message</th></tr></thead><tbody>");
        for (folder, message) in &page.failures {
            let _ = write!(
                p,
                "<tr><td class=\"path\">{}</td><td><pre>{}</pre></td></tr>",
                name(folder),
                text(message)
            );
        }
        p.push_str("</tbody></table>");
    }
    p.push_str("</section>\n");
    if !page.files.is_empty() {
        let links: Vec<String> = page
            .files
            .iter()
            .map(|f| format!("<a href=\"{}\">{}</a>", href(f), name(f)))
            .collect();
        let _ = writeln!(
            p,
            "<section><h2>Files</h2><p>{}</p></section>",
            links.join(", ")
        );
    }
    let _ = writeln!(p, "<script>{SORT_JS}</script>\n</body>\n</html>");
    p
}
