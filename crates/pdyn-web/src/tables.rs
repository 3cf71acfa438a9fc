//! A finished run as the page draws it: the time series to plot (every output column of a
//! mechanics run, an N-body run's invariants, an MD run's thermo records), the monitored
//! quantities for the conservation panel, and the particles' paths for the animation. Numbers
//! that are not finite become `null` (JSON has no NaN); the page draws gaps there.

use pdyn::engine::RunOutput;
use serde_json::{json, Value};

/// One column for the page.
fn series(name: &str, values: impl IntoIterator<Item = f64>) -> Value {
    json!({"name": name, "values": values.into_iter().map(finite).collect::<Vec<_>>()})
}

fn finite(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// A particle's path: `x`, `y`, `z` at the frame times.
fn path(name: &str, x: Vec<f64>, y: Vec<f64>, z: Vec<f64>) -> Value {
    json!({"name": name, "x": x.into_iter().map(finite).collect::<Vec<_>>(),
           "y": y.into_iter().map(finite).collect::<Vec<_>>(),
           "z": z.into_iter().map(finite).collect::<Vec<_>>()})
}

/// Most coordinates the frames of one run keep (about 25 MB of JSON for the page): 1,000
/// frames of 500 atoms, 15 of 32,000.
const MAX_FRAME_VALUES: usize = 1_500_000;

/// Frames of an MD run, collected from `Progress::Frame` and thinned to at most `max` kept,
/// fewer for many atoms ([`MAX_FRAME_VALUES`]); every other one is dropped whenever the limit
/// is reached, so they stay evenly spaced.
pub struct Frames {
    max: usize,
    stride: usize,
    seen: usize,
    times: Vec<f64>,
    /// Per frame, `[x…, y…, z…]` of every atom.
    positions: Vec<Vec<f64>>,
}

impl Frames {
    /// No frames yet; at most `max` kept (at least 2).
    pub fn new(max: usize) -> Frames {
        Frames {
            max: max.max(2),
            stride: 1,
            seen: 0,
            times: Vec::new(),
            positions: Vec::new(),
        }
    }

    /// Keeps the frame at `time` if it falls on the current stride.
    pub fn push(&mut self, time: f64, x: &[f64], y: &[f64], z: &[f64]) {
        if self.seen == 0 {
            self.max = self.max.min(MAX_FRAME_VALUES / (3 * x.len()).max(1)).max(2);
        }
        let k = self.seen;
        self.seen += 1;
        if k % self.stride != 0 {
            return;
        }
        if self.times.len() == self.max {
            // Keep frames 0, 2, 4, … and take every other one from now on.
            self.times = self.times.iter().copied().step_by(2).collect();
            self.positions = std::mem::take(&mut self.positions)
                .into_iter()
                .step_by(2)
                .collect();
            self.stride *= 2;
            if k % self.stride != 0 {
                return;
            }
        }
        self.times.push(time);
        let mut p = Vec::with_capacity(3 * x.len());
        p.extend_from_slice(x);
        p.extend_from_slice(y);
        p.extend_from_slice(z);
        self.positions.push(p);
    }
}

/// The page's data for `out`: `{"kind", "series": [...], "conservation": [...], "time": [...],
/// "particles": [...], "frame_times": [...], "box": ...}`.
pub fn of(out: &RunOutput, frames: Frames) -> Value {
    match out {
        RunOutput::Mechanics(m) => {
            let res = &m.result;
            let col = |j: usize| res.rows.iter().map(move |r| r[j]);
            let index = |name: &str| res.columns.iter().position(|c| c == name);
            let t: Vec<f64> = index("t").map_or(Vec::new(), |j| col(j).collect());
            let all: Vec<Value> = res
                .columns
                .iter()
                .enumerate()
                .filter(|(_, c)| c.as_str() != "t")
                .map(|(j, c)| series(c, col(j)))
                .collect();
            let conservation: Vec<Value> = res
                .monitors
                .iter()
                .filter_map(|mon| index(&mon.name).map(|j| series(&mon.name, col(j))))
                .collect();
            let particles: Vec<Value> = m
                .model
                .particles
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    // A net's position that is a coordinate is that coordinate's column.
                    let axis = |k: usize, a: &str| {
                        index(&format!("{}.{a}", p.name))
                            .or_else(|| {
                                pdyn::sim::net::position_column(&m.model, i, k)
                                    .and_then(|c| index(&c))
                            })
                            .map_or(vec![0.0; t.len()], |j| col(j).collect())
                    };
                    path(&p.name, axis(0, "x"), axis(1, "y"), axis(2, "z"))
                })
                .collect();
            json!({"kind": "mechanics", "time": t.iter().copied().map(finite).collect::<Vec<_>>(),
                   "series": all, "conservation": conservation,
                   "particles": particles, "frame_times": t.into_iter().map(finite).collect::<Vec<_>>()})
        }
        RunOutput::Nbody(n) => {
            let res = &n.result;
            let t: Vec<f64> = res.conservation.iter().map(|r| r.t).collect();
            let e0 = res.conservation.first().map_or(0.0, |r| r.energy);
            let scale = if e0 != 0.0 { e0.abs() } else { 1.0 };
            let conservation = vec![series(
                "relative energy error",
                res.conservation.iter().map(|r| (r.energy - e0) / scale),
            )];
            let all = vec![
                series("energy", res.conservation.iter().map(|r| r.energy)),
                series("kinetic", res.conservation.iter().map(|r| r.kinetic)),
                series("potential", res.conservation.iter().map(|r| r.potential)),
                series(
                    "|L|",
                    res.conservation.iter().map(|r| {
                        let l = r.angular_momentum;
                        (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt()
                    }),
                ),
            ];
            // Each body's path over the output times (NaN where it does not exist: merged
            // or escaped).
            let times = res.times.len();
            let mut xyz = vec![
                [
                    vec![f64::NAN; times],
                    vec![f64::NAN; times],
                    vec![f64::NAN; times]
                ];
                res.names.len()
            ];
            for (k, states) in res.states.iter().enumerate() {
                for s in states {
                    if let Some(p) = xyz.get_mut(s.body) {
                        for (axis, &x) in p.iter_mut().zip(&s.pos) {
                            axis[k] = x;
                        }
                    }
                }
            }
            let particles: Vec<Value> = if res.states.is_empty() {
                Vec::new()
            } else {
                res.names
                    .iter()
                    .zip(xyz)
                    .map(|(name, [x, y, z])| path(name, x, y, z))
                    .collect()
            };
            json!({"kind": "nbody", "time": t.into_iter().map(finite).collect::<Vec<_>>(),
                   "series": all, "conservation": conservation, "particles": particles,
                   "frame_times": res.times.iter().copied().map(finite).collect::<Vec<_>>()})
        }
        RunOutput::Md(md) => {
            let r = &md.result.records;
            let t: Vec<f64> = r.iter().map(|x| x.time).collect();
            let all = vec![
                series("temperature", r.iter().map(|x| x.temperature)),
                series("kinetic", r.iter().map(|x| x.kinetic)),
                series("potential", r.iter().map(|x| x.potential)),
                series("total", r.iter().map(|x| x.total)),
                series("pressure", r.iter().map(|x| x.pressure)),
            ];
            let conservation = vec![series("conserved", r.iter().map(|x| x.conserved))];
            let atoms = frames.positions.first().map_or(0, |p| p.len() / 3);
            let frame_data: Vec<Vec<Value>> = frames
                .positions
                .iter()
                .map(|p| p.iter().copied().map(finite).collect())
                .collect();
            json!({"kind": "md", "time": t.into_iter().map(finite).collect::<Vec<_>>(),
                   "series": all, "conservation": conservation,
                   "atoms": atoms, "frames": frame_data,
                   "frame_times": frames.times.into_iter().map(finite).collect::<Vec<_>>(),
                   "box": md_box(md)})
        }
    }
}

/// The periodic box's edges, for drawing it.
fn md_box(md: &pdyn::engine::MdRun) -> Value {
    json!(pdyn::md::build::box_edges(&md.prepared))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_thinned_evenly_to_the_limit() {
        let mut f = Frames::new(4);
        for k in 0..20 {
            let x = [k as f64];
            f.push(k as f64, &x, &x, &x);
        }
        assert!(f.times.len() <= 4, "{:?}", f.times);
        // Evenly spaced, starting at the first frame.
        let d: Vec<f64> = f.times.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(d.iter().all(|&s| s == d[0]), "{:?}", f.times);
        assert_eq!(f.times[0], 0.0);
        assert_eq!(f.positions[1], vec![f.times[1]; 3]);
    }

    #[test]
    fn many_atoms_keep_fewer_frames_within_the_budget() {
        let atoms = 100_000;
        let x = vec![0.5; atoms];
        let mut f = Frames::new(400);
        for k in 0..100 {
            f.push(k as f64, &x, &x, &x);
        }
        let kept: usize = f.positions.iter().map(Vec::len).sum();
        assert!(kept <= MAX_FRAME_VALUES, "{kept}");
        assert!(f.times.len() >= 2, "{:?}", f.times);
    }
}
