// The operator's panel: one WebSocket to the NCK (status, events, acks in;
// commands out), the DRO, program view, controls and the log. Everything the
// NCK decides (states, refusals) comes back from it: the panel never guesses.
import { createPreview } from './preview.js';
import { toolPoint } from './canon.js';
import { createProgress } from './progress.js';
import { initMachine, allowed } from './machine.js';
import { initTools } from './tools.js';

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const token = params.get('token') || '';

const ui = {
  ws: null, seq: 0, status: null, authed: false, readonly: false,
  program: '', programLines: [], currentLine: 0, selectedLine: 0,
  mdiHistory: [], mdiIndex: -1, jogTimer: null, jogAxis: null,
  lag: [],           // [seq, NCK utime (us), receive time (us)] for the test and the title
  link: 'connecting', // connecting (never opened yet), up, lost (was up, dropped)
  canCommand: false,
};
window.ncpPanel = ui;  // for tests and the curious: read-only use
// a message as if from the server, for the tests of what the panel does
// with one (a hello with other limits)
ui.receive = (text) => onMessage(text);

const preview = createPreview($('preview'), $('preview-2d'));
ui.preview = preview;
const progress = createProgress();
ui.progress = progress;
// The override sliders' ranges: the limits the server reports in its hello,
// else LinuxCNC's (feed 0-200 %, spindle 50-150 %).
const OVERRIDE_DEFAULTS = { feed: [0, 200], rapid: [0, 100], spindle: [50, 150] };

// ---- log ------------------------------------------------------------------------------
function log(kind, text) {
  const el = document.createElement('div');
  el.className = kind;
  const t = new Date().toTimeString().slice(0, 8);
  el.textContent = `${t} ${kind.padEnd(7)} ${text}`;
  const box = $('log');
  box.appendChild(el);
  while (box.childNodes.length > 500) box.removeChild(box.firstChild);
  box.scrollTop = box.scrollHeight;
}

// ---- connection ---------------------------------------------------------------------------
// Before its socket first opens the page is connecting, not lost: "lost"
// (and the banner) is for a link that was up and dropped. It then tries
// again every second.
function setOnline(up) {
  if (up) ui.link = 'up';
  else if (ui.link === 'up') ui.link = 'lost';
  document.body.classList.toggle('offline', !up);
  document.body.classList.toggle('connecting', ui.link === 'connecting');
  document.body.classList.toggle('lost', ui.link === 'lost');
  $('banner').hidden = ui.link !== 'lost';
  $('conn').textContent = up ? (ui.authed ? (ui.readonly ? 'read-only' : 'connected') : 'watching (no token)')
    : ui.link === 'lost' ? 'lost: reconnecting…' : 'connecting…';
  $('conn').classList.toggle('up', up);
  ui.canCommand = up && ui.authed && !ui.readonly;
  refreshEnabled();
  if (!up) stopJog();
}

// Every control: enabled while this panel may command and, for those marked
// so, while the machine's state allows their use (machine.js).
function refreshEnabled() {
  const state = ui.status && ui.status.state;
  for (const el of document.querySelectorAll('button, input, select'))
    el.disabled = !('view' in el.dataset) && !('tab' in el.dataset) && !allowed(el, ui.canCommand, state);
}

// Once a link is dropped, nothing it still delivers counts; a stalled link's
// close handshake can take seconds, and the panel must show it offline at once.
function dropLink(ws) {
  if (ui.ws !== ws) return;
  ui.ws = null;
  if (ui.link === 'up') log('fault', 'connection to the NCK lost');
  setOnline(false);
  // without the token the server closes the socket after a moment: asking
  // again and again would only fill the log
  if (!token) { log('fault', 'no token: open the address cnc-run serve printed (with ?token=...)'); return; }
  setTimeout(connect, 1000);
}

