//! Progress: a bar with an ETA on a terminal; without one (pipes, CI logs, batch jobs) a plain
//! line per bar at most every [`line_interval`] (stage, done/total, elapsed, ETA), so a long
//! command is never silent for minutes. [`bar`] serves every command; [`ProgressObserver`]
//! shows a run's steps.

use super::energy::EnergyRecord;
use super::observer::Observer;
use crate::error::Result;
use crate::model::State;
use indicatif::WeakProgressBar;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

/// Steps between updates of the bar (updates are cheap, but not free on million-step runs).
const STRIDE: u64 = 256;

/// Shows how many of a run's steps are done.
#[derive(Debug)]
pub struct ProgressObserver {
    bar: ProgressBar,
}

impl ProgressObserver {
    /// A bar over `steps` steps labelled `msg`, shown only if `enabled` and stderr is a terminal.
    pub fn new(steps: u64, msg: &str, enabled: bool) -> Self {
        ProgressObserver {
            bar: bar(steps, msg, enabled),
        }
    }
}

impl Observer for ProgressObserver {
    fn observe(&mut self, step: u64, _s: &State, _e: &EnergyRecord) -> Result<()> {
        if step % STRIDE == 0 {
            self.bar.set_position(step);
        }
        Ok(())
    }
    fn finish(&mut self, _last_step: u64, _s: &State, _e: &EnergyRecord) -> Result<()> {
        self.bar.finish_and_clear();
        Ok(())
    }
}

/// A bar of `len` steps labelled `msg`: drawn when `enabled` and stderr is a terminal, reported
/// as plain lines when `enabled` and it is not, silent when not `enabled` (a command's inner
/// loops, whose command shows its own progress).
pub fn bar(len: u64, msg: &str, enabled: bool) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
    if enabled && !std::io::stderr().is_terminal() {
        watch(&pb, msg);
    }
    if enabled && std::io::stderr().is_terminal() {
        pb.set_draw_target(ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template(
            "{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} (eta {eta})",
        ) {
            pb.set_style(style);
        }
        pb.set_message(msg.to_string());
    }
    pb
}

/// Seconds between progress lines without a terminal: `SPRINGLAB_PROGRESS_INTERVAL` when set to
/// a positive number, else 10.
pub fn line_interval() -> Duration {
    std::env::var("SPRINGLAB_PROGRESS_INTERVAL")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0 && *s < 1e6)
        .map_or(Duration::from_secs(10), Duration::from_secs_f64)
}

/// A bar reported as lines, and when it last was.
struct Watched {
    bar: WeakProgressBar,
    msg: String,
    last: Instant,
}

fn watched() -> &'static Mutex<Vec<Watched>> {
    static LIST: OnceLock<Mutex<Vec<Watched>>> = OnceLock::new();
    LIST.get_or_init(|| {
        // One reporter thread for the process, started with the first watched bar.
        std::thread::spawn(report_lines);
        Mutex::new(Vec::new())
    })
}

fn watch(pb: &ProgressBar, msg: &str) {
    let mut list = watched().lock().unwrap_or_else(|e| e.into_inner());
    list.push(Watched {
        bar: pb.downgrade(),
        msg: msg.to_string(),
        last: Instant::now(),
    });
}

/// The line for one bar: `progress: MSG: DONE/TOTAL, ELAPSED s elapsed, about ETA s left`.
fn progress_line(msg: &str, pb: &ProgressBar) -> String {
    let pos = pb.position();
    let len = pb.length().unwrap_or(0);
    let elapsed = pb.elapsed().as_secs_f64();
    // At the average rate so far: a stuck last item shows a growing wait, not a wild guess.
    let eta = if pos > 0 && len >= pos {
        format!(
            ", about {:.0} s left",
            elapsed * (len - pos) as f64 / pos as f64
        )
    } else {
        String::new()
    };
    format!("progress: {msg}: {pos}/{len} done, {elapsed:.0} s elapsed{eta}")
}

fn report_lines() {
    let every = line_interval();
    loop {
        std::thread::sleep(every.min(Duration::from_secs(1)));
        let mut list = watched().lock().unwrap_or_else(|e| e.into_inner());
        list.retain_mut(|w| {
            let Some(pb) = w.bar.upgrade().filter(|b| !b.is_finished()) else {
                return false;
            };
            if w.last.elapsed() >= every {
                eprintln!("{}", progress_line(&w.msg, &pb));
                w.last = Instant::now();
            }
            true
        });
    }
}
