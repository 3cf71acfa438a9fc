//! Fuzz the expression parser and everything it feeds: lowering, printing, re-parsing,
//! differentiation. Run: `RUSTC_BOOTSTRAP=1 cargo fuzz run parse` from the repository root.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pdyn_expr::{Pool, Value};

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else { return };
    if src.len() > 256 {
        return;
    }
    let mut p = Pool::new();
    match p.parse_value(src) {
        Ok(v) => {
            let parts: Vec<_> = match v {
                Value::Scalar(s) => vec![s],
                Value::Vector(c) => c.to_vec(),
            };
            for x in parts {
                let text = p.to_text(x);
                // Printed text always parses again (names may change role, so only no error).
                assert!(p.parse_value(&text).is_ok(), "{src:?} printed as {text:?} does not parse");
                let _ = p.to_latex(x);
                let _ = p.dt(x);
            }
        }
        Err(e) => {
            let _ = e.render(src, "fuzz");
        }
    }
});
