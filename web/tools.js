// The Tools and History tabs: the tool table and the job history as the
// NCK's files have them (serve reads them for the panel: the "tools" and
// "history" queries), the same files `cnc-ctl tool list` and `cnc-ctl
// history` read. A tool's Z offset and diameter change through MDI G10 L1,
// the line `cnc-ctl tool set` sends: the NCK decides when it may (not while
// a program runs) and rewrites the file, and its refusal is shown here.

const MM_PER_INCH = 25.4;
const LINEAR = 'XYZUVWD';

// One LinuxCNC tool table line ("T2 P2 Z0.12 D0.2362 ;6 mm end mill"), in
// the file's inches, or null for a line that is no tool (cnc-ctl's reading).
export function parseToolLine(line) {
  const semi = line.indexOf(';');
  const body = semi >= 0 ? line.slice(0, semi) : line;
  const t = { comment: semi >= 0 ? line.slice(semi + 1).trim() : '' };
  const words = body.trim().split(/\s+/).filter(Boolean);
  for (const w of words) {
    const m = w.match(/^([A-Za-z])([-+]?[0-9.]+(?:[eE][-+]?\d+)?)$/);
    if (!m) return null;
    t[m[1].toUpperCase()] = Number(m[2]);
  }
  return 'T' in t ? t : null;
}

// The history's lines (JSON, one a job), newest first; a hand-edited line
// that is no JSON is left out, as cnc-ctl leaves it.
export function parseHistory(text) {
  const jobs = [];
  for (const line of text.split('\n')) {
    if (!line.startsWith('{')) continue;
    try { jobs.push(JSON.parse(line)); } catch { /* not one of ours */ }
  }
  return jobs.reverse();
}

const secs = (v) => (typeof v === 'number' ? `${v.toFixed(3)} s` : '—');
const cell = (tr, text, cls) => {
  const td = document.createElement('td');
  td.textContent = text;
  if (cls) td.className = cls;
  tr.appendChild(td);
  return td;
};

