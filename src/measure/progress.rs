//! Progress bars: drawn on a terminal only, silent otherwise (pipes, CI, batch jobs).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// A bar of `len` steps labelled `msg`, hidden unless `enabled` and stderr is a terminal.
pub fn bar(len: u64, msg: &str, enabled: bool) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
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
