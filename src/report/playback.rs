//! Side-by-side playback of the compared runs on a scene page: every method's particles (and
//! its short springs and rods) drawn on a canvas per method, all at the same scale, played at
//! [`PLAYBACK_FPS`] frames per simulated second from the frames compare's runs kept
//! ([`crate::measure::trace::Trace::frames`]). The data goes to `playback.js` beside the page
//! (a local script, nothing fetched from outside); a little inline script draws it.
//!
//! Encoding: positions are projected on the page's main plane and quantised to 12 bits over
//! the box the stable runs span (padded 5 %); each coordinate is two characters of
//! [`ALPHABET`] (value = 64·first + second). The value 4095 marks a coordinate off the box or
//! not finite: the particle is not drawn, and the panel says how many are off-screen — a
//! blow-up is shown, never clipped to the border.

use crate::measure::case::CaseResult;
use crate::measure::compare::PLAYBACK_FPS;
use crate::measure::study::SceneStudy;
use crate::scenario::Scenario;
use serde::Serialize;

/// The 64 characters of the two-character coordinate code.
pub const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";

/// The code of a coordinate off the box (or not finite).
const OFF: u16 = 4095;

/// The oblique (cabinet) view: the depth axis is drawn at half scale along 45°, so a cloth
/// seen edge-on in the page's main plane still shows its surface.
const DEPTH: f64 = 0.5 * std::f64::consts::FRAC_1_SQRT_2;

/// A position in the oblique view of `plane`: (horizontal, vertical).
fn project(x: &[f64; 3], plane: [usize; 2]) -> (f64, f64) {
    let d = x[3 - plane[0] - plane[1]];
    (x[plane[0]] + DEPTH * d, x[plane[1]] + DEPTH * d)
}

/// Springs longer than this multiple of the median rest length are not drawn (bending
/// springs would double every line of a cloth).
const LINE_LENGTH_FACTOR: f64 = 1.5;

/// One method's frames.
#[derive(Debug, Serialize)]
struct Run {
    name: String,
    status: crate::run::RunStatus,
    /// Time of the blow-up (s), when the run blew up.
    unstable_time: Option<f64>,
    /// Frames recorded (a run that blew up has fewer).
    count: usize,
    /// `count` frames × particles × 2 coordinates, two characters each.
    frames: String,
}

/// Everything `playback.js` holds.
#[derive(Debug, Serialize)]
struct Data {
    fps: f64,
    /// Frame times (s) of the longest run.
    times: Vec<f64>,
    particles: usize,
    /// Axis names of the plane, horizontal then vertical.
    axes: [String; 2],
    /// The depth axis, drawn obliquely.
    depth: String,
    /// The box drawn: [horizontal min, max, vertical min, max] (m).
    bounds: [f64; 4],
    /// Particle pairs joined by a line (short springs and rods).
    lines: Vec<[usize; 2]>,
    runs: Vec<Run>,
}

/// The playback of `s` in `plane` as (`playback.js` contents, the page's HTML section), or
/// `None` for a scene of one particle or without frames.
pub fn playback(s: &SceneStudy, scene: &Scenario, plane: [usize; 2]) -> Option<(String, String)> {
    let runs: Vec<&CaseResult> = s
        .compare
        .entries
        .iter()
        .filter_map(|e| e.result.as_ref())
        .filter(|r| r.trace.as_ref().is_some_and(|t| !t.frames.is_empty()))
        .collect();
    let n = scene.particles.len();
    if n < 2 || runs.is_empty() {
        return None;
    }
    let bounds = bounds(&runs, plane)?;
    let longest = runs
        .iter()
        .filter_map(|r| r.trace.as_ref())
        .max_by_key(|t| t.frames.len())?;
    let data = Data {
        fps: PLAYBACK_FPS,
        times: longest.frames.iter().map(|(t, _)| *t).collect(),
        particles: n,
        axes: plane.map(|a| ["x", "y", "z"][a].to_string()),
        depth: ["x", "y", "z"][3 - plane[0] - plane[1]].to_string(),
        bounds,
        lines: lines(scene),
        runs: runs
            .iter()
            .map(|r| {
                let frames = &r.trace.as_ref().expect("filtered").frames;
                Run {
                    name: r.method.clone(),
                    status: r.status,
                    unstable_time: r.unstable_time,
                    count: frames.len(),
                    frames: encode(frames, plane, bounds),
                }
            })
            .collect(),
    };
    let json = serde_json::to_string(&data).ok()?;
    let js = format!("window.SPRINGLAB_PLAYBACK = {json};\n");
    Some((js, section(&data)))
}

