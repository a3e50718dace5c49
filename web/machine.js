// The machine's manual controls: per-axis home, spindle, coolant, touch-off,
// and the tool table's place. The service protocol has no spindle, coolant or
// touch-off command of its own, so they go as the MDI lines a machinist would
// type (what `cnc-ctl touch-off` sends, too): the NCK's MDI rules then decide,
// with its reasons, and the panel never moves anything the NCK would not.
// Controls marked data-needs="idle" are only offered while the machine is
// idle: a home or an MDI line is refused while a program runs, and a button
// that cannot work should say so before it is pressed.

const SYSTEMS = ['G54', 'G55', 'G56', 'G57', 'G58', 'G59', 'G59.1', 'G59.2', 'G59.3'];
const BUSY_TITLE = 'only while the machine is idle';

export function initMachine({ $, send, log }) {
  const mdi = (text) => send({ cmd: 'mdi', text });

  // spindle: M3/M4 with the speed typed beside it, M5
  const rpm = () => {
    const v = Number($('spindle-rpm').value);
    if (!(v > 0)) { log('refused', 'spindle: the speed is a number of rpm above 0'); return null; }
    return v;
  };
  $('spindle-cw').addEventListener('click', () => { const v = rpm(); if (v) mdi(`M3 S${v}`); });
  $('spindle-ccw').addEventListener('click', () => { const v = rpm(); if (v) mdi(`M4 S${v}`); });
  $('spindle-stop').addEventListener('click', () => mdi('M5'));
  // coolant: M7 mist, M8 flood, M9 both off
  $('coolant-mist').addEventListener('click', () => mdi('M7'));
  $('coolant-flood').addEventListener('click', () => mdi('M8'));
  $('coolant-off').addEventListener('click', () => mdi('M9'));

  // touch-off: G10 L20 sets the chosen system's offset so that the axis
  // reads VALUE there now; P0 is the system in force
  const sys = $('touch-system');
  sys.innerHTML = '<option value="0" title="the system in force (P0)">in use</option>' +
    SYSTEMS.map((n, i) => `<option value="${i + 1}">${n}</option>`).join('');
  $('touch-form').addEventListener('submit', (e) => {
    e.preventDefault();
    const axis = $('touch-axis').value, text = $('touch-value').value.trim();
    const v = Number(text);
    if (!axis || text === '' || !isFinite(v)) { log('refused', 'touch-off: the value is the position the axis is to read, in mm'); return; }
    mdi(`G10 L20 P${sys.value} ${axis}${v}`);
  });

  let axesShown = '';
  return {
    // the status's axes: a home button and a touch-off choice each
    axes(axes, onBuilt) {
      const key = axes.join('');
      if (key === axesShown) return;
      axesShown = key;
      const box = $('home-buttons');
      box.innerHTML = '';
      for (const a of axes) {
        const b = document.createElement('button');
        b.id = `home-${a}`;
        b.textContent = `Home ${a.toUpperCase()}`;
        b.dataset.needs = 'idle';
        b.addEventListener('click', () => send({ cmd: 'home', axis: a.toUpperCase() }));
        box.appendChild(b);
      }
      const sel = $('touch-axis'), keep = sel.value;
      sel.innerHTML = axes.map((a) => `<option value="${a.toUpperCase()}">${a.toUpperCase()}</option>`).join('');
      if (keep) sel.value = keep;
      onBuilt();
    },
    // what the status says is on: the matching button lit
    show(s) {
      $('spindle-cw').classList.toggle('on', s.spindle.dir > 0);
      $('spindle-ccw').classList.toggle('on', s.spindle.dir < 0);
      $('spindle-stop').classList.toggle('on', !s.spindle.dir);
      $('coolant-mist').classList.toggle('on', !!s.coolant.mist);
      $('coolant-flood').classList.toggle('on', !!s.coolant.flood);
      $('coolant-off').classList.toggle('on', !s.coolant.mist && !s.coolant.flood);
    },
  };
}

// Whether one control may be used now. Those the service cannot serve at all
// (data-unavailable) stay disabled, their title saying why.
export function allowed(el, canCommand, state) {
  if ('unavailable' in el.dataset) return false;
  if (!canCommand) return false;
  if (el.dataset.needs === 'idle' && state !== 'idle') {
    if (!el.dataset.title) el.dataset.title = el.title || '';
    el.title = `${el.dataset.title ? el.dataset.title + ': ' : ''}${BUSY_TITLE} (now ${state || 'unknown'})`;
    return false;
  }
  if ('title' in el.dataset) el.title = el.dataset.title;
  return true;
}
