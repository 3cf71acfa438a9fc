//! What a mechanics run prints at the end: the method and its statistics, the final values,
//! events, the contact modes, impacts and energy accounting of a hybrid run, and the
//! conserved quantities with their verdicts.

use super::{RunResult, RunSettings};
use std::path::Path;

/// The report of a finished run (`out`: where the files were written).
pub fn text_report(
    model: &pdyn_mech::Model,
    res: &RunResult,
    set: &RunSettings,
    out: Option<&Path>,
) -> String {
    let mut s = format!("{}\n", model.name);
    s += &format!(
        "method {}, t = 0..{}, {} accepted / {} rejected steps, {} f-evaluations, {} output rows\n",
        res.method,
        set.t_end,
        res.stats.accepted,
        res.stats.rejected,
        res.stats.fevals,
        res.outputs
    );
    if let Some(last) = res.rows.last() {
        s += "\nfinal values:\n";
        for (c, v) in res.columns.iter().zip(last) {
            s += &format!("  {c:<20} {v:.10e}\n");
        }
    }
    if !res.events.is_empty() {
        s += "\nevents:\n";
        for e in &res.events {
            s += &format!(
                "  {:<16} t = {:.12e} ({})\n",
                e.name,
                e.t,
                if e.rising { "rising" } else { "falling" }
            );
        }
    }
    if let Some(h) = &res.hybrid {
        s += &hybrid_text(h);
    }
    if !res.monitors.is_empty() {
        s += "\nconserved quantities:\n";
        for m in &res.monitors {
            let ok = m.drift <= set.drift_tolerance;
            s += &format!(
                "  {:<20} initial {:.10e}, drift {:.3e} ({}) {}\n",
                m.name,
                m.initial,
                m.drift,
                if m.relative { "relative" } else { "absolute" },
                if ok { "ok" } else { "DRIFTING" }
            );
        }
    }
    if let Some(dir) = out {
        s += &format!(
            "\nwrote {}/trajectory.csv and summary.json\n",
            dir.display()
        );
    }
    s
}

/// Most lines of each list (mode intervals, switches, impacts) in the text report; the whole
/// lists are in `summary.json`.
const HYBRID_LINES: usize = 12;

/// The mode timeline, impacts, Zeno accumulations, event actions and energy accounting of a
/// hybrid run.
fn hybrid_text(h: &super::hybrid::HybridReport) -> String {
    let mut s = String::new();
    let more = |s: &mut String, total: usize| {
        if total > HYBRID_LINES {
            *s += &format!("  ... {} more in summary.json\n", total - HYBRID_LINES);
        }
    };
    if !h.timeline.is_empty() {
        s += "\ncontact modes:\n";
        for iv in h.timeline.iter().take(HYBRID_LINES) {
            let modes: Vec<String> = iv.modes.iter().map(|(c, m)| format!("{c} {m}")).collect();
            s += &format!(
                "  t = {:.9e} .. {:.9e}  {}\n",
                iv.t_from,
                iv.t_to,
                modes.join(", ")
            );
        }
        more(&mut s, h.timeline.len());
    }
    if !h.switches.is_empty() {
        s += "\nswitches:\n";
        for sw in h.switches.iter().take(HYBRID_LINES) {
            s += &format!(
                "  t = {:.12e}  {}: {} -> {} ({})\n",
                sw.t, sw.contact, sw.from, sw.to, sw.reason
            );
        }
        more(&mut s, h.switches.len());
    }
    if !h.impacts.is_empty() {
        s += &format!("\nimpacts ({}):\n", h.impacts.len());
        for im in h.impacts.iter().take(HYBRID_LINES) {
            s += &format!(
                "  t = {:.12e}  {}: normal speed {:.6e} -> {:.6e}, impulse {:.6e}, energy lost {:.6e}\n",
                im.t, im.contact, im.normal_speed_before, im.normal_speed_after, im.impulse, im.energy_lost
            );
        }
        more(&mut s, h.impacts.len());
    }
    for z in &h.zeno {
        s += &format!(
            "\nZeno: the bounces at `{}` accumulate at t = {:.12e} (ratio {:.9}, {} bounces integrated): resting contact from there\n",
            z.contact, z.t_accumulation, z.ratio, z.bounces
        );
    }
    if !h.actions.is_empty() {
        s += "\nevent actions:\n";
        for a in h.actions.iter().take(HYBRID_LINES) {
            s += &format!("  t = {:.12e}  {}: {}\n", a.t, a.event, a.set.join("; "));
        }
        more(&mut s, h.actions.len());
    }
    s += &format!(
        "\nenergy: work of the contact forces {:.9e}, dissipated by friction {:.9e}, lost in impacts {:.9e}",
        h.work_contacts, h.dissipated_friction, h.dissipated_impacts
    );
    if h.energy_actions != 0.0 {
        s += &format!(", added by event actions {:.9e}", h.energy_actions);
    }
    s += "\n";
    s
}
