// The web case lcm-devices (run by tests/web/panel-test.mjs): the panel on a
// real distributed serve, not on an injected status. `cnc-run serve --backend
// lcm --http` and three `cnc-axis` (X, Y, Z) run in a network namespace of
// their own, as tests/service/dist runs them (its INI keys: DP 5, the longer
// loss and heartbeat watches for a shared host, homing that moves). The
// browser must reach serve's loopback address inside that namespace: chromium
// itself is started there (`ip netns exec`), and puppeteer talks to it over
// a pipe (--remote-debugging-pipe), which no namespace separates. The panel
// homes, loads tests/service/path.ngc and starts it; the #devices row must
// show each LLC's axis, state, DP and clock offset as the status has them at
// every status read: "running" while the program runs; still following once
// serve idles (at DP 5 serve streams the axes at rest between jobs, so the
// LLCs say running); "fault" for an LLC killed, serve's fault naming it,
// and its row its last error ("unheard", the HLC's word: it said nothing),
// which the log has in full and a reset does not clear while it is gone.
import { spawn, spawnSync } from 'node:child_process';
import crypto from 'node:crypto';
import fs from 'node:fs';
import path from 'node:path';

const HOME_KEYS = 'HOME_SEARCH_VEL = 20\nHOME_LATCH_VEL = -2\nHOME_OFFSET = 2\nHOME = 0\nHOME_SEQUENCE = 0\n';
const LCM_KEYS = '\n[LCM]\nDP = 5\nMAX_LOST_PERIODS = 100\nHEARTBEAT_TIMEOUT_MS = 500\n';

class Skip extends Error {}

// The namespace, lo up with multicast routed on it (LCM's group).
function makeNetns(name) {
  if (process.geteuid() !== 0) throw new Skip('not root: cannot make a network namespace');
  for (const argv of [['netns', 'add', name], ['-n', name, 'link', 'set', 'lo', 'up'],
    ['-n', name, 'link', 'set', 'lo', 'multicast', 'on'],
    ['-n', name, 'route', 'add', '224.0.0.0/4', 'dev', 'lo']]) {
    const r = spawnSync('ip', argv, { encoding: 'utf8' });
    if (r.status !== 0) {
      spawnSync('ip', ['netns', 'del', name]);
      throw new Skip(`ip ${argv.join(' ')} failed: ${(r.stderr || r.error || '').toString().trim()}`);
    }
  }
}

// The LCM key the binaries find (ncpar/auth.h), made when missing, as
// tests/tools/ncpauth.py's ensure_key does: every process here shares it.
function ensureKey(work) {
  if (!(process.env.XDG_CONFIG_HOME || '').startsWith('/') && !process.env.HOME)
    process.env.XDG_CONFIG_HOME = path.join(work, 'config');
  const dir = (process.env.XDG_CONFIG_HOME || '').startsWith('/')
    ? path.join(process.env.XDG_CONFIG_HOME, 'ncpar') : path.join(process.env.HOME, '.config', 'ncpar');
  const key = path.join(dir, 'lcm.key');
  if (fs.existsSync(key)) return;
  fs.mkdirSync(dir, { recursive: true, mode: 0o700 });
  try {
    fs.writeFileSync(key, crypto.randomBytes(32), { mode: 0o600, flag: 'wx' });
  } catch (e) {
    if (e.code !== 'EEXIST') throw e;
  }
}

function writeIni(work, root) {
  let text = fs.readFileSync(path.join(root, 'rt-config', 'sim-3axis.ini'), 'utf8');
  for (const a of 'XYZ') text = text.replace(`[AXIS_${a}]\n`, `[AXIS_${a}]\n${HOME_KEYS}`);
  const ini = path.join(work, 'lcm.ini');
  fs.writeFileSync(ini, text + LCM_KEYS);
  return ini;
}

// What the #devices row shows and the status it shows, read in one task
// (the panel updates the DOM in the task that takes the status).
const devicesNow = (page) => page.evaluate(() => ({
  s: window.ncpPanel.status,
  title: document.querySelector('#devices-t').textContent,
  hidden: document.querySelector('#devices').hidden,
  rows: document.querySelector('#devices').textContent.split('\n'),
}));

// Each row against the status: "X: running, +12 us, 3.1 um" under "LLCs DP 5",
// ", last error: ..." after it where the status has one for that LLC.
// The LLCs' states by axis, or the mismatch as text.
function rowsAgree(d) {
  const llcs = d.s.llcs || [];
  if (d.hidden || d.title !== `LLCs DP ${d.s.llc_dp}`) return `the row is ${d.hidden ? 'hidden' : `titled '${d.title}'`}`;
  if (llcs.length !== 3 || d.rows.length !== 3) return `${llcs.length} LLCs in the status, rows ${JSON.stringify(d.rows)}`;
  const states = {};
  for (let k = 0; k < 3; k++) {
    const l = llcs[k], m = d.rows[k].match(/^([XYZ]): (\w+), ([-+]\d+) us, -?[\d.]+ um(?:, last error: (.+))?$/);
    if (!m) return `row '${d.rows[k]}'`;
    if (m[1] !== l.axis || m[2] !== l.state || Number(m[3]) !== l.clock_offset_us || (m[4] || '') !== l.error)
      return `row '${d.rows[k]}' for ${JSON.stringify(l)} at DP ${d.s.llc_dp}`;
    states[m[1]] = m[2];
  }
  return states;
}

