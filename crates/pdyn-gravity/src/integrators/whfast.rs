//! WHFast: the Wisdom–Holman map in Jacobi coordinates with symplectic correctors.
//! Second order (the error is `O(ε h²)` for a perturbation of relative size `ε`, and
//! `O(ε² h²)` with correctors of order ≥ 3), fixed step, symplectic.
//!
//! Rein & Tamayo (2015), *WHFast: a fast and unbiased implementation of a symplectic
//! Wisdom–Holman integrator for long-term gravitational simulations*, MNRAS 452, 376;
//! Wisdom & Holman (1991), AJ 102, 1528; correctors: Wisdom, Holman & Touma (1996),
//! Fields Inst. Commun. 10, 217.
//!
//! Jacobi coordinates: with `ηᵢ = m₀ + … + mᵢ` and `Rᵢ` the centre of mass of bodies
//! `0..=i`, body `i ≥ 1` has `r'ᵢ = rᵢ − R_{i−1}` (likewise velocities and accelerations)
//! and `r'₀ = R_{N−1}`. The Hamiltonian splits into `H_K = Σᵢ (p'ᵢ²/2m'ᵢ − G mᵢ η_{i−1}/r'ᵢ)`,
//! independent Kepler problems with `μᵢ = G ηᵢ` solved exactly by the universal-variable
//! solver ([`crate::kepler`]), and the interaction `H_I`, which only changes momenta: its
//! Jacobi acceleration is the Jacobi transform of the Newtonian accelerations plus
//! `G ηᵢ r'ᵢ/r'ᵢ³` (the Kepler part subtracted back). For body 1 both terms are the 0–1
//! attraction and cancel exactly, so that pair is left out of both; with two bodies WHFast
//! is then the exact Kepler solution.
//!
//! A step is drift `h/2` (Kepler), kick `h` (interaction), drift `h/2`. Between steps the two
//! half drifts are fused into one, so the state is synchronised (and the corrector undone)
//! only when output is needed. The corrector of order `k ∈ {3, 5, 7, 11, 17}` is a product
//! of operators `Z(a, b) = K(a) I(−b) K(−2a) I(b) K(a)` with the tabulated `aᵢ = i √(7/40)`
//! and `bᵢ` of Wisdom et al. (1996) (values as in REBOUND's `integrator_whfast.c`), applied
//! once at the start and inverted at synchronisation. A last step shortened to `h` to land on
//! an end time is corrected the same way, with the corrector built for `h` (as REBOUND's).

#![allow(clippy::excessive_precision, clippy::needless_range_loop)]

use pdyn_particles::Particles;

use crate::error::{GravityError, Warning};
use crate::forces::Forces;
use crate::kepler::kepler_drift_batch;

/// WHFast parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WhFastParams {
    /// Order of the symplectic corrector: 0 (none), 3, 5, 7, 11 or 17.
    pub corrector: u32,
    /// A kick where some body's perturbing acceleration exceeds this fraction of its Kepler
    /// acceleration stops the run with [`GravityError::CloseEncounter`].
    pub close_encounter_ratio: f64,
    /// A step longer than this fraction of the shortest Jacobi orbital period raises
    /// [`Warning::LongWhFastStep`].
    pub period_fraction_warning: f64,
}

impl Default for WhFastParams {
    fn default() -> Self {
        WhFastParams {
            // REBOUND's default; 11 or 17 for high-accuracy long-term runs.
            corrector: 0,
            close_encounter_ratio: 0.5,
            period_fraction_warning: 0.1,
        }
    }
}

