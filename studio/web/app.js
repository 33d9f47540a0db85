// taut studio's page: plain JavaScript over the HTTP API (docs/studio.md)
// and its event stream. No build step: this file is served as it is.
'use strict';

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const S = {
  client: (crypto.randomUUID ? crypto.randomUUID() : String(Math.random()).slice(2)),
  token: params.get('token'),
  file: null,        // {name, kind: image|svg|gcode, bytes}
  drawing: null,     // the answer of /api/vectorize, /api/text or /api/gcode
  card: null,        // the answer of /api/stringart
  machines: [],
  connected: false,
  status: null,
  run: null,
  job: null,
  controller: null,
  simulator: null,
  travelled: [],     // machine positions seen while running, [x, y]
  settings: [],
  said: {},          // the machine's answer to each setting changed in the table
};

// ---- the API ------------------------------------------------------------

async function api(path, { method = 'GET', body, query } = {}) {
  const url = new URL(path, location.href);
  for (const [k, v] of Object.entries(query || {})) {
    if (v !== undefined && v !== null && v !== '') url.searchParams.set(k, v);
  }
  const headers = { 'X-Taut-Client': S.client };
  if (S.token) headers.Authorization = 'Bearer ' + S.token;
  const r = await fetch(url, { method, body, headers });
  const type = r.headers.get('content-type') || '';
  const answer = type.includes('json') ? await r.json() : await r.text();
  if (!r.ok) throw new Error((answer && answer.error) || r.statusText);
  return answer;
}

function notice(text, error) {
  const n = $('notice');
  n.hidden = !text;
  n.textContent = text || '';
  n.classList.toggle('error', !!error);
}

async function attempt(what, f) {
  try {
    return await f();
  } catch (e) {
    notice(what + ': ' + e.message, true);
    return undefined;
  }
}

function clock(s) {
  if (s === null || s === undefined || !isFinite(s)) return '–';
  s = Math.max(0, Math.round(s));
  const h = Math.floor(s / 3600), m = Math.floor(s / 60) % 60, sec = s % 60;
  const two = (v) => String(v).padStart(2, '0');
  return h ? `${h}:${two(m)}:${two(sec)}` : `${m}:${two(sec)}`;
}

function debounce(f, ms) {
  let t;
  const later = (...a) => { clearTimeout(t); t = setTimeout(() => f(...a), ms); };
  later.cancel = () => clearTimeout(t);
  return later;
}

function download(name, data, type) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([data], { type }));
  a.download = name;
  document.body.appendChild(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
}

// ---- opening a file -------------------------------------------------------

function kindOf(name, bytes) {
  const head = new Uint8Array(bytes.slice(0, 4));
  if (head[0] === 0x89 && head[1] === 0x50) return 'image';
  if (head[0] === 0xff && head[1] === 0xd8) return 'image';
  const lower = name.toLowerCase();
  if (lower.endsWith('.svg')) return 'svg';
  if (/\.(png|jpe?g)$/.test(lower)) return 'image';
  return 'gcode';
}

async function openFile(file) {
  const bytes = await file.arrayBuffer();
  const kind = kindOf(file.name, bytes);
  S.file = { name: file.name, kind, bytes, ownSize: kind === 'svg' };
  $('file-name').textContent = `${file.name} (${(bytes.byteLength / 1024).toFixed(0)} KB, ${kind === 'gcode' ? 'G-code' : kind})`;
  notice('');
  const img = $('input-image');
  if (kind === 'gcode') {
    img.removeAttribute('src');
    $('input-empty').textContent = 'G-code: its toolpath is on the right';
    $('input-empty').hidden = false;
    await gcodeFile();
  } else {
    img.src = URL.createObjectURL(new Blob([bytes], { type: kind === 'svg' ? 'image/svg+xml' : '' }));
    $('input-empty').hidden = true;
    if ($('stringart-panel').open && !$('plotter-panel').open) await stringart();
    else await vectorize();
  }
}

