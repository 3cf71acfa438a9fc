//! Running a prepared model: steps in chunks (so that trajectory frames, temperature ramps and
//! progress happen between them), thermodynamics converted to the file's units, RDF and MSD
//! gathered on the way, and the energy-drift check of an NVE (or Nosé–Hoover) run.
//!
//! A run that becomes unstable (pdyn-md detects a non-finite state, a jump larger than half
//! a length unit in one step, or a change of the conserved energy beyond 1 energy unit per
//! atom) stops there; everything recorded up to that step is returned with the failure, and
//! the trajectory written so far ends with the failing configuration.

use super::build::{Engine, Prepared, UnitSystem};
use super::checkpoint::Gathered;
use super::rdf_blocks::RdfBlocks;
use super::spec::{Ensemble, MdSpec, Mode, Units};
use crate::checkpoint::{Checkpointer, Restart};
use crate::stream::RowFile;
use crate::Error;
use pdyn_md::analysis::Msd;
use pdyn_md::potential::PairPotential;
use pdyn_md::thermostat::Thermostat;
use pdyn_md::{MdError, Simulation, System, ThermoRecord};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Blocks of particles for the MSD's error bar.
const MSD_BLOCKS: usize = 5;

/// Largest system for the RDF (an all-pairs histogram, `O(N²)` per frame).
pub const RDF_MAX_ATOMS: usize = 100_000;

/// What a run is asked to do besides stepping.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Directory for `traj.xyz` (written during the run when `dump_every > 0`).
    pub out: Option<PathBuf>,
    /// Relative drift of the conserved energy that triggers a warning.
    pub drift_tolerance: f64,
    /// Set by another thread to stop the run after the current step (Ctrl-C in Python).
    pub interrupt: Option<pdyn_ode::Interrupt>,
    /// Frames for a live display (`Progress::Frame`) every this many steps; 0: at the model's
    /// `dump_every` (none without).
    pub frame_every: u64,
}

/// What happens during a run, for a live display.
#[derive(Debug, Clone, Copy)]
pub enum Progress<'a> {
    /// A thermodynamic record (file units).
    Record(&'a ThermoRecord),
    /// Steps completed so far.
    Step(u64),
    /// The system at a frame step (`RunOptions::frame_every`, else `dump_every`; and the
    /// first), for a front end that shows the atoms moving.
    Frame {
        /// The step.
        step: u64,
        /// The atoms (positions in file units).
        system: &'a System,
    },
}

/// Energy conservation of a run whose dynamics conserve an energy (NVE, Nosé–Hoover).
#[derive(Debug, Clone, PartialEq)]
pub struct Drift {
    /// `max |E(t) − E(0)|` over the records divided by the mean kinetic energy (the scale of
    /// the energy's fluctuations; `E` itself may be near zero).
    pub relative: f64,
    /// Slope of a least-squares line through `E(t)/N` (energy per atom per time unit).
    pub slope_per_atom: f64,
    /// The scale used (mean kinetic energy).
    pub scale: f64,
}

/// A mean and its standard error from block averages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Average {
    /// Mean over the records.
    pub mean: f64,
    /// Standard error of the mean from `blocks` block averages (None with too few records).
    pub error: Option<f64>,
    /// Number of blocks.
    pub blocks: usize,
}

/// The results of a run.
#[derive(Debug, Clone)]
pub struct MdResult {
    /// Thermodynamic records, file units.
    pub records: Vec<ThermoRecord>,
    /// Why the run stopped early, if it did.
    pub failure: Option<MdError>,
    /// Steps completed.
    pub steps: u64,
    /// Neighbour-list builds.
    pub builds: u64,
    /// Atoms.
    pub atoms: usize,
    /// Trajectory frames written.
    pub frames: u64,
    /// `(r, g(r))` when asked for.
    pub rdf: Option<(Vec<f64>, Vec<f64>)>,
    /// Frames the RDF averaged.
    pub rdf_frames: u64,
    /// Standard error of `g(r)` per bin from 5 blocks of frames (None with fewer than two
    /// blocks with frames).
    pub rdf_error: Option<Box<[f64]>>,
    /// `(step, time, msd)` every `msd_every` steps (and the last step) when asked for.
    pub msd: Vec<[f64; 3]>,
    /// Standard error of each `msd` value from 5 blocks of particles (`Msd::block_error`;
    /// NaN with fewer than 5 particles).
    pub msd_error: Vec<f64>,
    /// Energy conservation (NVE, Nosé–Hoover).
    pub drift: Option<Box<Drift>>,
    /// Warnings for the user.
    pub warnings: Vec<String>,
    /// Wall-clock seconds spent stepping.
    pub seconds: f64,
    /// First step that counts in the averages.
    pub average_from: u64,
    /// How the temperature was measured.
    pub temperature_convention: Box<TemperatureConvention>,
    /// Stopped early by [`RunOptions::interrupt`].
    pub interrupted: bool,
}

