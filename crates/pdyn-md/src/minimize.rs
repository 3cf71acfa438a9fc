//! Energy minimisation by FIRE, the fast inertial relaxation engine (Bitzek, Koskinen, Gähler,
//! Moseler & Gumbsch, Phys. Rev. Lett. 97, 170201 (2006)).
//!
//! MD with mixing `v ← (1 − α) v + α |v| F̂` while the power `P = F·v` is positive; after
//! `N_min` such steps the step grows (`h ← min(f_inc h, h_max)`) and `α ← f_α α`; when `P ≤ 0`
//! the velocities are zeroed, `h ← f_dec h`, `α ← α_start`. Each particle's displacement per
//! step is capped at `max_step` so overlapping starts relax without exploding. Use it to
//! resolve `MdError::Overlap` before a run.

use crate::potential::PairPotential;
use crate::simulation::bond_forces;
use crate::{ForceField, MdError, NeighborList, System};

/// FIRE parameters (Bitzek et al.'s recommended values).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FireParams {
    /// Initial time step (default 0.005).
    pub dt: f64,
    /// Largest time step (default 0.05).
    pub dt_max: f64,
    /// Steps with `P > 0` before the step grows (default 5).
    pub n_min: u32,
    /// Step growth factor (default 1.1).
    pub f_inc: f64,
    /// Step shrink factor (default 0.5).
    pub f_dec: f64,
    /// Initial mixing α (default 0.1).
    pub alpha_start: f64,
    /// α decay (default 0.99).
    pub f_alpha: f64,
    /// Largest displacement per step (default 0.1 σ).
    pub max_step: f64,
    /// Converged when the largest force norm is below this (default 1e-4 ε/σ).
    pub force_tolerance: f64,
    /// Iteration limit (default 10 000).
    pub max_iter: u32,
    /// Neighbour-list skin (default 0.3 σ).
    pub skin: f64,
}

impl Default for FireParams {
    fn default() -> Self {
        FireParams {
            dt: 0.005,
            dt_max: 0.05,
            n_min: 5,
            f_inc: 1.1,
            f_dec: 0.5,
            alpha_start: 0.1,
            f_alpha: 0.99,
            max_step: 0.1,
            force_tolerance: 1e-4,
            max_iter: 10_000,
            skin: 0.3,
        }
    }
}

/// Outcome of a minimisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MinimizeReport {
    /// Iterations taken.
    pub iterations: u32,
    /// Final potential energy.
    pub energy: f64,
    /// Final largest force norm.
    pub max_force: f64,
    /// Whether `max_force < force_tolerance`.
    pub converged: bool,
}

/// Minimises the potential energy of `system` in place (velocities are zeroed at the end).
pub fn minimize_fire<P: PairPotential>(
    system: &mut System,
    ff: &ForceField<P>,
    params: &FireParams,
) -> Result<MinimizeReport, MdError> {
    let mut nl = NeighborList::new(ff.max_cutoff(), params.skin)?;
    nl.check_box(&system.sim_box)?;
    let n = system.particles.len();
    let mut out = vec![[0.0; 3]; n];
    let mut scratch = crate::forces::ForceScratch::default();
    let special = crate::special::SpecialPairs::from_bonds(n, &system.bonds, system.special_lj)?;
    let mut eval = |s: &mut System, nl: &mut NeighborList| -> Result<(f64, f64), MdError> {
        if nl.needs_rebuild(&s.particles) {
            nl.build(&mut s.particles, &mut s.images, &s.sim_box);
        } else {
            nl.update_positions(&s.particles);
        }
        let (u_p, _) = ff.compute(nl, &s.types, &mut scratch, &mut out, true);
        let (u_s, _) = special.correct(s, ff, &mut out);
        let (u_b, _) = bond_forces(s, &mut out, true)?;
        let u = u_p + u_s + u_b;
        let mut fmax2: f64 = 0.0;
        let p = &mut s.particles;
        for (i, f) in out.iter().enumerate() {
            [p.ax[i], p.ay[i], p.az[i]] = *f; // forces, not accelerations (unit mass)
            fmax2 = fmax2.max(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        }
        Ok((u, fmax2.sqrt()))
    };
    let p = &mut system.particles;
    for v in [&mut p.vx, &mut p.vy, &mut p.vz] {
        v.iter_mut().for_each(|c| *c = 0.0);
    }
    let (mut u, mut fmax) = eval(system, &mut nl)?;
    let (mut h, mut alpha, mut since) = (params.dt, params.alpha_start, 0u32);
    let mut it = 0;
    while it < params.max_iter
        && fmax.partial_cmp(&params.force_tolerance) != Some(std::cmp::Ordering::Less)
    {
        it += 1;
        let p = &mut system.particles;
        let (mut pw, mut vn, mut fnorm) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let (v, f) = (p.vel(i), p.acc(i));
            pw += v.dot(f);
            vn += v.norm2();
            fnorm += f.norm2();
        }
        let (vn, fnorm) = (vn.sqrt(), fnorm.sqrt());
        if pw > 0.0 {
            let c = if fnorm > 0.0 { alpha * vn / fnorm } else { 0.0 };
            for i in 0..n {
                p.set_vel(i, (1.0 - alpha) * p.vel(i) + c * p.acc(i));
            }
            since += 1;
            if since > params.n_min {
                h = (h * params.f_inc).min(params.dt_max);
                alpha *= params.f_alpha;
            }
        } else {
            for i in 0..n {
                p.set_vel(i, pdyn_particles::Vec3::ZERO);
            }
            since = 0;
            h *= params.f_dec;
            alpha = params.alpha_start;
        }
        // semi-implicit Euler with displacement cap
        p.kick(h);
        for i in 0..n {
            let dx = h * p.vel(i);
            let d = dx.norm();
            let dx = if d > params.max_step {
                (params.max_step / d) * dx
            } else {
                dx
            };
            p.set_pos(i, p.pos(i) + dx);
        }
        (u, fmax) = eval(system, &mut nl)?;
    }
    let p = &mut system.particles;
    for v in [
        &mut p.vx, &mut p.vy, &mut p.vz, &mut p.ax, &mut p.ay, &mut p.az,
    ] {
        v.iter_mut().for_each(|c| *c = 0.0);
    }
    Ok(MinimizeReport {
        iterations: it,
        energy: u,
        max_force: fmax,
        converged: fmax < params.force_tolerance,
    })
}