$('open').addEventListener('change', (e) => { if (e.target.files[0]) openFile(e.target.files[0]); });
document.addEventListener('dragover', (e) => { e.preventDefault(); document.body.classList.add('dragging'); });
document.addEventListener('dragleave', (e) => { if (!e.relatedTarget) document.body.classList.remove('dragging'); });
document.addEventListener('drop', (e) => {
  e.preventDefault();
  document.body.classList.remove('dragging');
  const f = e.dataTransfer.files[0];
  if (f) openFile(f);
});

// ---- plotters ---------------------------------------------------------------

function plotter() { return $('v-machine').value || 'flatbed'; }

function showDrawing(d, what) {
  S.drawing = d;
  S.travelled = [];
  $('save-gcode').disabled = false;
  const note = d.note ? ` (${d.note})` : '';
  $('v-figures').textContent =
    `${what}: ${d.lines} G-code lines, drawing time ${clock(d.estimate_s)}, ` +
    `pen down ${d.pen_down_mm.toFixed(0)} mm, pen-up travel ${d.pen_up_mm.toFixed(0)} mm${note}`;
  drawToolpath();
  updateButtons();
}

let vectorizing = 0;
async function vectorize() {
  if (!S.file || S.file.kind === 'gcode') { notice('open a picture (PNG, JPEG or SVG) first'); return; }
  const n = ++vectorizing;
  // This run takes the fields as they are now: a live run still waiting
  // on an edit (a width typed just before a file was opened) would only
  // do it again.
  liveVectorize.cancel();
  $('v-figures').textContent = 'vectorising…';
  const mode = $('v-mode').value;
  const query = {
    machine: plotter(), width_mm: $('v-width').value, mode,
    canny: `${$('v-low').value},${$('v-high').value}`, blur: $('v-blur').value,
    feed: $('v-feed').value, name: S.file.name, one_pen: $('v-one-pen').checked ? 1 : '',
  };
  // An SVG opens at its own size until the width is changed.
  if (S.file.ownSize) delete query.width_mm;
  if (mode !== 'edges') query.threshold = $('v-threshold').value;
  query.hatch_mm = $('v-hatch').value;
  const d = await attempt('vectorise', () => api('/api/vectorize', { method: 'POST', body: S.file.bytes, query }));
  if (n !== vectorizing) return;
  if (!d) { $('v-figures').textContent = ''; return; }
  notice('');
  const width = Math.round(d.width_mm * 100) / 100;
  if (width && Number($('v-width').value) !== width) $('v-width').value = width;
  showDrawing(d, d.svg ? `${d.strokes} strokes in ${d.layers} pass${d.layers === 1 ? '' : 'es'}` : `${d.strokes} strokes`);
}
const liveVectorize = debounce(() => { if (S.file && S.file.kind !== 'gcode') vectorize(); }, 350);

async function gcodeFile() {
  const d = await attempt(S.file.name, () => api('/api/gcode', { method: 'POST', body: S.file.bytes, query: { machine: plotter() } }));
  if (d) { notice(''); showDrawing(d, S.file.name); }
}

async function text() {
  const query = { machine: plotter(), font: $('t-font').value, height_mm: $('t-height').value, feed: $('v-feed').value };
  const d = await attempt('text', () => api('/api/text', { method: 'POST', body: $('t-text').value, query }));
  if (d) { notice(''); showDrawing(d, `text "${$('t-text').value}"`); }
}

$('vectorize').addEventListener('click', vectorize);
$('text').addEventListener('click', text);
$('save-gcode').addEventListener('click', () => {
  if (!S.drawing) return;
  const base = S.file ? S.file.name.replace(/\.[^.]*$/, '') : 'drawing';
  download(base + '.gcode', S.drawing.gcode, 'text/plain');
});
for (const id of ['v-machine', 'v-width', 'v-mode', 'v-low', 'v-high', 'v-threshold', 'v-hatch', 'v-blur', 'v-feed', 'v-one-pen']) {
  $(id).addEventListener('input', liveVectorize);
}
$('v-width').addEventListener('input', () => { if (S.file) S.file.ownSize = false; });
function modeFields() {
  const mode = $('v-mode').value;
  for (const e of document.querySelectorAll('.hatch')) e.hidden = mode === 'edges';
  for (const e of document.querySelectorAll('.edges')) e.hidden = mode !== 'edges';
}
$('v-mode').addEventListener('change', modeFields);

