//! Where the values are in a TOML file, for mutation testing and fuzzing: shared by
//! `crates/pdyn-cli/tests/mutations.rs` and the structure-aware fuzz targets (`fuzz/`).

/// Byte ranges of the values in `key = value` lines (a quoted string or a bare token).
pub fn value_spans(src: &str) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut offset = 0;
    for line in src.split_inclusive('\n') {
        let t = line.trim_start();
        if !t.starts_with('#') && !t.starts_with('[') {
            let mut i = 0;
            let b = line.as_bytes();
            while let Some(eq) = line[i..].find('=').map(|k| k + i) {
                let mut s = eq + 1;
                while s < b.len() && b[s] == b' ' {
                    s += 1;
                }
                if s >= b.len() {
                    break;
                }
                let e = if b[s] == b'"' {
                    match line[s + 1..].find('"') {
                        Some(k) => s + 1 + k + 1,
                        None => break,
                    }
                } else {
                    let mut e = s;
                    while e < b.len() && !matches!(b[e], b',' | b'}' | b'\n' | b' ' | b'#') {
                        e += 1;
                    }
                    e
                };
                if e > s {
                    spans.push((offset + s, offset + e));
                }
                i = e.max(eq + 1);
            }
        }
        offset += line.len();
    }
    spans
}
