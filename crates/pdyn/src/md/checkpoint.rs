//! An MD run's state in a checkpoint (issue 29; the file itself: `crate::checkpoint`): the
//! simulation's [`Snapshot`] and what the run has gathered so far ([`Gathered`]: the thermo
//! records the block averages and the drift are taken from, the MSD's origin and values, the
//! RDF's histograms, the counters), every floating-point number as its bits, so that a run
//! restarted from it ends with the files of the run that was never stopped, byte for byte.

use super::rdf_blocks::RdfBlocks;
use crate::checkpoint::{bits, unbit, unbits};
use pdyn_md::analysis::Msd;
use pdyn_md::{Snapshot, ThermoRecord, ThermostatState, Vec3};
use serde_json::{json, Value};

/// What a run has gathered up to a step (besides the RDF and the MSD origin).
#[derive(Debug, Default)]
pub struct Gathered {
    /// Steps done.
    pub done: u64,
    /// Neighbour-list builds during the run.
    pub builds: u64,
    /// Trajectory frames written.
    pub frames: u64,
    /// Thermo records, file units.
    pub records: Vec<ThermoRecord>,
    /// Thermo records of the second half seen by the RDF's frame choice.
    pub rdf_seen: u64,
    /// `(step, time, msd)` rows.
    pub msd: Vec<[f64; 3]>,
    /// Their standard errors.
    pub msd_error: Vec<f64>,
    /// Wall-clock seconds spent stepping (over every part of a restarted run).
    pub seconds: f64,
}

/// The RDF's accumulations: each block's counts, frames and `Σ N·ρ`, and the frames taken.
pub type RdfState = (Vec<(Vec<u64>, u64, f64)>, u64);

/// What [`state`] wrote, read back.
#[derive(Debug)]
pub struct Resumed {
    /// The simulation.
    pub snapshot: Snapshot,
    /// The run's accumulations.
    pub gathered: Gathered,
    /// The RDF's, when the run has one.
    pub rdf: Option<RdfState>,
    /// The MSD's origin (unwrapped positions at step 0), when the run has one.
    pub msd_origin: Option<Vec<Vec3>>,
}

const RECORD_FIELDS: usize = 9;

fn record_numbers(r: &ThermoRecord) -> [f64; RECORD_FIELDS] {
    [
        r.time,
        r.temperature,
        r.full_step_temperature,
        r.half_step_temperature,
        r.kinetic,
        r.potential,
        r.total,
        r.pressure,
        r.conserved,
    ]
}

fn opt_bits(x: Option<f64>) -> Value {
    x.map_or(Value::Null, |v| json!(v.to_bits()))
}

fn flat3(v: &[[f64; 3]]) -> Value {
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    bits(&flat)
}

