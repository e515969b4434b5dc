//! Progress of the long phases on stderr: a bar for those that count their steps (sampling,
//! irradiance, shading), the time alone for those that do not (loading the scene,
//! preparing it: with a scanned mesh of millions of triangles, either can take a minute).
//!
//! On a terminal, a bar (or a spinner) redrawn in place. Anywhere else (a redirected stderr, a
//! farm's job log) a bar's redraws would be noise, and silence until the end leaves whoever
//! watches the log unable to tell a long render from a hung one. So there a phase that runs longer than
//! [`LOG_INTERVAL`] writes one plain line per interval:
//!
//! ```text
//! lucent: load after 0:00:10
//! lucent: shading 45% after 0:01:23, about 0:01:41 left
//! ```
//!
//! Short phases write nothing, so a typical render's stderr holds its warnings alone (the
//! summary line goes to stdout).

use std::io::{IsTerminal, Write};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Time between two log lines of one phase, and before its first.
pub const LOG_INTERVAL: Duration = Duration::from_secs(10);

/// How often the log's writer looks at the phase's position.
const POLL: Duration = Duration::from_millis(200);

/// A progress bar of `len` steps for the phase `message`: drawn on a terminal, logged
/// every [`LOG_INTERVAL`] elsewhere, hidden when `enabled` is false.
pub(crate) fn bar(enabled: bool, len: u64, message: &'static str) -> ProgressBar {
    if !enabled {
        return ProgressBar::hidden();
    }
    if !std::io::stderr().is_terminal() {
        return logged(Some(len), message);
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:40}] {percent:>3}% {elapsed_precise}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message(message);
    bar
}

/// Runs `phase`, a phase without a count of its steps called `message`, under a [`spinner`]
/// cleared when it returns, whether it succeeded or not.
pub(crate) fn during<T>(enabled: bool, message: &'static str, phase: impl FnOnce() -> T) -> T {
    let shown = spinner(enabled, message);
    let result = phase();
    shown.finish_and_clear();
    result
}

/// A phase without a count of its steps, `message`: a spinner with the time elapsed on a
/// terminal, a line every [`LOG_INTERVAL`] elsewhere (`lucent: load after 0:00:10`), nothing
/// when `enabled` is false.
fn spinner(enabled: bool, message: &'static str) -> ProgressBar {
    if !enabled {
        return ProgressBar::hidden();
    }
    if !std::io::stderr().is_terminal() {
        return logged(None, message);
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} {spinner} {elapsed_precise}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.set_message(message);
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// A hidden bar of `length` steps (`None`: uncounted) whose phase is logged on stderr every
/// [`LOG_INTERVAL`].
fn logged(length: Option<u64>, message: &'static str) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(length, ProgressDrawTarget::hidden());
    log_while_running(
        &bar,
        message,
        LOG_INTERVAL,
        Arc::new(Mutex::new(std::io::stderr())),
    );
    bar
}

/// Writes a [`log_line`] of `bar` to `sink` every `interval` until the bar is finished or
/// dropped, from a thread of its own (which holds the bar only while it reads it). Write
/// errors are ignored: a closed stderr must not stop the render. If no thread can be
/// started, the phase runs without a log.
fn log_while_running<W: Write + Send + 'static>(
    bar: &ProgressBar,
    message: &'static str,
    interval: Duration,
    sink: Arc<Mutex<W>>,
) {
    let weak = bar.downgrade();
    let _ = std::thread::Builder::new()
        .name("progress".into())
        .spawn(move || {
            let mut next = interval;
            loop {
                std::thread::sleep(POLL.min(interval));
                let Some(bar) = weak.upgrade() else { return };
                if bar.is_finished() {
                    return;
                }
                let elapsed = bar.elapsed();
                if elapsed < next {
                    continue;
                }
                let line = log_line(message, bar.position(), bar.length(), elapsed);
                if let Ok(mut sink) = sink.lock() {
                    let _ = writeln!(sink, "{line}");
                    let _ = sink.flush();
                }
                next = elapsed + interval;
            }
        });
}

