// Plots after a run: feed and each joint's velocity, acceleration and jerk against its
// limits, from the status stream's samples (joint positions at set-point indices, so at the
// status interval: the derivatives are averages over it and the jerk is rough).

function diff(t, y) {
  const out = { t: [], y: [] };
  for (let k = 1; k < y.length; k++) {
    const dt = t[k] - t[k - 1];
    if (dt > 0) { out.t.push((t[k] + t[k - 1]) / 2); out.y.push((y[k] - y[k - 1]) / dt); }
  }
  return out;
}

function ticks(lo, hi, n) {
  const span = hi - lo || 1, raw = span / n, mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => span / s <= n) || 10 * mag;
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  return out;
}

function label(v) {
  const a = Math.abs(v);
  if (a === 0) return '0';
  if (a >= 1e5 || a < 1e-3) return v.toExponential(1);
  return String(+v.toPrecision(4));
}

/// One plot on a new canvas in `parent`.
function plot(parent, title, unit, series, limit) {
  const canvas = document.createElement('canvas');
  canvas.dataset.title = title;
  parent.appendChild(canvas);
  const dpr = window.devicePixelRatio || 1;
  const W = canvas.clientWidth || 320, H = canvas.clientHeight || 170;
  canvas.width = W * dpr; canvas.height = H * dpr;
  const g = canvas.getContext('2d');
  g.scale(dpr, dpr);
  g.fillStyle = '#fff'; g.fillRect(0, 0, W, H);
  const L = 58, R = 8, T = 20, B = 30;
  const t0 = series.t[0] ?? 0, t1 = series.t[series.t.length - 1] ?? 1;
  let lo = Math.min(0, ...series.y), hi = Math.max(0, ...series.y);
  if (limit && isFinite(limit)) { lo = Math.min(lo, -limit); hi = Math.max(hi, limit); }
  const pad = (hi - lo) * 0.05 || 1; lo -= pad; hi += pad;
  const x = (t) => L + (t - t0) / ((t1 - t0) || 1) * (W - L - R);
  const y = (v) => T + (hi - v) / (hi - lo) * (H - T - B);
  g.font = '12px "DejaVu Sans", sans-serif';
  g.fillStyle = '#111'; g.textAlign = 'left'; g.fillText(title, L, 13);
  g.strokeStyle = '#ddd'; g.fillStyle = '#333'; g.lineWidth = 1;
  g.textAlign = 'right';
  for (const v of ticks(lo, hi, 5)) {
    g.beginPath(); g.moveTo(L, y(v)); g.lineTo(W - R, y(v)); g.stroke();
    g.fillText(label(v), L - 4, y(v) + 4);
  }
  g.textAlign = 'center';
  for (const t of ticks(t0, t1, 6)) g.fillText(label(t), x(t), H - B + 14);
  g.fillText('time (s)', (L + W - R) / 2, H - 3);
  g.save(); g.translate(11, (T + H - B) / 2); g.rotate(-Math.PI / 2); g.fillText(unit, 0, 0); g.restore();
  g.strokeStyle = '#000'; g.strokeRect(L, T, W - L - R, H - T - B);
  if (limit && isFinite(limit)) {
    g.strokeStyle = '#d22'; g.lineWidth = 1.5;
    for (const v of [limit, -limit]) { g.beginPath(); g.moveTo(L, y(v)); g.lineTo(W - R, y(v)); g.stroke(); }
  }
  g.strokeStyle = '#1f5fd0'; g.lineWidth = 1.2; g.beginPath();
  series.t.forEach((t, k) => (k ? g.lineTo(x(t), y(series.y[k])) : g.moveTo(x(t), y(series.y[k]))));
  g.stroke();
  return canvas;
}

/// Draws the plots of `samples` ({t, joints, tip}) for `machine` into `parent`.
export function drawPlots(parent, samples, machine) {
  parent.replaceChildren();
  if (samples.length < 4) return 0;
  const t = samples.map((s) => s.t);
  let n = 0;
  const feed = diff(t, samples.map((s, k) => (k ? Math.hypot(...s.tip.map((v, i) => v - samples[k - 1].tip[i])) : 0))
    .reduce((acc, d, k) => (acc.push((acc[k - 1] || 0) + d), acc), []));
  plot(parent, 'Feed (path speed)', 'mm/s', feed, null); n++;
  machine.joints.forEach((j, i) => {
    const scale = j.unit === 'deg' ? 180 / Math.PI : 1;
    const v = diff(t, samples.map((s) => s.joints[i] * scale));
    const a = diff(v.t, v.y);
    const jk = diff(a.t, a.y);
    const name = j.name.toUpperCase();
    plot(parent, `${name} velocity`, `${j.unit}/s`, v, j.max_velocity); n++;
    plot(parent, `${name} acceleration`, `${j.unit}/s²`, a, j.max_acceleration); n++;
    plot(parent, `${name} jerk`, `${j.unit}/s³`, jk, j.max_jerk); n++;
  });
  return n;
}