export async function lcmDevices({ BUILD, WORK, ROOT, CHROMIUM, puppeteer, launchArgs, report, shot }) {
  const ns = `ncpweb${process.pid}`;
  const work = path.join(WORK, 'lcm');
  const procs = [];
  let browser, serve;
  const log = (name) => fs.openSync(path.join(work, name), 'w');
  const nsSpawn = (argv, out, opts = {}) => {
    const p = spawn('ip', ['netns', 'exec', ns, ...argv], { stdio: ['ignore', out, out], ...opts });
    procs.push(p);
    return p;
  };
  try {
    fs.rmSync(work, { recursive: true, force: true });
    fs.mkdirSync(work, { recursive: true });
    makeNetns(ns);
    ensureKey(work);
    const ini = writeIni(work, ROOT);
    const programs = path.join(work, 'programs');
    fs.mkdirSync(programs);
    fs.copyFileSync(path.join(ROOT, 'tests', 'service', 'path.ngc'), path.join(programs, 'path.ngc'));
    // the LLCs first: serve waits for each axis's answer
    const llcs = {};
    for (const a of 'XYZ')
      llcs[a] = nsSpawn([path.resolve(BUILD, 'cnc-axis'), '--axis', a, '--config', ini,
        '--trace', path.join(work, `ax${a}.csv`)], log(`ax${a}.err`));
    await new Promise((r) => setTimeout(r, 200));
    const serveLog = path.join(work, 'serve.log');
    serve = nsSpawn([path.resolve(BUILD, 'cnc-run'), 'serve', '--config', ini, '--backend', 'lcm',
      '--http', '127.0.0.1:8080', '--prefix', `WEBL${process.pid}_`], log('serve.log'), { cwd: programs });
    let url;
    for (const deadline = Date.now() + 10000; !url;) {
      const m = fs.readFileSync(serveLog, 'utf8').match(/panel at (http:\/\/\S+\/\?token=[0-9a-f]+)/);
      if (m) url = m[1];
      else if (serve.exitCode !== null) throw new Error(`serve exited with ${serve.exitCode}: ${fs.readFileSync(serveLog, 'utf8').trim().slice(-300)}`);
      else if (Date.now() > deadline) throw new Error('serve printed no panel address within 10 s');
      else await new Promise((r) => setTimeout(r, 50));
    }
    // chromium in the namespace, spoken to over its pipe
    const wrapper = path.join(work, 'chromium-in-netns');
    fs.writeFileSync(wrapper, `#!/bin/sh\nexec ip netns exec ${ns} '${CHROMIUM}' "$@"\n`, { mode: 0o755 });
    browser = await puppeteer.launch({ executablePath: wrapper, pipe: true, headless: true, args: launchArgs, timeout: 30000 });
    const page = await browser.newPage();
    await page.setViewport({ width: 1280, height: 800 });
    await page.goto(url, { waitUntil: 'load', timeout: 20000 });
    await page.waitForFunction(() => window.ncpPanel && window.ncpPanel.status && window.ncpPanel.authed, { timeout: 20000 });
    // reads the row at each status until want(states, status) holds
    const until = async (what, want, ms) => {
      let d, agree;
      for (const deadline = Date.now() + ms; ;) {
        d = await devicesNow(page);
        agree = d.s ? rowsAgree(d) : 'no status';
        if (typeof agree === 'string') throw new Error(`${what}: ${agree}`);
        if (want(agree, d.s)) return d;
        if (Date.now() > deadline)
          throw new Error(`${what}: not within ${ms / 1000} s (state ${d.s.state}, LLCs ${JSON.stringify(agree)})`);
        await new Promise((r) => setTimeout(r, 20));
      }
    };
    const first = await until('the LLCs before homing', () => true, 1000);
    if (first.s.llc_dp !== 5) throw new Error(`status says DP ${first.s.llc_dp}, the INI 5`);
    await page.waitForSelector('#home:not([disabled])', { timeout: 5000 });
    await page.click('#home');
    await until('homed', (_, s) => s.state === 'idle' && Object.values(s.homed).every(Boolean), 20000);
    await page.waitForFunction(() => document.querySelector('#files option[value="path.ngc"]'), { timeout: 5000 });
    await page.select('#files', 'path.ngc');
    await page.click('#load');
    await until('path.ngc loaded', (_, s) => (s.program || '').endsWith('path.ngc') && s.state === 'idle', 10000);
    await page.waitForSelector('#run:not([disabled])', { timeout: 5000 });
    await page.click('#run');
    const running = await until('every LLC running while the program runs',
      (st, s) => s.state === 'running' && s.vel > 0 && Object.values(st).every((x) => x === 'running'), 8000);
    // the clock offsets as they come, while the axes move
    const offsets = new Set();
    for (let i = 0; i < 10; i++) {
      const d = await until('running', () => true, 1000);
      for (const l of d.s.llcs) offsets.add(`${l.axis}${l.clock_offset_us}`);
      await new Promise((r) => setTimeout(r, 50));
    }
    // three LLC rows make the left column taller than 800 px: E-stop stays in sight
    const estop = await page.$eval('#estop', (e) => { const r = e.getBoundingClientRect(); return [r.top, r.bottom, innerHeight]; });
    if (estop[0] < 0 || estop[1] > estop[2]) throw new Error(`E-stop out of sight at ${estop[0]}..${estop[1]} px`);
    // and the DRO with them: one line per LLC keeps X in its column's view
    const dro = await page.evaluate(() => {
      const x = document.querySelector('#dro tbody tr').getBoundingClientRect();
      const col = document.querySelector('#dro').closest('section, aside, div').getBoundingClientRect();
      return [x.top, x.bottom, Math.max(col.top, 0), Math.min(col.bottom, innerHeight)];
    });
    if (dro[0] < dro[2] || dro[1] > dro[3]) throw new Error(`the DRO's X row at ${dro[0]}..${dro[1]} px, out of its column's view ${dro[2]}..${dro[3]}`);
    await shot(page, '20-lcm-running');
    // At its end serve idles, and at DP 5 it goes on sending setpoints (the
    // axes at rest) so the LLCs keep following, as serve's status says
    const after = await until('the program at its end', (_, s) => s.state === 'idle', 20000);
    const idleStates = rowsAgree(await devicesNow(page));
    if (!Object.values(idleStates).every((x) => ['running', 'waiting', 'done'].includes(x)))
      throw new Error(`LLCs after the program: ${JSON.stringify(idleStates)}`);
    await shot(page, '21-lcm-idle');
    // Y's LLC dies: serve's fault names it, and its row must not go on saying
    // what its last status said
    llcs.Y.kill('SIGKILL');
    const ended = await until("Y's LLC shown in fault once it is gone",
      (st, s) => s.state === 'fault' && st.Y === 'fault', 5000);
    if (!/axis Y/.test(ended.s.error)) throw new Error(`the fault does not name axis Y: ${ended.s.error}`);
    // its last error in its row (X and Z are held: none), the whole text in the log
    const told = await until("Y's last error in its row",
      () => true, 1000);
    const yRow = told.rows.find((r) => r.startsWith('Y: '));
    if (!/, last error: unheard \(killed or cut off\)$/.test(yRow) || told.rows.some((r) => !r.startsWith('Y: ') && /last error/.test(r)))
      throw new Error(`the LLC rows once Y is gone: ${JSON.stringify(told.rows)}`);
    await page.waitForFunction(() => /axis Y's LLC, last error: (no status for|heartbeat lost)/.test(document.querySelector('#log').textContent), { timeout: 3000 });
    await shot(page, '22-lcm-llc-lost');
    // a reset: Y is not back, so its last error stays in its row
    await page.waitForSelector('#reset:not([disabled])', { timeout: 5000 });
    await new Promise((r) => setTimeout(r, 600));   // past serve's heartbeat watch (500 ms)
    await page.click('#reset');
    await new Promise((r) => setTimeout(r, 500));
    const kept = await until("Y's last error after a reset", () => true, 1000);
    if (!kept.rows.some((r) => /^Y: .*, last error: unheard \(killed or cut off\)$/.test(r)))
      throw new Error(`the LLC rows after a reset, Y still gone: ${JSON.stringify(kept.rows)}`);
    report('lcm-devices', 'PASS');
    console.log(`# lcm-devices: running ${JSON.stringify(running.rows)}; at the end (${after.s.state}) ` +
      `${JSON.stringify(idleStates)}; Y killed: ${JSON.stringify(told.rows)}; ${offsets.size} clock offsets seen while running`);
  } catch (e) {
    report('lcm-devices', e instanceof Skip ? 'SKIP' : 'FAIL', e.message.split('\n')[0]);
  } finally {
    if (browser) await browser.close().catch(() => {});
    // serve first (its stop ends the LLCs' job), then whatever is left
    const wait = async (ps, ms) => {
      for (let i = 0; i < ms / 50 && ps.some((p) => p.exitCode === null); i++) await new Promise((r) => setTimeout(r, 50));
    };
    const rest = procs.filter((p) => p !== serve);
    if (serve && serve.exitCode === null) serve.kill('SIGTERM');
    if (serve) await wait([serve], 5000);
    for (const p of rest) if (p.exitCode === null) p.kill('SIGTERM');
    await wait(rest, 5000);
    for (const p of procs) if (p.exitCode === null) p.kill('SIGKILL');
    spawnSync('ip', ['netns', 'del', ns]);
  }
}
