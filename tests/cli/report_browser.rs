//! Opens the generated report in a real headless browser (Debian's chromium): the overview
//! and a scene page load with no missing resource, and their screenshots are not blank; the
//! hanging chain's playback plays (its frame counter advances and the drawn frames differ).
//! Without chromium the test fails under CI=true (CI installs it) and is skipped otherwise.

use std::path::{Path, PathBuf};
use std::process::Command;

const CHROMIUM: &str = "/usr/bin/chromium";

fn chromium(user_dir: &Path, extra: &[String], url: &str) -> std::process::Output {
    Command::new(CHROMIUM)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--enable-logging=stderr",
            "--window-size=1200,900",
        ])
        .arg(format!("--user-data-dir={}", user_dir.display()))
        .args(extra)
        .arg(url)
        .output()
        .expect("run chromium")
}

/// Distinct RGB colours in a PNG (a blank page has one).
fn distinct_colours(png_path: &Path) -> usize {
    let dec = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(png_path).unwrap(),
    ));
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bpp = info.color_type.samples()
        * if info.bit_depth == png::BitDepth::Sixteen {
            2
        } else {
            1
        };
    let mut set = std::collections::HashSet::new();
    for px in buf[..info.buffer_size()].chunks(bpp) {
        set.insert(px[..bpp.min(3)].to_vec());
    }
    set.len()
}

#[test]
fn report_opens_in_headless_chromium() {
    if !Path::new(CHROMIUM).exists() {
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("{CHROMIUM} is missing: CI must install it (apt-get install -y chromium)");
        }
        eprintln!("SKIP report_opens_in_headless_chromium: {CHROMIUM} not installed");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("reports");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // Two shipped scenes: a page with every kind of table and the overview linking them.
    let scenes = tmp.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    for s in ["anchored_spring", "hanging_chain"] {
        std::fs::copy(
            root.join(format!("scenarios/{s}.toml")),
            scenes.join(format!("{s}.toml")),
        )
        .unwrap();
    }
    let st = crate::support::bin()
        .args(["report", "--quick", "--scenarios"])
        .arg(&scenes)
        .arg("--out")
        .arg(&out)
        .status()
        .unwrap();
    assert!(st.success());
    let pages: Vec<PathBuf> = vec![
        out.join("index.html"),
        out.join("anchored_spring/index.html"),
    ];
    for (k, page) in pages.iter().enumerate() {
        let url = format!("file://{}", page.display());
        let ud = tmp.path().join(format!("profile-{k}"));
        // Missing resources show up as network errors in the log.
        let dom = chromium(&ud, &["--dump-dom".into()], &url);
        assert!(dom.status.success(), "chromium failed on {url}");
        let html = String::from_utf8_lossy(&dom.stdout);
        assert!(html.contains("springlab"), "{url}: page did not load");
        let log = String::from_utf8_lossy(&dom.stderr);
        for bad in ["ERR_FILE_NOT_FOUND", "net::ERR_"] {
            assert!(!log.contains(bad), "{url}: missing resource: {log}");
        }
        let shot = tmp.path().join(format!("shot-{k}.png"));
        let ss = chromium(&ud, &[format!("--screenshot={}", shot.display())], &url);
        assert!(
            ss.status.success() && shot.is_file(),
            "no screenshot of {url}"
        );
        let n = distinct_colours(&shot);
        assert!(n > 20, "{url}: screenshot looks blank ({n} colours)");
    }
    // Playback: after 3 s of virtual time the page has advanced frames, and the checksums of
    // the drawn particle positions differ between frames (the chain falls).
    let page = out.join("hanging_chain/index.html");
    assert!(out.join("hanging_chain/playback.js").is_file());
    let url = format!("file://{}", page.display());
    let dom = chromium(
        &tmp.path().join("profile-playback"),
        &["--dump-dom".into(), "--virtual-time-budget=3000".into()],
        &url,
    );
    assert!(dom.status.success(), "chromium failed on {url}");
    let html = String::from_utf8_lossy(&dom.stdout);
    let attr = |name: &str| -> String {
        let key = format!("{name}=\"");
        let i = html
            .find(&key)
            .unwrap_or_else(|| panic!("{url}: no {name}"));
        let rest = &html[i + key.len()..];
        rest[..rest.find('"').unwrap()].to_string()
    };
    let frame: usize = attr("data-frame").parse().unwrap();
    assert!(frame > 0, "{url}: playback did not advance");
    let drawn: std::collections::HashSet<String> =
        attr("data-drawn").split(',').map(String::from).collect();
    assert!(drawn.len() >= 3, "{url}: frames do not change: {drawn:?}");
}
