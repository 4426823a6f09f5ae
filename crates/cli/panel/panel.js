// The operator panel: one WebSocket to `tezgah serve` (the page's own host, the page's
// `?token=` passed on), commands out, replies, control changes and the status stream in.

import { View3D } from './view3d.js';
import { drawPlots } from './plots.js';

const $ = (id) => document.getElementById(id);
const fmt = (v, d = 3) => (v === null || v === undefined || !isFinite(v) ? '—' : v.toFixed(d));
const STATE_CLASS = { idle: 'ok', running: 'info', holding: 'warn', held: 'warn', paused: 'warn',
  aborting: 'bad', fault: 'bad' };

const panel = {
  ws: null, machine: null, status: null, inControl: false, nextId: 1, pending: new Map(),
  program: { name: '', text: '', lines: [] }, current: 0, pieces: [], editing: false,
  samples: [], recording: false, history: [], jogging: null, lastStatusKey: '',
};
window.tezgah = panel; // for the end-to-end test and the curious

const view = new View3D($('view'));

function log(text) { $('log').textContent = text; }

// ---- connection -------------------------------------------------------------------------

function connect() {
  const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
  const ws = new WebSocket(`${scheme}://${location.host}/${location.search}`);
  panel.ws = ws;
  ws.onopen = () => { $('link').textContent = 'online'; $('link').className = 'badge ok'; };
  ws.onclose = () => {
    $('link').textContent = 'offline'; $('link').className = 'badge bad';
    for (const [, p] of panel.pending) p.resolve({ ok: false, error: 'disconnected' });
    panel.pending.clear();
    panel.inControl = false;
    showControl(null);
    setTimeout(connect, 1500);
  };
  ws.onmessage = (e) => {
    let m;
    try { m = JSON.parse(e.data); } catch { return; }
    if (m.type === 'status') onStatus(m);
    else if (m.type === 'reply') {
      const p = panel.pending.get(m.id);
      if (p) { panel.pending.delete(m.id); p.resolve(m); } else if (!m.ok) log(m.error);
    } else if (m.type === 'control') showControl(m);
    else if (m.type === 'hello') onHello(m.machine);
  };
}

/// Sends a command; resolves with its reply.
function request(command) {
  return new Promise((resolve) => {
    if (!panel.ws || panel.ws.readyState !== WebSocket.OPEN) {
      resolve({ ok: false, error: 'not connected' });
      return;
    }
    const id = panel.nextId++;
    panel.pending.set(id, { resolve });
    panel.ws.send(JSON.stringify({ id, ...command }));
  });
}

/// A command whose refusal is shown.
async function command(c, what) {
  const r = await request(c);
  if (!r.ok) log(`${what || c.command}: ${r.error}`);
  return r;
}

function showControl(m) {
  if (!m) { $('control-text').textContent = 'not connected'; $('take-control').hidden = true; return; }
  panel.inControl = m.you;
  $('control-text').textContent = m.you ? `in control (client ${m.client})`
    : m.holder ? `watching: client ${m.holder} is in control` : 'watching: nobody is in control';
  $('take-control').hidden = m.you;
  document.body.classList.toggle('watching', !m.you);
  for (const b of document.querySelectorAll('main button, main input')) {
    if (!b.closest('#view-area') && b.id !== 'file' && b.id !== 'edit') b.disabled = !m.you;
  }
  if (!m.you) log('Watching. “Take control” to drive the machine (the other client is told).');
  else log('');
}

// ---- machine ----------------------------------------------------------------------------

