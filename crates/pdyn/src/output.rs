//! Output files of a run: the trajectory table as CSV and the summary as JSON.
//!
//! CSV columns: `t`; every free coordinate `q` then every rate `q'` (state order); each
//! particle's position components `NAME.x`, `NAME.y`, `NAME.z` (components that are identically
//! zero are left out); every reaction by name; the conserved quantities pdyn monitors
//! (`energy`, `angular_momentum.z`, `momentum.x`, ...); the model's `[monitors]`.

use crate::sim::RunResult;
use serde_json::json;
use std::io::Write;
use std::path::Path;

/// The header line of a CSV table (with its newline): the names joined by commas, a name
/// that holds a comma, a quote or a line break quoted as RFC 4180 says (`"x[0,1]"`, a quote
/// doubled), so that every CSV reader (pandas, Excel, `pdyn kin --data`) sees one column per
/// name. A family's members are named `x[0,1]`: unquoted, a reader split them in two.
pub fn csv_header<S: AsRef<str>>(names: &[S]) -> String {
    let mut line = String::new();
    for (i, name) in names.iter().enumerate() {
        let name = name.as_ref();
        if i > 0 {
            line.push(',');
        }
        if name.contains([',', '"', '\n', '\r']) {
            line.push('"');
            line.push_str(&name.replace('"', "\"\""));
            line.push('"');
        } else {
            line.push_str(name);
        }
    }
    line.push('\n');
    line
}

/// Writes the trajectory table.
pub fn write_csv(res: &RunResult, path: &Path) -> std::io::Result<()> {
    let mut f = std::fs::File::create(path)?;
    f.write_all(csv_header(&res.columns).as_bytes())?;
    // Rows are formatted into one buffer, written every 256 KiB: a run of 1,000 stick-slip
    // cycles writes 1.6 million numbers, and the formatting is half of its time.
    let mut out: Vec<u8> = Vec::with_capacity(CSV_CHUNK + 4096);
    for row in &res.rows {
        for (i, x) in row.iter().enumerate() {
            if i > 0 {
                out.push(b',');
            }
            append_number(&mut out, *x);
        }
        out.push(b'\n');
        if out.len() >= CSV_CHUNK {
            f.write_all(&out)?;
            out.clear();
        }
    }
    f.write_all(&out)?;
    f.flush()
}

/// Bytes of `trajectory.csv` formatted before each write.
const CSV_CHUNK: usize = 1 << 18;

/// Appends `x` in the shortest form that reads back as the same `f64` (`0.1`, `1e-7`,
/// `-0.9700043600000001`: never more than 17 significant digits). Fixed 18-digit output
/// (`{:.17e}`) printed digits no reader needs and took a tenth of a 16-link chain's `pdyn run`
/// (exact-digit formatting falls back to bignum arithmetic); `{:e}`'s shortest digits took 8 %.
///
/// The digits come from `zmij` (Żmij, serde_json's own formatter), which takes about 60 % of
/// `ryu`'s time (the 100-link chain's 1.7·10⁶ numbers: 87–109 ms by `ryu`, 56–67 ms by `zmij`)
/// and prints the same text but for a `+` in positive exponents (`1e+21`), dropped here so
/// that tables read as they did with `ryu`: `1e21`, `NaN`, `inf`, `-inf`.
///
/// A number below [`PLUS_FROM`] in magnitude (every number of a usual table) has no `+` to
/// look for: its text is copied as `zmij` wrote it.
#[inline]
pub fn append_number(out: &mut Vec<u8>, x: f64) {
    let mut buf = zmij::Buffer::new();
    let text = buf.format(x).as_bytes();
    if x.abs() < PLUS_FROM {
        out.extend_from_slice(text);
        return;
    }
    match exponent_plus(text) {
        Some(k) => {
            out.extend_from_slice(&text[..k]);
            out.extend_from_slice(&text[k + 1..]);
        }
        None => out.extend_from_slice(text),
    }
}

/// [`append_number`] into a `String`.
#[inline]
pub fn push_number(line: &mut String, x: f64) {
    let mut buf = zmij::Buffer::new();
    let text = buf.format(x);
    if x.abs() < PLUS_FROM {
        line.push_str(text);
        return;
    }
    match exponent_plus(text.as_bytes()) {
        Some(k) => {
            line.push_str(&text[..k]);
            line.push_str(&text[k + 1..]);
        }
        None => line.push_str(text),
    }
}