// ---- the toolpath and where the machine went ---------------------------------

function drawToolpath() {
  const c = $('toolpath');
  const g = c.getContext('2d');
  g.clearRect(0, 0, c.width, c.height);
  const d = S.drawing;
  const pts = S.travelled;
  if (!d && !pts.length) return;
  let lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
  const grow = (x, y) => { lo = [Math.min(lo[0], x), Math.min(lo[1], y)]; hi = [Math.max(hi[0], x), Math.max(hi[1], y)]; };
  if (d) for (const m of d.toolpath) { grow(m[0], m[1]); grow(m[2], m[3]); }
  for (const p of pts) grow(p[0], p[1]);
  const span = Math.max(hi[0] - lo[0], hi[1] - lo[1], 1) * 1.08;
  const cx = (lo[0] + hi[0]) / 2, cy = (lo[1] + hi[1]) / 2;
  const k = c.width / span;
  const at = (x, y) => [c.width / 2 + (x - cx) * k, c.height / 2 - (y - cy) * k];
  if (d) {
    g.lineCap = 'round';
    g.setLineDash([4, 4]);
    g.strokeStyle = 'rgba(70,130,230,0.35)';
    g.lineWidth = 1;
    g.beginPath();
    for (const m of d.toolpath) if (!m[4]) { g.moveTo(...at(m[0], m[1])); g.lineTo(...at(m[2], m[3])); }
    g.stroke();
    g.setLineDash([]);
    g.strokeStyle = '#1a1a2e';
    g.lineWidth = 1.6;
    g.beginPath();
    for (const m of d.toolpath) if (m[4]) { g.moveTo(...at(m[0], m[1])); g.lineTo(...at(m[2], m[3])); }
    g.stroke();
  }
  if (pts.length) {
    g.strokeStyle = 'rgba(220,40,30,0.8)';
    g.lineWidth = 1.2;
    g.beginPath();
    g.moveTo(...at(...pts[0]));
    for (const p of pts) g.lineTo(...at(...p));
    g.stroke();
    const [x, y] = at(...pts[pts.length - 1]);
    g.fillStyle = '#dc281e';
    g.beginPath();
    g.arc(x, y, 4, 0, 2 * Math.PI);
    g.fill();
  }
}

// ---- string art ---------------------------------------------------------------

function board() {
  return { nails: $('s-nails').value, shape: $('s-shape').value, radius_cm: $('s-radius').value };
}

function templateLink() {
  const url = new URL('/api/template', location.href);
  for (const [k, v] of Object.entries(board())) url.searchParams.set(k, v);
  if (S.token) url.searchParams.set('token', S.token);
  $('template').href = url;
}

