//! `[nbody]` and `[md]` model files from Python: `pdyn.Model.from_file` on such a file holds a
//! [`PyParticleModel`], whose `run` calls the library entry `pdyn run` calls (`pdyn::run`)
//! with the GIL released and returns
//! plain data: the summary (the text of the CLI's `summary.json`), warnings, the failure, and
//! the tables as float64 arrays (the Python layer builds `pdyn.ParticleResult`).

use crate::convert::{f64_array, f64_matrix};
use crate::errors::{guarded, to_py};
use pdyn::model_file::{Kind, ModelFile};
use pdyn::{Error, RunOutput};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// An N-body or molecular-dynamics model file, loaded.
#[pyclass(module = "pdyn._pdyn", name = "ParticleModel", frozen)]
pub(crate) struct PyParticleModel {
    file: ModelFile,
    /// The model's name and parameters, read when it was loaded (its errors raised then).
    name: String,
    parameters: Vec<(String, f64)>,
}

/// The model `file` checked as `pdyn run` reads it (every located error at load time).
pub(crate) fn load(file: ModelFile) -> Result<PyParticleModel, Error> {
    let (name, parameters) = match file.kind {
        Kind::Nbody => {
            let spec = pdyn::nbody::load(&file.source, &file.origin, &[])?;
            (spec.name, spec.parameters)
        }
        Kind::Md => {
            let spec = pdyn::md::load(&file.source, &file.origin, &[])?;
            (spec.name, spec.parameters)
        }
        Kind::Mechanics => {
            return Err(Error::argument(
                "model",
                "a mechanics model is a pdyn.Model of its own",
            ))
        }
    };
    Ok(PyParticleModel {
        file,
        name,
        parameters,
    })
}

#[pymethods]
impl PyParticleModel {
    /// `"nbody"` or `"md"`.
    #[getter]
    fn kind(&self) -> &'static str {
        match self.file.kind {
            Kind::Nbody => "nbody",
            _ => "md",
        }
    }

    /// The model's name.
    #[getter]
    fn name(&self) -> String {
        self.name.clone()
    }

    /// The TOML text.
    #[getter]
    fn source(&self) -> String {
        self.file.source.clone()
    }

    /// The file name used in messages.
    #[getter]
    fn origin(&self) -> String {
        self.file.origin.clone()
    }

    /// `[(name, value)]` of `[parameters]`, in file order.
    #[getter]
    fn parameters(&self) -> Vec<(String, f64)> {
        self.parameters.clone()
    }

    /// Raises the located error of a command for mechanics models only (derive, forces,
    /// sweep, ensemble) given this model: `pdyn run` runs it.
    fn refuse(&self, py: Python<'_>) -> PyResult<()> {
        guarded(py, || match self.file.mechanics() {
            Err(e) => Err(to_py(py, &e)),
            Ok(_) => Ok(()),
        })
    }

    /// Runs the model as `pdyn run` does (see `pdyn.Model.run`), through the same library
    /// entry (`pdyn::engine::run_long`); `out` writes the CLI's files there, and its plots
    /// with `plots`. `checkpoint_every` (`"15min"`, `"500steps"`, `"off"`) writes
    /// `out/checkpoint.json` as `pdyn run --checkpoint-every` does, `restart` continues from
    /// one as `--restart` does; with either, the rows go to the files as the run goes and an
    /// N-body result keeps only the first and last output (the files hold every row).
    #[pyo3(signature = (t_end=None, method=None, dt=None, points=None, t_eval=None, drift_tolerance=None, params=None, out=None, plots=false, jit=true, rtol=None, atol=None, max_step=None, max_steps=None, checkpoint_every=None, restart=None))]
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        py: Python<'_>,
        t_end: Option<f64>,
        method: Option<String>,
        dt: Option<f64>,
        points: Option<usize>,
        t_eval: Option<Vec<f64>>,
        drift_tolerance: Option<f64>,
        params: Option<Vec<(String, f64)>>,
        out: Option<PathBuf>,
        plots: bool,
        jit: bool,
        rtol: Option<f64>,
        atol: Option<f64>,
        max_step: Option<f64>,
        max_steps: Option<usize>,
        checkpoint_every: Option<String>,
        restart: Option<PathBuf>,
    ) -> PyResult<PyObject> {
        guarded(py, || {
            let every = checkpoint_every
                .as_deref()
                .map(pdyn::checkpoint::Every::parse)
                .transpose()
                .map_err(|m| {
                    to_py(
                        py,
                        &Error::argument("checkpoint_every", format!("checkpoint_every={m}")),
                    )
                })?;
            let long = pdyn::engine::LongRun {
                stream_only: restart.is_some()
                    || every.is_some_and(|e| e != pdyn::checkpoint::Every::Off),
                checkpoint_every: every,
                restart,
            };
            let req = pdyn::Request {
                method,
                rtol,
                atol,
                t_end,
                dt,
                max_step,
                max_steps,
                points,
                t_eval,
                drift_tolerance,
                params: params.unwrap_or_default(),
                jit: if jit {
                    pdyn::sim::JitMode::Auto
                } else {
                    pdyn::sim::JitMode::Off
                },
                out,
                plots,
                ..Default::default()
            };
            let finished = crate::interrupt::interruptible(py, |stop| {
                let req = pdyn::Request {
                    interrupt: Some(stop),
                    ..req
                };
                pdyn::engine::run_long(&self.file, &req, &long, &mut |_| {})
            })?;
            let ran = finished.value.map_err(|e| to_py(py, &e))?;
            let d = to_dict(py, ran)?;
            d.bind(py).set_item("interrupted", finished.interrupted)?;
            Ok(d)
        })
    }
}

