// The 3-D path preview: plain WebGL lines, an orbit camera (rotate, pan, zoom; mouse, wheel
// and touch), the path coloured by kind as Kelekçi (2021) does, the travel box and the tool.

const COLOURS = {
  line: [0.25, 0.88, 0.82],   // turquoise
  arc: [0.24, 0.80, 0.29],    // green
  fitted: [1.0, 0.25, 0.25],  // red
  nurbs: [1.0, 0.88, 0.25],   // yellow
  rapid: [0.78, 0.78, 0.78],  // dashed grey
  box: [0.35, 0.40, 0.46],
  tool: [1.0, 0.45, 0.95],
  axisX: [0.9, 0.3, 0.3], axisY: [0.3, 0.9, 0.3], axisZ: [0.35, 0.5, 1.0],
};

const VERTEX = `
attribute vec3 pos; attribute vec3 col; uniform mat4 mvp; varying vec3 v;
void main() { v = col; gl_Position = mvp * vec4(pos, 1.0); }`;
const FRAGMENT = `
precision mediump float; varying vec3 v;
void main() { gl_FragColor = vec4(v, 1.0); }`;

function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
}

function lookAt(eye, target, up) {
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const norm = (a) => { const l = Math.hypot(...a) || 1; return a.map((x) => x / l); };
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const z = norm(sub(eye, target)), x = norm(cross(up, z)), y = cross(z, x);
  return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
    -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
}

function multiply(a, b) {
  const o = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++)
    for (let k = 0; k < 4; k++) o[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return o;
}

