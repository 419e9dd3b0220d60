//! Progress on stderr while `run` works: one spinner per operation being planned (operations
//! plan in parallel) and a bar over the moves of the verification. Drawn only when stderr is
//! a terminal (indicatif hides its bars otherwise) and not with `run --quiet`; the stage
//! lines (`[impeller-cam] planning operations …`) are printed either way unless quiet.

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The progress display of one run.
#[derive(Debug, Clone)]
pub struct Progress {
    multi: MultiProgress,
    quiet: bool,
}

impl Progress {
    /// A display on stderr (hidden with `quiet`).
    pub fn new(quiet: bool) -> Self {
        let target = if quiet {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        };
        Self {
            multi: MultiProgress::with_draw_target(target),
            quiet,
        }
    }

    /// Whether the display is quiet (no stage lines either).
    pub fn quiet(&self) -> bool {
        self.quiet
    }

    /// A stage line (`[impeller-cam] {name} …`), printed above any bar.
    pub fn stage(&self, name: &str) {
        if !self.quiet {
            let line = format!("[impeller-cam] {name} …");
            if self.multi.is_hidden() {
                eprintln!("{line}");
            } else {
                let _ = self.multi.println(line);
            }
        }
    }

    /// A spinner for one operation being planned; finish it with [`Task::done`]. Without a
    /// terminal (a log file, CI) there is no spinner: the start and the summary are printed
    /// as stage lines instead, so a long planning run still shows which operations are under
    /// way and which are done.
    pub fn task(&self, what: String) -> Task {
        if self.multi.is_hidden() {
            self.stage(&what);
            return Task {
                bar: ProgressBar::hidden(),
                lines: !self.quiet,
            };
        }
        let bar = self.multi.add(ProgressBar::new_spinner());
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} {elapsed:>4}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_message(what);
        bar.enable_steady_tick(Duration::from_millis(120));
        Task { bar, lines: false }
    }

    /// A bar over `total` units (moves) with a message.
    pub fn bar(&self, total: u64, what: &str) -> ProgressBar {
        let bar = self.multi.add(ProgressBar::new(total));
        bar.set_style(
            ProgressStyle::with_template(
                "{msg} [{bar:30}] {pos}/{len} moves {elapsed:>4} (eta {eta})",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar.set_message(what.to_string());
        bar
    }
}

/// A spinner of [`Progress::task`].
#[derive(Debug)]
pub struct Task {
    bar: ProgressBar,
    /// Print the summary as a line (no terminal, not quiet).
    lines: bool,
}

/// How often a task without a terminal prints how far its planning has come.
const PROGRESS_LINE_EVERY: Duration = Duration::from_secs(10);

/// What an operation reports while it plans ([`cam_plan::PlanProgress`]), shown on its
/// task: on a terminal as the spinner's message (`planning rest (rest_finishing): 78/359
/// samples above the threshold (22 %)`), without one as a line at most every
/// [`PROGRESS_LINE_EVERY`] (a long planning in a log still shows it moves), nothing when
/// quiet; the message is formatted only when it is shown.
#[derive(Debug)]
pub struct TaskProgress {
    bar: ProgressBar,
    what: String,
    lines: bool,
    last_line: Mutex<Instant>,
}

impl Task {
    /// The listener an operation's planning reports to, labelled `what` (the task's own
    /// message).
    pub fn listener(&self, what: String) -> TaskProgress {
        TaskProgress {
            bar: self.bar.clone(),
            what,
            lines: self.lines,
            last_line: Mutex::new(Instant::now()),
        }
    }

    /// Ends the spinner, leaving `summary` in its place (or prints it as a line).
    pub fn done(self, summary: String) {
        if self.lines {
            eprintln!("[impeller-cam] {summary}");
        }
        self.bar.finish_with_message(summary);
    }
}

impl TaskProgress {
    /// The message of a report: `{task}: {done}/{total} {what} ({percent} %)`.
    fn message(&self, what: &str, done: usize, total: usize) -> String {
        let pct = if total > 0 {
            100.0 * done as f64 / total as f64
        } else {
            100.0
        };
        format!("{}: {done}/{total} {what} ({pct:.0} %)", self.what)
    }
}

impl cam_plan::PlanProgress for TaskProgress {
    fn report(&self, what: &str, done: usize, total: usize) {
        if self.lines {
            // A poisoned lock only means another report panicked: keep reporting.
            let mut last = self
                .last_line
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            if last.elapsed() >= PROGRESS_LINE_EVERY {
                *last = Instant::now();
                eprintln!("[impeller-cam] {}", self.message(what, done, total));
            }
        } else if !self.bar.is_hidden() {
            self.bar.set_message(self.message(what, done, total));
        }
    }
}
