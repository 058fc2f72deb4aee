//! The sample page, `report.html`: in the order a reader needs it — the verdict per channel with
//! its reasons, Table 1 (σ′s, σa, α′ per channel and η, each with its uncertainty terms), Figure 4
//! (profile and fit), Figure 6 when both methods ran, the evidence (bracket, radiance map,
//! response), and the inputs with a rendered swatch beside the spectrophotometer's colour.

use std::fmt::Write as _;

use scatterfit_io::result_table::sig4;

use super::evidence;
use super::markup::{badge, head, href, inline_svg, name, png_data_uri, text};
use super::view::{ResultView, Valued};

/// What the sample page shows besides the result: figures already drawn and pictures already
/// encoded, so that the page itself is plain text work.
#[derive(Debug, Clone, Default)]
pub struct SampleExtras {
    /// Figure 4 (the fit), SVG text as `crate::plot::render_svg` gives it.
    pub fit_svg: Option<String>,
    /// Figure 6 (existing and proposed methods), SVG text, when both methods ran.
    pub compare_svg: Option<String>,
    /// The radiance map with its marks: a whole `<figure>` (HTML).
    pub radiance_map: Option<String>,
    /// The camera response figure, SVG text.
    pub response_svg: Option<String>,
    /// The bracket's frames: (file name, shutter time \[s\], PNG thumbnail).
    pub thumbnails: Vec<(String, f64, Vec<u8>)>,
    /// Frames of the bracket (for the caption when there are no thumbnails).
    pub frame_count: usize,
    /// The rendered swatch (PNG) and what it is.
    pub swatch: Option<(Vec<u8>, String)>,
    /// Result files beside the page, linked at its end (relative names).
    pub files: Vec<String>,
}

/// The value's cells: the value, its fit term (when `fit`), its spectro term, its g term.
fn valued_cells(v: &Valued, fit: bool) -> String {
    let term = |e: Option<f64>| format!("<td class=\"num err\">{}</td>", opt(e));
    format!(
        "<td class=\"num\">{}</td>{}{}{}",
        v.value_text(),
        if fit { term(v.fit()) } else { String::new() },
        term(v.0.and_then(|e| e.spectro)),
        term(v.0.and_then(|e| e.g))
    )
}

fn opt(v: Option<f64>) -> String {
    v.map_or("—".into(), sig4)
}