function connect() {
  const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
  const url = `${proto}//${location.host}/ws${token ? '?token=' + encodeURIComponent(token) : ''}`;
  const ws = new WebSocket(url, 'ncp-panel');
  ui.ws = ws;
  ws.onmessage = (m) => { if (ui.ws === ws) onMessage(m.data); };
  ws.onopen = () => { ui.lastRecv = performance.now(); };
  ws.onclose = () => dropLink(ws);
  // a stalled link shows as lost too: the status comes at least every 20 ms
  ws.onerror = () => {};
}
// The watchdog's own tick runs late when the page itself was busy (a slow
// first WebGL set-up, a starved or throttled browser); the statuses that came
// meanwhile are then still queued behind it, so the link gets a fresh 2 s.
let watchdogTick = performance.now();
setInterval(() => {
  const now = performance.now();
  const pageStalled = now - watchdogTick > 1500;
  watchdogTick = now;
  if (pageStalled && ui.lastRecv) ui.lastRecv = now;
  if (ui.ws && ui.ws.readyState === WebSocket.OPEN && ui.lastRecv && now - ui.lastRecv > 2000) {
    log('fault', 'no status for 2 s: reconnecting');
    const ws = ui.ws;
    dropLink(ws);
    ws.close();
  }
}, 500);

function send(obj) {
  if (!ui.ws || ui.ws.readyState !== WebSocket.OPEN) return 0;
  if (obj.cmd !== 'keepalive' && !['list', 'program', 'preview', 'tools', 'history', 'got'].includes(obj.cmd)) obj.seq = ++ui.seq;
  ui.ws.send(JSON.stringify(obj));
  return obj.seq || 0;
}

// The slow queries (list, program, preview): the server answers a socket's
// first QUERIES_IN_FLIGHT and refuses more until they are answered, so the
// rest wait here. A panel opened while a program is loaded asks for all
// three at once, and a refused preview would leave it without a drawing.
const QUERIES_IN_FLIGHT = 2;
const queries = { inFlight: [], waiting: [] };
function ask(cmd) {
  if (!queries.waiting.includes(cmd)) queries.waiting.push(cmd);
  pumpQueries();
}
function pumpQueries() {
  while (queries.inFlight.length < QUERIES_IN_FLIGHT && queries.waiting.length) {
    const cmd = queries.waiting.shift();
    queries.inFlight.push(cmd);
    send({ cmd });
  }
}
function answered(cmd) {
  const i = queries.inFlight.indexOf(cmd);
  if (i >= 0) queries.inFlight.splice(i, 1);
  pumpQueries();
}
// the server's worker was busy with other sockets' queries: the one sent
// last is asked again in a moment
function retryQuery() {
  const cmd = queries.inFlight.pop();
  if (cmd && !queries.waiting.includes(cmd)) queries.waiting.unshift(cmd);
  setTimeout(pumpQueries, 500);
}

function onMessage(text) {
  ui.lastRecv = performance.now();
  let m;
  try { m = JSON.parse(text); } catch { return; }
  switch (m.type) {
    case 'part': {
      // a large answer comes in parts, so that acks and statuses are not
      // held behind it: joined, it is read as one message. Each part read
      // is told: the server keeps only a few parts ahead of the panel's
      // reading, so that an ack never waits behind megabytes in the socket
      ui.parts = ui.parts || {};
      const p = ui.parts[m.id] || (ui.parts[m.id] = { text: '', n: 0 });
      p.text += m.data;
      p.n++;
      if (!m.last) { send({ cmd: 'got', id: m.id, parts: p.n }); break; }
      delete ui.parts[m.id];
      onMessage(p.text);
      break;
    }
    case 'hello':
      ui.authed = m.authed; ui.readonly = m.readonly; ui.loadedPath = null; ui.parts = {};
      queries.inFlight = []; queries.waiting = [];
      setOverrideLimits(m.limits);
      ui.travel = m.travel || null;
      if (ui.travelShown) { ui.travelShown = null; preview.setTravel(null); }
      setOnline(true);
      log('info', m.authed ? (m.readonly ? 'connected, read-only' : 'connected') : 'connected without a valid token: watching only');
      if (m.authed) { ask('list'); tools.hello(); }
      break;
    case 'status': onStatus(m); break;
    case 'ack':
      if (m.result !== 'accepted') log('rejected', `#${m.seq}: ${m.reason}`);
      tools.onAck(m);
      break;
    case 'refused':
      // seq 0: a query's answer (the worker could not answer it), or its
      // refusal for now
      if (!m.seq && /earlier queries/.test(m.reason)) { retryQuery(); break; }
      if (!m.seq && queries.inFlight.length) answered(queries.inFlight[0]);
      log('refused', (m.seq ? `#${m.seq}: ` : '') + m.reason);
      break;
    case 'event': {
      const where = m.file ? `${m.file}${m.line ? ':' + m.line : ''}${m.col ? ':' + m.col : ''}: ` : '';
      log(m.kind, where + m.text);
      break;
    }
    case 'list': answered('list'); fillFiles(m.files); break;
    case 'loaded':
      // a load was checked: its text and preview are the NCK's copy, anew
      // even when the path is the same one
      ui.loadedPath = m.path;
      if (ui.authed) { ask('program'); ask('preview'); }
      break;
    case 'program': answered('program'); showProgram(m.path, m.text); break;
    case 'preview': answered('preview'); setCanon(m.canon); break;
    case 'tools': case 'history': answered(m.type); tools.onAnswer(m); break;
  }
}

