//! Python bindings of rotorsim (module `rotorsim._native`, wrapped by the `rotorsim` package).
//! Every computation is a call of the rotorsim library; this crate converts arguments and
//! results and maps errors to Python exceptions (nothing here panics on user input).
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;
use rotorsim::hydraulics::bench::{self, BenchTest};
use rotorsim::hydraulics::{DamperDeck, DamperModel, DeckError, Device, IntegratorOptions, Scheme};
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
    fn replay(
        &self,
        py: Python<'_>,
        time_s: Vec<f64>,
        stroke_m: Vec<f64>,
    ) -> PyResult<bench::Replay> {
        let source = format!("stroke history for deck {}", self.deck.source);
        let test = BenchTest::from_arrays(&source, time_s, stroke_m)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        if self.model == DamperModel::Physical {
            let d = test.stroke_m.iter().fold(0.0f64, |a, d| a.max(d.abs()));
            self.deck
                .check_stroke(d, "stroke history")
                .map_err(PyValueError::new_err)?;
        }
        py.detach(|| bench::replay(self.device.as_ref(), &test))
            .map_err(|e| {
                let mut msg = format!(
                    "replay of the stroke history with the {} model: {e}",
                    self.model.name()
                );
                if self.model == DamperModel::Physical {
                    msg = self.deck.with_review(msg);
                }
                PyValueError::new_err(msg)
            })
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
        let r = self.replay(py, values(&time_s), values(&stroke_m))?;
        Ok(PyArray1::from_vec(py, r.force_model_n))
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

#[pymodule]
#[pyo3(name = "_native")]
fn native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Damper>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
