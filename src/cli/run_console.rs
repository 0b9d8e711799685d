//! The console of `rotorsim run`: its first line, then per model a progress bar on a terminal,
//! plain progress lines otherwise.
use crate::run::job::{RotorModel, RunObserver, RunStart};
use crate::run::{fmt_measure, Progress};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::OnceLock;
use std::time::Instant;

/// Progress bars, one per model, on a terminal.
struct Bars {
    bars: Vec<ProgressBar>,
}

impl Bars {
    fn new(names: &[String], revs: usize) -> Self {
        let mp = MultiProgress::with_draw_target(ProgressDrawTarget::stderr());
        let style = ProgressStyle::with_template(
            "{prefix:>10} [{bar:30}] rev {pos}/{len} {msg} ({elapsed})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
        let bars = names
            .iter()
            .map(|m| {
                let b = mp.add(ProgressBar::new(revs as u64));
                b.set_style(style.clone());
                b.set_prefix(m.clone());
                b.set_message("starting");
                b
            })
            .collect();
        Bars { bars }
    }
}

impl Progress for Bars {
    fn revolution(&self, i: usize, rev: usize, _revs: usize, m: Option<f64>) {
        let b = &self.bars[i];
        b.set_position(rev as u64);
        b.set_message(format!("periodicity {}", fmt_measure(m)));
    }
    fn finished(&self, i: usize, ok: bool, message: &str) {
        let b = &self.bars[i];
        if ok {
            b.finish_with_message(message.to_string());
        } else {
            b.abandon_with_message(format!("FAILED: {message}"));
        }
    }
}

/// Seconds between plain progress lines when stderr is not a terminal (logs, batch jobs).
const PLAIN_PROGRESS_EVERY_S: f64 = 5.0;

/// Plain progress lines on a stderr that is not a terminal: per model, a line at most every
/// `every` seconds (revolution, periodicity, elapsed time), and one when it ends.
struct Lines {
    names: Vec<String>,
    every: f64,
    start: Instant,
    last: std::sync::Mutex<Vec<f64>>,
}

impl Lines {
    fn new(names: &[String], every: f64) -> Self {
        Lines {
            names: names.to_vec(),
            every,
            start: Instant::now(),
            last: std::sync::Mutex::new(vec![f64::NEG_INFINITY; names.len()]),
        }
    }
}

impl Progress for Lines {
    fn revolution(&self, i: usize, rev: usize, revs: usize, m: Option<f64>) {
        let now = self.start.elapsed().as_secs_f64();
        let due = match self.last.lock() {
            Ok(mut last) if now - last[i] >= self.every => {
                last[i] = now;
                true
            }
            _ => false,
        };
        if due {
            errln!(
                "{}: revolution {rev} of at most {revs}, periodicity {}, {now:.0} s",
                self.names[i],
                fmt_measure(m)
            );
        }
    }
    fn finished(&self, i: usize, ok: bool, message: &str) {
        let now = self.start.elapsed().as_secs_f64();
        let state = if ok { "done" } else { "FAILED" };
        errln!("{}: {state} after {now:.1} s: {message}", self.names[i]);
    }
}

/// The console of a run: its first line, then progress bars on a terminal, plain lines
/// otherwise (logs, batch jobs).
#[derive(Default)]
pub struct Console {
    display: OnceLock<Box<dyn Progress + Send>>,
}

impl RunObserver for Console {
    fn start(&self, s: &RunStart) {
        let names: Vec<&str> = s.models.iter().map(|m| m.name()).collect();
        errln!(
            "rotorsim run: {} model(s) {}{}, {} to a residual of {:.0e}, at most {} revolutions x {} steps{}",
            s.models.len(),
            names.join(", "),
            match (s.blades, s.airframe) {
                (Some(n), true) => format!(" on all {n} blades of a hub on the airframe"),
                (Some(n), false) => format!(" on all {n} blades of a driven hub"),
                (None, _) => String::new(),
            },
            s.method.name(),
            s.tol,
            s.revs,
            s.steps_per_rev,
            match s.model {
                RotorModel::Sdof => " (lag-hinge TEST DOUBLE, --model sdof)",
                RotorModel::Rigid => " (rigid-blade reduction of the rotor deck, --model rigid)",
                RotorModel::Uh60a => "",
            }
        );
        let display: Box<dyn Progress + Send> = if std::io::stderr().is_terminal() {
            Box::new(Bars::new(&s.units, s.revs))
        } else {
            Box::new(Lines::new(&s.units, PLAIN_PROGRESS_EVERY_S))
        };
        let _ = self.display.set(display);
    }
}

impl Progress for Console {
    fn revolution(&self, i: usize, rev: usize, revs: usize, m: Option<f64>) {
        if let Some(d) = self.display.get() {
            d.revolution(i, rev, revs, m);
        }
    }
    fn finished(&self, i: usize, ok: bool, message: &str) {
        if let Some(d) = self.display.get() {
            d.finished(i, ok, message);
        }
    }
}