/// Published to 50 digits; kept as printed so they can be checked against the paper.
/// `aᵢ = i √(7/40)` of the correctors (Wisdom, Holman & Touma 1996).
const A1: f64 = 0.418_330_013_267_037_773_989_086_012_892_593_744_696_407_684_649_34;
const B31: f64 = -0.024_900_596_027_799_867_499_350_357_910_273_437_184_309_981_229_127;
const B5: [f64; 2] = [
    -0.008_300_198_675_933_289_166_450_119_303_424_479_061_436_660_409_709_0,
    0.041_500_993_379_666_445_832_250_596_517_122_395_307_183_302_048_545,
];
const B7: [f64; 3] = [
    0.002_492_681_142_692_210_577_903_059_395_277_696_445_053_900_858_221_9,
    -0.018_270_923_246_702_131_478_062_356_884_535_264_841_652_263_842_597,
    0.053_964_399_093_127_498_721_765_893_493_510_877_532_452_806_339_655,
];
const B11: [f64; 5] = [
    0.000_203_615_796_478_546_513_016_328_187_746_337_164_736_965_374_368_47,
    -0.002_348_721_529_229_535_418_830_732_885_105_548_987_625_509_741_975_4,
    0.012_309_078_592_019_946_317_544_564_763_237_909_911_330_686_448_336,
    -0.038_121_613_681_288_650_508_647_613_260_247_372_125_243_616_270_670,
    0.072_593_394_748_842_738_674_253_180_742_744_961_827_622_366_521_517,
];
const B17: [f64; 8] = [
    -0.000_004_334_741_547_337_358_019_065_022_349_812_494_489_678_984_143_224_1,
    0.000_076_436_355_227_935_738_363_241_846_979_413_475_106_795_392_377_415,
    -0.000_635_999_830_758_176_589_831_668_816_250_785_458_641_408_485_602_59,
    0.003_313_257_706_938_065_565_549_019_683_345_199_408_006_680_161_145_9,
    -0.012_071_760_822_342_291_062_449_751_726_959_664_253_913_904_872_527,
    0.032_422_198_864_713_580_293_681_523_029_577_130_832_258_806_467_604,
    -0.065_192_863_576_377_893_658_290_760_803_725_762_027_864_651_086_787,
    0.093_056_103_771_425_958_591_541_059_067_553_547_100_903_397_724_386,
];

/// WHFast workspace: Jacobi coordinates and the cumulative masses.
#[derive(Debug, Clone)]
pub(crate) struct WhFast {
    params: WhFastParams,
    jr: Vec<[f64; 3]>,
    jv: Vec<[f64; 3]>,
    ja: Vec<[f64; 3]>,
    /// Jacobi state before the current step (restored if the step fails).
    backup_r: Vec<[f64; 3]>,
    backup_v: Vec<[f64; 3]>,
    eta: Vec<f64>,
    /// `μᵢ = G ηᵢ` of each Jacobi Kepler problem (index 0 unused).
    mu: Vec<f64>,
    synchronized: bool,
    dt: f64,
}

fn to_jacobi(m: &[f64], eta: &[f64], src: [&[f64]; 3], dst: &mut [[f64; 3]]) {
    let n = m.len();
    let mut s = [m[0] * src[0][0], m[0] * src[1][0], m[0] * src[2][0]];
    for i in 1..n {
        for k in 0..3 {
            dst[i][k] = src[k][i] - s[k] / eta[i - 1];
            s[k] += m[i] * src[k][i];
        }
    }
    for k in 0..3 {
        dst[0][k] = s[k] / eta[n - 1];
    }
}

fn from_jacobi(m: &[f64], eta: &[f64], src: &[[f64; 3]], dst: [&mut [f64]; 3]) {
    let n = m.len();
    let mut big_r = src[0];
    let [dx, dy, dz] = dst;
    for i in (1..n).rev() {
        let w = m[i] / eta[i];
        for k in 0..3 {
            big_r[k] -= w * src[i][k];
        }
        dx[i] = src[i][0] + big_r[0];
        dy[i] = src[i][1] + big_r[1];
        dz[i] = src[i][2] + big_r[2];
    }
    dx[0] = big_r[0];
    dy[0] = big_r[1];
    dz[0] = big_r[2];
}

impl WhFast {
    /// The Jacobi state (positions, velocities, accelerations, the backup), whether it is
    /// synchronized, and the step (the masses' `eta` and `mu` are rebuilt from the particles).
    pub fn save(
        &self,
        scalars: &mut Vec<f64>,
        counters: &mut Vec<u64>,
        arrays: &mut Vec<Vec<f64>>,
    ) {
        scalars.push(self.dt);
        counters.push(u64::from(self.synchronized));
        for a in [&self.jr, &self.jv, &self.ja, &self.backup_r, &self.backup_v] {
            arrays.push(super::flatten3(a));
        }
    }

