//! Python bindings of rotorsim (module `rotorsim._native`, wrapped by the `rotorsim` package).
//! Every computation is a call of the rotorsim library; this crate converts arguments and
//! results and maps errors to Python exceptions (nothing here panics on user input).
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyFileNotFoundError, PyKeyboardInterrupt, PyOSError, PyValueError};
use pyo3::prelude::*;
use rotorsim::checks::bench::BenchSettings;
use rotorsim::checks::modes::ModesSettings;
use rotorsim::diagnose::pipeline::Config as DiagnoseConfig;
use rotorsim::diagnose::settings::DiagnoseSettings;
use rotorsim::hydraulics::bench::{self as damper_bench, BenchTest};
use rotorsim::hydraulics::{
    DamperDeck, DamperModel, DeckError, Device, HydraulicError, IntegratorOptions, Scheme,
};
use rotorsim::resonance::StabilitySettings;
use rotorsim::run::job::{RunObserver, RunSettings, RunStart};
use rotorsim::run::settings::JobSettings;
use rotorsim::run::stop::{RunStopped, StopFlag, STOPPED_PREFIX};
use rotorsim::run::Progress;
use rotorsim::sweep::job::{resolve_shard, SweepJob};
use rotorsim::sweep::{Case, SweepProgress};
use std::path::PathBuf;
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::time::Duration;

fn deck_error(e: DeckError) -> PyErr {
    let msg = e.to_string();
    match &e {
        DeckError::Read { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(msg)
        }
        DeckError::Read { .. } => PyOSError::new_err(msg),
        _ => PyValueError::new_err(msg),
    }
}

/// A damper device built from a damper deck; see the `rotorsim.Damper` wrapper.
#[pyclass(module = "rotorsim._native", frozen)]
struct Damper {
    deck: DamperDeck,
    model: DamperModel,
    device: Box<dyn Device>,
    substeps: usize,
    scheme: String,
}

/// The replay's columns: time, stroke, velocity, force and the device's channels, as numpy
/// arrays (no Python lists in between).
type Columns<'py> = Vec<(String, Bound<'py, PyArray1<f64>>)>;

