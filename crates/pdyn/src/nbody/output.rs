//! What an N-body run writes: `trajectory.csv` and `elements.csv` in long format (one row per
//! body and output time, so mergers and removals need no changing columns),
//! `conservation.csv` (energy, its parts, the virial ratio and the angular momentum at each
//! output), `summary.json`, and the text report.

use super::run::{BodyState, ConservationRow, ElementsRow, NbodyResult};
use super::spec::NbodySpec;
use crate::stream::RowFile;
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

/// How the run was set up, for the summary and the report.
#[derive(Debug, Clone)]
pub struct RunInfo {
    /// Integrator name.
    pub integrator: &'static str,
    /// Step (initial step for IAS15).
    pub dt: f64,
    /// End time asked for.
    pub t_end: f64,
    /// `direct` or `tree (theta = ...)`.
    pub gravity: String,
    /// Bodies at the start.
    pub n_bodies: usize,
    /// Drift tolerance of the monitors.
    pub drift_tolerance: f64,
}

/// `trajectory.csv`'s header.
pub const TRAJECTORY_HEADER: &str = "t,body,x,y,z,vx,vy,vz\n";
/// `elements.csv`'s header.
pub const ELEMENTS_HEADER: &str = "t,body,a,e,inc,Omega,omega,f,M,period\n";
/// `conservation.csv`'s header.
pub const CONSERVATION_HEADER: &str = "t,n,energy,kinetic,potential,virial_ratio,Lx,Ly,Lz\n";

/// Appends `,x` for each value, then the end of the line.
fn fields(w: &mut Vec<u8>, values: impl IntoIterator<Item = f64>) {
    for x in values {
        w.push(b',');
        crate::output::append_number(w, x);
    }
    w.push(b'\n');
}

/// Appends `t,NAME` (a row's first two cells).
fn time_and_name(w: &mut Vec<u8>, t: f64, name: &str) {
    crate::output::append_number(w, t);
    w.push(b',');
    w.extend_from_slice(name.as_bytes());
}

/// The rows of `trajectory.csv` (`t,body,x,y,z,vx,vy,vz`) of one output time. Numbers in the
/// shortest form that reads back exactly (`ryu`, as every pdyn CSV): an output row is a few
/// dozen numbers, and formatting them was most of an output's cost.
pub fn trajectory_rows(w: &mut Vec<u8>, t: f64, states: &[BodyState], names: &[String]) {
    for s in states {
        time_and_name(w, t, &names[s.body]);
        fields(w, s.pos.into_iter().chain(s.vel));
    }
}

/// Rows of `elements.csv` (`t,body,a,e,inc,Omega,omega,f,M,period`, angles in radians; empty
/// cells where a body has no elements).
pub fn elements_rows(w: &mut Vec<u8>, rows: &[ElementsRow], names: &[String]) {
    for r in rows {
        time_and_name(w, r.t, &names[r.body]);
        match r.orbit {
            Some(o) => fields(w, [o.a, o.e, o.inc, o.Omega, o.omega, o.f, o.M, o.period]),
            None => w.extend_from_slice(b",,,,,,,,\n"),
        }
    }
}

/// One row of `conservation.csv` (`t,n,energy,kinetic,potential,virial_ratio,Lx,Ly,Lz`).
pub fn conservation_row(w: &mut Vec<u8>, r: &ConservationRow) {
    crate::output::append_number(w, r.t);
    let _ = write!(w, ",{}", r.n);
    let [lx, ly, lz] = r.angular_momentum;
    fields(
        w,
        [
            r.energy,
            r.kinetic,
            r.potential,
            virial(r.kinetic, r.potential),
            lx,
            ly,
            lz,
        ],
    );
}

/// The files of an N-body run written as it goes (`pdyn run --out DIR`): `trajectory.csv`
/// and `elements.csv` when trajectories are kept, `conservation.csv`; every output time's
/// rows appended whole ([`RowFile`]).
#[derive(Debug)]
pub struct Stream {
    /// `trajectory.csv`.
    pub trajectory: Option<RowFile>,
    /// `elements.csv`.
    pub elements: Option<RowFile>,
    /// `conservation.csv`.
    pub conservation: RowFile,
    /// Keep the whole history in memory as well (Python's arrays, plots); otherwise the
    /// result keeps only the first and last output (bounded memory).
    pub keep: bool,
}

