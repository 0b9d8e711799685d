//! Python bindings of rotorsim (module `rotorsim._native`, wrapped by the `rotorsim` package).
//! Every computation is a call of the rotorsim library; this crate converts arguments and
//! results and maps errors to Python exceptions (nothing here panics on user input).
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;
use rotorsim::hydraulics::bench::{self, BenchTest};
use rotorsim::hydraulics::{
    DamperDeck, DamperModel, DeckError, Device, HydraulicError, IntegratorOptions, Scheme,
};
use rotorsim::overrides::Override;
use rotorsim::run::job::{NamedOptions, RunJob, RunObserver, RunStart};
use rotorsim::run::Progress;
use std::path::PathBuf;

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
    ) -> PyResult<bench::Replay> {
        let test = self.check(time_s, stroke_m)?;
        py.detach(|| bench::replay(self.device.as_ref(), &test))
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
            .detach(|| bench::replay_force(self.device.as_ref(), &test.time_s, &test.stroke_m))
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
    let missing = e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::NotFound)
    });
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

/// A result folder's files: the folder, summary.json and each model's last_rev.csv.
type RunFiles = (PathBuf, PathBuf, Vec<(String, PathBuf)>);

/// `rotorsim run` as a library call: the CLI's defaults for every option not given, the same
/// checks and messages. Returns the result folder's files: (folder, summary, [(model, last_rev)]).
#[pyfunction]
#[pyo3(signature = (out, rotor = None, flight = None, damper = "all", set = Vec::new(),
    all_blades = false, airloads = "measured", revs = None, steps_per_rev = None,
    substeps = None, progress = None))]
#[allow(clippy::too_many_arguments)]
fn run(
    py: Python<'_>,
    out: PathBuf,
    rotor: Option<PathBuf>,
    flight: Option<PathBuf>,
    damper: &str,
    set: Vec<String>,
    all_blades: bool,
    airloads: &str,
    revs: Option<usize>,
    steps_per_rev: Option<usize>,
    substeps: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<RunFiles> {
    let mut job = RunJob::new(out);
    if let Some(r) = rotor {
        job.rotor = r;
    }
    if !job.rotor.exists() {
        return Err(PyFileNotFoundError::new_err(format!(
            "rotor deck {}: no such file",
            job.rotor.display()
        )));
    }
    if let Some(f) = flight {
        job.flight = f;
    }
    job.revs = revs.unwrap_or(job.revs);
    job.steps_per_rev = steps_per_rev.unwrap_or(job.steps_per_rev);
    job.substeps = substeps.unwrap_or(job.substeps);
    job.all_blades = all_blades;
    job.overrides = set
        .iter()
        .map(|s| Override::parse(s))
        .collect::<anyhow::Result<_>>()
        .map_err(run_error)?;
    job.set_named(&NamedOptions {
        damper,
        airloads,
        ..NamedOptions::default()
    })
    .map_err(run_error)?;
    let observer = PyProgress(progress);
    let outcome = py.detach(|| job.execute(&observer)).map_err(run_error)?;
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

#[pymodule]
#[pyo3(name = "_native")]
fn native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Damper>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