// The loaded program's drawing: the preview shows it, the DRO's distance to
// go and the cut colour follow the tool along it.
function setCanon(text) {
  ui.path = preview.setCanon(text);
  progress.reset(ui.path);
}

// ---- status -> DRO, program line, preview ---------------------------------------------
const fmt = (v, d = 3) => (v === null || v === undefined ? '—' : Number(v).toFixed(d));

// "12.3 s" or "1 min 41.6 s"
function duration(t) {
  if (t < 60) return `${t.toFixed(1)} s`;
  const m = Math.floor(t / 60);
  return `${m} min ${(t - 60 * m).toFixed(1)} s`;
}

// The loaded program's estimate (serve finds it after the load), and the
// last run's own time beside it
function cycleTime(s) {
  const e = s.estimate || {};
  const est = e.state === 'done' ? `${duration(e.program_time_s)} (estimate)`
    : e.state === 'running' ? 'estimating…'
    : e.state === 'failed' ? 'no estimate (see the log)' : '';
  // while it runs: what is left of the estimate at the feed override now
  if (s.remaining_s != null && e.state === 'done')
    return `${duration(s.remaining_s)} left of ${duration(e.program_time_s)} (estimate)`;
  const last = s.program_time_s > 0 ? `last run ${duration(s.program_time_s)}` : '';
  return [est, last].filter(Boolean).join(', ') || '—';
}

// What drives the axes beyond the simulator: each CiA 402 drive's state and
// last EMCY, or each LLC's state, DP, clock offset, following error and
// last error
function devices(s) {
  const drives = (s.drives || []).map((d) =>
    `${d.axis} node ${d.node}: ${d.state} (${d.statusword})${d.error !== '0x0000' ? `, EMCY ${d.error} ${d.error_text}` : ''}`);
  // one short line per LLC (state, clock offset, following error), the DP
  // in the title: three of them must not push the DRO out of the column.
  // Its last error (kept until a reset) in a few words: the whole text is
  // the event in the log
  const llcs = (s.llcs || []).map((l) =>
    `${l.axis}: ${l.state}, ${l.clock_offset_us >= 0 ? '+' : ''}${l.clock_offset_us} us, ${fmt(l.ferr_nm / 1000, 1)} um` +
    (l.error ? `, last error: ${l.error}` : ''));
  return { title: drives.length ? 'drives' : `LLCs DP ${s.llc_dp}`, text: drives.concat(llcs).join('\n') };
}