/// A one-dimensional float64 array's values (a copy: the replay runs without the GIL).
fn values(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

impl Damper {
    /// The stroke history checked as the bench CSV reader checks a file, and against the
    /// physical damper's travel.
    fn check(&self, time_s: Vec<f64>, stroke_m: Vec<f64>) -> PyResult<BenchTest> {
        let source = format!("stroke history for deck {}", self.deck.source);
        let test = BenchTest::from_arrays(&source, time_s, stroke_m)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        if self.model == DamperModel::Physical {
            let d = test.stroke_m.iter().fold(0.0f64, |a, d| a.max(d.abs()));
            self.deck
                .check_stroke(d, "stroke history")
                .map_err(PyValueError::new_err)?;
        }
        Ok(test)
    }

    fn replay_error(&self, e: HydraulicError) -> PyErr {
        let mut msg = format!(
            "replay of the stroke history with the {} model: {e}",
            self.model.name()
        );
        if self.model == DamperModel::Physical {
            msg = self.deck.with_review(msg);
        }
        PyValueError::new_err(msg)
    }

    fn replay(
        &self,
        py: Python<'_>,
        time_s: Vec<f64>,
        stroke_m: Vec<f64>,
    ) -> PyResult<damper_bench::Replay> {
        let test = self.check(time_s, stroke_m)?;
        py.detach(|| damper_bench::replay(self.device.as_ref(), &test))
            .map_err(|e| self.replay_error(e))
    }
}

#[pymethods]
impl Damper {
    #[new]
    #[pyo3(signature = (deck, model = "physical", substeps = 25, scheme = "rk4"))]
    fn new(deck: PathBuf, model: &str, substeps: usize, scheme: &str) -> PyResult<Self> {
        let d = DamperDeck::from_file(&deck).map_err(deck_error)?;
        let m: DamperModel = model
            .parse()
            .map_err(|e: String| PyValueError::new_err(format!("model {model}: {e}")))?;
        let s: Scheme = scheme
            .parse()
            .map_err(|e| PyValueError::new_err(format!("scheme {scheme}: {e}")))?;
        if substeps == 0 {
            return Err(PyValueError::new_err("substeps must be >= 1"));
        }
        let opts = IntegratorOptions {
            scheme: s,
            substeps,
        };
        let device = d.build(m, opts).map_err(deck_error)?;
        Ok(Self {
            deck: d,
            model: m,
            device,
            substeps,
            scheme: scheme.to_string(),
        })
    }

    /// Force [N] at each sample of the stroke history (the first: the device's initial force).
    fn force<'py>(
        &self,
        py: Python<'py>,
        time_s: PyReadonlyArray1<'py, f64>,
        stroke_m: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (time_s, stroke_m) = (values(&time_s), values(&stroke_m));
        let test = self.check(time_s, stroke_m)?;
        let force = py
            .detach(|| {
                damper_bench::replay_force(self.device.as_ref(), &test.time_s, &test.stroke_m)
            })
            .map_err(|e| self.replay_error(e))?;
        Ok(PyArray1::from_vec(py, force))
    }

    /// The replay's columns (name, values): time_s, stroke_m, velocity_m_s, force_N and the
    /// device's internal channels, named with their units.
    fn states<'py>(
        &self,
        py: Python<'py>,
        time_s: PyReadonlyArray1<'py, f64>,
        stroke_m: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Columns<'py>> {
        let h = self.replay(py, values(&time_s), values(&stroke_m))?.history;
        let mut cols: Vec<(String, Vec<f64>)> = vec![
            ("time_s".to_string(), h.time_s),
            ("stroke_m".to_string(), h.stroke_m),
            ("velocity_m_s".to_string(), h.velocity_m_s),
            ("force_N".to_string(), h.force_n),
        ];
        cols.extend(
            h.channel_names
                .iter()
                .map(|n| n.to_string())
                .zip(h.channels),
        );
        Ok(cols
            .into_iter()
            .map(|(n, v)| (n, PyArray1::from_vec(py, v)))
            .collect())
    }

    /// Names (with units) of the device's internal channels.
    #[getter]
    fn channel_names(&self) -> Vec<&'static str> {
        self.device.channel_names().to_vec()
    }

    #[getter]
    fn model(&self) -> &'static str {
        self.model.name()
    }

    #[getter]
    fn deck(&self) -> String {
        self.deck.source.clone()
    }

    #[getter]
    fn substeps(&self) -> usize {
        self.substeps
    }

    #[getter]
    fn scheme(&self) -> String {
        self.scheme.clone()
    }
}

/// A run's error as a Python exception: FileNotFoundError when a file is missing, else
/// ValueError, with the library's whole message (file, key and what was expected).
fn run_error(e: anyhow::Error) -> PyErr {
    let msg = rotorsim::cli::error_chain(&e);
    // some readers keep only the io error's text (ENOENT reads "... (os error 2)")
    let missing = e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::NotFound)
    }) || msg.contains("(os error 2)");
    if missing {
        PyFileNotFoundError::new_err(msg)
    } else {
        PyValueError::new_err(msg)
    }
}

/// Progress of a run handed to a Python callable `progress(event: dict)` (called with the GIL
/// taken; an exception in it is printed and the run goes on).
struct PyProgress(Option<Py<PyAny>>);

