//! `--html-report FILE`: the run as one self-contained HTML page, for people: an overview
//! table of every input, then per asset its pictures and continuity figures.
//!
//! Pictures are embedded as `data:` URIs and the page has no script, so it opens from a CI
//! artifact with no server. Everything taken from the inputs (paths, mesh names, messages) is
//! escaped: a mesh named `<script>` is text.

use std::fmt::Write as _;
use std::path::Path;

use base64::Engine as _;
use g2tess::render::{EdgeClass, Mode, Settings, View};

use super::batch::{Outcome, Status, Summary};
use super::scope::Job;

/// What the page needs to know of the run.
pub struct Run<'a> {
    pub jobs: &'a [Job],
    pub outcomes: &'a [Outcome],
    pub summary: &'a Summary,
    pub check: bool,
    pub exit_status: i32,
    /// Per job, its picture (PNG) or why there is none.
    pub pictures: &'a [Option<Result<Vec<u8>, String>>],
    pub settings: &'a Settings,
}

/// Writes the page atomically; the error is a message naming the file.
pub fn write(file: &Path, run: &Run) -> Result<(), String> {
    g2tess::gltf_io::write::atomic_write(file, page(run).as_bytes()).map_err(|e| e.to_string())
}

/// `text` safe inside HTML text and quoted attributes.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
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

const STYLE: &str = "body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;color:#222}\
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ccc;padding:.2em .5em;text-align:right}\
th{background:#f0f0f0}td.l,th.l{text-align:left}tr.failed td,tr.changed td{background:#fde8e8}\
tr.cancelled td{color:#888}.status{font-weight:bold}.failed .status,.changed .status{color:#b00}\
pre.error{background:#fde8e8;padding:.5em;white-space:pre-wrap}img{max-width:100%;border:1px solid #ddd}\
section{margin-top:2em;border-top:2px solid #ddd}.swatch{display:inline-block;width:1em;height:1em;vertical-align:middle;margin:0 .3em 0 .8em}";

fn page(run: &Run) -> String {
    let mut h = String::new();
    let s = run.summary;
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>g2tess report</title><style>{STYLE}</style></head><body>\n<h1>g2tess report</h1>\n<p id=\"summary\">g2tess {} · {} · exit status {} · {} done, {} skipped, {} failed, {} unchanged, {} changed, {} cancelled · triangles {} → {} · {} → {} · {:.2} s</p>\n",
        env!("CARGO_PKG_VERSION"),
        if run.check { "check" } else { "write" },
        run.exit_status,
        s.done,
        s.skipped,
        s.failed,
        s.unchanged,
        s.changed,
        s.cancelled,
        s.triangles_in,
        s.triangles_out,
        bytes(s.bytes_in),
        bytes(s.bytes_out),
        s.seconds
    );
    overview(&mut h, run);
    legend(&mut h, run.settings);
    for (k, job) in run.jobs.iter().enumerate() {
        asset(
            &mut h,
            k,
            job,
            &run.outcomes[k],
            &run.pictures[k],
            run.settings,
        );
    }
    h.push_str("</body></html>\n");
    h
}

fn status_name(status: Status) -> &'static str {
    match status {
        Status::Done => "done",
        Status::Skipped => "skipped",
        Status::Failed => "failed",
        Status::Unchanged => "unchanged",
        Status::Changed => "changed",
        Status::Cancelled => "cancelled",
    }
}

fn bytes(n: u64) -> String {
    match n {
        n if n >= 1 << 20 => format!("{:.1} MiB", n as f64 / (1u64 << 20) as f64),
        n if n >= 1 << 10 => format!("{:.1} KiB", n as f64 / 1024.0),
        n => format!("{n} B"),
    }
}

fn overview(h: &mut String, run: &Run) {
    h.push_str("<table id=\"files\"><thead><tr><th>#</th><th class=\"l\">input</th><th class=\"l\">output</th><th class=\"l\">status</th><th>triangles in</th><th>triangles out</th><th>size in</th><th>size out</th><th>seconds</th><th>warnings</th><th class=\"l\">error</th></tr></thead><tbody>\n");
    for (k, (job, o)) in run.jobs.iter().zip(run.outcomes).enumerate() {
        let r = o.report.as_ref();
        let count = |f: fn(&g2tess::pipeline::FileReport) -> String| r.map(f).unwrap_or_default();
        let _ = writeln!(
            h,
            "<tr class=\"{st}\"><td>{n}</td><td class=\"l\"><a href=\"#asset-{k}\">{input}</a></td><td class=\"l\">{output}</td><td class=\"l status\">{st}</td><td>{ti}</td><td>{to}</td><td>{bi}</td><td>{bo}</td><td>{sec:.2}</td><td>{w}</td><td class=\"l\">{err}</td></tr>",
            st = status_name(o.status),
            n = k + 1,
            input = escape(&job.input.display().to_string()),
            output = escape(&job.output.display().to_string()),
            ti = count(|r| r.triangles_in.to_string()),
            to = count(|r| r.triangles_out.to_string()),
            bi = count(|r| bytes(r.bytes_in)),
            bo = count(|r| bytes(r.bytes_out)),
            sec = o.seconds,
            w = r.map_or(0, |r| r.warnings().count()),
            err = escape(o.error.as_deref().unwrap_or("")),
        );
    }
    h.push_str("</tbody></table>\n");
}