/// How a run's temperature `T = 2K/(N_f k_B)` is measured (stated in `summary.json`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TemperatureConvention {
    /// `N_f`.
    pub degrees_of_freedom: f64,
    /// Whether the dynamics conserves the total momentum (then `N_f = 3N − 3`, else `3N`).
    pub momentum_conserved: bool,
    /// Which velocities `K` comes from.
    pub estimator: pdyn_md::KineticEstimator,
}

/// The time step's bias of the thermodynamics, estimated from the difference between the
/// full-step and half-step temperatures (both `O(h²)` away from each other and from the
/// `h → 0` limit), when it exceeds twice the reported temperature's standard error. `None`
/// when it does not, or when there are too few records for an error bar. `lammps_langevin`:
/// the run used Langevin's `scheme = "lammps"`, whose full-step velocities are the good ones
/// (the half-step ones carry the difference), but whose configurations are biased.
pub fn time_step_bias_warning(res: &MdResult, dt: f64, lammps_langevin: bool) -> Option<String> {
    let t = res.average(|r| r.temperature)?;
    let diff = res.average(|r| r.full_step_temperature - r.half_step_temperature)?;
    let err = t.error?;
    // NaN compares false: no warning without a meaningful difference
    let beyond = diff.mean.abs() > 2.0 * err;
    if !beyond || t.mean == 0.0 {
        return None;
    }
    let rel = diff.mean / t.mean;
    let reported = match res.temperature_convention.estimator {
        pdyn_md::KineticEstimator::FullStep if lammps_langevin => {
            "The reported temperature uses the full-step velocities, as LAMMPS's does (exact \
             for a free particle under this scheme); the potential energy, the pressure and the \
             bond lengths carry scheme = \"lammps\"'s configurational O(dt²) bias, larger than \
             BAOAB's (LAMMPS's in.chain at dt = 0.012: PE/N +0.03 ε, bond lengths 2 % wider \
             than at small steps). Use it to reproduce a LAMMPS run; for physics, use \
             scheme = \"baoab\""
        }
        pdyn_md::KineticEstimator::HalfStep => {
            "The reported temperature and pressure use the half-step velocities, which are \
             free of this bias in BAOAB; the potential energy and the virial carry an O(dt²) \
             bias of their own, usually smaller but not measured here"
        }
        pdyn_md::KineticEstimator::FullStep => {
            "The reported temperature, kinetic energy and pressure use the full-step velocities \
             and carry a bias of about this size"
        }
    };
    Some(format!(
        "dt = {dt} is large for these thermodynamics: the full-step velocities' temperature \
         differs from the half-step one by {:+.2} % ({:.1} times the standard error of T, {:.2e}), \
         an O(dt²) time-step error. {reported}. Compare with a run at dt = {}.",
        100.0 * rel,
        diff.mean.abs() / err,
        err,
        dt / 2.0
    ))
}

impl MdResult {
    /// Block average of one column of the records (`f` picks it); the start (step 0, before
    /// any dynamics) and the records before `equilibrate` are left out.
    pub fn average(&self, f: impl Fn(&ThermoRecord) -> f64) -> Option<Average> {
        let from = self.average_from.max(1);
        let xs: Vec<f64> = self
            .records
            .iter()
            .filter(|r| r.step >= from)
            .map(f)
            .collect();
        block_average(&xs)
    }
}

