//! The progress lines: every active stage and bar is on one board, and one ticker thread per
//! process prints a line for each innermost one (a stage or bar that no other active one sits
//! in) whenever [`line_interval`] has passed since the last line, however long a single case
//! runs. A bar drawn on a terminal shows itself (it redraws on its own tick) and gets no line;
//! a stage line printed while such a bar is drawn is printed around it.
//!
//! Nesting is per thread: a stage or bar opened while a [`Stage`] of the same thread is open
//! sits in it, so a command's line names the stage its work is in, not the whole command.

use indicatif::{ProgressBar, WeakProgressBar};
use std::cell::RefCell;
use std::marker::PhantomData;
use std::sync::{Mutex, MutexGuard, OnceLock};
use std::time::{Duration, Instant};

/// Seconds between progress lines: `SPRINGLAB_PROGRESS_INTERVAL` when set to a positive number,
/// else 10.
pub fn line_interval() -> Duration {
    std::env::var("SPRINGLAB_PROGRESS_INTERVAL")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0 && *s < 1e6)
        .map_or(Duration::from_secs(10), Duration::from_secs_f64)
}

/// One active stage or bar.
struct Item {
    id: u64,
    /// The stage of the same thread it was opened in.
    parent: Option<u64>,
    label: String,
    started: Instant,
    /// The bar's count, for a bar; None for a stage.
    bar: Option<WeakProgressBar>,
    /// A bar drawn on a terminal: it shows itself.
    drawn: bool,
}

/// Everything active, and when the last line was printed.
struct Board {
    items: Vec<Item>,
    last_line: Instant,
    next_id: u64,
}

thread_local! {
    /// The stages open on this thread, innermost last.
    static OPEN: RefCell<Vec<u64>> = const { RefCell::new(Vec::new()) };
}

fn board() -> MutexGuard<'static, Board> {
    static BOARD: OnceLock<Mutex<Board>> = OnceLock::new();
    BOARD
        .get_or_init(|| {
            // One ticker for the process, started with the first stage or bar.
            std::thread::spawn(tick);
            Mutex::new(Board {
                items: Vec::new(),
                last_line: Instant::now(),
                next_id: 1,
            })
        })
        .lock()
        .unwrap_or_else(|e| e.into_inner())
}

/// A named stretch of a long command (a reference solve, the timing runs, the command itself):
/// while it is open, progress lines name it unless a stage or bar opened inside it is active.
/// Closed when dropped, on the thread that opened it.
#[derive(Debug)]
pub struct Stage {
    id: Option<u64>,
    /// Stages nest per thread, so a stage stays on its thread.
    _thread_bound: PhantomData<*const ()>,
}

/// Opens the stage `label` (a line reads `progress: LABEL: T s elapsed`) when `enabled`; a
/// disabled stage shows nothing, like a disabled bar.
pub fn stage(label: impl Into<String>, enabled: bool) -> Stage {
    let id = enabled.then(|| {
        let id = register(label.into(), None, false);
        OPEN.with(|s| s.borrow_mut().push(id));
        id
    });
    Stage {
        id,
        _thread_bound: PhantomData,
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        let Some(id) = self.id else { return };
        OPEN.with(|s| {
            let mut s = s.borrow_mut();
            if let Some(k) = s.iter().rposition(|&x| x == id) {
                s.remove(k);
            }
        });
        board().items.retain(|it| it.id != id);
    }
}

/// Puts bar `pb` labelled `msg` on the board until it finishes or is dropped; `drawn`: it is
/// drawn on a terminal.
pub(super) fn watch(pb: &ProgressBar, msg: &str, drawn: bool) {
    register(msg.to_string(), Some(pb.downgrade()), drawn);
}

fn register(label: String, bar: Option<WeakProgressBar>, drawn: bool) -> u64 {
    let parent = OPEN.with(|s| s.borrow().last().copied());
    let mut b = board();
    if b.items.is_empty() {
        // The first line of a new stretch of work comes one interval after it starts.
        b.last_line = Instant::now();
    }
    let id = b.next_id;
    b.next_id += 1;
    b.items.push(Item {
        id,
        parent,
        label,
        started: Instant::now(),
        bar,
        drawn,
    });
    id
}

/// The line for `it`: `progress: LABEL: DONE/TOTAL done, T s elapsed, about T s left` for a
/// bar, `progress: LABEL: T s elapsed` for a stage.
fn line(it: &Item, pb: Option<&ProgressBar>) -> String {
    let Some(pb) = pb else {
        let elapsed = it.started.elapsed().as_secs_f64();
        return format!("progress: {}: {elapsed:.0} s elapsed", it.label);
    };
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
    format!(
        "progress: {}: {pos}/{len} done, {elapsed:.0} s elapsed{eta}",
        it.label
    )
}

/// The ticker: several times per interval, drops finished bars and, once an interval has
/// passed since the last line, prints a line for every innermost active stage or bar.
fn tick() {
    let every = line_interval();
    let pause = (every / 5).clamp(Duration::from_millis(10), Duration::from_millis(250));
    loop {
        std::thread::sleep(pause);
        let mut b = board();
        b.items.retain(|it| {
            it.bar
                .as_ref()
                .is_none_or(|w| w.upgrade().is_some_and(|p| !p.is_finished()))
        });
        if b.items.is_empty() || b.last_line.elapsed() < every {
            continue;
        }
        let mut text = String::new();
        let mut drawn_bar = None;
        for it in &b.items {
            let pb = it.bar.as_ref().and_then(|w| w.upgrade());
            if it.drawn {
                drawn_bar = drawn_bar.or(pb);
                continue;
            }
            if b.items.iter().any(|o| o.parent == Some(it.id)) {
                continue;
            }
            text.push_str(&line(it, pb.as_ref()));
            text.push('\n');
        }
        b.last_line = Instant::now();
        // Printed with the board released: a slow reader of stderr holds up only the ticker.
        drop(b);
        if !text.is_empty() {
            match drawn_bar {
                Some(pb) => pb.suspend(|| eprint!("{text}")),
                None => eprint!("{text}"),
            }
        }
    }
}