fn unflat3(v: &Value) -> Option<Vec<[f64; 3]>> {
    let flat = unbits(v)?;
    if flat.len() % 3 != 0 {
        return None;
    }
    Some(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

fn thermostat_json(t: &ThermostatState) -> Value {
    match t {
        ThermostatState::None => json!({"kind": t.name()}),
        ThermostatState::Langevin {
            temperature,
            rng,
            spare,
        } => json!({
            "kind": t.name(), "temperature": temperature.to_bits(), "rng": rng, "spare": opt_bits(*spare),
        }),
        ThermostatState::NoseHooverChain { temperature, xi, v } => json!({
            "kind": t.name(), "temperature": temperature.to_bits(), "xi": bits(xi), "v": bits(v),
        }),
        ThermostatState::Berendsen { temperature } => {
            json!({"kind": t.name(), "temperature": temperature.to_bits()})
        }
    }
}

fn thermostat_of(v: &Value) -> Option<ThermostatState> {
    let temperature = || unbit(&v["temperature"]);
    Some(match v["kind"].as_str()? {
        "none" => ThermostatState::None,
        "langevin" => {
            let words: Vec<u64> = v["rng"]
                .as_array()?
                .iter()
                .map(Value::as_u64)
                .collect::<Option<_>>()?;
            ThermostatState::Langevin {
                temperature: temperature()?,
                rng: words.try_into().ok()?,
                spare: if v["spare"].is_null() {
                    None
                } else {
                    Some(unbit(&v["spare"])?)
                },
            }
        }
        "nose-hoover" => ThermostatState::NoseHooverChain {
            temperature: temperature()?,
            xi: unbits(&v["xi"])?,
            v: unbits(&v["v"])?,
        },
        "berendsen" => ThermostatState::Berendsen {
            temperature: temperature()?,
        },
        _ => return None,
    })
}

fn snapshot_json(s: &Snapshot) -> Value {
    let images: Vec<i32> = s.images.iter().flatten().copied().collect();
    json!({
        "step": s.step,
        "positions": s.positions.iter().map(|a| bits(a)).collect::<Vec<_>>(),
        "velocities": s.velocities.iter().map(|a| bits(a)).collect::<Vec<_>>(),
        "accelerations": s.accelerations.iter().map(|a| bits(a)).collect::<Vec<_>>(),
        "images": images,
        "forces": flat3(&s.forces),
        "potential": s.potential.to_bits(),
        "virial": s.virial.to_bits(),
        "e0": opt_bits(s.e0),
        "half_step_kinetic": opt_bits(s.half_step_kinetic),
        "neighbor_reference": flat3(&s.neighbor_reference),
        "neighbor_builds": s.neighbor_builds,
        "thermostat": thermostat_json(&s.thermostat),
    })
}

fn three(v: &Value) -> Option<[Vec<f64>; 3]> {
    let a = v.as_array()?;
    if a.len() != 3 {
        return None;
    }
    Some([unbits(&a[0])?, unbits(&a[1])?, unbits(&a[2])?])
}

fn opt_unbit(v: &Value) -> Option<Option<f64>> {
    if v.is_null() {
        Some(None)
    } else {
        unbit(v).map(Some)
    }
}

fn snapshot_of(v: &Value) -> Option<Snapshot> {
    let images: Vec<i32> = v["images"]
        .as_array()?
        .iter()
        .map(|x| x.as_i64().and_then(|i| i32::try_from(i).ok()))
        .collect::<Option<_>>()?;
    if images.len() % 3 != 0 {
        return None;
    }
    Some(Snapshot {
        step: v["step"].as_u64()?,
        positions: three(&v["positions"])?,
        velocities: three(&v["velocities"])?,
        accelerations: three(&v["accelerations"])?,
        images: images.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        forces: unflat3(&v["forces"])?,
        potential: unbit(&v["potential"])?,
        virial: unbit(&v["virial"])?,
        e0: opt_unbit(&v["e0"])?,
        half_step_kinetic: opt_unbit(&v["half_step_kinetic"])?,
        neighbor_reference: unflat3(&v["neighbor_reference"])?,
        neighbor_builds: v["neighbor_builds"].as_u64()?,
        thermostat: thermostat_of(&v["thermostat"])?,
    })
}

/// The checkpoint's `state` of a run: the simulation `snap`, what it gathered `g`, the RDF's
/// and the MSD's accumulations.
pub fn state(snap: &Snapshot, g: &Gathered, rdf: Option<&RdfBlocks>, msd: Option<&Msd>) -> Value {
    let record_steps: Vec<u64> = g.records.iter().map(|r| r.step).collect();
    let record_numbers: Vec<f64> = g.records.iter().flat_map(record_numbers).collect();
    let msd_rows: Vec<f64> = g.msd.iter().flatten().copied().collect();
    json!({
        "simulation": snapshot_json(snap),
        "done": g.done,
        "builds": g.builds,
        "frames": g.frames,
        "record_steps": record_steps,
        "records": bits(&record_numbers),
        "rdf_seen": g.rdf_seen,
        "msd": bits(&msd_rows),
        "msd_error": bits(&g.msd_error),
        "seconds": g.seconds.to_bits(),
        "rdf": rdf.map(|h| {
            let (blocks, taken) = h.accumulated();
            json!({
                "taken": taken,
                "blocks": blocks.iter().map(|(counts, frames, norm)| json!({
                    "counts": counts, "frames": frames, "norm": norm.to_bits(),
                })).collect::<Vec<_>>(),
            })
        }),
        "msd_origin": msd.map(|m| {
            let flat: Vec<f64> = m.origin().iter().flat_map(|v| v.0).collect();
            bits(&flat)
        }),
    })
}

/// Reads what [`state`] wrote (`None`: incomplete or of another version).
pub fn read_state(v: &Value) -> Option<Resumed> {
    let steps: Vec<u64> = v["record_steps"]
        .as_array()?
        .iter()
        .map(Value::as_u64)
        .collect::<Option<_>>()?;
    let numbers = unbits(&v["records"])?;
    if numbers.len() != steps.len() * RECORD_FIELDS {
        return None;
    }
    let records = steps
        .iter()
        .zip(numbers.chunks_exact(RECORD_FIELDS))
        .map(|(&step, x)| ThermoRecord {
            step,
            time: x[0],
            temperature: x[1],
            full_step_temperature: x[2],
            half_step_temperature: x[3],
            kinetic: x[4],
            potential: x[5],
            total: x[6],
            pressure: x[7],
            conserved: x[8],
        })
        .collect();
    let msd_rows = unbits(&v["msd"])?;
    if msd_rows.len() % 3 != 0 {
        return None;
    }
    let rdf = match &v["rdf"] {
        Value::Null => None,
        r => {
            let mut blocks = vec![];
            for b in r["blocks"].as_array()? {
                let counts: Vec<u64> = b["counts"]
                    .as_array()?
                    .iter()
                    .map(Value::as_u64)
                    .collect::<Option<_>>()?;
                blocks.push((counts, b["frames"].as_u64()?, unbit(&b["norm"])?));
            }
            Some((blocks, r["taken"].as_u64()?))
        }
    };
    let msd_origin = match &v["msd_origin"] {
        Value::Null => None,
        m => {
            let flat = unbits(m)?;
            if flat.len() % 3 != 0 {
                return None;
            }
            Some(
                flat.chunks_exact(3)
                    .map(|c| Vec3([c[0], c[1], c[2]]))
                    .collect(),
            )
        }
    };
    Some(Resumed {
        snapshot: snapshot_of(&v["simulation"])?,
        gathered: Gathered {
            done: v["done"].as_u64()?,
            builds: v["builds"].as_u64()?,
            frames: v["frames"].as_u64()?,
            records,
            rdf_seen: v["rdf_seen"].as_u64()?,
            msd: msd_rows
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
            msd_error: unbits(&v["msd_error"])?,
            seconds: unbit(&v["seconds"])?,
        },
        rdf,
        msd_origin,
    })
}
