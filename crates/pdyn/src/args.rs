//! Reading the text arguments of the symbolic commands (`kin`, `dsolve`, and their Python
//! twins `pdyn.kin`, `pdyn.dsolve`): comma-separated lists, `name = value` items, the names an
//! expression uses, and which `--set` values may not be assumed positive.

use crate::Error;
use pdyn_expr::syntax::Ast;
use pdyn_expr::{Id, Pool};

/// Splits at top-level commas (not inside parentheses or brackets).
pub fn split_top(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut depth = 0i32;
    let mut cur = String::new();
    for ch in s.chars() {
        match ch {
            '(' | '[' => depth += 1,
            ')' | ']' => depth -= 1,
            _ => {}
        }
        if ch == ',' && depth == 0 {
            out.push(std::mem::take(&mut cur));
        } else {
            cur.push(ch);
        }
    }
    if !cur.trim().is_empty() {
        out.push(cur);
    }
    out.into_iter().map(|p| p.trim().to_string()).collect()
}

/// `name = expr` items of a comma-separated list (`--polar "r = R, theta = t^2"`).
pub fn assignments(s: &str, origin: &str) -> Result<Vec<(String, String)>, Error> {
    split_top(s)
        .into_iter()
        .map(|item| {
            let (k, v) = item.split_once('=').ok_or_else(|| {
                Error::argument(
                    origin,
                    format!("{origin}: expected `name = value`, got `{item}`"),
                )
            })?;
            let k = k.trim().to_string();
            if k.is_empty() || !k.chars().all(|c| c.is_alphanumeric() || c == '_') {
                return Err(Error::argument(
                    origin,
                    format!("{origin}: `{k}` is not a name"),
                ));
            }
            Ok((k, v.trim().to_string()))
        })
        .collect()
}

/// Names used as plain identifiers in `ast` (candidates for parameters), in order.
pub fn idents(ast: &Ast, out: &mut Vec<String>) {
    match ast {
        Ast::Ident { name, .. } => {
            if !out.contains(name) {
                out.push(name.clone())
            }
        }
        Ast::Num { .. } | Ast::Quantity { .. } => {}
        Ast::Neg { expr, .. } | Ast::Prime { expr, .. } | Ast::Component { expr, .. } => {
            idents(expr, out)
        }
        Ast::Binary { lhs, rhs, .. } => {
            idents(lhs, out);
            idents(rhs, out);
        }
        Ast::Call { args, .. } => args.iter().for_each(|a| idents(a, out)),
        Ast::Vector { items, .. } => items.iter().for_each(|a| idents(a, out)),
    }
}

/// The names of an expression that become parameters assumed positive: all but `t`, `pi`,
/// `e`, those `skip` excludes (coordinates, the independent variable), those declared
/// `--signed`, and those given a value ≤ 0 with `--set`.
pub fn positive_parameters(
    names: Vec<String>,
    skip: impl Fn(&str) -> bool,
    signed: &[String],
    set: &[String],
) -> Vec<String> {
    let signed_by_set = not_positive_in_set(set);
    names
        .into_iter()
        .filter(|n| {
            !["t", "pi", "e"].contains(&n.as_str())
                && !skip(n)
                && !signed.contains(n)
                && !signed_by_set.contains(n)
        })
        .collect()
}

/// Names that `--set` gives a value that is not a positive number (`omega=-3`, `c=0`, or an
/// expression of other names). Parameters are assumed positive while deriving (it decides
/// `sqrt(R^2) = R` and the signs of discriminants); a value given later that contradicts or
/// may contradict the assumption must not inherit results derived under it, so these names
/// are derived without it, as if given with `--signed`.
pub fn not_positive_in_set(set: &[String]) -> Vec<String> {
    let mut out = Vec::new();
    for item in set.iter().flat_map(|s| split_top(s)) {
        let Some((name, value)) = item.split_once('=') else {
            continue;
        };
        let mut pool = Pool::new();
        let positive = pool
            .parse_scalar(value.trim())
            .ok()
            .and_then(|v| pool.eval_const(v).ok())
            .is_some_and(|v| v > 0.0 && v.is_finite());
        if !positive {
            out.push(name.trim().to_string());
        }
    }
    out
}

/// Substitutes every `(symbol, value)` pair in turn.
pub fn subs_all(pool: &mut Pool, e: Id, map: &[(Id, Id)]) -> Id {
    map.iter().fold(e, |acc, &(k, v)| pool.subs1(acc, k, v))
}