impl PyProgress {
    fn send(&self, make: impl FnOnce(Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyDict>>) {
        if let Some(cb) = &self.0 {
            Python::attach(|py| {
                if let Err(e) = make(py).and_then(|ev| cb.call1(py, (ev,))) {
                    e.print(py);
                }
            });
        }
    }
}

impl Progress for PyProgress {
    fn revolution(&self, index: usize, rev: usize, revs: usize, measure: Option<f64>) {
        self.send(|py| {
            let d = pyo3::types::PyDict::new(py);
            d.set_item("event", "revolution")?;
            d.set_item("unit", index)?;
            d.set_item("revolution", rev)?;
            d.set_item("of", revs)?;
            d.set_item("periodicity", measure)?;
            Ok(d)
        });
    }
    fn finished(&self, index: usize, ok: bool, message: &str) {
        self.send(|py| {
            let d = pyo3::types::PyDict::new(py);
            d.set_item("event", "finished")?;
            d.set_item("unit", index)?;
            d.set_item("ok", ok)?;
            d.set_item("message", message)?;
            Ok(d)
        });
    }
}

impl RunObserver for PyProgress {
    fn start(&self, start: &RunStart) {
        self.send(|py| {
            let d = pyo3::types::PyDict::new(py);
            d.set_item("event", "start")?;
            d.set_item("units", start.units.clone())?;
            d.set_item("revs", start.revs)?;
            Ok(d)
        });
    }
}

/// How often a call running without the GIL looks for Ctrl-C.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Runs `work` without the GIL on a thread of its own while the calling thread (Python's main
/// thread, where signal handlers run) looks for signals: an exception from a handler (Ctrl-C's
/// KeyboardInterrupt) raises `stop`, which `work` checks, and is returned beside its result once
/// it has ended.
fn interruptible<T: Send>(
    py: Python<'_>,
    stop: &StopFlag,
    work: impl FnOnce() -> T + Send,
) -> (T, Option<PyErr>) {
    py.detach(|| {
        std::thread::scope(|scope| {
            let (done, ended) = channel();
            let worker = scope.spawn(move || {
                let v = work();
                let _ = done.send(());
                v
            });
            let mut signal = None;
            // a closed channel: the worker panicked (its panic is raised by the join)
            while let Err(RecvTimeoutError::Timeout) = ended.recv_timeout(SIGNAL_POLL) {
                if signal.is_none() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        stop.request();
                        signal = Some(e);
                    }
                }
            }
            match worker.join() {
                Ok(v) => (v, signal),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        })
    })
}

/// The exception of a call interrupted by `signal`: a KeyboardInterrupt says where the run
/// stopped (when it did); any other exception from a signal handler is raised as it is.
fn interrupted<T>(py: Python<'_>, signal: PyErr, result: &anyhow::Result<T>) -> PyErr {
    let stopped = result
        .as_ref()
        .err()
        .and_then(|e| e.downcast_ref::<RunStopped>());
    match stopped {
        Some(s) if signal.is_instance_of::<PyKeyboardInterrupt>(py) => {
            PyKeyboardInterrupt::new_err(s.to_string())
        }
        _ => signal,
    }
}

/// A result folder's files: the folder, summary.json and each model's last_rev.csv.
type RunFiles = (PathBuf, PathBuf, Vec<(String, PathBuf)>);