/// Below this magnitude `zmij` writes no exponent with a `+`: it prints a finite number in
/// fixed notation up to the decimal exponent 15 (`FIXED_DEC_EXP`, -5..=15, for `f64`), and
/// the shortest text of a number below 10^15 is itself below 10^15 (it reads back as that
/// number). NaN compares false and is scanned (its text has no `+`). The scan per number was
/// about a third of [`append_number`]'s own instructions (the 100-link chain's 1.7·10⁶ numbers).
const PLUS_FROM: f64 = 1e15;

/// Where the `+` of a positive exponent is in `zmij`'s text: only numbers of magnitude 1e16
/// and above have one, so the common case is one comparison of the length and a scan from
/// the end over the few exponent digits.
fn exponent_plus(text: &[u8]) -> Option<usize> {
    // The exponent is at most three digits, after `e+`; the mantissa at least one digit.
    let tail = text.len().saturating_sub(5);
    text[tail..]
        .iter()
        .position(|&b| b == b'+')
        .map(|k| tail + k)
}

/// The JSON summary: the fields every kind shares ([`crate::summary::common`]: monitors with
/// their verdict against `drift_tolerance`, solver statistics, warnings), then the final
/// state, events, method and number of outputs.
pub fn summary(
    res: &RunResult,
    model_name: &str,
    state_names: &[String],
    drift_tolerance: f64,
) -> serde_json::Value {
    let last = res.rows.last();
    let final_state: serde_json::Map<String, serde_json::Value> = match last {
        Some(r) => res
            .columns
            .iter()
            .zip(r)
            .map(|(c, v)| (c.clone(), json_num(*v)))
            .collect(),
        None => Default::default(),
    };
    let monitors: Vec<crate::summary::Conserved<'_>> = res
        .monitors
        .iter()
        .map(|m| crate::summary::Conserved {
            name: &m.name,
            initial: m.initial,
            final_value: res
                .columns
                .iter()
                .position(|c| *c == m.name)
                .and_then(|k| last.map(|r| r[k])),
            drift: m.drift,
            relative: m.relative,
            scale: m.scale,
            tolerance: drift_tolerance,
            conserved: m.conserved,
        })
        .collect();
    crate::summary::common(
        "mechanics",
        model_name,
        res.failure.as_ref().map(|f| f.to_string()),
        &res.warnings,
        &monitors,
        json!({
            "steps": res.stats.steps, "accepted": res.stats.accepted, "rejected": res.stats.rejected,
            "fevals": res.stats.fevals, "jacobians": res.stats.jacobians,
            "lu_decompositions": res.stats.lu_decompositions,
        }),
        json!({
            "method": res.method.to_string(),
            "final": final_state,
            "events": res.events.iter().map(|e| json!({
                "name": e.name,
                "t": json_num(e.t),
                "direction": if e.rising { "rising" } else { "falling" },
                "state": state_names.iter().zip(&e.state).map(|(n, v)| (n.clone(), json_num(*v))).collect::<serde_json::Map<_, _>>(),
            })).collect::<Vec<_>>(),
            "outputs": res.outputs,
        }),
    )
}

/// The text of `summary.json` (and of `pdyn run --json`): the summary, then a hybrid run's
/// report (mode timeline, switches, impacts, Zeno accumulations, event actions, energy
/// accounting) as its `hybrid` object, `null` otherwise. The report is written straight from
/// its types: a run of 1,000 stick-slip cycles has 2,000 switches, and building them as a JSON
/// value tree first took a quarter of the whole run.
pub fn summary_text(
    sum: &serde_json::Value,
    hybrid: Option<&crate::sim::hybrid::HybridReport>,
) -> String {
    #[derive(serde::Serialize)]
    struct WithHybrid<'a> {
        #[serde(flatten)]
        summary: &'a serde_json::Value,
        hybrid: Option<&'a crate::sim::hybrid::HybridReport>,
    }
    let mut text = serde_json::to_string_pretty(&WithHybrid {
        summary: sum,
        hybrid,
    })
    .unwrap_or_else(|e| format!("{{\"error\": \"summary not serializable: {e}\"}}"));
    text.push('\n');
    text
}

/// A hybrid run's report as JSON text, the `hybrid` object of `summary.json` (for the Python
/// binding).
pub fn hybrid_json(h: &crate::sim::hybrid::HybridReport) -> String {
    serde_json::to_string(h).unwrap_or_else(|_| "null".to_string())
}

/// A number for JSON: finite values as numbers, NaN and infinities as the strings `"NaN"`,
/// `"inf"`, `"-inf"` (JSON has no such numbers; `null` would hide them).
pub fn json_num(x: f64) -> serde_json::Value {
    if x.is_finite() {
        json!(x)
    } else {
        json!(x.to_string())
    }
}

