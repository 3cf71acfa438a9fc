//! `pdyn modes --json`, written straight into its text: the same bytes as `serde_json`'s
//! pretty printing of the report as a `Value` (keys in sorted order, two-space indentation,
//! one array element per line), without the `Value`. A 10^4-mass chain's report holds
//! 10^5 numbers (ten shapes); making a `Value` of each, printing it through `fmt` and freeing
//! them took 95 of the command's 1,490 million instructions, this 32 million.

use pdyn_mech::damped::{DampedMode, DampedPath};
use pdyn_mech::modes::Modes;

/// A pretty JSON text written token by token, as `serde_json::ser::PrettyFormatter` does.
struct Pretty {
    out: Vec<u8>,
    depth: usize,
    /// True right after `[` or `{`: the next element starts without a comma, and a
    /// container closed here is empty (`[]`).
    first: bool,
}

impl Pretty {
    fn new(capacity: usize) -> Pretty {
        Pretty {
            out: Vec::with_capacity(capacity),
            depth: 0,
            first: true,
        }
    }

    fn newline(&mut self) {
        self.out.push(b'\n');
        for _ in 0..self.depth {
            self.out.extend_from_slice(b"  ");
        }
    }

    /// Before an array element or an object key.
    fn element(&mut self) {
        if !self.first {
            self.out.push(b',');
        }
        self.newline();
        self.first = false;
    }

    fn open(&mut self, bracket: u8) {
        self.out.push(bracket);
        self.depth += 1;
        self.first = true;
    }

    fn close(&mut self, bracket: u8) {
        self.depth -= 1;
        if !self.first {
            self.newline();
        }
        self.out.push(bracket);
        self.first = false;
    }

    fn key(&mut self, key: &str) {
        self.element();
        self.string(key);
        self.out.extend_from_slice(b": ");
    }

    /// A string, escaped as `serde_json` escapes it.
    fn string(&mut self, s: &str) {
        // Writing into a Vec cannot fail, and a `str` always serializes.
        let _ = serde_json::to_writer(&mut self.out, s);
    }

    fn integer(&mut self, n: usize) {
        let _ = serde_json::to_writer(&mut self.out, &n);
    }

    fn boolean(&mut self, b: bool) {
        self.out
            .extend_from_slice(if b { b"true" } else { b"false" });
    }

    /// [`pdyn::output::json_num`]'s value: a finite number as `serde_json` prints an `f64`,
    /// NaN and infinities as the strings `"NaN"`, `"inf"`, `"-inf"`.
    fn number(&mut self, x: f64) {
        if x.is_finite() {
            let _ = serde_json::to_writer(&mut self.out, &x);
        } else {
            self.string(&x.to_string());
        }
    }

    fn numbers(&mut self, xs: &[f64]) {
        self.open(b'[');
        for &x in xs {
            self.element();
            self.number(x);
        }
        self.close(b']');
    }

    fn by_axis(&mut self, v: &[f64; 3]) {
        self.open(b'{');
        for (axis, x) in ["x", "y", "z"].iter().zip(v) {
            self.key(axis);
            self.number(*x);
        }
        self.close(b'}');
    }
}

/// What the report says besides the modes.
pub struct Header<'a> {
    pub model: &'a str,
    pub about: &'a str,
    pub residual: f64,
    pub names: &'a [String],
    pub sparse: bool,
    /// How the damped modes were found and the damping's commutator, when there is damping.
    pub damped_path: Option<(DampedPath, f64)>,
    pub damped: Option<&'a [DampedMode]>,
}

/// The report's text: `modes` (its first `shown`), with `header`.
pub fn modes_json(header: &Header<'_>, modes: &Modes, shown: usize) -> String {
    let tau = std::f64::consts::TAU;
    let shown = &modes.modes[..shown.min(modes.modes.len())];
    let numbers = shown.iter().map(|m| m.shape.len() + 16).sum::<usize>();
    let mut j = Pretty::new(64 + 32 * (numbers + header.names.len()));
    // Keys in sorted order, as a `serde_json::Map` (a BTreeMap) prints them.
    j.open(b'{');
    j.key("about");
    j.string(header.about);
    j.key("coordinate_count");
    j.integer(header.names.len());
    j.key("coordinates");
    j.open(b'[');
    for name in header.names {
        j.element();
        j.string(name);
    }
    j.close(b']');
    if let Some(damped) = header.damped {
        j.key("damped_modes");
        j.open(b'[');
        for d in damped {
            j.element();
            j.open(b'{');
            j.key("damped_frequency");
            j.number(d.im);
            j.key("damping_ratio");
            j.number(d.damping_ratio);
            j.key("eigenvalue");
            j.numbers(&[d.re, d.im]);
            j.key("natural_frequency");
            j.number(d.omega_n);
            j.key("oscillatory");
            j.boolean(d.oscillatory);
            j.close(b'}');
        }
        j.close(b']');
    }
    if let Some((path, defect)) = header.damped_path {
        j.key("damped_path");
        j.string(path.name());
        j.key("damping_commutation_defect");
        j.number(defect);
    }
    j.key("model");
    j.string(header.model);
    j.key("modes");
    j.open(b'[');
    for (k, m) in shown.iter().enumerate() {
        j.element();
        j.open(b'{');
        j.key("effective_mass");
        j.by_axis(&m.effective_mass);
        j.key("frequency_hz");
        j.number(m.omega / tau);
        j.key("modal_mass");
        j.number(m.modal_mass);
        j.key("modal_stiffness");
        j.number(m.modal_stiffness);
        j.key("mode");
        j.integer(k + 1);
        j.key("omega");
        j.number(m.omega);
        j.key("omega_squared");
        j.number(m.omega_squared);
        j.key("participation");
        j.by_axis(&m.participation);
        j.key("period");
        j.number(tau / m.omega);
        j.key("shape");
        j.numbers(&m.shape);
        j.close(b'}');
    }
    j.close(b']');
    j.key("out_of_balance_force");
    j.number(header.residual);
    j.key("solver");
    j.string(if header.sparse { "sparse" } else { "dense" });
    j.key("stiffness_asymmetry");
    j.number(modes.stiffness_asymmetry);
    j.key("total_mass");
    j.by_axis(&modes.total_mass);
    j.close(b'}');
    // Only `str`s and serde_json's numbers were written: the bytes are UTF-8.
    String::from_utf8(j.out).unwrap_or_default()
}
