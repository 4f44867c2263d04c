//! What `rubber-atlas run` shows while it works: an indicatif bar on a terminal, a plain line
//! every ten seconds otherwise, nothing with --quiet. Rate and ETA count only the cells this
//! invocation computed, over the whole time it has run, so that they stay honest when some
//! cells cost far more than others and when a resumed run starts part-way.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use rubber_atlas::sweep::Progress;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Seconds between plain progress lines when stderr is not a terminal.
const LINE_INTERVAL: Duration = Duration::from_secs(10);

enum Mode {
    Quiet,
    Bar(ProgressBar),
    Lines { last: Mutex<Instant> },
}

/// The progress display of one run.
pub struct Reporter {
    mode: Mode,
    name: String,
    started: Mutex<Instant>,
    total: AtomicU64,
    resumed: AtomicU64,
    done: AtomicU64,
    /// Whether the file is being written: the last tally was printed before that line.
    writing: AtomicBool,
}

fn rate_and_eta(done: u64, resumed: u64, total: u64, elapsed: Duration) -> (f64, Option<Duration>) {
    let computed = done.saturating_sub(resumed);
    let seconds = elapsed.as_secs_f64();
    if computed == 0 || seconds <= 0.0 {
        return (0.0, None);
    }
    let rate = computed as f64 / seconds;
    let left = total.saturating_sub(done) as f64 / rate;
    (rate, Some(Duration::from_secs_f64(left)))
}

fn format_duration(d: Option<Duration>) -> String {
    match d {
        None => "?".into(),
        Some(d) => {
            let s = d.as_secs();
            if s >= 3600 {
                format!("{}h{:02}m", s / 3600, (s % 3600) / 60)
            } else if s >= 60 {
                format!("{}m{:02}s", s / 60, s % 60)
            } else {
                format!("{s}s")
            }
        }
    }
}

impl Reporter {
    pub fn new(quiet: bool, name: &str) -> Reporter {
        let mode = if quiet {
            Mode::Quiet
        } else if std::io::stderr().is_terminal() {
            Mode::Bar(ProgressBar::with_draw_target(
                Some(0),
                ProgressDrawTarget::stderr_with_hz(5),
            ))
        } else {
            Mode::Lines {
                last: Mutex::new(Instant::now()),
            }
        };
        Reporter {
            mode,
            name: name.to_string(),
            started: Mutex::new(Instant::now()),
            total: AtomicU64::new(0),
            resumed: AtomicU64::new(0),
            done: AtomicU64::new(0),
            writing: AtomicBool::new(false),
        }
    }

    fn line(&self) {
        let (done, total) = (
            self.done.load(Ordering::Relaxed),
            self.total.load(Ordering::Relaxed),
        );
        let elapsed = self.started.lock().unwrap().elapsed();
        let (rate, eta) = rate_and_eta(done, self.resumed.load(Ordering::Relaxed), total, elapsed);
        say!(
            "run {}: {done}/{total} cells ({:.1}%), {rate:.0} cells/s, ETA {}",
            self.name,
            100.0 * done as f64 / total.max(1) as f64,
            format_duration(eta)
        );
    }

    /// Clears the bar (the summary follows on stdout).
    pub fn finish(&self) {
        match &self.mode {
            Mode::Bar(bar) => bar.finish_and_clear(),
            // Nothing begun (an output already up to date): nothing to report; the tally was
            // printed before "writing the file".
            Mode::Lines { .. }
                if self.total.load(Ordering::Relaxed) > 0
                    && !self.writing.load(Ordering::Relaxed) =>
            {
                self.line()
            }
            Mode::Lines { .. } => {}
            Mode::Quiet => {}
        }
    }
}

impl Progress for Reporter {
    fn interrupted(&self) -> bool {
        crate::stop::requested()
    }

    fn begin(&self, total: u64, done: u64) {
        *self.started.lock().unwrap() = Instant::now();
        self.total.store(total, Ordering::Relaxed);
        self.resumed.store(done, Ordering::Relaxed);
        self.done.store(done, Ordering::Relaxed);
        match &self.mode {
            Mode::Bar(bar) => {
                let resumed = done;
                let style = ProgressStyle::with_template(
                    "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} cells, {cells_rate}, ETA {cells_eta}",
                )
                .expect("the template is valid")
                .with_key("cells_rate", move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let (rate, _) = rate_and_eta(s.pos(), resumed, s.len().unwrap_or(0), s.elapsed());
                    let _ = write!(w, "{rate:.0}/s");
                })
                .with_key("cells_eta", move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let (_, eta) = rate_and_eta(s.pos(), resumed, s.len().unwrap_or(0), s.elapsed());
                    let _ = write!(w, "{}", format_duration(eta));
                });
                bar.disable_steady_tick();
                bar.set_message("");
                bar.set_style(style);
                bar.set_prefix(format!("run {}", self.name));
                bar.set_length(total);
                bar.set_position(done);
                bar.reset_elapsed();
                if done > 0 {
                    bar.println(format!("resuming: {done} of {total} cells already done"));
                }
            }
            Mode::Lines { .. } => {
                if done > 0 {
                    say!(
                        "run {}: resuming, {done} of {total} cells already done",
                        self.name
                    );
                }
                self.line();
            }
            Mode::Quiet => {}
        }
    }

    fn advance(&self, cells: u64) {
        self.done.fetch_add(cells, Ordering::Relaxed);
        match &self.mode {
            Mode::Bar(bar) => bar.inc(cells),
            Mode::Lines { last } => {
                let mut last = last.lock().unwrap();
                if last.elapsed() >= LINE_INTERVAL {
                    *last = Instant::now();
                    drop(last);
                    self.line();
                }
            }
            Mode::Quiet => {}
        }
    }

    fn retract(&self, cells: u64) {
        self.done.fetch_sub(cells, Ordering::Relaxed);
        self.resumed.fetch_sub(cells, Ordering::Relaxed);
        match &self.mode {
            Mode::Bar(bar) => {
                bar.set_position(bar.position().saturating_sub(cells));
                bar.println(format!(
                    "a damaged unit of the journal ({cells} cells) is computed again"
                ));
            }
            Mode::Lines { .. } => say!(
                "run {}: a damaged unit of the journal ({cells} cells) is computed again",
                self.name
            ),
            Mode::Quiet => {}
        }
    }

    fn dropped(&self, cells: u64) {
        self.done.fetch_sub(cells, Ordering::Relaxed);
        if let Mode::Bar(bar) = &self.mode {
            bar.set_position(bar.position().saturating_sub(cells));
        }
    }

    fn laying_out(&self) {
        match &self.mode {
            Mode::Bar(bar) => {
                bar.set_style(
                    ProgressStyle::with_template("{prefix} [{elapsed_precise}] {spinner} {msg}")
                        .expect("the template is valid"),
                );
                bar.set_prefix(format!("run {}", self.name));
                bar.set_message("laying out the component axis (the grid's critical points)");
                bar.enable_steady_tick(Duration::from_millis(200));
            }
            Mode::Lines { .. } => say!(
                "run {}: laying out the component axis (the grid's critical points)",
                self.name
            ),
            Mode::Quiet => {}
        }
    }

    fn writing(&self) {
        match &self.mode {
            Mode::Bar(bar) => bar.set_message("writing the file"),
            // The last tally first: every cell is done when the file is written (it came
            // after "writing the file": an adversary pass).
            Mode::Lines { .. } => {
                self.writing.store(true, Ordering::Relaxed);
                self.line();
                say!("run {}: writing the file", self.name);
            }
            Mode::Quiet => {}
        }
    }
}
