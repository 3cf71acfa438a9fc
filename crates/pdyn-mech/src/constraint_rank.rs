//! Which constraints of a model are redundant or contradictory, for a derivation that came out
//! singular or inconsistent.
//!
//! Constraints `f_i(q, t) = 0` enter the equations of motion through their gradients
//! `∇f_i = ∂f_i/∂q` (once differentiated twice). When one gradient is a combination of the
//! others at the initial state, the constraint either repeats the others (`2x + 2y = 0` after
//! `x + y = 0`: its reaction is then undetermined) or contradicts them (`x + y = 1` after
//! `x + y = 0`: no position satisfies both). Gaussian elimination of the rows `[∇f_i | f_i]`
//! in file order, with the combination of earlier rows tracked, tells which and with which
//! constraints; the error then names them with their lines in the file.

use crate::derive::DeriveError;
use crate::model::CoordinateKind;
use crate::Model;
use pdyn_expr::error::line_col;
use pdyn_expr::{Id, Program};

/// Relative size below which an eliminated gradient counts as zero.
const RANK_TOLERANCE: f64 = 1e-9;

/// A clear error when some constraint's gradient depends on the earlier ones at the initial
/// state; `None` when the gradients are independent (the singularity lies elsewhere) or cannot
/// be evaluated.
pub(crate) fn dependent_constraint(model: &mut Model) -> Option<DeriveError> {
    if model.constraints.len() < 2 {
        return None;
    }
    let free: Vec<(Id, f64)> = model
        .coordinates
        .iter()
        .filter_map(|c| match c.kind {
            CoordinateKind::Free { initial, .. } => Some((c.sym, initial)),
            CoordinateKind::Prescribed { .. } => None,
        })
        .map(|(sym, initial)| (model.pool.coord(sym, 0), initial))
        .collect();
    let n = free.len();
    let qs: Vec<Id> = free.iter().map(|f| f.0).collect();
    let fs: Vec<Id> = model.constraints.iter().map(|c| c.equation).collect();
    let mut outputs = model.pool.jacobian(&fs, &qs);
    outputs.extend(&fs);
    let mut inputs = vec![model.pool.time()];
    inputs.extend(&qs);
    inputs.extend(model.parameters.iter().map(|p| p.id));
    let prog = Program::compile(&mut model.pool, &inputs, &outputs).ok()?;
    let mut values = vec![0.0];
    values.extend(free.iter().map(|f| f.1));
    values.extend(model.parameters.iter().map(|p| p.value));
    let mut out = vec![0.0; outputs.len()];
    prog.eval(&values, &mut prog.workspace(), &mut out);
    if out.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let m = fs.len();
    // Rows [∇f_i | f_i | e_i]: the identity part records which constraints each row combines.
    let mut rows: Vec<Vec<f64>> = (0..m)
        .map(|i| {
            let mut r = out[i * n..(i + 1) * n].to_vec();
            r.push(out[m * n + i]);
            r.extend((0..m).map(|k| if k == i { 1.0 } else { 0.0 }));
            r
        })
        .collect();
    let mut pivots: Vec<(usize, usize)> = Vec::new(); // (row, column)
    for i in 0..m {
        let scale = rows[i][..n].iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for &(pr, pc) in &pivots {
            let factor = rows[i][pc] / rows[pr][pc];
            if factor != 0.0 {
                let pivot_row = rows[pr].clone();
                for (x, p) in rows[i].iter_mut().zip(&pivot_row) {
                    *x -= factor * p;
                }
            }
        }
        let rest = rows[i][..n].iter().fold(0.0f64, |a, x| a.max(x.abs()));
        if rest > RANK_TOLERANCE * scale.max(f64::MIN_POSITIVE) {
            let col = (0..n)
                .max_by(|&a, &b| rows[i][a].abs().total_cmp(&rows[i][b].abs()))
                .unwrap_or(0);
            pivots.push((i, col));
            continue;
        }
        // Row i is a combination of earlier rows: name them.
        let with: Vec<String> = (0..i)
            .filter(|&k| rows[i][n + 1 + k].abs() > RANK_TOLERANCE)
            .map(|k| describe(model, k))
            .collect();
        let residual = rows[i][n];
        let size = (0..m)
            .filter(|&k| rows[i][n + 1 + k] != 0.0)
            .map(|k| out[m * n + k].abs())
            .fold(1.0f64, f64::max);
        let this = describe(model, i);
        let with = if with.is_empty() {
            "the others".to_string()
        } else {
            with.join(", ")
        };
        return Some(if residual.abs() > 1e-8 * size {
            DeriveError {
                message: format!(
                    "constraint {this} contradicts {with}: no position satisfies them all \
                     (at the initial state they leave a residual of {residual:.3e})"
                ),
                help: Some("remove or correct one of them".into()),
                location: Some(located(model, i)),
            }
        } else {
            DeriveError {
                message: format!(
                    "constraint {this} repeats {with}: it follows from them, so its reaction \
                     cannot be determined"
                ),
                help: Some("remove it; the remaining constraints already impose it".into()),
                location: Some(located(model, i)),
            }
        });
    }
    None
}

/// Line and column of constraint `k`.
fn located(model: &Model, k: usize) -> (u32, u32) {
    let (line, column) = line_col(&model.source, model.constraints[k].span.start);
    let narrow = |x: usize| u32::try_from(x).unwrap_or(u32::MAX);
    (narrow(line), narrow(column))
}

/// `` `label` (line N) `` of constraint `k`.
fn describe(model: &Model, k: usize) -> String {
    let c = &model.constraints[k];
    let (line, _) = line_col(&model.source, c.span.start);
    format!("`{}` (line {line})", c.label)
}