let generating = 0;
async function stringart() {
  if (!S.file || S.file.kind !== 'image') { notice('open a picture (PNG or JPEG) first'); return; }
  const n = ++generating;
  $('s-figures').textContent = 'generating…';
  const query = {
    ...board(), lines: $('s-lines').value, thread_mm: $('s-thread').value,
    zoom: $('s-zoom').value, cx: $('s-cx').value, cy: $('s-cy').value, contrast: $('s-contrast').value,
  };
  const card = await attempt('string art', () => api('/api/stringart', { method: 'POST', body: S.file.bytes, query }));
  if (n !== generating) return;
  if (!card) { $('s-figures').textContent = ''; return; }
  notice('');
  S.card = { ...card, board: board(), thread_mm: $('s-thread').value };
  $('input-image').src = 'data:image/png;base64,' + card.framed_png;
  const c = $('toolpath'), g = c.getContext('2d');
  const img = new Image();
  img.onload = () => { g.clearRect(0, 0, c.width, c.height); g.drawImage(img, 0, 0, c.width, c.height); };
  img.src = 'data:image/png;base64,' + card.preview_png;
  $('s-figures').textContent =
    `${card.lines} lines, machine time ${clock(card.estimate_s)} (drilling ${clock(card.drilling_s)}, ` +
    `winding ${clock(card.winding_s)}), thread ${card.thread_m.toFixed(1)} m`;
  for (const id of ['card-download', 'card-write', 'card-insert']) $(id).disabled = false;
}
const liveStringart = debounce(() => { if ($('s-live').checked && S.file && S.file.kind === 'image') stringart(); }, 500);
for (const id of ['s-nails', 's-shape', 's-radius', 's-lines', 's-thread', 's-zoom', 's-cx', 's-cy', 's-contrast']) {
  $(id).addEventListener('input', () => { templateLink(); liveStringart(); });
}
$('stringart').addEventListener('click', stringart);
$('card-download').addEventListener('click', () => {
  if (!S.card) return;
  download('param.txt', S.card.param, 'text/plain');
  setTimeout(() => download('poradi.txt', S.card.poradi, 'text/plain'), 300);
});
$('card-write').addEventListener('click', async () => {
  if (!S.card) return;
  const query = { ...S.card.board, thread_mm: S.card.thread_mm, dir: $('card-dir').value };
  const r = await attempt('write the card', () => api('/api/card', { method: 'POST', body: S.card.poradi, query }));
  if (r) notice(`card written to ${r.dir}: ${r.files.join(', ')}`);
});
$('card-insert').addEventListener('click', async () => {
  if (!S.card) return;
  const r = await attempt('the card', () => api('/api/sim/card', { method: 'POST', body: S.card.poradi, query: S.card.board }));
  if (r) notice(`the card is in the simulated machine (${r.nails} nails, ${r.connections} connections): answer its prompts below`);
});

// ---- the machine --------------------------------------------------------------

async function ports() {
  const list = await attempt('ports', () => api('/api/ports'));
  if (!list) return;
  const sel = $('ports');
  const was = sel.value;
  sel.innerHTML = '';
  for (const p of list) {
    const o = document.createElement('option');
    o.value = p.path;
    o.textContent = `${p.path} — ${p.what}`;
    sel.appendChild(o);
  }
  if (!list.length) sel.innerHTML = '<option value="">no serial port found</option>';
  if (was) sel.value = was;
}
$('refresh-ports').addEventListener('click', ports);

$('connect').addEventListener('click', async () => {
  if (S.connected) {
    await attempt('disconnect', () => api('/api/disconnect', { method: 'POST' }));
    return;
  }
  $('connect').disabled = true;
  $('connect').textContent = 'Connecting…';
  const r = await attempt('connect', () => api('/api/connect', { method: 'POST', query: { port: $('ports').value } }));
  $('connect').disabled = false;
  if (r) { notice(''); applySnapshot(r); }
  updateButtons();
});

async function line(text) {
  const r = await attempt(text, () => api('/api/machine/line', { method: 'POST', body: text }));
  return r;
}

async function realtime(cmd) {
  return attempt(cmd, () => api('/api/machine/realtime', { method: 'POST', query: { cmd } }));
}

for (const b of document.querySelectorAll('[data-line]')) {
  b.addEventListener('click', () => line(b.dataset.line));
}

// Work zero where the pen stands: Grbl's G10 L20 P0 (as CNCjs sends it);
// a machine without work offsets answers error:20 and takes G92 instead.
$('zero').addEventListener('click', async () => {
  const axes = isStringArt() ? 'C0 X0 Z0' : 'X0 Y0';
  const r = await line('G10 L20 P0 ' + axes);
  if (r && r.replies.some((x) => x.startsWith('error:20'))) await line('G92 ' + axes);
});

// Jogging: held, a $J= jog of one step; released, jog cancel (0x85).
for (const b of document.querySelectorAll('.jog-button')) {
  let held = false;
  const start = async (e) => {
    e.preventDefault();
    held = true;
    const step = Number($('jog-step').value) * Number(b.dataset.dir);
    await line(`$J=G91 G21 ${b.dataset.axis}${step} F${$('jog-feed').value}`);
  };
  const end = async () => {
    if (!held) return;
    held = false;
    await realtime('jog_cancel');
  };
  b.addEventListener('pointerdown', start);
  b.addEventListener('pointerup', end);
  b.addEventListener('pointerleave', end);
}