/// Writes `bytes` to `path` whole: into a temporary file beside it, synced, then renamed over
/// it, so that a reader (or a run killed meanwhile) sees the old file or the new one, never a
/// part of one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), crate::Error> {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".tmp");
    let tmp = path.with_file_name(name);
    let write = || -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    };
    if let Err(e) = write() {
        let _ = std::fs::remove_file(&tmp);
        return Err(crate::Error::io(&tmp, "write", e));
    }
    std::fs::rename(&tmp, path).map_err(|e| crate::Error::io(path, "rename into", e))
}

#[cfg(test)]
mod tests {
    use super::{append_number, push_number};

    /// Tables read as they did when `ryu` formatted them: the same text for every bit
    /// pattern (NaN, infinities, subnormals, -0, positive and negative exponents, integers
    /// from 1e15 to 1e22 where the exponent form starts), through both entry points.
    #[test]
    fn numbers_print_as_ryu_printed_them() {
        let mut x = 0x2545_f491_4f6c_dd1d_u64;
        let mut samples = vec![
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
            1e-5,
            1e-7,
            123456.0,
        ];
        for e in 10..=23 {
            let p = 10f64.powi(e);
            samples.extend([p, -p, p * 1.5, p - 1.0, 9.999999999999999 * p]);
        }
        for _ in 0..300_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            samples.push(f64::from_bits(x));
            // and numbers of a table's usual sizes
            samples.push(((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 1e3);
        }
        let mut ryu = ryu::Buffer::new();
        let (mut bytes, mut text) = (Vec::new(), String::new());
        for v in samples {
            bytes.clear();
            text.clear();
            append_number(&mut bytes, v);
            push_number(&mut text, v);
            let expected = ryu.format(v);
            assert_eq!(bytes, expected.as_bytes(), "{expected}");
            assert_eq!(text, expected);
        }
    }

    /// Every number in the table reads back as the same bits, in at most 17 significant
    /// digits, across binades and at the edges (subnormals, the largest finite, -0).
    #[test]
    fn table_numbers_read_back_as_the_same_bits() {
        let mut x = 0x1234_5678_9abc_def1_u64;
        let mut samples = vec![
            0.0,
            -0.0,
            0.1,
            1.0 / 3.0,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
        ];
        for _ in 0..20_000 {
            // xorshift over every bit pattern of finite doubles
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if v.is_finite() {
                samples.push(v);
            }
        }
        let mut s = String::new();
        for v in samples {
            s.clear();
            push_number(&mut s, v);
            let back: f64 = s.parse().unwrap_or_else(|e| panic!("{s}: {e}"));
            assert_eq!(back.to_bits(), v.to_bits(), "{s}");
            let mantissa: String = s
                .split(['e', 'E'])
                .next()
                .unwrap()
                .chars()
                .filter(char::is_ascii_digit)
                .collect();
            let digits = mantissa.trim_start_matches('0').trim_end_matches('0').len();
            assert!(digits <= 17, "{s}");
        }
        s.clear();
        push_number(&mut s, f64::NAN);
        assert_eq!(s, "NaN");
    }

    /// Numbers in `summary.json` (and every JSON pdyn reads back: `--json`, checkpoints' plain
    /// fields) read back as the same bits. serde_json's default float parser may be one unit in
    /// the last place off (a summary's `t_reached` of 12071462.258 read back as
    /// 12071462.258000001 made the SIGTERM test flaky); the `float_roundtrip` feature makes it
    /// exact, and this test fails without it.
    #[test]
    fn json_numbers_read_back_as_the_same_bits() {
        let mut x = 0x9e37_79b9_7f4a_7c15_u64;
        let mut wrong = Vec::new();
        for i in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            // Half over every bit pattern, half over times and energies of ordinary size, where
            // the 17-digit decimal forms are the ones a fast parser rounds wrongly.
            let v = if i % 2 == 0 {
                f64::from_bits(x)
            } else {
                (x >> 11) as f64 / (1u64 << 53) as f64 * 1e8
            };
            if !v.is_finite() {
                continue;
            }
            let text = super::json_num(v).to_string();
            let back: f64 = serde_json::from_str(&text).expect("a JSON number");
            if back.to_bits() != v.to_bits() {
                wrong.push(text);
            }
        }
        assert!(
            wrong.is_empty(),
            "{} numbers changed, e.g. {:?}",
            wrong.len(),
            &wrong[..wrong.len().min(5)]
        );
    }
}