function onStatus(m) {
  const recvUs = (performance.timeOrigin + performance.now()) * 1000;
  ui.lag.push([m.status.seq, m.utime, recvUs]);
  if (ui.lag.length > 5000) ui.lag.splice(0, 1000);
  const s = m.status;
  const prev = ui.status;
  ui.status = s;
  ui.http = m.http;
  $('state').textContent = s.state || '?';
  $('state').className = 'state ' + (s.state || '');
  $('prog-name').textContent = s.program || '';
  const body = $('dro').tBodies[0];
  const axes = Object.keys(s.pos_cmd);
  if (body.rows.length !== axes.length) {
    body.innerHTML = '';
    for (const a of axes) {
      const r = body.insertRow();
      r.innerHTML = `<td class="axis">${a.toUpperCase()}</td><td class="work"></td><td class="togo"></td><td></td><td></td><td></td>`;
    }
    buildJog(axes);
  }
  machine.axes(axes, refreshEnabled);
  if (!prev || prev.state !== s.state) refreshEnabled();
  const off = (s.g5x && s.g5x.offset) || {};
  const xyz = toolPoint(ui.path, axes.map((a) => s.pos_act[a] - (off[a] || 0)), axes, s.tool);
  // a new run starts at the program's start; the tool is followed while it runs
  const inProgram = ['running', 'stepping', 'paused'].includes(s.state);
  if (inProgram && !(prev && ['running', 'stepping', 'paused', 'stopping'].includes(prev.state))) progress.reset();
  if (inProgram) progress.follow(xyz);
  const toGo = inProgram ? progress.toGo(xyz) : null;
  ui.toGo = toGo;
  preview.setDone(progress.done);
  axes.forEach((a, i) => {
    const c = body.rows[i].cells;
    c[0].classList.toggle('unhomed', !s.homed[a]);
    c[0].title = s.homed[a] ? 'homed' : 'not homed';
    c[1].textContent = fmt(s.pos_act[a] - (off[a] || 0));
    c[2].textContent = toGo && i < 3 ? fmt(toGo[i]) : '';
    c[3].textContent = fmt(s.pos_cmd[a]);
    c[4].textContent = fmt(s.pos_act[a]);
    c[5].textContent = fmt(s.pos_cmd[a] - s.pos_act[a], 4);
  });
  machine.show(s);
  tools.onStatus(s, prev);
  showTravel(s, axes, off);
  $('line').textContent = s.line || '—';
  $('vel').textContent = `${fmt(s.vel, 0)} mm/min`;
  $('spindle').textContent = `${fmt(s.spindle.speed, 0)} rpm ${s.spindle.dir > 0 ? 'CW' : s.spindle.dir < 0 ? 'CCW' : 'stopped'}`;
  $('tool').textContent = `T${s.tool}`;
  $('g5x').textContent = (s.g5x && s.g5x.name) || '—';
  $('coolant').textContent = [s.coolant.mist && 'mist', s.coolant.flood && 'flood'].filter(Boolean).join(', ') || 'off';
  $('stepmode').textContent = s.step ? 'on' : 'off';
  $('estimate').textContent = cycleTime(s);
  const g = (s.gcodes || []).map((c) => (c === 'G64' && s.g64 && (s.g64.p > 0 || s.g64.q > 0)) ? `G64 P${s.g64.p} Q${s.g64.q}` : c);
  $('gcodes').textContent = g.join(' ') || '—';
  $('mcodes').textContent = (s.mcodes || []).join(' ') || '—';
  const dev = devices(s);
  $('devices').textContent = dev.text;
  $('devices-t').textContent = dev.title;
  $('devices').hidden = $('devices-t').hidden = !dev.text;
  if (document.activeElement !== $('step')) $('step').checked = !!s.step;
  for (const w of ['feed', 'rapid', 'spindle']) {
    const el = $('ov-' + w);
    if (document.activeElement !== el && !el.dragging) el.value = s[w + '_override'];
    $('ov-' + w + '-v').textContent = `${Math.round(s[w + '_override'])} %`;
  }
  if (!prev || prev.program !== s.program) {
    if (s.program && ui.authed && s.program !== ui.loadedPath) { ask('program'); ask('preview'); }
    else if (!s.program) { showProgram('', ''); setCanon(''); }
  }
  if (s.line !== ui.currentLine) highlight(s.line);
  preview.setTool(xyz, ['running', 'stepping', 'paused', 'mdi', 'jogging', 'homing', 'stopping'].includes(s.state));
  if (prev && prev.error !== s.error && s.error) log('error', s.error);
}