function isStringArt() {
  const m = S.settings.find((s) => s.startsWith('$machine='));
  return m ? m.endsWith('string_art') : false;
}

$('machine-switch').addEventListener('click', async () => {
  const r = await line('$machine=' + $('machine-select').value);
  if (r && r.replies.includes('ok')) await readSettings();
});

async function readSettings() {
  const r = await line('$$');
  if (!r) return;
  S.settings = r.replies.filter((x) => x.startsWith('$') && x.includes('='));
  renderSettings();
}
$('settings-read').addEventListener('click', readSettings);

// The machine's answer beside a setting (found anew: the table may have
// been drawn again while the line was out).
function showSaid(key) {
  const input = document.querySelector(`[data-setting="${key}"]`);
  if (!input) return;
  const said = input.parentElement.nextElementSibling;
  said.textContent = S.said[key] || '';
  said.className = S.said[key] === 'ok' ? 'ok' : 'bad';
}

function renderSettings() {
  const t = $('settings');
  t.innerHTML = '';
  for (const s of S.settings) {
    const [key, value] = [s.slice(1, s.indexOf('=')), s.slice(s.indexOf('=') + 1)];
    if (/^\d/.test(key)) continue; // Grbl's numbered copies of the named settings
    const tr = document.createElement('tr');
    const k = document.createElement('td');
    k.textContent = key;
    k.className = 'mono';
    const v = document.createElement('td');
    const input = document.createElement('input');
    input.value = value;
    input.dataset.setting = key;
    const said = document.createElement('td');
    input.addEventListener('change', async () => {
      delete S.said[key];
      showSaid(key);
      const value = input.value;
      const r = await line(`$${key}=${value}`);
      const ok = r && r.replies.includes('ok');
      S.said[key] = ok ? 'ok' : (r ? r.replies[r.replies.length - 1] : 'refused');
      if (ok) S.settings = S.settings.map((x) => (x.startsWith(`$${key}=`) ? `$${key}=${value}` : x));
      showSaid(key);
    });
    v.appendChild(input);
    tr.append(k, v, said);
    t.appendChild(tr);
    showSaid(key);
  }
  const m = S.settings.find((s) => s.startsWith('$machine='));
  if (m) $('machine-select').value = m.slice('$machine='.length);
  for (const e of document.querySelectorAll('.plotter-only')) e.hidden = isStringArt();
}

// The console: any line; ?, !, ~ and ^X as Grbl's real-time bytes.
$('console-input').addEventListener('keydown', async (e) => {
  if (e.key !== 'Enter') return;
  const text = e.target.value.trim();
  if (!text) return;
  e.target.value = '';
  const byte = { '!': 'hold', '~': 'resume', '^X': 'reset', '^x': 'reset', 'ctrl-x': 'reset' }[text];
  if (byte) await realtime(byte);
  else await line(text);
});

// The string-art job's buttons.
async function press(name, long) {
  return attempt(name, () => api('/api/machine/button', { method: 'POST', query: { name, long: long ? 1 : '' } }));
}
$('green').addEventListener('click', () => press('green', false));
$('green-long').addEventListener('click', () => press('green', true));
for (const b of document.querySelectorAll('[data-button]')) b.addEventListener('click', () => press(b.dataset.button, false));
$('job-resume').addEventListener('click', () => press('green', false));
$('job-discard').addEventListener('click', () => {
  if (confirm('Discard the job the power cut stopped? It cannot be resumed after this.')) press('green', true);
});
$('power-cut').addEventListener('click', async () => {
  const r = await attempt('power cut', () => api('/api/sim/power_cut', { method: 'POST' }));
  if (r) notice(`power cut ${r.power_cuts} (simulator): the machine starts again with what its EEPROM and card kept`);
});

// ---- running ------------------------------------------------------------------