/// Columns of equal length as a `(rows, len(names))` array and the names.
fn table(py: Python<'_>, names: &[&str], rows: Vec<Vec<f64>>) -> PyResult<PyObject> {
    let n = rows.len();
    let flat: Vec<f64> = rows.into_iter().flatten().collect();
    let d = PyDict::new(py);
    d.set_item("columns", names.to_vec())?;
    d.set_item("data", f64_matrix(py, flat, n, names.len())?)?;
    Ok(d.into_any().unbind())
}

fn to_dict(py: Python<'_>, ran: RunOutput) -> PyResult<PyObject> {
    let d = PyDict::new(py);
    d.set_item("summary", format!("{:#}", ran.summary()))?;
    d.set_item("failure", ran.failure().map(|f| f.to_string()))?;
    match ran {
        RunOutput::Mechanics(_) => return Err(crate::errors::pdyn_error(
            py,
            "PdynError",
            "internal error in pdyn (please report it): a mechanics model ran as a particle model"
                .into(),
        )),
        RunOutput::Nbody(run) => {
            let res = &run.result;
            d.set_item("kind", "nbody")?;
            d.set_item("warnings", res.warnings.clone())?;
            d.set_item("t", f64_array(py, res.times.clone()))?;
            d.set_item("names", res.names.clone())?;
            // trajectory.csv's rows: t, body index, mass, x, y, z, vx, vy, vz.
            let traj: Vec<Vec<f64>> = res
                .times
                .iter()
                .zip(&res.states)
                .flat_map(|(&t, states)| {
                    states.iter().map(move |s| {
                        vec![
                            t,
                            s.body as f64,
                            s.mass,
                            s.pos[0],
                            s.pos[1],
                            s.pos[2],
                            s.vel[0],
                            s.vel[1],
                            s.vel[2],
                        ]
                    })
                })
                .collect();
            d.set_item(
                "trajectory",
                table(
                    py,
                    &["t", "body", "mass", "x", "y", "z", "vx", "vy", "vz"],
                    traj,
                )?,
            )?;
            let nan = f64::NAN;
            let elements: Vec<Vec<f64>> = res
                .elements
                .iter()
                .map(|r| match r.orbit {
                    Some(o) => vec![
                        r.t,
                        r.body as f64,
                        o.a,
                        o.e,
                        o.inc,
                        o.Omega,
                        o.omega,
                        o.f,
                        o.M,
                        o.period,
                    ],
                    None => vec![r.t, r.body as f64, nan, nan, nan, nan, nan, nan, nan, nan],
                })
                .collect();
            d.set_item(
                "elements",
                table(
                    py,
                    &[
                        "t", "body", "a", "e", "inc", "Omega", "omega", "f", "M", "period",
                    ],
                    elements,
                )?,
            )?;
            let conservation: Vec<Vec<f64>> = res
                .conservation
                .iter()
                .map(|r| {
                    vec![
                        r.t,
                        r.n as f64,
                        r.energy,
                        r.kinetic,
                        r.potential,
                        r.angular_momentum[0],
                        r.angular_momentum[1],
                        r.angular_momentum[2],
                    ]
                })
                .collect();
            d.set_item(
                "conservation",
                table(
                    py,
                    &["t", "n", "energy", "kinetic", "potential", "Lx", "Ly", "Lz"],
                    conservation,
                )?,
            )?;
        }
        RunOutput::Md(run) => {
            let res = &run.result;
            d.set_item("kind", "md")?;
            d.set_item("warnings", res.warnings.clone())?;
            let thermo: Vec<Vec<f64>> = res
                .records
                .iter()
                .map(|r| {
                    vec![
                        r.step as f64,
                        r.time,
                        r.temperature,
                        r.kinetic,
                        r.potential,
                        r.total,
                        r.pressure,
                        r.conserved,
                    ]
                })
                .collect();
            let names: Vec<&str> = pdyn_md::THERMO_CSV_HEADER.split(',').collect();
            d.set_item("thermo", table(py, &names, thermo)?)?;
            match &res.rdf {
                Some((r, g)) => {
                    d.set_item("rdf_r", f64_array(py, r.clone()))?;
                    d.set_item("rdf_g", f64_array(py, g.clone()))?;
                }
                None => {
                    d.set_item("rdf_r", py.None())?;
                    d.set_item("rdf_g", py.None())?;
                }
            }
            let msd: Vec<Vec<f64>> = res.msd.iter().map(|m| m.to_vec()).collect();
            d.set_item("msd", table(py, &["step", "time", "msd"], msd)?)?;
        }
    }
    Ok(d.into_any().unbind())
}

/// Loads TOML text as the model it is: a mechanics `pdyn.Model`'s inner object, or a
/// `ParticleModel` for an `[nbody]` or `[md]` file.
#[pyfunction]
#[pyo3(signature = (text, origin = "<string>"))]
pub(crate) fn load_model(py: Python<'_>, text: &str, origin: &str) -> PyResult<PyObject> {
    guarded(py, || {
        let file = ModelFile::from_source(text.to_string(), origin.to_string());
        match file.kind {
            Kind::Mechanics => {
                let m = crate::model::PyModel::from_toml(py, text, origin)?;
                Ok(Py::new(py, m)?.into_any())
            }
            _ => {
                let m = load(file).map_err(|e| to_py(py, &e))?;
                Ok(Py::new(py, m)?.into_any())
            }
        }
    })
}