export function initTools({ $, send, ask, log, ui }) {
  const tabs = [...document.querySelectorAll('[data-tab]')];
  let shown = 'program';
  const showTab = (name) => {
    shown = name;
    for (const b of tabs) b.classList.toggle('on', b.dataset.tab === name);
    $('program').hidden = name !== 'program';
    $('tools-view').hidden = name !== 'tools';
    $('history-view').hidden = name !== 'history';
    if (name === 'tools' && ui.authed) ask('tools');
    if (name === 'history' && ui.authed) ask('history');
  };
  for (const b of tabs) b.addEventListener('click', () => showTab(b.dataset.tab));

  let tools = [];
  const msg = (kind, text) => {
    $('tool-msg').textContent = text;
    $('tool-msg').className = `tool-msg ${kind}`;
  };
  const fillForm = (t) => {
    $('tool-t').value = String(t.T);
    $('tool-z').value = 'Z' in t ? +(t.Z * MM_PER_INCH).toFixed(4) : '';
    $('tool-d').value = 'D' in t ? +(t.D * MM_PER_INCH).toFixed(4) : '';
  };
  $('tool-t').addEventListener('change', () => {
    const t = tools.find((x) => String(x.T) === $('tool-t').value);
    if (t) fillForm(t);
  });

  // the edit: what cnc-ctl tool set T Z .. D .. sends, in the units in force
  let pending = null;   // the edit sent: {seq, line, acked, after (statuses since its ack)}
  $('tool-form').addEventListener('submit', (e) => {
    e.preventDefault();
    const t = Number($('tool-t').value);
    const zt = $('tool-z').value.trim(), dt = $('tool-d').value.trim();
    const z = Number(zt), d = Number(dt);
    if (!(t > 0) || (zt === '' && dt === '') || !isFinite(z) || !isFinite(d) || d < 0) {
      msg('refused', 'a tool, and its Z offset or diameter in mm (a diameter not below 0)');
      return;
    }
    const inch = ui.status && (ui.status.gcodes || []).includes('G20');
    const k = inch ? 1 / MM_PER_INCH : 1;
    let line = `G10 L1 P${t}`;
    if (zt !== '') line += ` Z${+(z * k).toPrecision(12)}`;
    if (dt !== '') line += ` R${+(d * k / 2).toPrecision(12)}`;   // G10 L1 takes the radius
    const seq = send({ cmd: 'mdi', text: line });
    if (!seq) { msg('refused', 'not connected'); return; }
    pending = { seq, line, acked: false };
    msg('info', `${line}: sent`);
  });

  function showTools(m) {
    $('tools-path').textContent = m.why || m.path || '';
    const body = $('tool-table').tBodies[0];
    body.innerHTML = '';
    tools = m.text.split('\n').map(parseToolLine).filter(Boolean);
    const sel = $('tool-t'), keep = sel.value;
    sel.innerHTML = tools.map((t) => `<option value="${t.T}">T${t.T}</option>`).join('');
    for (const t of tools) {
      const tr = document.createElement('tr');
      tr.dataset.tool = t.T;
      cell(tr, `T${t.T}`);
      cell(tr, 'P' in t ? `P${t.P}` : '');
      cell(tr, 'Z' in t ? (t.Z * MM_PER_INCH).toFixed(4) : '', 'num');
      cell(tr, 'D' in t ? (t.D * MM_PER_INCH).toFixed(4) : '', 'num');
      cell(tr, t.comment);
      tr.addEventListener('click', () => fillForm(t));
      body.appendChild(tr);
    }
    if (tools.some((t) => String(t.T) === keep)) sel.value = keep;
    const cur = tools.find((t) => String(t.T) === sel.value);
    // the first table fills the form; later ones leave what was typed
    if (cur && !keep) fillForm(cur);
  }

  function showHistory(m) {
    $('history-path').textContent = m.why || m.path || '';
    const body = $('history-table').tBodies[0];
    body.innerHTML = '';
    for (const j of parseHistory(m.text)) {
      const tr = document.createElement('tr');
      cell(tr, (j.end || '').replace('T', ' ').replace(/\.\d+Z$/, ''));
      cell(tr, (j.program || '').split('/').pop()).title = j.program || '';
      cell(tr, j.result + (j.reason ? `: ${j.reason}` : ''), `result ${j.result}`);
      cell(tr, secs(j.program_time_s), 'num');
      cell(tr, secs(j.estimate_s), 'num');
      body.appendChild(tr);
    }
  }

  return {
    onAnswer(m) {
      if (m.type === 'tools') showTools(m);
      else showHistory(m);
    },
    // the tool edit's ack: refused (shown, with the NCK's reason) or taken,
    // then done once the MDI line ran and the machine is idle again
    onAck(m) {
      if (!pending || m.seq !== pending.seq) return;
      if (m.result !== 'accepted') {
        msg('refused', `${pending.line}: ${m.reason}`);
        pending = null;
        return;
      }
      pending.acked = true;
      pending.after = 0;
    },
    onStatus(s, prev) {
      // as cnc-ctl waits: a status from before the ack may still show the
      // state before the line, so the second one after it that is not in
      // MDI says it ran
      if (pending && pending.acked && s.state !== 'mdi' && ++pending.after >= 2) {
        const ok = s.state === 'idle';
        msg(ok ? 'info' : 'refused', `${pending.line}: ${ok ? 'done' : `ended in ${s.state}: ${s.error || ''}`}`);
        pending = null;
        ask('tools');
      }
      // a job ended: its line is in the history now
      const busy = (x) => x && ['running', 'paused', 'stepping', 'stopping'].includes(x.state);
      if (busy(prev) && !busy(s) && shown === 'history') ask('history');
    },
    // a new connection: the tab shown asks again
    hello() { if (shown !== 'program') showTab(shown); },
  };
}