$('send').addEventListener('click', async () => {
  if (!S.drawing) return;
  S.travelled = [];
  const name = S.file ? S.file.name : 'drawing';
  const r = await attempt('send', () => api('/api/run', { method: 'POST', body: S.drawing.gcode, query: { name } }));
  if (r) { notice(''); showRun(r); }
});
$('pause').addEventListener('click', async () => showRun(await attempt('pause', () => api('/api/run/pause', { method: 'POST' }))));
$('resume').addEventListener('click', async () => showRun(await attempt('resume', () => api('/api/run/resume', { method: 'POST' }))));
$('stop').addEventListener('click', async () => showRun(await attempt('stop', () => api('/api/run/stop', { method: 'POST' }))));

function showRun(r) {
  if (!r) return;
  S.run = r;
  const p = $('progress');
  p.dataset.state = r.state;
  p.dataset.line = r.line;
  p.dataset.of = r.of;
  let text = `${r.state}: line ${r.line} of ${r.of}, ${r.percent.toFixed(0)} %, ETA ${clock(r.eta_s)}`;
  if (r.state === 'done') text = `done: ${r.of} lines in ${clock(r.elapsed_s)} (planner: ${clock(r.estimate_s)})`;
  if (r.errors && r.errors.length) text += `, ${r.errors.length} refused`;
  p.textContent = text;
  $('run-bar').value = r.percent;
  if (r.state === 'interrupted') notice(`${r.name}: interrupted: ${r.reason}. Nothing is sent again by itself: send the file again when ready.`, true);
  updateButtons();
}

function updateButtons() {
  const running = S.run && (S.run.state === 'running' || S.run.state === 'paused');
  const mine = !S.controller || S.controller === S.client;
  $('send').disabled = !S.drawing || !S.connected || running || !mine;
  $('pause').disabled = !running || S.run.state !== 'running' || !mine;
  $('resume').disabled = !running || S.run.state !== 'paused' || !mine;
  $('stop').disabled = !running || !mine;
  $('connect').textContent = S.connected ? 'Disconnect' : 'Connect';
  $('take-over').hidden = mine;
  $('control').textContent = mine ? 'controlling' : 'watching (another window controls the machine)';
  for (const e of document.querySelectorAll('.sim-only')) e.hidden = !S.simulator;
}

// ---- the event stream ------------------------------------------------------------

function logLine(l) {
  const log = $('log');
  const div = document.createElement('div');
  div.className = l.dir + (l.words ? ' bad' : '');
  div.textContent = l.text;
  if (l.words) {
    const w = document.createElement('span');
    w.className = 'words';
    w.textContent = l.words;
    div.appendChild(w);
  }
  const atEnd = log.scrollTop + log.clientHeight >= log.scrollHeight - 4;
  log.appendChild(div);
  while (log.childNodes.length > 500) log.removeChild(log.firstChild);
  if (atEnd) log.scrollTop = log.scrollHeight;
  if (l.words) notice(l.words, true);
}

function showStatus(st) {
  S.status = st;
  const m = $('machine-state');
  m.textContent = st.state || '–';
  m.className = 'pill' + (st.state === 'Alarm' ? ' alarm' : '');
  if (st.mpos && st.mpos.length >= 2) {
    const names = isStringArt() ? ['C', 'X', 'Z'] : ['X', 'Y'];
    $('position').textContent = names.map((n, i) => `${n} ${st.mpos[i].toFixed(3)}`).join(' ');
    $('position').dataset.x = st.mpos[0];
    $('position').dataset.y = st.mpos[1];
    const running = S.run && (S.run.state === 'running' || S.run.state === 'paused');
    if (running && !isStringArt() && S.drawing) {
      const last = S.travelled[S.travelled.length - 1];
      if (!last || last[0] !== st.mpos[0] || last[1] !== st.mpos[1]) {
        S.travelled.push([st.mpos[0], st.mpos[1]]);
        drawToolpath();
      }
    }
  }
}

function showLink(connected, port, lost) {
  S.connected = connected;
  const l = $('link-state');
  l.textContent = connected ? `connected: ${port}` : (lost ? 'connection lost' : 'not connected');
  l.className = 'pill ' + (connected ? 'on' : (lost ? 'alarm' : 'off'));
  if (lost) notice(lost + '. Nothing is sent again by itself: connect again when the machine is back.', true);
  updateButtons();
}