function onHello(machine) {
  panel.machine = machine;
  $('machine-name').textContent = machine.name;
  // DRO rows: X Y Z (tool tip), then the joints beyond three (rotaries), machine only.
  const rows = ['X', 'Y', 'Z'].map((a, i) => ({ axis: a, i, cartesian: true }));
  machine.joints.slice(3).forEach((j, k) => rows.push({ axis: j.name.toUpperCase(), i: k + 3, cartesian: false }));
  $('dro').tBodies[0].replaceChildren(...rows.map((r) => {
    const tr = document.createElement('tr');
    tr.innerHTML = `<td class="axis">${r.axis}</td><td class="machine" id="m-${r.axis}">—</td>`
      + `<td class="work" id="w-${r.axis}">—</td><td class="togo" id="g-${r.axis}">—</td><td></td>`;
    if (r.cartesian) {
      const b = document.createElement('button');
      b.textContent = `${r.axis}=0`;
      b.title = `G10 L20: make the work ${r.axis} zero here`;
      b.id = `zero-${r.axis}`;
      b.onclick = () => zero(r.axis);
      tr.lastChild.appendChild(b);
    }
    return tr;
  }));
  panel.droRows = rows;
  // Jog buttons per joint.
  $('jog-buttons').replaceChildren(...machine.joints.flatMap((j, i) => {
    const name = document.createElement('span');
    name.textContent = j.name.toUpperCase();
    return [name, jogButton(i, 'minus', '−'), jogButton(i, 'plus', '+')];
  }));
  // The travel box (the first three joints of a Cartesian machine are X Y Z).
  const lin = machine.joints.slice(0, 3);
  if (lin.length === 3 && lin.every((j) => j.unit === 'mm' && j.min !== null && j.max !== null)) {
    view.setBox(lin.map((j) => j.min), lin.map((j) => j.max));
  }
}

function jogButton(joint, direction, text) {
  const b = document.createElement('button');
  b.textContent = text;
  b.id = `jog-${joint}-${direction}`;
  b.addEventListener('pointerdown', (e) => { e.preventDefault(); b.setPointerCapture(e.pointerId); startJog(joint, direction, b); });
  const stop = () => stopJog(b);
  b.addEventListener('pointerup', stop);
  b.addEventListener('pointercancel', stop);
  return b;
}

function incStep() { return Number(document.querySelector('input[name=inc]:checked').value); }

function startJog(joint, direction, button) {
  if ($('inc-mode').checked) {
    command({ command: 'increment', joint, direction, step: incStep() }, 'INC');
    return;
  }
  if (panel.jogging) return;
  panel.jogging = { joint, button };
  if (button) button.classList.add('active');
  const speed = Number($('jog-speed').value);
  command({ command: 'jog', joint, direction, ...(speed > 0 ? { speed } : {}) }, 'JOG');
}

function stopJog(button) {
  if (!panel.jogging) return;
  if (panel.jogging.button) panel.jogging.button.classList.remove('active');
  panel.jogging = null;
  command({ command: 'jog_stop' }, 'JOG');
  if (button) button.classList.remove('active');
}

async function zero(axis) {
  const system = panel.status ? panel.status.work.coordinate_system : 1;
  const r = await mdi(`G10 L20 P${system} ${axis}0`);
  if (r.ok) log(`work ${axis} zeroed in G5${system <= 6 ? 3 + system : '9.' + (system - 6)}`);
}

// ---- status -----------------------------------------------------------------------------

function systemName(n) { return n <= 6 ? `G${53 + n}` : `G59.${n - 6}`; }

function onStatus(s) {
  const first = !panel.status;
  panel.status = s;
  const state = s.state.state;
  $('mode').textContent = s.mode;
  $('state').textContent = state === 'paused' ? `paused (${s.state.reason.replace('_', ' ')})` : state;
  $('state').className = `badge ${STATE_CLASS[state] || ''}`;
  $('homed').textContent = s.homed ? 'homed' : 'not homed';
  $('homed').className = `badge ${s.homed ? 'ok' : ''}`;
  $('underruns').textContent = s.underruns;
  $('time-scale').textContent = fmt(s.time_scale, 2);
  $('late').textContent = `${Math.round(s.late_worst_s * 1e6)} µs` + (s.late_over_half ? ` (${s.late_over_half} over ½ period)` : '');
  $('alarm').hidden = !s.error;
  $('alarm').textContent = s.error ? `ALARM: ${s.error}` : '';
  // DRO.
  const w = s.work, mm = w.inches ? 1 / 25.4 : 1, d = w.inches ? 4 : 3;
  const togo = distanceToGo(s);
  (panel.droRows || []).forEach((r) => {
    if (r.cartesian) {
      $(`m-${r.axis}`).textContent = fmt(s.tip[r.i] * mm, d);
      $(`w-${r.axis}`).textContent = fmt(w.position[r.i] * mm, d);
      $(`g-${r.axis}`).textContent = togo ? fmt(togo[r.i] * mm, d) : '—';
    } else {
      $(`m-${r.axis}`).textContent = fmt(s.joints[r.i] * 180 / Math.PI, 3);
    }
  });
  $('modal').textContent = [systemName(w.coordinate_system), w.inches ? 'G20' : 'G21',
    w.incremental ? 'G91' : 'G90', w.plane ? `G${w.plane}` : 'G17.1', w.motion !== null ? `G${w.motion / 10}` : 'G80',
    `F${+w.feed_rate.toFixed(3)}`].join(' ');
  const o = (v) => v.map((x) => fmt(x * mm, d)).join(' ');
  $('offsets').textContent = `${systemName(w.coordinate_system)} offset ${o(w.g5x)}`
    + (w.rotation_deg ? ` R${w.rotation_deg}` : '') + ` · G92 ${o(w.g92)} · tool ${o(w.tool)}`;
  // Switches the operator set.
  if (document.activeElement !== $('feed-override')) {
    $('feed-override').value = s.feed_override_percent;
    $('feed-override-value').textContent = `${Math.round(s.feed_override_percent)} %`;
  }
  $('single-block').checked = s.single_block;
  $('optional-stop').checked = s.optional_stop;
  $('jog-override-value').textContent = `${Math.round(s.jog_override_percent)} %`;
  // Program line.
  if (s.mode === 'auto' && s.executing_line && s.executing_line !== panel.current) highlight(s.executing_line);
  view.setTool(s.tip, s.tool_axis);
  record(s);
  if (first) log('');
}

