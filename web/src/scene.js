// The particles animated on a canvas: paths drawn faintly, the particles as discs at the
// current frame. Planar motion is drawn in its plane; motion in 3-D is projected (an oblique
// view that turns slowly while playing). MD frames draw the atoms in their periodic box.
import { PALETTE } from "./plots.js";

export class Scene {
  constructor(canvas, slider, label, playButton) {
    this.canvas = canvas;
    this.slider = slider;
    this.label = label;
    this.play = playButton;
    this.data = null;
    this.frame = 0;
    this.timer = null;
    this.angle = 0.6;
    slider.addEventListener("input", () => this.show(Number(slider.value)));
    playButton.addEventListener("click", () => (this.timer ? this.stop() : this.start()));
  }

  /** `result` as `pdyn_web::run` returns it. */
  load(result) {
    this.stop();
    const frames = result.frame_times ?? [];
    const paths = result.particles ?? [];
    if (result.kind === "md") {
      this.data = { kind: "md", times: frames, frames: result.frames ?? [], atoms: result.atoms ?? 0, box: result.box };
    } else {
      this.data = { kind: result.kind, times: frames, paths };
    }
    this.axes = this.chooseAxes();
    this.slider.max = String(Math.max(0, frames.length - 1));
    this.slider.value = "0";
    this.show(0);
  }

  /** The two axes that vary for planar motion, or all three. */
  chooseAxes() {
    const d = this.data;
    const range = [0, 1, 2].map((a) => {
      let lo = Infinity;
      let hi = -Infinity;
      const visit = (v) => {
        if (v !== null && Number.isFinite(v)) {
          lo = Math.min(lo, v);
          hi = Math.max(hi, v);
        }
      };
      if (d.kind === "md") {
        for (const f of d.frames) for (let i = 0; i < d.atoms; i++) visit(f[a * d.atoms + i]);
      } else {
        for (const p of d.paths) for (const v of p["xyz"[a]]) visit(v);
      }
      return [lo, hi];
    });
    const varies = range.map(([lo, hi]) => hi - lo > 1e-12 * (1 + Math.abs(hi) + Math.abs(lo)));
    const used = [0, 1, 2].filter((a) => varies[a]);
    this.range = range;
    return used.length === 3 ? [0, 1, 2] : used.length === 2 ? used : used.length === 1 ? [used[0], used[0] === 1 ? 0 : 1] : [0, 1];
  }

  project(p) {
    if (this.axes.length === 3) {
      const c = Math.cos(this.angle);
      const s = Math.sin(this.angle);
      return [p[0] * c - p[1] * s, p[2] + 0.35 * (p[0] * s + p[1] * c)];
    }
    return [p[this.axes[0]], p[this.axes[1]]];
  }

  bounds(points) {
    let [x0, x1, y0, y1] = [Infinity, -Infinity, Infinity, -Infinity];
    for (const [x, y] of points) {
      if (!Number.isFinite(x) || !Number.isFinite(y)) continue;
      x0 = Math.min(x0, x);
      x1 = Math.max(x1, x);
      y0 = Math.min(y0, y);
      y1 = Math.max(y1, y);
    }
    if (!Number.isFinite(x0)) return [-1, 1, -1, 1];
    const pad = 0.08 * Math.max(x1 - x0, y1 - y0, 1e-9);
    return [x0 - pad, x1 + pad, y0 - pad, y1 + pad];
  }