/// Mean and standard error from `5` contiguous blocks (Flyvbjerg & Petersen, J. Chem. Phys.
/// 91, 461 (1989)): the error of correlated samples is estimated from block means, which are
/// nearly independent when blocks are longer than the correlation time. Fewer than 10 values
/// give a mean without an error.
pub fn block_average(xs: &[f64]) -> Option<Average> {
    if xs.is_empty() {
        return None;
    }
    let mean = xs.iter().sum::<f64>() / xs.len() as f64;
    const NB: usize = 5;
    if xs.len() < 2 * NB {
        return Some(Average {
            mean,
            error: None,
            blocks: 0,
        });
    }
    Some(Average {
        mean,
        error: pdyn_md::analysis::block_means(xs, NB).map(|(_, error)| error),
        blocks: NB,
    })
}

fn io_err(path: &Path, action: &'static str, e: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        action,
        error: Arc::new(e),
    }
}

/// Runs `prep` for its `steps`, reporting to `progress`.
pub fn run(
    prep: &mut Prepared,
    opts: &RunOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<MdResult, Error> {
    run_with(prep, opts, progress, None, None)
}

/// [`run`] with checkpoints (issue 29): with `checkpoints`, one is written after a stretch of
/// steps when it is due and when the run is interrupted; with `restart` (a checkpoint read
/// and checked by `crate::checkpoint::read`), the run continues from it, `thermo.csv` and
/// `traj.xyz` truncated to the lengths it recorded and appended to.
pub fn run_with(
    prep: &mut Prepared,
    opts: &RunOptions,
    progress: &mut dyn FnMut(Progress),
    checkpoints: Option<&mut Checkpointer>,
    restart: Option<&Restart>,
) -> Result<MdResult, Error> {
    let spec = prep.spec.clone();
    let u = prep.units;
    let resumed = match restart {
        Some(r) => Some(super::checkpoint::read_state(&r.state).ok_or_else(|| {
            Error::argument(
                "--restart",
                "the checkpoint's MD state is incomplete or of another version",
            )
        })?),
        None => None,
    };
    let lengths = restart.map(|r| {
        let len = |k: usize| r.files.get(k).and_then(serde_json::Value::as_u64);
        [len(0), len(1)]
    });
    let go = Continuation {
        checkpoints,
        resumed,
        lengths,
    };
    match &mut prep.engine {
        Engine::Lj(sim) => run_sim(sim, &spec, u, opts, progress, go),
        Engine::General(sim) => run_sim(sim, &spec, u, opts, progress, go),
    }
}

/// How a run continues: the checkpoints it writes, the state and file lengths it resumes from.
struct Continuation<'a> {
    checkpoints: Option<&'a mut Checkpointer>,
    resumed: Option<super::checkpoint::Resumed>,
    /// `thermo.csv`, `traj.xyz`.
    lengths: Option<[Option<u64>; 2]>,
}

fn restart_error(message: String) -> Error {
    Error::argument(
        "--restart",
        format!("the checkpoint does not fit this model: {message}"),
    )
}