export class View3D {
  constructor(canvas) {
    this.canvas = canvas;
    const gl = canvas.getContext('webgl', { antialias: true, preserveDrawingBuffer: true });
    this.gl = gl;
    this.ok = !!gl;
    this.layers = { path: null, box: null, tool: null };
    this.bounds = null;
    this.box = null;
    this.tool = null;
    this.cam = { target: [0, 0, 0], dist: 300, yaw: -Math.PI / 3, pitch: 0.6 };
    if (!gl) return;
    const shader = (type, src) => {
      const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s); return s;
    };
    const p = gl.createProgram();
    gl.attachShader(p, shader(gl.VERTEX_SHADER, VERTEX));
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, FRAGMENT));
    gl.linkProgram(p);
    this.program = p;
    this.loc = { pos: gl.getAttribLocation(p, 'pos'), col: gl.getAttribLocation(p, 'col'),
      mvp: gl.getUniformLocation(p, 'mvp') };
    this.input();
    new ResizeObserver(() => this.redraw()).observe(canvas);
    this.redraw();
  }

  /// A layer from [x,y,z,r,g,b] pairs of vertices (gl.LINES).
  layer(name, data) {
    const gl = this.gl;
    if (!gl) return;
    if (this.layers[name]) gl.deleteBuffer(this.layers[name].buffer);
    const buffer = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(data), gl.STATIC_DRAW);
    this.layers[name] = { buffer, count: data.length / 6 };
    this.redraw();
  }

  /// The program's pieces: {kind, line, points: [[x,y,z], …]}.
  setPath(pieces) {
    const data = [];
    let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const piece of pieces) for (const p of piece.points) {
      for (let i = 0; i < 3; i++) { lo[i] = Math.min(lo[i], p[i]); hi[i] = Math.max(hi[i], p[i]); }
    }
    if (!pieces.length) { lo = [0, 0, 0]; hi = [0, 0, 0]; }
    const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1);
    const dash = size / 120;
    for (const piece of pieces) {
      const c = COLOURS[piece.kind] || COLOURS.line;
      const pts = piece.points;
      for (let k = 1; k < pts.length; k++) {
        const a = pts[k - 1], b = pts[k];
        if (piece.kind === 'rapid') {
          const len = Math.hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
          const n = Math.min(400, Math.max(1, Math.floor(len / dash)));
          for (let d = 0; d < n; d += 2) {
            const s = d / n, e = Math.min(1, (d + 1) / n);
            const at = (t) => [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t];
            data.push(...at(s), ...c, ...at(e), ...c);
          }
        } else {
          data.push(...a, ...c, ...b, ...c);
        }
      }
    }
    this.bounds = { lo, hi };
    this.layer('path', data);
    this.fit();
  }

  /// The machine's travel (mm); axes with no limits are left out.
  setBox(lo, hi) {
    this.box = { lo, hi };
    const c = COLOURS.box, data = [];
    const corner = (i) => [i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]];
    for (let i = 0; i < 8; i++) for (const bit of [1, 2, 4]) {
      if (!(i & bit)) data.push(...corner(i), ...c, ...corner(i | bit), ...c);
    }
    // The machine's axes at its origin.
    const l = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 12;
    data.push(0, 0, 0, ...COLOURS.axisX, l, 0, 0, ...COLOURS.axisX);
    data.push(0, 0, 0, ...COLOURS.axisY, 0, l, 0, ...COLOURS.axisY);
    data.push(0, 0, 0, ...COLOURS.axisZ, 0, 0, l, ...COLOURS.axisZ);
    this.layer('box', data);
    if (!this.bounds) this.fit();
  }

  /// The tool's tip: a cross with a shank along the tool axis (tip → spindle; +Z when the
  /// machine has no rotary joints).
  setTool(p, axis) {
    const k = axis || [0, 0, 1];
    const key = [...p, ...k];
    if (this.tool && this.tool.every((v, i) => v === key[i])) return;
    this.tool = key;
    const s = this.scale() / 40, c = COLOURS.tool;
    const [x, y, z] = p;
    this.layer('tool', [x - s, y, z, ...c, x + s, y, z, ...c, x, y - s, z, ...c, x, y + s, z, ...c,
      x, y, z, ...c, x + 4 * s * k[0], y + 4 * s * k[1], z + 4 * s * k[2], ...c]);
  }

  scale() {
    const b = this.bounds && isFinite(this.bounds.lo[0]) ? this.bounds : this.box;
    if (!b) return 100;
    return Math.max(b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2], 1);
  }

  fit() {
    const b = this.bounds && this.bounds.hi[0] >= this.bounds.lo[0] && this.scale() > 1 ? this.bounds : this.box;
    if (b) {
      this.cam.target = [0, 1, 2].map((i) => (b.lo[i] + b.hi[i]) / 2);
      this.cam.dist = this.scale() * 1.8;
    }
    this.redraw();
  }

  top() { this.cam.yaw = -Math.PI / 2; this.cam.pitch = Math.PI / 2 - 1e-3; this.redraw(); }
  iso() { this.cam.yaw = -Math.PI / 3; this.cam.pitch = 0.6; this.redraw(); }

  input() {
    const c = this.canvas, pointers = new Map();
    let pinch = null;
    c.addEventListener('contextmenu', (e) => e.preventDefault());
    c.addEventListener('pointerdown', (e) => {
      c.setPointerCapture(e.pointerId);
      pointers.set(e.pointerId, { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button !== 0 });
      pinch = null;
    });
    const up = (e) => { pointers.delete(e.pointerId); pinch = null; };
    c.addEventListener('pointerup', up);
    c.addEventListener('pointercancel', up);
    c.addEventListener('pointermove', (e) => {
      const p = pointers.get(e.pointerId);
      if (!p) return;
      if (pointers.size === 2) {
        const [a, b] = [...pointers.values()];
        p.x = e.clientX; p.y = e.clientY;
        const d = Math.hypot(a.x - b.x, a.y - b.y);
        if (pinch) this.zoom(pinch / d);
        pinch = d;
        return;
      }
      const dx = e.clientX - p.x, dy = e.clientY - p.y;
      p.x = e.clientX; p.y = e.clientY;
      if (p.pan) this.pan(dx, dy); else this.rotate(dx, dy);
    });
    c.addEventListener('wheel', (e) => { e.preventDefault(); this.zoom(Math.exp(e.deltaY * 0.0015)); },
      { passive: false });
  }

  rotate(dx, dy) {
    this.cam.yaw -= dx * 0.008;
    this.cam.pitch = Math.max(-1.55, Math.min(1.55, this.cam.pitch + dy * 0.008));
    this.redraw();
  }

  zoom(f) { this.cam.dist = Math.max(0.5, Math.min(1e6, this.cam.dist * f)); this.redraw(); }

  pan(dx, dy) {
    const { yaw, pitch, dist } = this.cam;
    const k = dist * 0.0015;
    const right = [-Math.sin(yaw), Math.cos(yaw), 0];
    const up = [-Math.sin(pitch) * Math.cos(yaw), -Math.sin(pitch) * Math.sin(yaw), Math.cos(pitch)];
    for (let i = 0; i < 3; i++) this.cam.target[i] += (-dx * right[i] + dy * up[i]) * k;
    this.redraw();
  }

  redraw() {
    if (!this.ok || this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => { this.pending = false; this.draw(); });
  }

  draw() {
    const gl = this.gl, c = this.canvas, dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(c.clientWidth * dpr)), h = Math.max(1, Math.round(c.clientHeight * dpr));
    if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
    gl.viewport(0, 0, w, h);
    gl.clearColor(0.063, 0.075, 0.086, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    const { target, dist, yaw, pitch } = this.cam;
    const eye = [target[0] + dist * Math.cos(pitch) * Math.cos(yaw),
      target[1] + dist * Math.cos(pitch) * Math.sin(yaw), target[2] + dist * Math.sin(pitch)];
    const mvp = multiply(perspective(0.8, w / h, dist / 100, dist * 100), lookAt(eye, target, [0, 0, 1]));
    gl.useProgram(this.program);
    gl.uniformMatrix4fv(this.loc.mvp, false, new Float32Array(mvp));
    for (const name of ['box', 'path', 'tool']) {
      const l = this.layers[name];
      if (!l || !l.count) continue;
      gl.bindBuffer(gl.ARRAY_BUFFER, l.buffer);
      gl.enableVertexAttribArray(this.loc.pos);
      gl.vertexAttribPointer(this.loc.pos, 3, gl.FLOAT, false, 24, 0);
      gl.enableVertexAttribArray(this.loc.col);
      gl.vertexAttribPointer(this.loc.col, 3, gl.FLOAT, false, 24, 12);
      gl.drawArrays(gl.LINES, 0, l.count);
    }
  }
}