  show(k) {
    const d = this.data;
    if (!d) return;
    this.frame = k;
    const ctx = this.canvas.getContext("2d");
    const W = this.canvas.width;
    const H = this.canvas.height;
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(0, 0, W, H);
    const t = d.times[k];
    this.label.value = t === undefined || t === null ? "" : `t = ${Number(t).toPrecision(6)}`;
    const pointsOf = (i) => (d.kind === "md" ? this.atoms(i) : d.paths.map((p) => [p.x[i], p.y[i], p.z[i]]));
    // Bounds over all frames keep the view still.
    const all = [];
    if (d.kind === "md") {
      const b = d.box ?? [1, 1, 1];
      for (const x of [0, b[0]]) for (const y of [0, b[1]]) for (const z of [0, b[2]]) all.push(this.project([x, y, z]));
    } else {
      for (let i = 0; i < d.times.length; i++) for (const p of pointsOf(i)) all.push(this.project(p));
    }
    const [x0, x1, y0, y1] = this.bounds(all);
    const scale = Math.min(W / (x1 - x0), H / (y1 - y0));
    const ox = (W - scale * (x1 - x0)) / 2;
    const oy = (H - scale * (y1 - y0)) / 2;
    const screen = ([x, y]) => [ox + (x - x0) * scale, H - (oy + (y - y0) * scale)];
    if (d.kind === "md") {
      this.drawBox(ctx, screen, d.box ?? [1, 1, 1]);
      const atoms = pointsOf(k);
      ctx.fillStyle = PALETTE[0];
      for (const p of atoms) {
        const [x, y] = screen(this.project(p));
        ctx.beginPath();
        ctx.arc(x, y, 2.5, 0, 2 * Math.PI);
        ctx.fill();
      }
      return;
    }
    d.paths.forEach((p, j) => {
      const colour = PALETTE[j % PALETTE.length];
      ctx.strokeStyle = colour;
      ctx.globalAlpha = 0.35;
      ctx.lineWidth = 1;
      ctx.beginPath();
      let pen = false;
      for (let i = 0; i < d.times.length; i++) {
        const q = [p.x[i], p.y[i], p.z[i]];
        if (q.some((v) => v === null)) {
          pen = false;
          continue;
        }
        const [x, y] = screen(this.project(q));
        if (pen) ctx.lineTo(x, y);
        else ctx.moveTo(x, y);
        pen = true;
      }
      ctx.stroke();
      ctx.globalAlpha = 1;
      const q = [p.x[k], p.y[k], p.z[k]];
      if (q.some((v) => v === null)) return;
      const [x, y] = screen(this.project(q));
      ctx.fillStyle = colour;
      ctx.beginPath();
      ctx.arc(x, y, 6, 0, 2 * Math.PI);
      ctx.fill();
      ctx.fillStyle = "#111";
      ctx.font = "13px system-ui, sans-serif";
      ctx.fillText(p.name, x + 8, y - 8);
    });
  }

  atoms(i) {
    const d = this.data;
    const f = d.frames[i] ?? [];
    const n = d.atoms;
    const out = new Array(n);
    for (let a = 0; a < n; a++) out[a] = [f[a], f[n + a], f[2 * n + a]];
    return out;
  }

  drawBox(ctx, screen, b) {
    const corners = [];
    for (const x of [0, b[0]]) for (const y of [0, b[1]]) for (const z of [0, b[2]]) corners.push([x, y, z]);
    ctx.strokeStyle = "#999";
    ctx.lineWidth = 1;
    for (let i = 0; i < 8; i++)
      for (let j = i + 1; j < 8; j++) {
        const diff = [0, 1, 2].filter((a) => corners[i][a] !== corners[j][a]).length;
        if (diff !== 1) continue;
        const [ax, ay] = screen(this.project(corners[i]));
        const [bx, by] = screen(this.project(corners[j]));
        ctx.beginPath();
        ctx.moveTo(ax, ay);
        ctx.lineTo(bx, by);
        ctx.stroke();
      }
  }

  start() {
    if (!this.data || this.data.times.length < 2) return;
    this.play.textContent = "Pause";
    const n = this.data.times.length;
    const stepMs = Math.max(16, 8000 / n);
    this.timer = setInterval(() => {
      if (this.axes.length === 3) this.angle += 0.01;
      const k = (this.frame + 1) % n;
      this.slider.value = String(k);
      this.show(k);
    }, stepMs);
  }

  stop() {
    if (this.timer) clearInterval(this.timer);
    this.timer = null;
    this.play.textContent = "Play";
  }
}