/// Opens an output file: created with `header`, or resumed at the checkpoint's length.
fn open_rows(path: &Path, header: &str, resume: Option<Option<u64>>) -> Result<RowFile, Error> {
    match resume {
        None => RowFile::create(path, header),
        Some(Some(len)) => RowFile::resume(path, len),
        Some(None) => Err(restart_error(format!(
            "it recorded no length for {}",
            path.display()
        ))),
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// A record in file units.
fn convert(r: &ThermoRecord, u: UnitSystem, dt: f64) -> ThermoRecord {
    ThermoRecord {
        time: r.step as f64 * dt,
        pressure: r.pressure * u.pressure,
        ..*r
    }
}

fn set_target(t: &mut Thermostat, temperature: f64) {
    match t {
        Thermostat::Langevin(l) => l.temperature = temperature,
        Thermostat::NoseHooverChain(c) => c.temperature = temperature,
        Thermostat::Berendsen(b) => b.temperature = temperature,
        _ => {}
    }
}

/// One trajectory frame in file units (velocities converted in `real`).
fn write_frame(
    w: &mut impl Write,
    s: &System,
    names: &[&str],
    u: UnitSystem,
    step: u64,
    time: f64,
) -> Result<(), MdError> {
    if u.units == Units::Lj {
        return pdyn_md::io::write_xyz(w, s, names, step, time);
    }
    let mut c = s.clone();
    for v in [
        &mut c.particles.vx,
        &mut c.particles.vy,
        &mut c.particles.vz,
    ] {
        v.iter_mut().for_each(|x| *x /= u.time);
    }
    pdyn_md::io::write_xyz(w, &c, names, step, time)
}

/// Appends one XYZ frame at `step` to `traj.xyz` in a single row write: a stopped run leaves
/// whole frames.
fn append_frame(
    file: &mut RowFile,
    path: &Path,
    s: &System,
    names: &[&str],
    u: UnitSystem,
    step: u64,
    dt: f64,
) -> Result<(), Error> {
    let mut buf = Vec::new();
    write_frame(&mut buf, s, names, u, step, step as f64 * dt).map_err(|e| match e {
        MdError::Io { kind } => io_err(path, "write", std::io::Error::from(kind)),
        e => Error::Internal {
            message: format!("writing a trajectory frame: {e}"),
        },
    })?;
    file.rows(|b| b.extend_from_slice(&buf))
}

fn run_sim<P: PairPotential>(
    sim: &mut Simulation<P>,
    spec: &MdSpec,
    u: UnitSystem,
    opts: &RunOptions,
    progress: &mut dyn FnMut(Progress),
    go: Continuation,
) -> Result<MdResult, Error> {
    let Continuation {
        mut checkpoints,
        resumed,
        lengths,
    } = go;
    let n = sim.system.particles.len();
    let mut g = Gathered::default();
    let mut resumed_rdf = None;
    let mut resumed_msd = None;
    if let Some(r) = resumed {
        sim.restore(&r.snapshot)
            .map_err(|e| restart_error(e.to_string()))?;
        g = r.gathered;
        resumed_rdf = r.rdf;
        resumed_msd = r.msd_origin;
    }
    let dt = spec.dt.value;
    let names: Vec<&str> = spec.species.iter().map(|s| s.name.as_str()).collect();
    // Frames and thermo rows go to the files as the run goes, whole (a frame is one "row").
    let mut traj = match (&opts.out, spec.dump_every) {
        (Some(dir), d) if d > 0 => {
            let path = dir.join("traj.xyz");
            Some((open_rows(&path, "", lengths.map(|l| l[1]))?, path))
        }
        _ => None,
    };
    // The degrees of freedom of the temperature column ride along as a last column `dof`
    // (the same value on every row): the header stays one line of plain names, which pandas,
    // spreadsheets and `csv` readers take as they are, `temperature` keeps its name, and the
    // convention (3N − 3 as LAMMPS's `compute temp`, or 3N under Langevin) is in the file.
    let dof = sim.dof();
    let mut thermo_file = match &opts.out {
        Some(dir) => Some(open_rows(
            &dir.join("thermo.csv"),
            &format!("{},dof\n", pdyn_md::THERMO_CSV_HEADER),
            lengths.map(|l| l[0]),
        )?),
        None => None,
    };
    let mut write_error: Option<Error> = None;
    let resuming = lengths.is_some();
    // Frames shown live: as the front end asks, else at dump_every.
    let frame_every = if opts.frame_every > 0 {
        opts.frame_every
    } else {
        spec.dump_every
    };
    if frame_every > 0 {
        progress(Progress::Frame {
            step: sim.step,
            system: &sim.system,
        });
    }
    if let (Some((w, path)), false) = (&mut traj, resuming) {
        append_frame(w, path, &sim.system, &names, u, sim.step, dt)?;
        g.frames += 1;
    }
    let msd0 = spec.msd.then(|| match resumed_msd.take() {
        Some(origin) => Msd::from_origin(origin),
        None => Msd::new(&sim.system),
    });
    let half = spec.steps / 2;
    // At most `rdf_frames` frames, equally spaced over the records of the second half.
    let second_half_records = {
        let te = spec.thermo_every.max(1);
        let (first, last) = ((spec.steps / 2).div_ceil(te).max(1), spec.steps / te);
        (last + 1).saturating_sub(first)
    };
    let planned_rdf_frames = match spec.rdf_every {
        // the multiples of rdf_every in [max(half, 1), steps]
        Some(e) => spec.steps / e - (half.max(1) - 1) / e,
        None => (spec.rdf_frames as u64).min(second_half_records),
    };
    let mut rdf = if spec.rdf && n <= RDF_MAX_ATOMS {
        // the range was checked against the box when the model was built
        let r_max = spec
            .rdf_range
            .as_ref()
            .map_or(0.5 * sim.system.sim_box.min_edge() * (1.0 - 1e-9), |r| {
                r.value
            });
        Some(
            RdfBlocks::new(r_max, spec.rdf_bins, planned_rdf_frames).map_err(|e| {
                Error::Internal {
                    message: format!("RDF: {e}"),
                }
            })?,
        )
    } else {
        None
    };
    if let (Some(h), Some((blocks, taken))) = (&mut rdf, &resumed_rdf) {
        h.restore(blocks, *taken)
            .map_err(|e| restart_error(e.to_string()))?;
    }
    let mut warnings = vec![];
    if spec.rdf && rdf.is_none() {
        warnings.push(format!(
            "rdf = true ignored: {n} atoms is more than {RDF_MAX_ATOMS} for the all-pairs histogram"
        ));
    }
    // Record j of the R is taken when (j·F mod R) < F: exactly min(F, R) of them, spread
    // evenly (Bresenham), the first included.
    let rdf_take = |j: u64| {
        let (f, r) = (spec.rdf_frames as u64, second_half_records.max(1));
        (j % r) * (f % r) % r < f || f >= r
    };
    let msd_err = |m: &Msd, s: &System| m.block_error(s, MSD_BLOCKS).unwrap_or(f64::NAN);
    if let (Some(m), true) = (&msd0, sim.step == 0) {
        g.msd.push([0.0, 0.0, m.value(&sim.system)]);
        g.msd_error.push(msd_err(m, &sim.system));
    }
    let every = spec.thermo_every.max(1);
    // the run stops at every step where something is due: thermo, a frame, an MSD or RDF sample
    let chunk = [
        spec.dump_every,
        frame_every,
        spec.msd_every,
        spec.rdf_every.unwrap_or(0),
    ]
    .into_iter()
    .filter(|&k| k > 0)
    .fold(every, gcd);
    let ramp = match (
        &spec.thermostat.temperature,
        &spec.thermostat.final_temperature,
    ) {
        (Some(a), Some(b)) if spec.thermostat.ensemble != Ensemble::Nve => Some((a.value, b.value)),
        _ => None,
    };
    let start = crate::clock::Stopwatch::start();
    let seconds_before = g.seconds;
    let mut failure = None;
    let mut interrupted = false;
    // Flushes and syncs the files, then writes the checkpoint of the state now.
    let mut checkpoint = |sim: &Simulation<P>,
                          g: &mut Gathered,
                          rdf: Option<&RdfBlocks>,
                          msd0: Option<&Msd>,
                          thermo_file: &mut Option<RowFile>,
                          traj: &mut Option<(RowFile, PathBuf)>,
                          force: bool|
     -> Result<(), Error> {
        let Some(cp) = checkpoints.as_deref_mut() else {
            return Ok(());
        };
        if !force && !cp.due(g.done) {
            return Ok(());
        }
        let mut files = [None, None];
        if let Some(f) = thermo_file {
            f.sync()?;
            files[0] = Some(f.len());
        }
        if let Some((f, _)) = traj {
            f.sync()?;
            files[1] = Some(f.len());
        }
        g.seconds = seconds_before + start.seconds();
        let state = super::checkpoint::state(&sim.snapshot(), g, rdf, msd0);
        cp.write(
            sim.step as f64 * dt,
            g.done,
            serde_json::json!(files),
            state,
        )
    };
    while g.done < spec.steps || (g.done == 0 && g.records.is_empty()) {
        let stop = opts.interrupt.as_ref();
        if g.done > 0 && stop.is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed)) {
            interrupted = true;
            checkpoint(
                sim,
                &mut g,
                rdf.as_ref(),
                msd0.as_ref(),
                &mut thermo_file,
                &mut traj,
                true,
            )?;
            break;
        }
        let done = g.done;
        // Up to the next multiple of the stretch: a run restarted from a stop inside a
        // stretch (an interrupt) falls back onto the uninterrupted run's stretches.
        let k = (chunk - done % chunk).min(spec.steps - done);
        if let Some((a, b)) = ramp {
            // The target steps once per thermo block, at the block's middle, whatever the
            // stretches the run is cut into (frames, dumps, MSD samples): what is observed
            // must not change the trajectory.
            let block = done / every * every;
            let block_len = every.min(spec.steps - block);
            let frac = (block as f64 + 0.5 * block_len as f64) / spec.steps.max(1) as f64;
            set_target(&mut sim.thermostat, a + (b - a) * frac);
        }
        let mut obs = |r: &ThermoRecord, s: &System| {
            let c = convert(r, u, dt);
            progress(Progress::Record(&c));
            if let Some(f) = &mut thermo_file {
                if let Err(e) = f.rows(|b| {
                    let _ = writeln!(b, "{c},{dof}");
                }) {
                    write_error.get_or_insert(e);
                }
            }
            g.records.push(c);
            if let (Some(h), None) = (&mut rdf, spec.rdf_every) {
                if r.step >= half && r.step > 0 {
                    if rdf_take(g.rdf_seen) {
                        // the box is fixed, so `add` cannot refuse r_max here
                        let _ = h.add(s);
                    }
                    g.rdf_seen += 1;
                }
            }
        };
        // the interrupt is also checked after every step inside the stretch (a long stretch
        // of a large system would otherwise keep Ctrl-C waiting for seconds)
        let outcome = sim.run_interruptible(k, &mut obs, opts.interrupt.as_deref());
        match outcome {
            Ok(rep) => {
                g.builds += rep.builds;
                g.done += rep.steps;
            }
            Err(f) => {
                g.builds += f.partial.builds;
                g.done += f.partial.steps;
                failure = Some(f.error);
            }
        }
        progress(Progress::Step(g.done));
        let step = sim.step;
        if let Some(m) = &msd0 {
            if step % spec.msd_every.max(1) == 0 && step > 0 {
                g.msd
                    .push([step as f64, step as f64 * dt, m.value(&sim.system)]);
                g.msd_error.push(msd_err(m, &sim.system));
            }
        }
        if let (Some(h), Some(e)) = (&mut rdf, spec.rdf_every) {
            if step >= half && step > 0 && step % e == 0 {
                let _ = h.add(&sim.system);
            }
        }
        let dump = spec.dump_every > 0 && sim.step % spec.dump_every == 0;
        if frame_every > 0 && sim.step % frame_every == 0 {
            progress(Progress::Frame {
                step: sim.step,
                system: &sim.system,
            });
        }
        if let Some((w, path)) = &mut traj {
            if dump || failure.is_some() {
                append_frame(w, path, &sim.system, &names, u, sim.step, dt)?;
                g.frames += 1;
            }
        }
        if let Some(e) = write_error.take() {
            return Err(e);
        }
        if failure.is_some() || k == 0 {
            break;
        }
        if g.done < spec.steps {
            checkpoint(
                sim,
                &mut g,
                rdf.as_ref(),
                msd0.as_ref(),
                &mut thermo_file,
                &mut traj,
                false,
            )?;
        }
    }
    let seconds = seconds_before + start.seconds();
    let Gathered {
        done,
        builds,
        frames,
        mut records,
        mut msd,
        mut msd_error,
        ..
    } = g;
    if failure.is_none() && records.last().map(|r| r.step) != Some(sim.step) {
        // the last step, when it is not a multiple of thermo_every
        let c = convert(&sim.thermo(), u, dt);
        progress(Progress::Record(&c));
        if let Some(f) = &mut thermo_file {
            f.rows(|b| {
                let _ = writeln!(b, "{c},{dof}");
            })?;
        }
        records.push(c);
        if let Some(h) = &mut rdf {
            if spec.rdf_every.is_none() && c.step > 0 && (h.frames() as usize) < spec.rdf_frames {
                let _ = h.add(&sim.system);
            }
        }
    }
    if let Some(m) = &msd0 {
        // the last step, when it is not a multiple of msd_every
        if failure.is_none() && msd.last().map(|x| x[0]) != Some(sim.step as f64) {
            msd.push([sim.step as f64, sim.step as f64 * dt, m.value(&sim.system)]);
            msd_error.push(msd_err(m, &sim.system));
        }
    }
    let rdf_frames = rdf.as_ref().map_or(0, |h| h.frames());
    if spec.rdf && rdf.is_some() && rdf_frames == 0 {
        warnings.push("rdf = true: no frame to average (the run has no steps)".into());
        rdf = None;
    }
    // Said when the file asked for a count (the default is "up to 20").
    let asked = spec.rdf_frames != super::spec::RDF_FRAMES && spec.rdf_every.is_none();
    if asked && rdf.is_some() && failure.is_none() && (rdf_frames as usize) < spec.rdf_frames {
        warnings.push(format!(
            "the RDF averages {rdf_frames} frames, fewer than rdf_frames = {}: the second half \
             of the run has only that many thermo records (lower thermo_every or run longer)",
            spec.rdf_frames
        ));
    }
    if let Some((w, _)) = &mut traj {
        w.flush()?;
    }
    if let Some(f) = &mut thermo_file {
        f.flush()?;
    }
    let drift = match spec.thermostat.ensemble {
        Ensemble::Nve | Ensemble::NoseHoover { .. } if records.len() >= 2 => {
            let c0 = records[0].conserved;
            let dev = records
                .iter()
                .map(|r| (r.conserved - c0).abs())
                .fold(0.0, f64::max);
            let scale = records.iter().map(|r| r.kinetic).sum::<f64>() / records.len() as f64;
            let relative = if scale > 0.0 { dev / scale } else { dev };
            let slope = fit_slope(&records, n);
            // boxed: MdResult stays small beside the N-body result in the callers' enums
            Some(Box::new(Drift {
                relative,
                slope_per_atom: slope,
                scale,
            }))
        }
        _ => None,
    };
    if let Some(d) = &drift {
        if d.relative.is_nan() || d.relative > opts.drift_tolerance {
            let plain = spec.pairs.iter().any(|p| p.mode == Mode::Plain);
            warnings.push(format!(
                "the total energy should be conserved but drifted by {:.3e} of the mean kinetic energy over {} steps: \
                 this result cannot be trusted (the First Law of Scientific Computing). {}",
                d.relative,
                done,
                if plain {
                    "With mode = \"plain\" the energy jumps each time a pair crosses the cutoff: \
                     mode = \"shifted-energy\" removes that; if the drift remains, reduce the time step."
                        .to_string()
                } else {
                    format!("Reduce the time step ({}).", crate::options::RunOption::Dt.with(dt / 2.0))
                }
            ));
        }
    }
    let rdf_result = match &rdf {
        Some(h) => Some(h.result().map_err(|e| Error::Internal {
            message: format!("RDF: {e}"),
        })?),
        None => None,
    };
    let temperature_convention = TemperatureConvention {
        degrees_of_freedom: sim.dof(),
        momentum_conserved: sim.conserves_momentum(),
        estimator: sim.kinetic_estimator(),
    };
    let mut res = MdResult {
        records,
        failure,
        steps: done,
        builds,
        atoms: n,
        frames,
        rdf_frames: if rdf.is_some() { rdf_frames } else { 0 },
        rdf_error: rdf_result
            .as_ref()
            .and_then(|b| b.error.clone())
            .map(Vec::into_boxed_slice),
        rdf: rdf_result.map(|b| (b.r, b.g)),
        msd,
        msd_error,
        drift,
        warnings,
        seconds,
        average_from: spec.equilibrate,
        temperature_convention: Box::new(temperature_convention),
        interrupted,
    };
    if res.failure.is_none() {
        let lammps_langevin = matches!(
            spec.thermostat.ensemble,
            Ensemble::Langevin {
                scheme: pdyn_md::thermostat::LangevinScheme::Lammps { .. },
                ..
            }
        );
        if let Some(w) = time_step_bias_warning(&res, dt, lammps_langevin) {
            res.warnings.push(w);
        }
    }
    Ok(res)
}

/// Least-squares slope of the conserved energy per atom against time.
fn fit_slope(records: &[ThermoRecord], n: usize) -> f64 {
    let m = records.len() as f64;
    let n = n.max(1) as f64;
    let tm = records.iter().map(|r| r.time).sum::<f64>() / m;
    let em = records.iter().map(|r| r.conserved / n).sum::<f64>() / m;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for r in records {
        sxy += (r.time - tm) * (r.conserved / n - em);
        sxx += (r.time - tm).powi(2);
    }
    if sxx > 0.0 {
        sxy / sxx
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_average_of_known_blocks() {
        // five blocks with means 1..5: mean 3, standard error sqrt(2.5/5) = sqrt(0.5)
        let xs: Vec<f64> = (1..=5).flat_map(|b| [b as f64; 4]).collect();
        let a = block_average(&xs).unwrap();
        assert!((a.mean - 3.0).abs() < 1e-15);
        assert!((a.error.unwrap() - 0.5f64.sqrt()).abs() < 1e-15);
        assert_eq!(block_average(&[1.0, 2.0]).unwrap().error, None);
        assert!(block_average(&[]).is_none());
    }
}