/// From the tool to the end of the executing line's moves (AUTO with a preview only).
function distanceToGo(s) {
  if (s.mode !== 'auto' || s.state.state === 'idle' || !panel.pieces.length) return null;
  let end = null;
  for (const p of panel.pieces) if (p.line === s.executing_line) end = p.points[p.points.length - 1];
  return end ? end.map((v, i) => v - s.tip[i]) : null;
}

/// Samples of an AUTO run for the plots; drawn when it ends.
function record(s) {
  const state = s.state.state;
  const moving = s.mode === 'auto' && state !== 'idle';
  const period = panel.machine ? panel.machine.period_s : 0.001;
  if (moving) {
    if (!panel.recording) { panel.recording = true; panel.samples = []; }
    const sample = { t: s.index * period, joints: s.joints.slice(), tip: s.tip.slice() };
    const last = panel.samples[panel.samples.length - 1];
    if (!last || sample.t > last.t) panel.samples.push(sample);
    if (panel.samples.length > 200000) panel.samples.splice(0, 1000);
  } else if (panel.recording) {
    panel.recording = false;
    const t0 = panel.samples.length ? panel.samples[0].t : 0;
    panel.samples.forEach((x) => { x.t -= t0; });
    const n = drawPlots($('plots'), panel.samples, panel.machine);
    $('plots-note').textContent = n ? `(${panel.samples.length} status samples; derivatives averaged over the status interval)` : '';
  }
}

// ---- program ----------------------------------------------------------------------------

function showProgram(text, name) {
  panel.program = { name, text, lines: text.split('\n') };
  panel.current = 0;
  $('program-name').textContent = name;
  $('editor').value = text;
  const frag = document.createDocumentFragment();
  panel.program.lines.forEach((l, k) => {
    const div = document.createElement('div');
    div.className = 'ln';
    div.dataset.line = k + 1;
    const no = document.createElement('span');
    no.className = 'no'; no.textContent = k + 1;
    const t = document.createElement('span');
    t.textContent = l || ' ';
    div.append(no, t);
    frag.appendChild(div);
  });
  $('code').replaceChildren(frag);
  $('program-error').hidden = true;
}

function highlight(line) {
  const code = $('code');
  const old = code.querySelector('.ln.current');
  if (old) old.classList.remove('current');
  panel.current = line;
  const el = code.querySelector(`.ln[data-line="${line}"]`);
  if (el) {
    el.classList.add('current');
    const top = el.offsetTop - code.offsetTop;
    if (top < code.scrollTop || top > code.scrollTop + code.clientHeight - 20) code.scrollTop = top - code.clientHeight / 3;
  }
}

function setEditing(on) {
  if (!on && panel.editing) showProgram($('editor').value, panel.program.name || 'edited');
  panel.editing = on;
  $('editor').hidden = !on;
  $('code').hidden = on;
  $('edit').textContent = on ? 'Done' : 'Edit';
}

