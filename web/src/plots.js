// Interactive time plots (uPlot: zoom by dragging, double-click to reset, legend values under
// the cursor). Colours are the Okabe–Ito palette, distinguishable with the common forms of
// colour blindness, and every series also has its own dash pattern, so no reading depends on
// colour alone.
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";

export const PALETTE = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442"];
const DASHES = [[], [8, 4], [2, 3], [10, 3, 2, 3], [4, 4], [1, 2], [12, 6], [6, 2, 2, 2]];

function chart(node, title, time, series, xLabel) {
  const box = document.createElement("figure");
  box.className = "plot";
  const cap = document.createElement("figcaption");
  cap.textContent = title;
  box.appendChild(cap);
  node.appendChild(box);
  const width = Math.max(320, Math.min(node.clientWidth || 720, 900) - 16);
  const opts = {
    width,
    height: 300,
    scales: { x: { time: false } },
    axes: [{ label: xLabel }, {}],
    series: [{ label: xLabel }].concat(
      series.map((s, k) => ({
        label: s.name,
        stroke: PALETTE[k % PALETTE.length],
        dash: DASHES[Math.floor(k / PALETTE.length + k) % DASHES.length],
        width: 1.75,
        spanGaps: false,
      })),
    ),
  };
  const data = [time].concat(series.map((s) => s.values));
  return new uPlot(opts, data, box);
}

/** Plots a run's series (at most `maxPerChart` per chart) and its conservation panel. */
export function showPlots(node, result) {
  node.replaceChildren();
  const time = result.time ?? [];
  if (time.length < 2) {
    const p = document.createElement("p");
    p.textContent = "Too few output points to plot.";
    node.appendChild(p);
    return;
  }
  const xLabel = "t";
  const groups = groupSeries(result.series ?? []);
  for (const [title, series] of groups) chart(node, title, time, series, xLabel);
  if (result.conservation?.length) chart(node, "Conserved quantities (should stay flat)", time, result.conservation, xLabel);
}

/** Coordinates and rates apart from the other outputs, at most 8 lines a chart. */
function groupSeries(series) {
  const state = series.filter((s) => !s.name.includes("."));
  const other = series.filter((s) => s.name.includes("."));
  const out = [];
  const push = (title, list) => {
    for (let i = 0; i < list.length; i += 8) out.push([list.length > 8 ? `${title} (${i / 8 + 1})` : title, list.slice(i, i + 8)]);
  };
  if (state.length) push("State", state);
  if (other.length) push("Positions, reactions, monitors", other);
  return out;
}