fn legend(h: &mut String, settings: &Settings) {
    let modes: Vec<&str> = settings.modes.iter().map(|m| mode_name(*m)).collect();
    let views: Vec<&str> = settings.views.iter().map(|v| view_name(*v)).collect();
    let _ = write!(
        h,
        "<p id=\"legend\">Pictures: one row per mode ({}); per view ({}) the input, then the output, drawn with one camera. Zebra stripes jump across a break of the normal (G¹) and bend at a break of curvature (G²).",
        modes.join(", "),
        views.join(", ")
    );
    if settings.modes.contains(&Mode::H) {
        h.push_str(" Edges in the h row:");
        let swatches = [
            ("blended, small h", EdgeClass::Blended(0.02)),
            (
                "blended, largest h",
                EdgeClass::Blended(g2tess::sharpness::H_MAX),
            ),
            ("crease (h = 0)", EdgeClass::Crease),
            ("open", EdgeClass::Open),
            ("non-manifold", EdgeClass::NonManifold),
            ("degenerate", EdgeClass::Degenerate),
        ];
        for (name, class) in swatches {
            let [r, g, b] = class.colour();
            let _ = write!(
                h,
                "<span class=\"swatch\" style=\"background:rgb({r},{g},{b})\"></span>{name}"
            );
        }
    }
    h.push_str("</p>\n");
}

fn mode_name(m: Mode) -> &'static str {
    match m {
        Mode::Shaded => "shaded",
        Mode::Zebra => "zebra",
        Mode::Flat => "flat",
        Mode::H => "h",
    }
}

fn view_name(v: View) -> &'static str {
    match v {
        View::Front => "front",
        View::Side => "side",
        View::Top => "top",
        View::Iso => "iso",
    }
}

fn asset(
    h: &mut String,
    k: usize,
    job: &Job,
    o: &Outcome,
    picture: &Option<Result<Vec<u8>, String>>,
    settings: &Settings,
) {
    let input = escape(&job.input.display().to_string());
    let _ = writeln!(
        h,
        "<section id=\"asset-{k}\" class=\"{st}\"><h2>{input}</h2><p>Status: <span class=\"status\">{st}</span> · output {}</p>",
        escape(&job.output.display().to_string()),
        st = status_name(o.status),
    );
    if let Some(e) = &o.error {
        let _ = writeln!(h, "<pre class=\"error\">{}</pre>", escape(e));
    }
    match picture {
        Some(Ok(png)) => {
            let views: Vec<&str> = settings.views.iter().map(|v| view_name(*v)).collect();
            let _ = writeln!(
                h,
                "<p><img alt=\"{input}: input and output, views {}\" src=\"data:image/png;base64,{}\"></p>",
                views.join(", "),
                base64::engine::general_purpose::STANDARD.encode(png)
            );
        }
        Some(Err(e)) => {
            let _ = writeln!(h, "<pre class=\"error\">no picture: {}</pre>", escape(e));
        }
        None => {}
    }
    if let Some(r) = &o.report {
        h.push_str("<table class=\"meshes\"><thead><tr><th>mesh</th><th class=\"l\">name</th><th>triangles in</th><th>triangles out</th><th>blended edges</th><th>creases</th><th>open edges</th><th>max normal jump (°)</th><th>max gap (× mean edge)</th></tr></thead><tbody>\n");
        for m in &r.meshes {
            let tin: usize = m.primitives.iter().map(|p| p.triangles_in).sum();
            let tout: usize = m.primitives.iter().map(|p| p.triangles_out).sum();
            let e = &m.edges;
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td class=\"l\">{}</td><td>{tin}</td><td>{tout}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                m.mesh,
                escape(m.name.as_deref().unwrap_or("")),
                e.smooth_edges,
                e.crease_edges,
                e.open_edges,
                e.max_normal_jump_deg.map_or(String::from("–"), |v| format!("{v:.3}")),
                e.max_gap.map_or(String::from("–"), |v| format!("{v:.2e}")),
            );
        }
        h.push_str("</tbody></table>\n");
        if r.warnings().next().is_some() {
            h.push_str("<ul class=\"warnings\">");
            for w in r.warnings() {
                let _ = write!(h, "<li>{}</li>", escape(&w.to_string()));
            }
            h.push_str("</ul>\n");
        }
    }
    h.push_str("</section>\n");
}

#[cfg(test)]
mod tests {
    use super::escape;

    #[test]
    fn markup_from_an_asset_is_text() {
        assert_eq!(
            escape("<script>alert('x')</script> & \"q\""),
            "&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &quot;q&quot;"
        );
    }
}
