//! The HTML report of a run, opened in a real browser (headless Chromium): every picture
//! decodes, the table has a row per input, a failed file shows its message, markup from an
//! asset stays text, and the page is not blank.
//!
//! Chromium comes from the distribution's packages (`.ci/run` installs it). Without it the
//! browser checks are skipped with a message, unless `G2TESS_REQUIRE_BROWSER=1`, which makes
//! a missing browser fail the test.

use crate::gltf_build;

use std::path::{Path, PathBuf};
use std::process::Command;

/// A mesh name that would run a script and add an element if it were not escaped.
const HOSTILE_NAME: &str = "<script>document.title='owned'</script><b id=\"injected\">x</b>";

/// The installed Chromium, or `None` (a failure when `G2TESS_REQUIRE_BROWSER=1`).
fn chromium() -> Option<PathBuf> {
    let found = ["chromium", "chromium-browser", "google-chrome"]
        .iter()
        .find_map(|name| {
            std::env::var_os("PATH").and_then(|paths| {
                std::env::split_paths(&paths)
                    .map(|dir| dir.join(name))
                    .find(|p| p.is_file())
            })
        });
    if found.is_none() {
        if std::env::var("G2TESS_REQUIRE_BROWSER").as_deref() == Ok("1") {
            panic!("Chromium is required but not installed (apt-get install chromium)");
        }
        eprintln!("skipped: Chromium is not installed (apt-get install chromium)");
    }
    found
}

/// Runs headless Chromium on `page` with `extra` arguments; returns its stdout.
fn browse(browser: &Path, page: &Path, extra: &[&str]) -> String {
    let profile = tempfile::tempdir().unwrap();
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(extra)
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs");
    assert!(
        out.status.success(),
        "chromium failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Reads back what the page's check script wrote into the DOM.
const CHECK_SCRIPT: &str = r#"<script>
window.addEventListener('load', () => {
  const images = [...document.images];
  const result = {
    images: images.length,
    decoded: images.filter(i => i.complete && i.naturalWidth > 0).length,
    rows: document.querySelectorAll('#files tbody tr').length,
    failed_rows: document.querySelectorAll('#files tbody tr.failed').length,
    injected: document.getElementById('injected') !== null,
    title: document.title,
  };
  const out = document.createElement('pre');
  out.id = 'check';
  out.textContent = JSON.stringify(result);
  document.body.appendChild(out);
});
</script>"#;

#[test]
fn the_html_report_opens_in_a_browser_with_every_picture_and_row() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir(&inputs).unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb");
    std::fs::copy(&fixture, inputs.join("icosahedron.glb")).unwrap();
    let hostile = gltf_build::gltf(HOSTILE_NAME, None, &[gltf_build::octahedron()]);
    std::fs::write(inputs.join("hostile.gltf"), hostile).unwrap();
    std::fs::write(inputs.join("broken.gltf"), "{ \"asset\": ").unwrap();
    let report = dir.path().join("report.html");
    let out = Command::new(env!("CARGO_BIN_EXE_g2tess"))
        .arg(&inputs)
        .arg("-o")
        .arg(dir.path().join("out"))
        .arg("--html-report")
        .arg(&report)
        .args(["--render-size", "64", "--render-views", "front,iso", "-q"])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(1),
        "one input fails: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(&report).unwrap();

    // The page itself: escaped, self-contained, the failure with its location.
    assert!(
        !html.contains(HOSTILE_NAME),
        "the mesh name went into the page as markup"
    );
    assert!(html.contains("&lt;script&gt;document.title=&#39;owned&#39;&lt;/script&gt;"));
    assert!(
        !html.contains("src=\"http") && !html.contains("src=\"file"),
        "the page refers to other files"
    );
    assert_eq!(
        html.matches("data:image/png;base64,").count(),
        2,
        "one picture per processed input"
    );
    let broken_row = html
        .lines()
        .find(|l| l.contains("<tr class=\"failed\">"))
        .expect("a failed row");
    assert!(broken_row.contains("broken.gltf"), "{broken_row}");

    let Some(browser) = chromium() else { return };
    // A copy with a script that writes what the browser made of the page into the DOM.
    let checked = dir.path().join("checked.html");
    std::fs::write(
        &checked,
        html.replace("</body>", &format!("{CHECK_SCRIPT}</body>")),
    )
    .unwrap();
    let dom = browse(
        &browser,
        &checked,
        &["--virtual-time-budget=10000", "--dump-dom"],
    );
    let start = dom
        .find("<pre id=\"check\">")
        .expect("the check script ran")
        + "<pre id=\"check\">".len();
    let end = start + dom[start..].find("</pre>").unwrap();
    let text = dom[start..end]
        .replace("&quot;", "\"")
        .replace("&amp;", "&");
    let result: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(result["images"], 2, "{result}");
    assert_eq!(result["decoded"], 2, "a picture did not decode: {result}");
    assert_eq!(result["rows"], 3, "one table row per input: {result}");
    assert_eq!(result["failed_rows"], 1, "{result}");
    assert_eq!(
        result["injected"], false,
        "markup from the asset became an element: {result}"
    );
    assert_eq!(
        result["title"], "g2tess report",
        "a script from the asset ran: {result}"
    );

    // The page as a person sees it: not blank.
    let shot = dir.path().join("shot.png");
    browse(
        &browser,
        &report,
        &[
            &format!("--screenshot={}", shot.display()),
            "--window-size=1024,900",
        ],
    );
    let decoder = png::Decoder::new(std::io::Cursor::new(std::fs::read(&shot).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels: Vec<&[u8]> = buf[..info.buffer_size()].chunks_exact(channels).collect();
    let inked = pixels
        .iter()
        .filter(|p| p[..3].iter().any(|&c| c < 200))
        .count();
    let colours: std::collections::HashSet<&[u8]> = pixels.iter().copied().collect();
    assert!(
        inked * 50 > pixels.len(),
        "the screenshot is nearly blank: {inked} of {} pixels inked",
        pixels.len()
    );
    assert!(
        colours.len() > 50,
        "the screenshot has only {} colours",
        colours.len()
    );
}
