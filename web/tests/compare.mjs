// Compares the page's JSON with the CLI's, value by value: strings, booleans and integers
// must be equal; floating-point numbers are counted as bit-identical or not, with the largest
// difference kept (relative, and scaled by max(1, |a|, |b|)). Wall-clock fields differ by nature and are skipped.
const TIMING = /(^|_)(seconds|per_second|wall|elapsed)(_|$)|^loop_seconds$|^atom_steps_per_second$/;

export function compare(page, cli) {
  const stats = { identical: 0, differing: 0, maxRelative: 0, maxScaled: 0, worst: "", mismatches: [] };
  walk(page, cli, "", stats);
  return stats;
}

function walk(a, b, path, s) {
  if (typeof a === "number" && typeof b === "number") {
    if (Object.is(a, b)) {
      s.identical++;
      return;
    }
    if (Number.isInteger(a) && Number.isInteger(b) && Math.abs(a) < 2 ** 31 && Math.abs(b) < 2 ** 31 && !/\.|e/.test(String(a) + String(b))) {
      // Counts (steps, evaluations, rows) are not approximations.
      s.mismatches.push(`${path}: ${a} ≠ ${b}`);
      return;
    }
    s.differing++;
    const rel = Math.abs(a - b) / Math.max(Math.abs(a), Math.abs(b), 1e-300);
    s.maxRelative = Math.max(s.maxRelative, rel);
    // Round-off is relative to the value's size, and to 1 near zero.
    const scaled = Math.abs(a - b) / Math.max(1, Math.abs(a), Math.abs(b));
    if (scaled >= s.maxScaled) {
      s.maxScaled = scaled;
      s.worst = `${path}: page ${a}, CLI ${b}`;
    }
    return;
  }
  if (Array.isArray(a) && Array.isArray(b)) {
    if (a.length !== b.length) s.mismatches.push(`${path}: ${a.length} items ≠ ${b.length}`);
    for (let i = 0; i < Math.min(a.length, b.length); i++) walk(a[i], b[i], `${path}[${i}]`, s);
    return;
  }
  if (a && b && typeof a === "object" && typeof b === "object") {
    const keys = new Set([...Object.keys(a), ...Object.keys(b)]);
    for (const k of keys) {
      if (TIMING.test(k)) continue;
      if (!(k in a) || !(k in b)) {
        s.mismatches.push(`${path}.${k}: only in the ${k in a ? "page" : "CLI"}`);
        continue;
      }
      walk(a[k], b[k], path ? `${path}.${k}` : k, s);
    }
    return;
  }
  if (a !== b) s.mismatches.push(`${path}: ${JSON.stringify(a)?.slice(0, 120)} ≠ ${JSON.stringify(b)?.slice(0, 120)}`);
}