// The machine's travel (soft limits, machine coordinates) when the server's
// hello carries it as {"travel": {"min": {"x": ..}, "max": {..}}}: drawn as
// the box in the drawing's coordinates, so it moves with the work offset and
// the tool's length. Without it the box is the program's extents.
function showTravel(s, axes, off) {
  if (!ui.travel || !ui.travel.min || !ui.travel.max) return;
  const corner = (lim) => toolPoint(ui.path, axes.map((a) => (lim[a] ?? NaN) - (off[a] || 0)), axes, s.tool);
  const box = [corner(ui.travel.min), corner(ui.travel.max)];
  if (box.flat().some((v) => !isFinite(v))) return;
  const key = JSON.stringify(box);
  if (key === ui.travelShown) return;
  ui.travelShown = key;
  preview.setTravel(box);
}

// ---- program ------------------------------------------------------------------------------
function showProgram(path, text) {
  const box = $('program');
  box.innerHTML = '';
  ui.programLines = [];
  const frag = document.createDocumentFragment();
  text.split('\n').forEach((line, i) => {
    const el = document.createElement('div');
    el.textContent = line || ' ';
    el.dataset.line = i + 1;
    frag.appendChild(el);
    ui.programLines.push(el);
  });
  box.appendChild(frag);
  ui.currentLine = 0;
  if (ui.status) highlight(ui.status.line);
}

function highlight(line) {
  const old = ui.programLines[ui.currentLine - 1];
  if (old) old.classList.remove('current');
  ui.currentLine = line;
  const el = ui.programLines[line - 1];
  if (el) {
    el.classList.add('current');
    const box = $('program');
    const top = el.offsetTop - box.offsetTop;
    if (top < box.scrollTop || top > box.scrollTop + box.clientHeight - 20)
      box.scrollTop = top - box.clientHeight / 3;
  }
}

$('program').addEventListener('click', (e) => {
  const el = e.target.closest('div[data-line]');
  if (!el) return;
  const old = ui.programLines[ui.selectedLine - 1];
  if (old) old.classList.remove('selected');
  ui.selectedLine = Number(el.dataset.line);
  el.classList.add('selected');
  $('sel-line').textContent = ui.selectedLine;
});

function fillFiles(files) {
  const sel = $('files');
  const keep = sel.value;
  sel.innerHTML = '';
  for (const f of files) {
    const o = document.createElement('option');
    o.value = o.textContent = f;
    sel.appendChild(o);
  }
  if (ui.pendingSelect && files.includes(ui.pendingSelect)) { sel.value = ui.pendingSelect; ui.pendingSelect = null; }
  else if (files.includes(keep)) sel.value = keep;
  else if (files.includes('demo.ngc')) sel.value = 'demo.ngc';
}

// ---- controls ----------------------------------------------------------------------------
for (const el of document.querySelectorAll('[data-cmd]'))
  el.addEventListener('click', () => send({ cmd: el.dataset.cmd }));
$('load').addEventListener('click', () => { if ($('files').value) send({ cmd: 'load', path: $('files').value }); });
$('run').addEventListener('click', () => send({ cmd: 'run' }));

// ---- upload: POST the file into the NCK's folder, then load it like any other --------------
$('upload').addEventListener('click', () => $('upload-file').click());
$('upload-file').addEventListener('change', async () => {
  const input = $('upload-file');
  const file = input.files[0];
  input.value = '';
  if (!file) return;
  const q = new URLSearchParams({ token, name: file.name, overwrite: $('upload-overwrite').checked ? '1' : '0' });
  let answer;
  try {
    const r = await fetch(`/upload?${q}`, { method: 'POST', body: file });
    answer = await r.json();
  } catch (e) {
    answer = { ok: false, reason: `upload failed: ${e.message}` };
  }
  ui.lastUpload = answer;
  if (!answer.ok) { log('refused', `upload of ${file.name}: ${answer.reason}`); return; }
  log('info', `uploaded ${answer.name}`);
  ui.pendingSelect = answer.name;
  ask('list');
  send({ cmd: 'load', path: answer.name });
});
$('run-from').addEventListener('click', () => { if (ui.selectedLine) send({ cmd: 'run', line: ui.selectedLine }); });
$('step').addEventListener('change', () => send({ cmd: 'step', on: $('step').checked ? 1 : 0 }));

