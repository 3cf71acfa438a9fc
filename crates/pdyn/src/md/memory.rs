//! How much memory an `[md]` model needs, estimated before anything is allocated, and how much
//! the machine has: a model that does not fit is refused with both sizes (it died with
//! "memory allocation of 128000000 bytes failed" at 32 million atoms).
//!
//! The estimate is an upper bound of the peak, per atom (measured: 450–510 bytes per atom
//! for the LJ liquid at 10⁵–5·10⁵ atoms, estimated 676):
//! - 200 bytes: the particles (positions, velocities, accelerations, masses: 80), types and
//!   image counts (16), the lattice as generated before it is stored (56), the force totals
//!   and output (48);
//! - 156 bytes per atom or ghost in the neighbour list (its sorted positions, owners,
//!   permutation, bins, reference positions: 96; up to four per-segment force buffers: 60),
//!   ghosts being the atoms within `cutoff + skin` of a face, `Π (Lₖ + 2w)/Lₖ`;
//! - 8 bytes per pair within `cutoff + skin` of the half list, `(2π/3) ρ (rc + skin)³`
//!   (4-byte indices, twice while the list is rebuilt);
//! - 24 bytes for the MSD's reference positions when `msd = true`.
//!
//! The limit is `MemAvailable` of `/proc/meminfo`, or [`FALLBACK_LIMIT`] where it cannot be
//! read; the environment variable `PDYN_MEMORY_LIMIT` (bytes, or with `K`, `M`, `G` suffixes)
//! sets it instead.

/// The limit where `/proc/meminfo` cannot be read: 8 GiB.
pub const FALLBACK_LIMIT: u64 = 8 << 30;

/// The memory a model needs, estimated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Atoms.
    pub atoms: u64,
    /// Bytes per atom.
    pub per_atom: f64,
    /// Bytes in all.
    pub bytes: f64,
}

/// The estimate for `atoms` atoms in a box of edges `edges`, pairs within `reach` (the
/// largest cutoff plus the skin), with or without the MSD.
pub fn estimate(atoms: u64, edges: [f64; 3], reach: f64, msd: bool) -> Estimate {
    let volume = edges[0] * edges[1] * edges[2];
    let density = if volume > 0.0 {
        atoms as f64 / volume
    } else {
        0.0
    };
    let ghosts: f64 = edges
        .iter()
        .map(|&l| if l > 0.0 { (l + 2.0 * reach) / l } else { 1.0 })
        .product::<f64>()
        .min(27.0);
    let pairs = 2.0 * std::f64::consts::PI / 3.0 * density * reach.powi(3);
    let per_atom = 200.0 + 156.0 * ghosts + 8.0 * pairs + if msd { 24.0 } else { 0.0 };
    Estimate {
        atoms,
        per_atom,
        bytes: per_atom * atoms as f64,
    }
}

/// Where the limit came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LimitSource {
    /// `PDYN_MEMORY_LIMIT`.
    Environment,
    /// `MemAvailable` in `/proc/meminfo`.
    MemAvailable,
    /// [`FALLBACK_LIMIT`].
    Fallback,
}

impl std::fmt::Display for LimitSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LimitSource::Environment => "PDYN_MEMORY_LIMIT",
            LimitSource::MemAvailable => "MemAvailable in /proc/meminfo",
            LimitSource::Fallback => "pdyn's fixed limit where /proc/meminfo cannot be read",
        })
    }
}

/// The memory a model may use, in bytes, and where that comes from.
pub fn limit() -> (u64, LimitSource) {
    if let Some(v) = std::env::var_os("PDYN_MEMORY_LIMIT") {
        if let Some(b) = v.to_str().and_then(parse_size) {
            return (b, LimitSource::Environment);
        }
    }
    match std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| mem_available(&s))
    {
        Some(b) => (b, LimitSource::MemAvailable),
        None => (FALLBACK_LIMIT, LimitSource::Fallback),
    }
}

/// `MemAvailable` of a `/proc/meminfo` text, in bytes.
pub fn mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kb.checked_mul(1024)
}

/// `123`, `4K`, `5M`, `6G` (powers of 1024), `2.5G`.
pub fn parse_size(s: &str) -> Option<u64> {
    let s = s.trim();
    let (num, mult) = match s.chars().last()? {
        'k' | 'K' => (&s[..s.len() - 1], 1u64 << 10),
        'm' | 'M' => (&s[..s.len() - 1], 1 << 20),
        'g' | 'G' => (&s[..s.len() - 1], 1 << 30),
        _ => (s, 1),
    };
    let x: f64 = num.trim().parse().ok()?;
    (x.is_finite() && x >= 0.0).then_some((x * mult as f64) as u64)
}

/// Bytes for a person: `21.6 GB`.
pub fn human(bytes: f64) -> String {
    let units = [("GB", 1e9), ("MB", 1e6), ("kB", 1e3)];
    for (u, s) in units {
        if bytes >= s {
            return format!("{:.1} {u}", bytes / s);
        }
    }
    format!("{bytes:.0} bytes")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_meminfo_are_read() {
        assert_eq!(parse_size("123"), Some(123));
        assert_eq!(parse_size("4K"), Some(4096));
        assert_eq!(parse_size("2.5G"), Some(5 << 29));
        assert_eq!(parse_size("x"), None);
        assert_eq!(parse_size("-1"), None);
        let info = "MemTotal:       24000000 kB\nMemFree:  100 kB\nMemAvailable:   22000000 kB\n";
        assert_eq!(mem_available(info), Some(22_000_000 * 1024));
        assert_eq!(mem_available("MemTotal: 5 kB\n"), None);
    }

    /// The LJ liquid of the example (fcc, ρ = 0.8442, rc + skin = 2.8): ~39 pairs per atom;
    /// at 32 million atoms about 21.6 GB, each term as derived in the module's text.
    #[test]
    fn the_lj_liquid_estimate_follows_its_terms() {
        let a = libm::cbrt(4.0f64 / 0.8442);
        let edge = 200.0 * a;
        let e = estimate(32_000_000, [edge; 3], 2.8, false);
        let pairs = 2.0 * std::f64::consts::PI / 3.0 * 0.8442 * 2.8f64.powi(3);
        let ghosts = ((edge + 5.6) / edge).powi(3);
        let want = 200.0 + 156.0 * ghosts + 8.0 * pairs;
        assert!((e.per_atom - want).abs() < 1e-9, "{} vs {want}", e.per_atom);
        assert!((e.bytes / 1e9 - 21.6).abs() < 0.2, "{}", human(e.bytes));
    }
}