/// `rotorsim run` as a library call: `settings`, a JSON object of [`RunSettings`] fields (the
/// CLI's options by their names; the CLI's default for every one not given), the same checks
/// and messages; Ctrl-C stops it (KeyboardInterrupt). Returns the result folder's files:
/// (folder, summary, [(model, last_rev)]).
#[pyfunction]
#[pyo3(signature = (out, settings = "{}", progress = None))]
fn run(
    py: Python<'_>,
    out: PathBuf,
    settings: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<RunFiles> {
    let settings = RunSettings::from_json(settings).map_err(run_error)?;
    if !settings.rotor.exists() {
        return Err(PyFileNotFoundError::new_err(format!(
            "rotor deck {}: no such file",
            settings.rotor.display()
        )));
    }
    let job = settings.job(out).map_err(run_error)?;
    let observer = PyProgress(progress);
    let stop = StopFlag::new();
    let (result, signal) = interruptible(py, &stop, || job.execute_until(&observer, &stop));
    if let Some(signal) = signal {
        return Err(interrupted(py, signal, &result));
    }
    let outcome = result.map_err(run_error)?;
    let p = outcome.published;
    Ok((
        p.folder,
        p.summary,
        p.last_rev
            .into_iter()
            .map(|(m, f)| (m.name().to_string(), f))
            .collect(),
    ))
}

/// The options of `rotorsim run` by name with their defaults, as JSON (what `run` takes).
#[pyfunction]
fn run_options() -> String {
    RunSettings::defaults_json()
}

/// The options of each job by name with their defaults, as JSON (what its function takes):
/// `run`, `bench`, `stability` or `modes`.
#[pyfunction]
fn job_options(job: &str) -> PyResult<String> {
    match job {
        "run" => Ok(RunSettings::defaults_json()),
        "bench" => Ok(BenchSettings::defaults_json()),
        "stability" => Ok(StabilitySettings::defaults_json()),
        "modes" => Ok(ModesSettings::defaults_json()),
        _ => Err(PyValueError::new_err(format!(
            "job {job}: expected run, bench, stability or modes"
        ))),
    }
}

/// `rotorsim bench` as a library call: `settings`, a JSON object of [`BenchSettings`] fields
/// (the command's options by their names; its default for every one not given), the same
/// checks and messages. Returns the result folder.
#[pyfunction]
#[pyo3(name = "bench", signature = (out, settings = "{}"))]
fn bench_job(py: Python<'_>, out: PathBuf, settings: &str) -> PyResult<PathBuf> {
    let job = BenchSettings::from_json(settings)
        .and_then(|s| s.job(out))
        .map_err(run_error)?;
    py.detach(|| job.execute(&mut |_, _, _| {}, &mut |_| {}))
        .map_err(run_error)?;
    Ok(job.out)
}

/// `rotorsim stability` as a library call: `settings`, a JSON object of [`StabilitySettings`]
/// fields (the command's options by their names; its default for every one not given), the
/// same checks and messages. Returns the result folder.
#[pyfunction]
#[pyo3(signature = (out, settings = "{}"))]
fn stability(py: Python<'_>, out: PathBuf, settings: &str) -> PyResult<PathBuf> {
    let job = StabilitySettings::from_json(settings)
        .and_then(|s| s.job(out))
        .map_err(run_error)?;
    py.detach(|| job.execute(&mut |_| {})).map_err(run_error)?;
    Ok(job.out)
}

/// `rotorsim modes` as a library call: `settings`, a JSON object of [`ModesSettings`] fields
/// (the command's options by their names; its default for every one not given), the same
/// checks and messages. Give `deck` (a model deck) or `rotor` (a rotor deck's fan plot).
/// Returns the result folder.
#[pyfunction]
#[pyo3(signature = (out, settings = "{}"))]
fn modes(py: Python<'_>, out: PathBuf, settings: &str) -> PyResult<PathBuf> {
    let job = ModesSettings::from_json(settings)
        .and_then(|s| s.job(out))
        .map_err(run_error)?;
    py.detach(|| job.execute(&mut |_| {})).map_err(run_error)?;
    Ok(job.out)
}

/// `rotorsim diagnose` as a library call: `settings` is a JSON object of its options (the
/// fields of `DiagnoseSettings`, the command line's names), every other the command's default;
/// the same checks and messages. `progress` gets its progress lines. Returns the result folder.
#[pyfunction]
#[pyo3(signature = (out, settings, progress = None))]
fn diagnose(
    py: Python<'_>,
    out: PathBuf,
    settings: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<PathBuf> {
    let cfg = DiagnoseSettings::from_json(settings)
        .map_err(run_error)?
        .job(out);
    let say = |line: &str| {
        if let Some(cb) = &progress {
            Python::attach(|py| {
                if let Err(e) = cb.call1(py, (line,)) {
                    e.print(py);
                }
            });
        }
    };
    py.detach(|| rotorsim::diagnose::pipeline::run(&cfg, &say))
        .map_err(run_error)?;
    Ok(cfg.out)
}

/// The options of `rotorsim diagnose` by name with their defaults, as JSON (what `diagnose`
/// takes).
#[pyfunction]
fn diagnose_options() -> String {
    DiagnoseSettings::defaults_json()
}

/// Progress of a sweep handed to a Python callable `progress(event: dict)` (called with the GIL
/// taken; an exception in it is printed and the sweep goes on).
struct PySweepProgress(Option<Py<PyAny>>);

impl SweepProgress for PySweepProgress {
    fn start(&self, to_run: usize, total: usize) {
        if let Some(cb) = &self.0 {
            Python::attach(|py| {
                let ev = pyo3::types::PyDict::new(py);
                let r = ev
                    .set_item("event", "start")
                    .and_then(|_| ev.set_item("to_run", to_run))
                    .and_then(|_| ev.set_item("total", total))
                    .and_then(|_| cb.call1(py, (ev,)));
                if let Err(e) = r {
                    e.print(py);
                }
            });
        }
    }
    fn case_done(&self, case: &Case, result: &Result<(), String>, wall_s: f64) {
        if let Some(cb) = &self.0 {
            Python::attach(|py| {
                let ev = pyo3::types::PyDict::new(py);
                let r = ev
                    .set_item("event", "case")
                    .and_then(|_| ev.set_item("case", &case.id))
                    .and_then(|_| ev.set_item("ok", result.is_ok()))
                    .and_then(|_| ev.set_item("message", result.as_ref().err()))
                    .and_then(|_| ev.set_item("wall_s", wall_s))
                    .and_then(|_| cb.call1(py, (ev,)));
                if let Err(e) = r {
                    e.print(py);
                }
            });
        }
    }
}

/// `rotorsim sweep PLAN --out DIR` as a library call: the command's defaults for every option
/// not given, the same checks and messages; Ctrl-C stops it (KeyboardInterrupt). Returns the
/// sweep folder and the failed cases (id, reason).
#[pyfunction]
#[pyo3(signature = (plan, out, jobs = None, shard = None, retry_failed = false,
    warm_start = None, progress = None))]