async function load() {
  if (panel.editing) setEditing(false);
  const text = panel.program.text;
  for (const el of $('code').querySelectorAll('.bad')) { el.classList.remove('bad'); el.querySelector('.msg')?.remove(); }
  const r = await request({ command: 'load', program: text });
  if (!r.ok) {
    $('program-error').hidden = false;
    $('program-error').textContent = r.error;
    const at = /program:(\d+):(\d+):\s*(.*)/.exec(r.error || '');
    if (at) {
      const el = $('code').querySelector(`.ln[data-line="${at[1]}"]`);
      if (el) {
        el.classList.add('bad');
        const msg = document.createElement('span');
        msg.className = 'msg'; msg.textContent = `← col ${at[2]}: ${at[3]}`;
        el.appendChild(msg);
        el.scrollIntoView({ block: 'nearest' });
      }
    }
    return r;
  }
  $('program-error').hidden = true;
  const p = await request({ command: 'preview' });
  if (p.ok) {
    panel.pieces = p.data.pieces;
    view.setPath(p.data.pieces);
    log(`loaded ${panel.program.name}: ${panel.program.lines.length} lines`
      + (p.data.cut ? ' (preview cut short)' : ''));
  }
  return r;
}

async function mdi(block) {
  const r = await command({ command: 'mdi', block }, 'MDI');
  panel.history.unshift({ block, ok: r.ok });
  panel.history = panel.history.slice(0, 50);
  $('mdi-history').replaceChildren(...panel.history.map((h) => {
    const li = document.createElement('li');
    li.textContent = h.block;
    if (!h.ok) li.className = 'bad';
    li.onclick = () => { $('mdi').value = h.block; $('mdi').focus(); };
    return li;
  }));
  return r;
}

// ---- wiring -----------------------------------------------------------------------------

$('take-control').onclick = () => request({ command: 'take_control' });
$('file').onchange = async (e) => {
  const f = e.target.files[0];
  if (!f) return;
  showProgram(await f.text(), f.name);
  setEditing(false);
};
$('edit').onclick = () => setEditing(!panel.editing);
$('load').onclick = load;
$('cycle-start').onclick = () => command({ command: 'cycle_start' }, 'cycle start');
$('feed-hold').onclick = () => command({ command: 'feed_hold' }, 'feed hold');
$('resume').onclick = () => command({ command: 'resume' }, 'resume');
$('abort').onclick = () => command({ command: 'abort' }, 'abort');
$('single-block').onchange = (e) => command({ command: 'single_block', on: e.target.checked });
$('optional-stop').onchange = (e) => command({ command: 'optional_stop', on: e.target.checked });
$('restart').onclick = () => command({ command: 'restart_from', line: Number($('restart-line').value) }, 'restart');
$('feed-override').oninput = (e) => {
  $('feed-override-value').textContent = `${e.target.value} %`;
  command({ command: 'feed_override', percent: Number(e.target.value) }, 'feed override');
};
$('jog-override').oninput = (e) => command({ command: 'jog_override', percent: Number(e.target.value) }, 'jog override');
$('home').onclick = () => command({ command: 'home' }, 'home');
$('mdi-form').onsubmit = (e) => {
  e.preventDefault();
  const block = $('mdi').value.trim();
  if (block) { mdi(block); $('mdi').value = ''; }
};
$('view-fit').onclick = () => view.fit();
$('view-top').onclick = () => view.top();
$('view-iso').onclick = () => view.iso();

// Keyboard jogging (not while typing): arrows X and Y, Page Up/Down Z.
const KEYS = { ArrowLeft: [0, 'minus'], ArrowRight: [0, 'plus'], ArrowDown: [1, 'minus'],
  ArrowUp: [1, 'plus'], PageDown: [2, 'minus'], PageUp: [2, 'plus'] };
const typing = () => ['INPUT', 'TEXTAREA', 'SELECT'].includes(document.activeElement?.tagName)
  && document.activeElement.type !== 'range' && document.activeElement.type !== 'checkbox';
window.addEventListener('keydown', (e) => {
  const k = KEYS[e.key];
  if (!k || typing() || !panel.inControl) return;
  e.preventDefault();
  if (!e.repeat) startJog(k[0], k[1], $(`jog-${k[0]}-${k[1]}`));
});
window.addEventListener('keyup', (e) => { if (KEYS[e.key] && !$('inc-mode').checked) stopJog(); });
window.addEventListener('blur', () => stopJog());

showProgram('G21 G90 G17\n(open a file or edit)\nM2\n', 'untitled');
connect();