function setOverrideLimits(limits) {
  for (const w of ['feed', 'rapid', 'spindle']) {
    const l = (limits && limits[w]) || OVERRIDE_DEFAULTS[w];
    const el = $('ov-' + w);
    el.min = l[0];
    el.max = l[1];
  }
}
setOverrideLimits(null);

for (const w of ['feed', 'rapid', 'spindle']) {
  const el = $('ov-' + w);
  el.addEventListener('pointerdown', () => { el.dragging = true; });
  el.addEventListener('pointerup', () => { el.dragging = false; });
  el.addEventListener('input', () => { $('ov-' + w + '-v').textContent = `${el.value} %`; });
  el.addEventListener('change', () => send({ cmd: 'override', which: w, value: Number(el.value) }));
}

$('mdi-form').addEventListener('submit', (e) => {
  e.preventDefault();
  const text = $('mdi').value.trim();
  if (!text) return;
  send({ cmd: 'mdi', text });
  ui.mdiHistory = [text, ...ui.mdiHistory.filter((t) => t !== text)].slice(0, 50);
  ui.mdiIndex = -1;
  $('mdi').value = '';
  const ol = $('mdi-history');
  ol.innerHTML = '';
  for (const t of ui.mdiHistory) {
    const li = document.createElement('li');
    li.textContent = t;
    li.addEventListener('click', () => { $('mdi').value = t; $('mdi').focus(); });
    ol.appendChild(li);
  }
});
$('mdi').addEventListener('keydown', (e) => {
  if (e.key !== 'ArrowUp' && e.key !== 'ArrowDown') return;
  e.preventDefault();
  ui.mdiIndex = Math.max(-1, Math.min(ui.mdiHistory.length - 1, ui.mdiIndex + (e.key === 'ArrowUp' ? 1 : -1)));
  $('mdi').value = ui.mdiIndex < 0 ? '' : ui.mdiHistory[ui.mdiIndex];
});

// ---- jogging: steps, or continuous while held with a keep-alive ------------------------------
const jogStep = () => Number(document.querySelector('input[name=jogstep]:checked').value);

function startJog(axis, dir) {
  const step = jogStep();
  if (step > 0) { send({ cmd: 'jog', axis, dir, dist: step }); return; }
  if (ui.jogAxis) return;
  ui.jogAxis = axis;
  send({ cmd: 'jog', axis, dir });
  ui.jogTimer = setInterval(() => send({ cmd: 'keepalive' }), 100);
}

function stopJog() {
  if (!ui.jogAxis) return;
  clearInterval(ui.jogTimer);
  send({ cmd: 'jog_stop', axis: ui.jogAxis });
  ui.jogAxis = null;
}

function buildJog(axes) {
  const box = $('jog-buttons');
  box.innerHTML = '';
  for (const a of axes) {
    for (const dir of [-1, 1]) {
      const b = document.createElement('button');
      b.textContent = `${a.toUpperCase()}${dir > 0 ? '+' : '−'}`;
      b.id = `jog-${a}${dir > 0 ? 'p' : 'm'}`;
      b.addEventListener('pointerdown', () => startJog(a.toUpperCase(), dir));
      b.addEventListener('pointerup', stopJog);
      b.addEventListener('pointerleave', stopJog);
      box.appendChild(b);
    }
  }
  refreshEnabled();
}

const jogKeys = { ArrowLeft: ['X', -1], ArrowRight: ['X', 1], ArrowDown: ['Y', -1], ArrowUp: ['Y', 1], PageDown: ['Z', -1], PageUp: ['Z', 1] };
document.addEventListener('keydown', (e) => {
  const k = jogKeys[e.key];
  if (!k || e.repeat || e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
  if (!ui.authed || ui.readonly || document.body.classList.contains('offline')) return;
  e.preventDefault();
  startJog(k[0], k[1]);
});
document.addEventListener('keyup', (e) => { if (jogKeys[e.key]) stopJog(); });
window.addEventListener('blur', stopJog);

const machine = initMachine({ $, send, log });
const tools = initTools({ $, send, ask, log, ui });
setOnline(false);
connect();
