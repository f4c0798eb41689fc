// Canvas drawing shared by the pages: line charts, the green-screen histogram,
// the sprites overlay's colours.

export const VERDICT_COLOURS = {
  stored: '#3ddc84',
  usable: '#22d3ee',
  touches_border: '#f5a524',
  no_ground_hit: '#a78bfa',
  leaves_floor: '#f472b6',
  touches_wall: '#ef4444',
  noise: '#e879f9',
  still: '#94a3b8',
  too_large: '#fb923c',
  view_too_steep: '#facc15',
};
export const VERDICT_LABELS = {
  stored: 'stored (session runs)',
  usable: 'usable (no session)',
  touches_border: 'touches the image border',
  no_ground_hit: 'ray misses the floor',
  leaves_floor: 'leaves the floor',
  touches_wall: 'touches a wall',
  noise: 'noise (keyed background)',
  still: 'still',
  too_large: 'billboard too large (px_per_m)',
  view_too_steep: 'seen from too far above',
};
export function verdictColour(v) {
  return VERDICT_COLOURS[v] || '#eab308';
}

// Sizes a canvas's backing store to its CSS box (device pixels); returns the
// context scaled so drawing is in CSS pixels.
export function fitCanvas(canvas) {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  const ctx = canvas.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  return { ctx, w: canvas.clientWidth, h: canvas.clientHeight };
}

const css = (name, fallback) =>
  getComputedStyle(document.documentElement).getPropertyValue(name).trim() || fallback;

// A time-series chart: series [{values: [[t, v]...], colour}], over [t0, t1].
export function lineChart(canvas, series, t0, t1, { unit = '', min = 0 } = {}) {
  const { ctx, w, h } = fitCanvas(canvas);
  ctx.clearRect(0, 0, w, h);
  let max = min + 1;
  for (const s of series) for (const [, v] of s.values) if (Number.isFinite(v)) max = Math.max(max, v);
  max = niceCeil(max);
  const left = 34;
  const right = w - 4;
  const top = 7;
  const bottom = h - 12;
  const x = (t) => left + ((t - t0) / (t1 - t0)) * (right - left);
  const y = (v) => bottom - ((v - min) / (max - min)) * (bottom - top);
  ctx.font = '10px ' + css('--mono', 'monospace');
  ctx.fillStyle = css('--muted', '#8a94a6');
  ctx.strokeStyle = css('--grid', '#263041');
  ctx.lineWidth = 1;
  ctx.textBaseline = 'middle';
  ctx.textAlign = 'right';
  for (const v of [min, (min + max) / 2, max]) {
    ctx.beginPath();
    ctx.moveTo(left, Math.round(y(v)) + 0.5);
    ctx.lineTo(right, Math.round(y(v)) + 0.5);
    ctx.stroke();
    ctx.fillText(short(v) + unit, left - 4, y(v));
  }
  ctx.textAlign = 'center';
  ctx.textBaseline = 'alphabetic';
  for (let m = 0; m <= 5; m++) {
    const t = t1 - m * 60;
    if (t < t0) break;
    ctx.fillText(m === 0 ? 'now' : `-${m}m`, Math.min(right - 10, Math.max(left + 8, x(t))), h - 1);
  }
  for (const s of series) {
    ctx.strokeStyle = s.colour;
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    let pen = false;
    let lastT = null;
    for (const [t, v] of s.values) {
      if (!Number.isFinite(v) || t < t0) {
        pen = false;
        continue;
      }
      if (lastT !== null && t - lastT > 3) pen = false; // a gap in the samples
      if (pen) ctx.lineTo(x(t), y(v));
      else ctx.moveTo(x(t), y(v));
      pen = true;
      lastT = t;
    }
    ctx.stroke();
  }
}

function niceCeil(v) {
  if (v <= 0) return 1;
  const p = Math.pow(10, Math.floor(Math.log10(v)));
  for (const m of [1, 2, 2.5, 5, 10]) if (v <= m * p) return m * p;
  return 10 * p;
}

function short(v) {
  if (v >= 1000) return (v / 1000).toFixed(v >= 10000 ? 0 : 1) + 'k';
  if (v >= 10 || v === 0) return String(Math.round(v));
  return v.toFixed(1);
}

// The green-screen histogram: 32 bins a channel, r, g, b overlaid.
export function histogram(canvas, hist) {
  const { ctx, w, h } = fitCanvas(canvas);
  ctx.clearRect(0, 0, w, h);
  ctx.fillStyle = css('--well', '#0b0f16');
  ctx.fillRect(0, 0, w, h);
  if (!hist) return;
  let max = 1;
  for (const ch of ['r', 'g', 'b']) for (const v of hist[ch] || []) max = Math.max(max, v);
  const colours = { r: 'rgba(255,90,90,0.45)', g: 'rgba(80,230,120,0.55)', b: 'rgba(90,150,255,0.45)' };
  for (const ch of ['r', 'g', 'b']) {
    const bins = hist[ch] || [];
    const n = bins.length || 32;
    ctx.fillStyle = colours[ch];
    ctx.beginPath();
    ctx.moveTo(0, h);
    bins.forEach((v, i) => {
      const y = h - Math.sqrt(v / max) * (h - 2);
      ctx.lineTo((i / n) * w, y);
      ctx.lineTo(((i + 1) / n) * w, y);
    });
    ctx.lineTo(w, h);
    ctx.closePath();
    ctx.fill();
    ctx.strokeStyle = colours[ch].replace(/[\d.]+\)$/, '0.95)');
    ctx.lineWidth = 1;
    ctx.stroke();
  }
  // the clipping end and the dark end (green below 40 of 255)
  ctx.fillStyle = 'rgba(255,255,255,0.08)';
  ctx.fillRect(0, 0, (40 / 256) * w, h);
}

// A top-down plan's grid (the calibration wizard's and the studio's): a line every `step` metres
// over the ground seen, [gx0, gx1] x [gy0, gy1], then the ground axes through the origin,
// labelled. X and Y map ground metres to canvas pixels (ground y up).
export function groundGrid(ctx, w, h, X, Y, [gx0, gx1, gy0, gy1], step) {
  ctx.strokeStyle = '#182130';
  ctx.lineWidth = 1;
  for (let gx = Math.ceil(gx0 / step) * step; gx <= gx1; gx += step) {
    ctx.beginPath(); ctx.moveTo(Math.round(X(gx)) + 0.5, 0); ctx.lineTo(Math.round(X(gx)) + 0.5, h); ctx.stroke();
  }
  for (let gy = Math.ceil(gy0 / step) * step; gy <= gy1; gy += step) {
    ctx.beginPath(); ctx.moveTo(0, Math.round(Y(gy)) + 0.5); ctx.lineTo(w, Math.round(Y(gy)) + 0.5); ctx.stroke();
  }
  ctx.strokeStyle = '#34425a';
  ctx.beginPath(); ctx.moveTo(X(0), 0); ctx.lineTo(X(0), h); ctx.moveTo(0, Y(0)); ctx.lineTo(w, Y(0)); ctx.stroke();
  ctx.font = '10px ui-monospace, monospace';
  ctx.fillStyle = '#5b677a';
  ctx.fillText('x', w - 10, Y(0) - 4);
  ctx.fillText('y', X(0) + 4, 10);
}