impl Stream {
    /// Creates the files in `dir` (which exists) with their headers.
    pub fn create(dir: &Path, trajectory: bool, keep: bool) -> Result<Stream, crate::Error> {
        let (trajectory, elements) = if trajectory {
            (
                Some(RowFile::create(
                    &dir.join("trajectory.csv"),
                    TRAJECTORY_HEADER,
                )?),
                Some(RowFile::create(&dir.join("elements.csv"), ELEMENTS_HEADER)?),
            )
        } else {
            (None, None)
        };
        Ok(Stream {
            trajectory,
            elements,
            conservation: RowFile::create(&dir.join("conservation.csv"), CONSERVATION_HEADER)?,
            keep,
        })
    }

    /// The files in `dir`, each truncated to the length a checkpoint recorded
    /// (`[trajectory, elements, conservation]`, `None` for a file the run does not write).
    pub fn resume(
        dir: &Path,
        lengths: [Option<u64>; 3],
        keep: bool,
    ) -> Result<Stream, crate::Error> {
        let open = |name: &str, len: Option<u64>| {
            len.map(|l| RowFile::resume(&dir.join(name), l)).transpose()
        };
        let missing = || crate::Error::Internal {
            message: "checkpoint without conservation.csv's length".into(),
        };
        Ok(Stream {
            trajectory: open("trajectory.csv", lengths[0])?,
            elements: open("elements.csv", lengths[1])?,
            conservation: open("conservation.csv", lengths[2])?.ok_or_else(missing)?,
            keep,
        })
    }

    /// Every file's buffered rows written out.
    pub fn flush(&mut self) -> Result<(), crate::Error> {
        for f in self.files() {
            f.flush()?;
        }
        Ok(())
    }

    /// Flushed and synced to the disk (before a checkpoint records the lengths).
    pub fn sync(&mut self) -> Result<(), crate::Error> {
        for f in self.files() {
            f.sync()?;
        }
        Ok(())
    }

    /// The files' lengths after the last flush (`[trajectory, elements, conservation]`).
    pub fn lengths(&self) -> [Option<u64>; 3] {
        [
            self.trajectory.as_ref().map(RowFile::len),
            self.elements.as_ref().map(RowFile::len),
            Some(self.conservation.len()),
        ]
    }

    fn files(&mut self) -> impl Iterator<Item = &mut RowFile> {
        self.trajectory
            .iter_mut()
            .chain(self.elements.iter_mut())
            .chain(std::iter::once(&mut self.conservation))
    }
}

/// `2T/|V|`: 1 for a system in virial equilibrium.
fn virial(kinetic: f64, potential: f64) -> f64 {
    2.0 * kinetic / potential.abs()
}