#[allow(clippy::too_many_arguments)]
fn sweep(
    py: Python<'_>,
    plan: PathBuf,
    out: PathBuf,
    jobs: Option<usize>,
    shard: Option<String>,
    retry_failed: bool,
    warm_start: Option<bool>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(PathBuf, Vec<(String, String)>)> {
    if jobs == Some(0) {
        return Err(PyValueError::new_err(
            "jobs: expected a whole number of at least 1, found 0",
        ));
    }
    let job = SweepJob {
        jobs,
        shard: resolve_shard(shard.as_deref()).map_err(run_error)?,
        retry_failed,
        warm_start,
        ..SweepJob::new(plan, out)
    };
    let plan = job.read_plan().map_err(run_error)?;
    let observer = PySweepProgress(progress);
    let stop = job.stop.clone();
    let (result, signal) = interruptible(py, &stop, || {
        job.execute(&plan, &|_, _| {}, &observer, &mut |_| {})
    });
    if let Some(signal) = signal {
        if !signal.is_instance_of::<PyKeyboardInterrupt>(py) {
            return Err(signal);
        }
        let msg = match &result {
            Ok(o) => {
                let r = &o.report;
                let stopped = r
                    .ran
                    .iter()
                    .filter(|(_, r)| r.as_ref().is_err_and(|e| e.starts_with(STOPPED_PREFIX)))
                    .count();
                let ok = r.skipped.len() + r.ran.iter().filter(|(_, r)| r.is_ok()).count();
                format!(
                    "sweep stopped by the user: {ok} of {} case(s) complete, {stopped} stopped or not started (a stopped case is marked incomplete: run the sweep again with retry_failed=True to finish it)",
                    r.total
                )
            }
            Err(e) => format!(
                "sweep stopped by the user: {}",
                rotorsim::cli::error_chain(e)
            ),
        };
        return Err(PyKeyboardInterrupt::new_err(msg));
    }
    let outcome = result.map_err(run_error)?;
    let mut failed: Vec<(String, String)> = outcome.report.failed_kept.clone();
    for (id, r) in &outcome.report.ran {
        if let Err(e) = r {
            failed.push((id.clone(), e.clone()));
        }
    }
    Ok((job.out, failed))
}

#[pymodule]
#[pyo3(name = "_native")]
fn native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Damper>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(run_options, m)?)?;
    m.add_function(wrap_pyfunction!(job_options, m)?)?;
    m.add_function(wrap_pyfunction!(bench_job, m)?)?;
    m.add_function(wrap_pyfunction!(stability, m)?)?;
    m.add_function(wrap_pyfunction!(modes, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose_options, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