// What the prompts that need more than green ask of the maker.
const HINTS = {
  '>>> axes were unpowered': 'Each white button twice: the first frees its axis (turn it to the zero pose by hand), '
    + 'the second takes that as its zero. Then green.',
  '>>> insert card': 'Put the card in the slot (on the simulator: Put the card in the simulated machine).',
  '>>> bad files': 'The card\'s files are refused (the console says why): write the card again.',
};

function showJob(job) {
  S.job = job;
  $('job-state').textContent = job.state ? `state: ${job.state}` : 'no job';
  const p = $('job-prompt');
  p.hidden = !job.prompt;
  p.textContent = job.prompt || '';
  const prompt = job.prompt || '';
  // After a reset (a power cut): the checkpoint found, and its offer.
  $('job-checkpoint').hidden = !job.checkpoint;
  $('job-checkpoint').textContent = job.checkpoint || '';
  $('job-offer').hidden = !prompt.startsWith('>>> resume ');
  const hint = Object.keys(HINTS).find((k) => prompt.startsWith(k));
  $('job-hint').hidden = !hint;
  $('job-hint').textContent = hint ? HINTS[hint] : '';
  if (job.progress) {
    const [phase, done, of] = job.progress;
    $('job-progress').max = of;
    $('job-progress').value = done;
    $('job-count').textContent = `${phase} ${done}/${of}`;
  }
  if (job.error) notice(job.error, true);
}

function applySnapshot(s) {
  showLink(s.connected, s.port, s.lost);
  showStatus(s.status);
  // Drawn again only when changed: a cell being edited stays.
  if (s.settings && JSON.stringify(s.settings) !== JSON.stringify(S.settings)) { S.settings = s.settings; renderSettings(); }
  if (s.job) showJob(s.job);
  if (s.run) showRun(s.run);
  if ('controller' in s) S.controller = s.controller;
  if ('simulator' in s) S.simulator = s.simulator;
  updateButtons();
}

function events() {
  const url = new URL('/api/events', location.href);
  url.protocol = location.protocol === 'https:' ? 'wss:' : 'ws:';
  url.searchParams.set('client', S.client);
  if (S.token) url.searchParams.set('token', S.token);
  const ws = new WebSocket(url);
  ws.onmessage = (m) => {
    const e = JSON.parse(m.data);
    switch (e.type) {
      case 'hello':
        $('log').innerHTML = '';
        for (const l of e.log) logLine(l);
        applySnapshot(e);
        break;
      case 'status': showStatus(e.status); break;
      case 'log': logLine(e.line); break;
      case 'run': showRun(e); break;
      case 'job': showJob(e.job); break;
      case 'link': showLink(e.connected, e.port, e.lost); ports(); break;
      case 'controller': S.controller = e.controller; updateButtons(); break;
    }
  };
  ws.onclose = () => {
    $('link-state').textContent = 'studio unreachable';
    $('link-state').className = 'pill alarm';
    setTimeout(events, 2000);
  };
}

$('take-over').addEventListener('click', async () => {
  const r = await attempt('take over', () => api('/api/controller', { method: 'POST' }));
  if (r) { S.controller = r.controller; updateButtons(); }
});

// ---- start ----------------------------------------------------------------------

for (const o of document.querySelectorAll('output')) {
  const input = $(o.htmlFor.value);
  const show = () => { o.textContent = input.value; };
  input.addEventListener('input', show);
  show();
}

(async function start() {
  const machines = await attempt('machines', () => api('/api/machines'));
  if (machines) {
    S.machines = machines;
    for (const m of machines) {
      for (const sel of [$('machine-select'), ...(m.plotter ? [$('v-machine')] : [])]) {
        const o = document.createElement('option');
        o.value = o.textContent = m.name;
        sel.appendChild(o);
      }
    }
    $('v-machine').value = 'flatbed';
  }
  modeFields();
  templateLink();
  await ports();
  events();
})();