/// `lucent: PHASE P% after H:MM:SS[, about H:MM:SS left]`: the time left is extrapolated
/// from the pace so far, once there is one.
fn log_line(message: &str, position: u64, length: Option<u64>, elapsed: Duration) -> String {
    let Some(length) = length.filter(|&l| l > 0) else {
        return format!("lucent: {message} after {}", clock(elapsed));
    };
    let position = position.min(length);
    let percent = position * 100 / length;
    let mut line = format!("lucent: {message} {percent}% after {}", clock(elapsed));
    if position > 0 && position < length {
        let left = elapsed.as_secs_f64() * (length - position) as f64 / position as f64;
        // Beyond what a Duration holds there is no estimate worth printing.
        if let Ok(left) = Duration::try_from_secs_f64(left) {
            line.push_str(&format!(", about {} left", clock(left)));
        }
    }
    line
}

/// Whole seconds as `H:MM:SS`.
fn clock(d: Duration) -> String {
    let s = d.as_secs();
    format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
}

#[cfg(test)]
mod tests {
    use std::time::Instant;

    use super::*;

    #[test]
    fn a_log_line_says_the_share_done_and_the_time_left() {
        let s = Duration::from_secs;
        assert_eq!(
            log_line("shading", 45, Some(100), s(83)),
            "lucent: shading 45% after 0:01:23, about 0:01:41 left"
        );
        assert_eq!(
            log_line("sampling", 0, Some(1000), s(10)),
            "lucent: sampling 0% after 0:00:10"
        );
        assert_eq!(
            log_line("irradiance", 2048, Some(1024), s(3725)),
            "lucent: irradiance 100% after 1:02:05"
        );
        assert_eq!(log_line("x", 5, None, s(0)), "lucent: x after 0:00:00");
        // A time left beyond a Duration's range is left out, not a panic.
        assert_eq!(
            log_line("x", 1, Some(u64::MAX), s(u64::MAX / 2)),
            format!("lucent: x 0% after {}", clock(s(u64::MAX / 2)))
        );
        assert_eq!(log_line("x", 5, Some(0), s(0)), "lucent: x after 0:00:00");
    }

    /// Lines come while the phase runs, none after it is finished, and a phase finished
    /// before its first interval writes nothing.
    #[test]
    fn a_running_phase_is_logged_until_it_finishes() {
        let sink = Arc::new(Mutex::new(Vec::<u8>::new()));
        let text = |sink: &Arc<Mutex<Vec<u8>>>| {
            String::from_utf8(sink.lock().expect("sink").clone()).expect("utf-8")
        };

        let quick = ProgressBar::with_draw_target(Some(10), ProgressDrawTarget::hidden());
        log_while_running(&quick, "quick", Duration::from_secs(3600), sink.clone());
        quick.finish_and_clear();

        let bar = ProgressBar::with_draw_target(Some(200), ProgressDrawTarget::hidden());
        bar.set_position(50);
        log_while_running(&bar, "shading", Duration::from_millis(20), sink.clone());
        let start = Instant::now();
        while !text(&sink).contains('\n') {
            assert!(start.elapsed() < Duration::from_secs(30), "no line logged");
            std::thread::sleep(Duration::from_millis(10));
        }
        bar.finish_and_clear();
        // The writer sees the finish at its next look; whatever it wrote before stays.
        std::thread::sleep(POLL * 3);
        let logged = text(&sink);
        std::thread::sleep(POLL * 3);
        assert_eq!(text(&sink), logged, "lines after the phase finished");
        assert!(!logged.contains("quick"), "{logged}");
        for line in logged.lines() {
            assert!(
                line.starts_with("lucent: shading 25% after 0:00:0"),
                "{line}"
            );
        }
    }

    /// A phase without a count (a [`spinner`] off a terminal) logs the time alone.
    #[test]
    fn a_phase_without_a_count_logs_its_time() {
        let sink = Arc::new(Mutex::new(Vec::<u8>::new()));
        let phase = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        log_while_running(&phase, "load", Duration::from_millis(20), sink.clone());
        let start = Instant::now();
        let logged = loop {
            let text = String::from_utf8(sink.lock().expect("sink").clone()).expect("utf-8");
            if text.contains('\n') {
                break text;
            }
            assert!(start.elapsed() < Duration::from_secs(30), "no line logged");
            std::thread::sleep(Duration::from_millis(10));
        };
        phase.finish_and_clear();
        let first = logged.lines().next().expect("a line");
        assert!(first.starts_with("lucent: load after 0:00:"), "{first}");
        assert!(!first.contains('%'), "{first}");
    }
}
