//! Fuzzing of the closed-form solver (`pdyn dsolve`): equations `lhs = rhs` separated by `;`,
//! with initial conditions x(0) = 1, x'(0) = 0 for each coordinate: the stable evaluation
//! (`dsolve::propagator`) at a few times, the closed form, then `--when x = 0`.
//! Run: `RUSTC_BOOTSTRAP=1 cargo fuzz run dsolve -- -max_total_time=1800 -timeout=30`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pdyn_expr::{FreeScope, Pool, Value};

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else { return };
    if src.len() > 512 {
        return;
    }
    let mut p = Pool::new();
    let mut scope = FreeScope::default();
    let mut eqs = Vec::new();
    for item in src.split(';').take(4) {
        let Ok(ast) = pdyn_expr::syntax::parse_equation(item) else { return };
        scope.learn(&ast.0);
        if let Some(r) = &ast.1 {
            scope.learn(r);
        }
        match p.parse_equation_in(item, &mut scope) {
            Ok(Value::Scalar(e)) => eqs.push(e),
            _ => return,
        }
    }
    let mut names: Vec<&String> = scope.coordinates.iter().collect();
    names.sort();
    let coords: Vec<_> = names.iter().map(|c| p.symbol(c, false)).collect();
    if coords.is_empty() || coords.len() > 4 {
        return;
    }
    let mut ics = Vec::new();
    for &c in &coords {
        ics.push((p.coord(c, 0), Pool::ONE));
        ics.push((p.coord(c, 1), Pool::ZERO));
    }
    // The stable evaluation (`dsolve --at`, `run --method exact`) of the same equations:
    // whatever they are, an error or finite-or-not numbers, never a panic or a hang.
    if let Ok(prop) = pdyn_mech::dsolve::propagator(&mut p, &eqs, &coords, &ics) {
        let _ = prop.sample(&[0.5, 1.0, 1.5, 10.0, 3.0]);
    }
    let Ok(cf) = pdyn_mech::dsolve::solve_system(&mut p, &eqs, &coords, &ics) else { return };
    let x = p.coord(coords[0], 0);
    let _ = pdyn_mech::dsolve::when(&mut p, &cf, x);
});