    /// Takes back what [`WhFast::save`] wrote.
    pub fn load(
        &mut self,
        scalars: &[f64],
        counters: &[u64],
        arrays: &[Vec<f64>],
    ) -> Result<(), &'static str> {
        let ([dt, ..], [sync, ..], [jr, jv, ja, br, bv, ..]) = (scalars, counters, arrays) else {
            return Err("too few WHFast numbers");
        };
        for (dst, src) in [
            (&mut self.jr, jr),
            (&mut self.jv, jv),
            (&mut self.ja, ja),
            (&mut self.backup_r, br),
            (&mut self.backup_v, bv),
        ] {
            super::load3(dst, src)?;
        }
        self.dt = *dt;
        self.synchronized = *sync != 0;
        Ok(())
    }

    /// Validates the parameters and converts `p` to Jacobi coordinates.
    pub fn new(
        params: WhFastParams,
        p: &Particles,
        g: f64,
        dt: f64,
        warnings: &mut Vec<Warning>,
    ) -> Result<Self, GravityError> {
        if ![0, 3, 5, 7, 11, 17].contains(&params.corrector) {
            return Err(GravityError::InvalidParameter {
                name: "corrector",
                value: params.corrector as f64,
            });
        }
        if params.close_encounter_ratio.is_nan() || params.close_encounter_ratio <= 0.0 {
            return Err(GravityError::InvalidParameter {
                name: "close_encounter_ratio",
                value: params.close_encounter_ratio,
            });
        }
        let n = p.len();
        if n == 0 || p.m[0] <= 0.0 {
            return Err(GravityError::MasslessPrimary);
        }
        let mut eta = vec![0.0; n];
        let mut acc = 0.0;
        for i in 0..n {
            acc += p.m[i];
            eta[i] = acc;
        }
        let mut w = WhFast {
            params,
            jr: vec![[0.0; 3]; n],
            jv: vec![[0.0; 3]; n],
            ja: vec![[0.0; 3]; n],
            backup_r: vec![[0.0; 3]; n],
            backup_v: vec![[0.0; 3]; n],
            mu: eta.iter().map(|e| g * e).collect(),
            eta,
            synchronized: true,
            dt,
        };
        to_jacobi(&p.m, &w.eta, [&p.x, &p.y, &p.z], &mut w.jr);
        to_jacobi(&p.m, &w.eta, [&p.vx, &p.vy, &p.vz], &mut w.jv);
        // Period check: P = 2π μ / β^{3/2} for each bound Jacobi orbit.
        let mut shortest: Option<(f64, usize)> = None;
        for i in 1..n {
            let mu = g * w.eta[i];
            let r = norm(w.jr[i]);
            let beta = 2.0 * mu / r - dot(w.jv[i], w.jv[i]);
            if beta > 0.0 {
                let period = 2.0 * std::f64::consts::PI * mu / (beta * beta.sqrt());
                if shortest.is_none_or(|(s, _)| period < s) {
                    shortest = Some((period, i));
                }
            }
        }
        if let Some((period, body)) = shortest {
            if dt > params.period_fraction_warning * period {
                warnings.push(Warning::LongWhFastStep {
                    dt,
                    shortest_period: period,
                    body,
                });
            }
        }
        Ok(w)
    }

    fn kepler(&mut self, _g: f64, h: f64, t: f64) -> Result<(), GravityError> {
        kepler_drift_batch(&self.mu[1..], &mut self.jr[1..], &mut self.jv[1..], h)
            .map_err(|i| GravityError::KeplerNotConverged { t, body: i + 1 })?;
        for k in 0..3 {
            self.jr[0][k] += h * self.jv[0][k];
        }
        Ok(())
    }

    fn interaction(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        h: f64,
        t: f64,
    ) -> Result<(), GravityError> {
        from_jacobi(&p.m, &self.eta, &self.jr, [&mut p.x, &mut p.y, &mut p.z]);
        let skipped = f.compute(p, true);
        to_jacobi(&p.m, &self.eta, [&p.ax, &p.ay, &p.az], &mut self.ja);
        let mut worst = (0.0, 0);
        for i in 1..self.jr.len() {
            let r = self.jr[i];
            let r2 = dot(r, r);
            let mu = f.g * self.eta[i];
            if i >= 2 || !skipped {
                let k = mu / (r2 * r2.sqrt());
                for c in 0..3 {
                    self.ja[i][c] += k * r[c];
                }
            }
            // (|a_int| r²/μ)², compared squared: no square root per body and step.
            let a2 = dot(self.ja[i], self.ja[i]);
            let ratio2 = a2 * r2 * r2 / (mu * mu);
            if ratio2 > worst.0 || ratio2.is_nan() {
                worst = (ratio2, i);
            }
            for c in 0..3 {
                self.jv[i][c] += h * self.ja[i][c];
            }
        }
        for c in 0..3 {
            self.jv[0][c] += h * self.ja[0][c];
        }
        let limit = self.params.close_encounter_ratio;
        if worst.0.is_nan() || worst.0 > limit * limit {
            return Err(GravityError::CloseEncounter {
                t,
                body: worst.1,
                ratio: worst.0.sqrt(),
            });
        }
        Ok(())
    }

    fn z_operator(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        a: f64,
        b: f64,
        t: f64,
    ) -> Result<(), GravityError> {
        self.kepler(f.g, a, t)?;
        self.interaction(p, f, -b, t)?;
        self.kepler(f.g, -2.0 * a, t)?;
        self.interaction(p, f, b, t)?;
        self.kepler(f.g, a, t)
    }

    fn apply_corrector(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        inv: f64,
        t: f64,
    ) -> Result<(), GravityError> {
        let dt = self.dt;
        let half: &[f64] = match self.params.corrector {
            3 => {
                self.z_operator(p, f, A1 * dt, -inv * B31 * dt, t)?;
                return self.z_operator(p, f, -A1 * dt, inv * B31 * dt, t);
            }
            5 => &B5,
            7 => &B7,
            11 => &B11,
            17 => &B17,
            _ => return Ok(()),
        };
        let k = half.len();
        // Z(−a_k, −b_1) … Z(−a_1, −b_k), then the mirror image with both signs flipped.
        for (j, &b) in half.iter().enumerate() {
            let a = A1 * (k - j) as f64;
            self.z_operator(p, f, -a * dt, -inv * b * dt, t)?;
        }
        for (j, &b) in half.iter().enumerate().rev() {
            let a = A1 * (k - j) as f64;
            self.z_operator(p, f, a * dt, inv * b * dt, t)?;
        }
        Ok(())
    }

    /// Saves the Jacobi state, runs `op`, and restores the state if `op` fails, so that an
    /// error leaves the integrator at the last completed step.
    fn transaction(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        op: impl FnOnce(&mut Self, &mut Particles, &mut Forces) -> Result<(), GravityError>,
    ) -> Result<(), GravityError> {
        self.backup_r.copy_from_slice(&self.jr);
        self.backup_v.copy_from_slice(&self.jv);
        let was_synchronized = self.synchronized;
        let result = op(self, p, f);
        if result.is_err() {
            self.jr.copy_from_slice(&self.backup_r);
            self.jv.copy_from_slice(&self.backup_v);
            self.synchronized = was_synchronized;
            if was_synchronized {
                self.write_back(p);
            }
        }
        result
    }

    /// One step of length `self.dt` (fusing the pending half drift); on error the state of
    /// the last completed step is kept.
    pub fn step(&mut self, p: &mut Particles, f: &mut Forces, t: f64) -> Result<(), GravityError> {
        self.transaction(p, f, |w, p, f| w.step_inner(p, f, t))
    }

    fn step_inner(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        t: f64,
    ) -> Result<(), GravityError> {
        let dt = self.dt;
        if self.synchronized {
            if self.params.corrector > 0 {
                self.apply_corrector(p, f, 1.0, t)?;
            }
            self.kepler(f.g, 0.5 * dt, t)?;
        } else {
            self.kepler(f.g, dt, t)?;
        }
        self.synchronized = false;
        self.interaction(p, f, dt, t + 0.5 * dt)
    }

    /// One drift–kick–drift step of length `h` (used to land exactly on an end time),
    /// corrected like a full step — `C(h) DKD(h) C(h)⁻¹` with the corrector `C` built for `h` —
    /// and leaving the state synchronised. Uncorrected, this one step would add the
    /// `O(ε h)` error of the plain map (4e-7 relative in the outer Solar System's positions
    /// at P_J/20), which the correctors otherwise keep at `O(ε² h²)`; REBOUND's shortened last
    /// step (`exact_finish_time = 1`) is corrected too.
    pub fn partial_step(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        t: f64,
        h: f64,
    ) -> Result<(), GravityError> {
        self.transaction(p, f, |w, p, f| w.partial_step_inner(p, f, t, h))
    }

    fn partial_step_inner(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        t: f64,
        h: f64,
    ) -> Result<(), GravityError> {
        self.synchronize(p, f, t)?;
        // A full step and its synchronisation with `self.dt = h` are exactly that; the
        // corrector reads its step from `self.dt`, restored on every path.
        let dt = std::mem::replace(&mut self.dt, h);
        let result = self
            .step_inner(p, f, t)
            .and_then(|()| self.synchronize(p, f, t + h));
        self.dt = dt;
        result
    }

    /// Finishes the pending half drift, undoes the corrector and writes inertial positions and
    /// velocities into `p`.
    pub fn synchronize(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        t: f64,
    ) -> Result<(), GravityError> {
        if !self.synchronized {
            self.kepler(f.g, 0.5 * self.dt, t)?;
            if self.params.corrector > 0 {
                self.apply_corrector(p, f, -1.0, t)?;
            }
            self.synchronized = true;
        }
        self.write_back(p);
        Ok(())
    }

    /// Writes into `p` the state [`WhFast::synchronize`] would, but keeps integrating from
    /// the unsynchronised Jacobi state (REBOUND's `keep_unsynchronized`): the half drift and
    /// the inverse corrector are applied to a copy. Outputs then cost one corrector, not two
    /// (undoing it and applying it again at the next step), and a run's trajectory does not
    /// depend on when it was looked at: integrating to `t₁` then `t₂` is bit for bit
    /// integrating to `t₂`.
    pub fn synchronized_view(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        t: f64,
    ) -> Result<(), GravityError> {
        if self.synchronized {
            self.write_back(p);
            return Ok(());
        }
        self.backup_r.copy_from_slice(&self.jr);
        self.backup_v.copy_from_slice(&self.jv);
        let result = self.kepler(f.g, 0.5 * self.dt, t).and_then(|()| {
            if self.params.corrector > 0 {
                self.apply_corrector(p, f, -1.0, t)
            } else {
                Ok(())
            }
        });
        if result.is_ok() {
            self.write_back(p);
        }
        self.jr.copy_from_slice(&self.backup_r);
        self.jv.copy_from_slice(&self.backup_v);
        result
    }

    fn write_back(&self, p: &mut Particles) {
        from_jacobi(&p.m, &self.eta, &self.jr, [&mut p.x, &mut p.y, &mut p.z]);
        from_jacobi(&p.m, &self.eta, &self.jv, [&mut p.vx, &mut p.vy, &mut p.vz]);
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_round_trip() {
        let m = [1.0, 1e-3, 0.0, 3e-4];
        let eta = [1.0, 1.001, 1.001, 1.0013];
        let x = [0.1, 1.0, -2.0, 3.0];
        let y = [0.0, 0.5, 0.25, -1.0];
        let z = [0.0, 0.1, 0.0, 0.2];
        let mut j = [[0.0; 3]; 4];
        to_jacobi(&m, &eta, [&x, &y, &z], &mut j);
        let (mut a, mut b, mut c) = ([0.0; 4], [0.0; 4], [0.0; 4]);
        from_jacobi(&m, &eta, &j, [&mut a, &mut b, &mut c]);
        for i in 0..4 {
            assert!((a[i] - x[i]).abs() < 1e-15 && (b[i] - y[i]).abs() < 1e-15);
            assert!((c[i] - z[i]).abs() < 1e-15);
        }
        // Body 1's Jacobi position is relative to body 0.
        assert_eq!(j[1], [0.9, 0.5, 0.1]);
    }

    #[test]
    fn corrector_coefficients_are_multiples_of_sqrt_7_over_40() {
        assert!((A1 - (7.0f64 / 40.0).sqrt()).abs() < 1e-16);
    }
}