/// The box every stable run's frames span (all runs' first frames when none is stable),
/// padded by 5 % and made square enough to keep the aspect ratio readable.
fn bounds(runs: &[&CaseResult], plane: [usize; 2]) -> Option<[f64; 4]> {
    let ok: Vec<&&CaseResult> = runs.iter().filter(|r| r.status.is_ok()).collect();
    let mut b = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut take = |x: &[f64; 3]| {
        let (h, v) = project(x, plane);
        if h.is_finite() && v.is_finite() {
            b = [b[0].min(h), b[1].max(h), b[2].min(v), b[3].max(v)];
        }
    };
    if ok.is_empty() {
        for r in runs {
            if let Some((_, x)) = r.trace.as_ref().and_then(|t| t.frames.first()) {
                x.iter().for_each(&mut take);
            }
        }
    } else {
        for r in ok {
            for (_, x) in &r.trace.as_ref().expect("filtered").frames {
                x.iter().for_each(&mut take);
            }
        }
    }
    if !(b[0] <= b[1] && b[2] <= b[3]) {
        return None;
    }
    let span = (b[1] - b[0]).max(b[3] - b[2]).max(1e-9);
    let (ph, pv) = (
        0.05 * span + 0.5 * (span * 0.25 - (b[1] - b[0])).max(0.0),
        0.05 * span + 0.5 * (span * 0.25 - (b[3] - b[2])).max(0.0),
    );
    Some([b[0] - ph, b[1] + ph, b[2] - pv, b[3] + pv])
}

/// Short springs (at most [`LINE_LENGTH_FACTOR`] × the median rest length) and every rod.
fn lines(scene: &Scenario) -> Vec<[usize; 2]> {
    let mut lengths: Vec<f64> = scene.springs.iter().map(|s| scene.rest_length(s)).collect();
    lengths.sort_by(f64::total_cmp);
    let median = lengths.get(lengths.len() / 2).copied().unwrap_or(0.0);
    scene
        .springs
        .iter()
        .filter(|s| scene.rest_length(s) <= LINE_LENGTH_FACTOR * median)
        .map(|s| [s.i, s.j])
        .chain(scene.constraints.iter().map(|c| [c.i, c.j]))
        .collect()
}

/// The two-character codes of every frame's projected positions.
fn encode(frames: &[(f64, Vec<[f64; 3]>)], plane: [usize; 2], b: [f64; 4]) -> String {
    let mut out = String::with_capacity(frames.len() * frames.first().map_or(0, |f| f.1.len()) * 4);
    let q = |v: f64, lo: f64, hi: f64| -> u16 {
        let f = (v - lo) / (hi - lo);
        if f.is_finite() && (0.0..=1.0).contains(&f) {
            (f * f64::from(OFF - 1)).round() as u16
        } else {
            OFF
        }
    };
    for (_, x) in frames {
        for p in x {
            let (h, v) = project(p, plane);
            for (val, (lo, hi)) in [(h, (b[0], b[1])), (v, (b[2], b[3]))] {
                let c = q(val, lo, hi);
                out.push(ALPHABET[usize::from(c / 64)] as char);
                out.push(ALPHABET[usize::from(c % 64)] as char);
            }
        }
    }
    out
}