/// `summary.json`.
pub fn summary(spec: &NbodySpec, info: &RunInfo, res: &NbodyResult) -> serde_json::Value {
    let finite = |x: f64| {
        if x.is_finite() {
            serde_json::json!(x)
        } else {
            serde_json::json!(x.to_string())
        }
    };
    let last = res.conservation.last();
    let final_bodies: Vec<serde_json::Value> = res
        .states
        .last()
        .map(|states| {
            states
                .iter()
                .map(|s| {
                    serde_json::json!({
                        "name": res.names[s.body],
                        "mass": s.mass,
                        "position": s.pos,
                        "velocity": s.vel,
                    })
                })
                .collect()
        })
        .unwrap_or_default();
    let monitors: Vec<crate::summary::Conserved<'_>> = res
        .monitors
        .iter()
        .map(|m| crate::summary::Conserved {
            name: m.name,
            initial: m.initial,
            final_value: last.map(|r| match m.name {
                "energy" => r.energy,
                _ => {
                    let l = r.angular_momentum;
                    (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt()
                }
            }),
            drift: m.drift,
            relative: true,
            scale: m.scale,
            tolerance: info.drift_tolerance,
            conserved: true,
        })
        .collect();
    crate::summary::common(
        "nbody",
        &spec.name,
        res.failure.as_ref().map(|f| f.to_string()),
        &res.warnings,
        &monitors,
        serde_json::json!({"steps": res.steps, "final_dt": res.final_dt, "outputs": res.outputs}),
        serde_json::json!({
            "units": spec.units.label,
            "G": spec.units.units.g(),
            "integrator": info.integrator,
            "gravity": info.gravity,
            "dt": info.dt,
            "t_end": info.t_end,
            "t_reached": res.t_reached,
            "bodies": {"initial": info.n_bodies, "final": last.map_or(0, |r| r.n)},
            "energy": {
                "initial": res.conservation.first().map(|r| r.energy),
                "final": last.map(|r| r.energy),
                "relative_error": finite(res.energy_error),
            },
            "virial_ratio": last.map(|r| finite(virial(r.kinetic, r.potential))),
            "drift_tolerance": info.drift_tolerance,
            "events": res.events.iter().map(|e| serde_json::json!({
                "t": e.t, "kind": e.kind, "bodies": e.bodies, "message": e.message,
            })).collect::<Vec<_>>(),
            "final_state": final_bodies,
            "parameters": spec.parameters.iter().map(|(n, v)| (n.clone(), serde_json::json!(v))).collect::<serde_json::Map<_, _>>(),
        }),
    )
}

/// The run's failure as an [`Error`] (a collision, an escape, a failed step) and the summary
/// with its `error` object, as `pdyn run --json` prints it and Python's `ParticleResult.summary`
/// holds it.
pub fn outcome(
    spec: &NbodySpec,
    info: &RunInfo,
    res: &NbodyResult,
) -> (serde_json::Value, Option<crate::Error>) {
    let failure = res.failure.clone().map(|error| crate::Error::Gravity {
        origin: spec.origin.clone(),
        error,
    });
    let mut sum = summary(spec, info, res);
    if let Some(f) = &failure {
        sum["error"] = f.to_json()["error"].clone();
    }
    let failure = failure.or_else(|| {
        res.interrupted
            .then(|| crate::summary::interrupted(&mut sum, &spec.origin, res.t_reached))
    });
    (sum, failure)
}

/// `summary.json` (`sum`) in `dir`, written whole (a temporary file renamed over it); the
/// CSV files were streamed during the run ([`Stream`]).
pub fn write_summary(dir: &Path, sum: &serde_json::Value) -> Result<(), crate::Error> {
    crate::output::write_atomic(&dir.join("summary.json"), format!("{sum:#}\n").as_bytes())
}

/// The text report of `pdyn run`.
pub fn text_report(
    spec: &NbodySpec,
    info: &RunInfo,
    res: &NbodyResult,
    out: Option<&Path>,
) -> String {
    let mut s = format!("{}\n", spec.name);
    let _ = writeln!(
        s,
        "{} bodies ({}, G = {}), {}, {} forces, dt = {}, t = 0..{}: {} steps, {} outputs",
        info.n_bodies,
        spec.units.label,
        spec.units.units.g(),
        info.integrator,
        info.gravity,
        info.dt,
        res.t_reached,
        res.steps,
        res.outputs
    );
    let _ = writeln!(
        s,
        "energy: initial {:.12e}, relative error at the end {:.3e}",
        res.conservation.first().map_or(f64::NAN, |r| r.energy),
        res.energy_error
    );
    if let Some(r) = res.conservation.last() {
        if r.n > 3 {
            let _ = writeln!(
                s,
                "virial ratio 2T/|V| at the end: {:.4}",
                virial(r.kinetic, r.potential)
            );
        }
    }
    if let Some(states) = res.states.last() {
        if states.len() <= 12 {
            s += "\nfinal state:\n";
            for b in states {
                let _ = writeln!(
                    s,
                    "  {:<12} r = [{:.10e}, {:.10e}, {:.10e}]  v = [{:.10e}, {:.10e}, {:.10e}]",
                    res.names[b.body], b.pos[0], b.pos[1], b.pos[2], b.vel[0], b.vel[1], b.vel[2]
                );
            }
            let t_last = res.t_reached;
            let rows: Vec<_> = res.elements.iter().filter(|r| r.t == t_last).collect();
            if !rows.is_empty() {
                s += "\nfinal orbital elements (about the declared primary, else Jacobi):\n";
                for r in rows {
                    match r.orbit {
                        Some(o) => {
                            let _ = writeln!(
                                s,
                                "  {:<12} a = {:.10e}  e = {:.6e}  inc = {:.6e}  period = {:.6e}",
                                res.names[r.body], o.a, o.e, o.inc, o.period
                            );
                        }
                        None => {
                            let _ = writeln!(s, "  {:<12} (no orbit)", res.names[r.body]);
                        }
                    }
                }
            }
        }
    }
    if !res.events.is_empty() {
        s += "\nevents:\n";
        for e in &res.events {
            let _ = writeln!(s, "  {:<16} t = {:.12e}: {}", e.kind, e.t, e.message);
        }
    }
    s += "\nconserved quantities:\n";
    for m in &res.monitors {
        let _ = writeln!(
            s,
            "  {:<20} initial {:.10e}, drift {:.3e} (relative to {:.3e}) {}",
            m.name,
            m.initial,
            m.drift,
            m.scale,
            if m.ok { "ok" } else { "DRIFTING" }
        );
    }
    if let Some(dir) = out {
        let files = if res.states.is_empty() {
            "conservation.csv and summary.json"
        } else {
            "trajectory.csv, elements.csv, conservation.csv and summary.json"
        };
        let _ = writeln!(s, "\nwrote {files} in {}", dir.display());
    }
    s
}