/// The page for `view` with `extras`.
pub(crate) fn sample_page(view: &ResultView, extras: &SampleExtras) -> String {
    let mut p = head(&format!("{} — scatterfit report", view.name));
    let _ = writeln!(
        p,
        "<header><h1>{}</h1><p class=\"meta\">overall {} · method {} · model {} · α′ from {} · \
         scatterfit {}</p><nav><a href=\"#verdict\">Verdict</a><a href=\"#table1\">Table 1</a>\
         <a href=\"#fig4\">Figure 4</a>{}<a href=\"#evidence\">Evidence</a>\
         <a href=\"#inputs\">Inputs</a></nav></header>",
        name(&view.name),
        badge(view.verdict),
        name(&view.method),
        name(&view.model),
        name(&view.albedo_model),
        name(&view.version),
        if extras.compare_svg.is_some() {
            "<a href=\"#fig6\">Figure 6</a>"
        } else {
            ""
        }
    );

    // The verdict.
    p.push_str(
        "<section id=\"verdict\"><h2>Verdict</h2><table><thead><tr><th>channel</th>\
         <th>verdict</th><th>reasons (data checks and fit)</th></tr></thead><tbody>\n",
    );
    for c in &view.channels {
        let reasons = if c.reasons.is_empty() {
            "<span class=\"muted\">every check passed</span>".to_string()
        } else {
            let mut ul = String::from("<ul class=\"reasons\">");
            for r in &c.reasons {
                let _ = write!(ul, "<li>{} {}</li>", badge(r.severity), text(&r.message));
            }
            ul + "</ul>"
        };
        let _ = writeln!(
            p,
            "<tr><th>{}</th><td>{}</td><td>{reasons}</td></tr>",
            c.name,
            badge(c.verdict)
        );
    }
    p.push_str(
        "</tbody></table><p class=\"muted\">ok: every check passed, the values are \
         measurements. suspect: values were found but a check says to look before trusting them. \
         failed: no value to trust.</p></section>\n",
    );

    // Table 1. α′ has a fit term only behind a spectrophotometer port (the fit's error reaches
    // the corrected α′ through the port's F); its column is shown when a channel has one.
    let albedo_fit = view.channels.iter().any(|c| c.albedo_prime.fit().is_some());
    let _ = writeln!(
        p,
        "<section id=\"table1\"><h2>Table 1: parameters</h2><p>η = {} <span class=\"err\">{}</span> \
         (from {})</p><div class=\"scroll\"><table><thead><tr><th rowspan=\"2\">channel</th>\
         <th colspan=\"4\">σ′s [mm⁻¹]</th><th colspan=\"4\">σa [mm⁻¹]</th><th colspan=\"{}\">α′</th>\
         <th rowspan=\"2\">Rd (spectro)</th></tr><tr><th>value</th><th>± fit</th><th>± spectro</th>\
         <th>± g</th><th>value</th><th>± fit</th><th>± spectro</th><th>± g</th><th>value</th>\
         {}<th>± spectro</th><th>± g</th></tr>\
         </thead><tbody>",
        view.eta.value_text(),
        view.eta.error_text(),
        name(&view.eta_source),
        if albedo_fit { 4 } else { 3 },
        if albedo_fit { "<th>± fit</th>" } else { "" },
    );
    for c in &view.channels {
        let _ = writeln!(
            p,
            "<tr><th>{}</th>{}{}{}<td class=\"num\">{}</td></tr>",
            c.name,
            valued_cells(&c.sigma_s_prime, true),
            valued_cells(&c.sigma_a, true),
            valued_cells(&c.albedo_prime, albedo_fit),
            opt(c.rd_total),
        );
    }
    p.push_str(
        "</tbody></table></div><p class=\"muted\">± terms are one standard error: fit, from the \
         fit's Jacobian at the solution (behind a spectrophotometer port carried through its \
         reading fraction, which also gives α′ a fit term); spectro, the spectrophotometer's part (its η and α′ at the \
         reading's repeatability, propagated through refits); g, the anisotropy's part (how far \
         the estimate moves over the range of g; 0 where g was given). The total is fit and spectro \
         in quadrature plus g (a bound, not a standard error).</p><h3>The fits</h3><div class=\"scroll\"><table><thead><tr><th>channel</th>\
         <th>MSE [mm⁻⁴]</th><th>rms ln residual</th><th>χ²/dof</th><th>rings used</th>\
         <th>inside the spot</th><th>below detection</th><th>invalid</th><th>solver</th>\
         <th>fit time [µs]</th></tr></thead><tbody>\n",
    );
    for c in &view.channels {
        let _ = writeln!(
            p,
            "<tr><th>{}</th><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td>{}<td>{}</td><td class=\"num\">{:.1}</td></tr>",
            c.name,
            opt(c.mse),
            opt(c.rms_log_residual),
            opt(c.chi2_reduced),
            c.rings
                .map(|n| format!("<td class=\"num\">{n}</td>"))
                .join(""),
            name(&c.solver),
            c.fit_time_s * 1e6
        );
    }
    p.push_str("</tbody></table></div>");
    if let Some(g) = &view.g {
        let _ = write!(p, "<p>{}</p>", text(g));
    }
    if let Some(port) = &view.port {
        let _ = write!(p, "<p>{}</p>", text(port));
    }
    p.push_str("</section>\n");

    // Figures 4 and 6.
    let _ = writeln!(
        p,
        "<section id=\"fig4\"><h2>Figure 4: profile and fit</h2><figure>{}<figcaption>The \
         measured radial profile Rd(r) per channel (log scale) and the fitted {} model. Filled \
         markers: rings the fit used, with one-standard-error bars; hollow grey markers: rings \
         not fitted (inside the light spot, below the bracket's detection limit).</figcaption>\
         </figure></section>",
        extras
            .fit_svg
            .as_deref()
            .map_or_else(|| "<p>no figure</p>".into(), |s| inline_svg(s, "Figure 4")),
        name(&view.model)
    );
    if let Some(svg) = &extras.compare_svg {
        let _ = writeln!(
            p,
            "<section id=\"fig6\"><h2>Figure 6: existing and proposed methods</h2><figure>{}\
             <figcaption>The measured profile with the existing method's fit (σ′s and σa \
             fitted; dashed) and the proposed method's (α′ from the spectrophotometer; solid).\
             </figcaption></figure></section>",
            inline_svg(svg, "Figure 6")
        );
    }

    // The evidence.
    p.push_str("<section id=\"evidence\"><h2>Evidence</h2><h3>The exposure bracket</h3>");
    if extras.thumbnails.is_empty() {
        let _ = write!(
            p,
            "<p class=\"muted\">{} frame(s); no thumbnails (a given radiance map, or frames \
             that could not be reduced).</p>",
            extras.frame_count
        );
    } else {
        p.push_str("<div class=\"thumbs\">");
        for (file, t, png) in &extras.thumbnails {
            let _ = write!(
                p,
                "<figure><img alt=\"frame {0}\" src=\"{1}\"><figcaption>{2} s<br>\
                 <span class=\"path\">{0}</span></figcaption></figure>",
                name(file),
                png_data_uri(png),
                sig4(*t)
            );
        }
        p.push_str("</div>");
    }
    p.push_str("<h3>The radiance map</h3>");
    p.push_str(
        extras
            .radiance_map
            .as_deref()
            .unwrap_or("<p class=\"muted\">no radiance map</p>"),
    );
    p.push_str("<h3>The camera response</h3>");
    match &extras.response_svg {
        Some(svg) => {
            let _ = write!(
                p,
                "<figure style=\"max-width:560px\">{}<figcaption>g(z) = ln of the exposure that \
                 gives pixel value z, per channel (Debevec &amp; Malik 1997); rms: the \
                 recovery's residual.</figcaption></figure>",
                inline_svg(svg, "camera response")
            );
        }
        None => {
            p.push_str("<p class=\"muted\">none: a linear 16-bit merge or a given radiance map</p>")
        }
    }
    p.push_str("</section>\n");

    // The inputs and the swatch.
    p.push_str("<section id=\"inputs\"><h2>Inputs</h2><div class=\"row\">");
    if let Some((png, what)) = &extras.swatch {
        let _ = write!(
            p,
            "<figure class=\"swatchbox\"><img class=\"swatch\" alt=\"rendered swatch\" src=\"{}\"><figcaption>\
             rendered: {}</figcaption></figure>",
            png_data_uri(png),
            text(what)
        );
    }
    if let Some([r, g, b]) = view.spectro_colour() {
        let _ = write!(
            p,
            "<figure class=\"swatchbox\"><div class=\"swatch\" style=\"background:rgb({r},{g},{b})\"></div>\
             <figcaption>spectrophotometer: Rd as sRGB #{r:02x}{g:02x}{b:02x}</figcaption></figure>"
        );
    }
    p.push_str("</div>");
    let _ = write!(
        p,
        "<p>sample folder <span class=\"path\">{}</span>; {} mm per pixel; spot radius {} mm</p>\
         <table><thead><tr><th>role</th><th>file</th><th>SHA-256</th></tr></thead><tbody>",
        name(&view.sample_dir),
        opt(view.mm_per_pixel),
        opt(view.spot_radius_mm)
    );
    for f in &view.files {
        let _ = write!(
            p,
            "<tr><td>{}</td><td class=\"path\">{}</td><td><code>{}</code></td></tr>",
            f.role,
            name(&f.path),
            name(&f.sha256)
        );
    }
    let _ = write!(
        p,
        "</tbody></table><h3>Options</h3><pre>{}</pre><p>scatterfit {}</p>",
        text(&view.options),
        name(&view.version)
    );
    if !extras.files.is_empty() {
        p.push_str("<p>Files beside this page: ");
        let links: Vec<String> = extras
            .files
            .iter()
            .map(|f| format!("<a href=\"{}\">{}</a>", href(f), name(f)))
            .collect();
        p.push_str(&links.join(", "));
        p.push_str("</p>");
    }
    p.push_str("</section>\n</body>\n</html>\n");
    p
}

/// The figure's SVG and the page's other pictures for a measurement (the work besides the text).
pub(crate) fn extras_for(
    m: &scatterfit_pipeline::Measurement,
    view: &ResultView,
    fit_svg: Option<String>,
    compare_svg: Option<String>,
) -> SampleExtras {
    let response_svg = evidence::response_figure(m).and_then(|f| crate::plot::render_svg(&f).ok());
    let swatch = view
        .coefficients()
        .zip(view.eta.value())
        .and_then(|(c, eta)| evidence::swatch(c, eta));
    SampleExtras {
        fit_svg,
        compare_svg,
        radiance_map: evidence::radiance_map(m, view.spot_radius_mm),
        response_svg,
        thumbnails: Vec::new(),
        frame_count: m.hdr.frames.len(),
        swatch,
        files: Vec::new(),
    }
}