/// The page section: one canvas per method, play/pause, a time slider and the drawing script.
fn section(d: &Data) -> String {
    let panels: String = d
        .runs
        .iter()
        .enumerate()
        .map(|(k, r)| {
            format!(
                "<figure class=\"pb\"><canvas id=\"pb{k}\" width=\"240\" height=\"240\"></canvas><figcaption>{}<span id=\"pbn{k}\"></span></figcaption></figure>",
                crate::report::html::esc(&r.name)
            )
        })
        .collect();
    format!(
        "<h2>Playback</h2>\n<p class=\"note\">Every method's run of the comparison above, side by side at the same scale in the {}{}-plane (oblique view: the {}-axis drawn at half scale up and to the right), {} frames per simulated second (lines: springs and rods). A run that blew up stops at its blow-up; particles that left the box are counted, not drawn at its edge. From the runs of <a href=\"compare/summary.json\">compare</a>; data in <code>playback.js</code>.</p>\n<p><button id=\"pbplay\">pause</button> <input id=\"pbtime\" type=\"range\" min=\"0\" max=\"{}\" value=\"0\"> t = <span id=\"pbt\">0</span> s</p>\n<div id=\"playback\" data-frame=\"0\" data-drawn=\"\">{panels}</div>\n<script src=\"playback.js\"></script>\n<script>{}</script>\n",
        d.axes[0],
        d.axes[1],
        d.depth,
        d.fps,
        d.times.len().saturating_sub(1),
        SCRIPT
    )
}

/// Draws frame k of every run; advances while playing. `data-frame` and `data-drawn` (a
/// checksum per drawn frame) let a headless browser test see that frames change.
const SCRIPT: &str = r##"
(function () {
  const P = window.SPRINGLAB_PLAYBACK; if (!P) return;
  const A = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
  const V = {}; for (let i = 0; i < 64; i++) V[A[i]] = i;
  const root = document.getElementById("playback"), slider = document.getElementById("pbtime");
  const btn = document.getElementById("pbplay"), tl = document.getElementById("pbt");
  let k = 0, playing = true, drawn = [];
  function draw() {
    let sum = 0;
    P.runs.forEach(function (r, i) {
      const c = document.getElementById("pb" + i), g = c.getContext("2d");
      const W = c.width, H = c.height, n = P.particles, f = Math.min(k, r.count - 1);
      const b = P.bounds, s = Math.min(W / (b[1] - b[0]), H / (b[3] - b[2]));
      const ox = (W - s * (b[1] - b[0])) / 2, oy = (H - s * (b[3] - b[2])) / 2;
      g.fillStyle = "#fff"; g.fillRect(0, 0, W, H);
      const xs = new Float64Array(n), ys = new Float64Array(n), on = new Uint8Array(n);
      let off = 0;
      for (let p = 0; p < n; p++) {
        const o = 4 * (f * n + p), s0 = r.frames, hq = 64 * V[s0[o]] + V[s0[o + 1]], vq = 64 * V[s0[o + 2]] + V[s0[o + 3]];
        if (hq === 4095 || vq === 4095) { off++; continue; }
        on[p] = 1; sum = (sum * 31 + hq * 7 + vq) % 1000000007;
        xs[p] = ox + (b[1] - b[0]) * hq / 4094 * s;
        ys[p] = H - oy - (b[3] - b[2]) * vq / 4094 * s;
      }
      g.strokeStyle = "#7f9fb0"; g.lineWidth = 1; g.beginPath();
      P.lines.forEach(function (l) { if (on[l[0]] && on[l[1]]) { g.moveTo(xs[l[0]], ys[l[0]]); g.lineTo(xs[l[1]], ys[l[1]]); } });
      g.stroke();
      g.fillStyle = r.status === "ok" ? "#1f5fa8" : "#b8321a";
      const d = n > 200 ? 1 : 1.5;
      for (let p = 0; p < n; p++) if (on[p]) g.fillRect(xs[p] - d, ys[p] - d, 2 * d, 2 * d);
      const blew = r.unstable_time !== null && k >= r.count - 1;
      document.getElementById("pbn" + i).textContent =
        (blew ? " — blew up at t = " + r.unstable_time.toPrecision(3) + " s" : "") + (off ? " — " + off + " off-screen" : "");
    });
    tl.textContent = (P.times[Math.min(k, P.times.length - 1)] || 0).toFixed(3);
    slider.value = k; root.dataset.frame = k;
    if (drawn.length < 64) { drawn.push(sum); root.dataset.drawn = drawn.join(","); }
  }
  btn.onclick = function () { playing = !playing; btn.textContent = playing ? "pause" : "play"; };
  slider.oninput = function () { k = +slider.value; draw(); };
  setInterval(function () { if (playing) { k = (k + 1) % P.times.length; draw(); } }, 1000 / P.fps);
  draw();
})();
"##;
