// The web cases tool-table, history and tool-refused (run by
// tests/web/panel-test.mjs): the panel's Tools and History tabs on a serve
// whose machine keeps a tool table ([EMCIO] TOOL_TABLE, a copy of
// rt-config/tools.tbl) and a job history ([DISPLAY] HISTORY_FILE), on
// rt-config/sim-3axis.ini. A tool's Z and diameter set in the tab must land
// in the table file (inches, as rs274 reads it) and in the tab; a program run
// to its end must show as the history's newest row with its program time and
// the load's estimate; an edit while a program runs must be refused by the
// NCK, the refusal shown in the tab and the file untouched.
import fs from 'node:fs';
import path from 'node:path';

const SHORT = 'G21 G90 G94\nG1 X20 Y10 F2400\nG1 X0 Y0\nM2\n';
const SLOW = 'G21 G90 G94\nG1 X60 F600\nG0 X0\nM2\n';

function machine(work, root) {
  const dir = path.join(work, 'tools-machine');
  fs.rmSync(dir, { recursive: true, force: true });
  fs.mkdirSync(dir, { recursive: true });
  const ini = fs.readFileSync(path.join(root, 'rt-config', 'sim-3axis.ini'), 'utf8') +
    '\n[EMCIO]\nTOOL_TABLE = tools.tbl\n\n[DISPLAY]\nHISTORY_FILE = jobs.jsonl\n';
  fs.writeFileSync(path.join(dir, 'machine.ini'), ini);
  fs.copyFileSync(path.join(root, 'rt-config', 'tools.tbl'), path.join(dir, 'tools.tbl'));
  return { ini: path.join(dir, 'machine.ini'), table: path.join(dir, 'tools.tbl'), history: path.join(dir, 'jobs.jsonl') };
}

// T's line of the table file as numbers (inches), or null.
function fileTool(table, t) {
  const line = fs.readFileSync(table, 'utf8').split('\n').find((l) => l.startsWith(`T${t} `));
  if (!line) return null;
  const v = {};
  for (const m of line.split(';')[0].matchAll(/([A-Z])([-+0-9.eE]+)/g)) v[m[1]] = Number(m[2]);
  return { ...v, line };
}

export async function toolCases(browser, h) {
  const { ROOT, WORK, report, check, sleep, startServer, stopServer, openPanel, waitFor, click, shot } = h;
  const NAMES = ['tool-table', 'history', 'tool-refused'];
  const m = machine(WORK, ROOT);
  let srv, page;
  try {
    srv = await startServer('tools', ['--config', m.ini]);
    fs.writeFileSync(path.join(srv.programs, 'short.ngc'), SHORT);
    fs.writeFileSync(path.join(srv.programs, 'slow.ngc'), SLOW);
    page = await browser.newPage();
    page.on('pageerror', (e) => console.log(`# the tools page: ${e.message}`));
    await page.setViewport({ width: 1280, height: 800 });
    await openPanel(page, srv, 15000);
    await click(page, '#home');
    await waitFor(page, 'homed', (s) => s.state === 'idle' && Object.values(s.homed).every(Boolean));
  } catch (e) {
    for (const c of NAMES) report(c, 'FAIL', `set-up: ${e.message.split('\n')[0]}`);
    if (page) await page.close().catch(() => {});
    await stopServer(srv);
    return;
  }
  const run = async (name, fn) => {
    try { await fn(); report(name, 'PASS'); }
    catch (e) {
      const said = await page.$eval('#tool-msg', (d) => d.textContent).catch(() => '');
      report(name, 'FAIL', `${e.message.split('\n')[0]}${said ? ' (tools tab: ' + said + ')' : ''}`);
    }
  };
  const row = (sel) => page.$$eval(`${sel} tbody tr`, (rows) => rows.map((r) => [...r.cells].map((c) => c.textContent)));
  const loadRun = async (name) => {
    await page.waitForFunction((n) => document.querySelector(`#files option[value="${n}"]`), { timeout: 5000 }, name);
    await page.select('#files', name);
    await click(page, '#load');
    await waitFor(page, `${name} loaded with its estimate`,
      (s) => (s.program || '').endsWith(name) && s.state === 'idle' && s.estimate && s.estimate.state === 'done', 10000);
    await click(page, '#run');
  };

  await run('tool-table', async () => {
    const before = fileTool(m.table, 2), t3 = fileTool(m.table, 3);
    await page.click('[data-tab="tools"]');
    await page.waitForFunction(() => document.querySelectorAll('#tool-table tbody tr').length === 8, { timeout: 5000 });
    const rows = await row('#tool-table');
    check(rows[1][0] === 'T2' && rows[1][2] === (before.Z * 25.4).toFixed(4) && rows[1][3] === (before.D * 25.4).toFixed(4) &&
      /6 mm flat end mill/.test(rows[1][4]), `T2's row ${JSON.stringify(rows[1])} for the file's ${before.line}`);
    // a click on T2's row puts it in the form; Z and D typed in mm
    await page.click('#tool-table tbody tr[data-tool="2"]');
    check(await page.$eval('#tool-t', (e) => e.value) === '2', 'a click on T2 did not choose it');
    await page.$eval('#tool-z', (e) => { e.value = '-5.5'; });
    await page.$eval('#tool-d', (e) => { e.value = '6.5'; });
    await click(page, '#tool-apply');
    await page.waitForFunction(() => /: done$/.test(document.querySelector('#tool-msg').textContent), { timeout: 5000 })
      .catch(async () => { throw new Error(`the edit: ${await page.$eval('#tool-msg', (e) => e.textContent)}`); });
    const after = fileTool(m.table, 2);
    check(Math.abs(after.Z * 25.4 + 5.5) < 1e-4 && Math.abs(after.D * 25.4 - 6.5) < 1e-4 && after.P === 2 &&
      /mill/.test(after.line), `the file's T2 after the edit: ${after.line}`);
    check(fileTool(m.table, 3).line === t3.line, `T3 changed: ${fileTool(m.table, 3).line}`);
    await page.waitForFunction(() => {
      const r = document.querySelector('#tool-table tbody tr[data-tool="2"]');
      return r && r.cells[2].textContent === '-5.5000' && r.cells[3].textContent === '6.5000';
    }, { timeout: 5000 }).catch(async () => { throw new Error(`T2's row after the edit: ${JSON.stringify((await row('#tool-table'))[1])}`); });
    await shot(page, '30-tools');
  });

  await run('history', async () => {
    const jobs = () => (fs.existsSync(m.history) ? fs.readFileSync(m.history, 'utf8').trim().split('\n').filter(Boolean) : []);
    const n0 = jobs().length;
    await page.click('[data-tab="history"]');
    await loadRun('short.ngc');
    const est = (await waitFor(page, 'running', (s) => s.state === 'running', 5000)).estimate.program_time_s;
    const done = await waitFor(page, 'short.ngc at its end', (s) => s.state === 'idle' && s.program_time_s > 0, 15000);
    await page.waitForFunction(() => document.querySelectorAll('#history-table tbody tr').length > 0 &&
      /short\.ngc/.test(document.querySelector('#history-table tbody tr').cells[1].textContent), { timeout: 5000 })
      .catch(async () => { throw new Error(`history rows ${JSON.stringify(await row('#history-table'))} path ${await page.$eval('#history-path', (e) => e.textContent)} log ${await page.$$eval('#log div', (d) => d.slice(-4).map((e) => e.textContent).join(' | '))}`); });
    check(jobs().length === n0 + 1, `${jobs().length - n0} lines appended to the history file`);
    const top = (await row('#history-table'))[0];
    check(top[2] === 'done' && top[3] === `${done.program_time_s.toFixed(3)} s` && top[4] === `${est.toFixed(3)} s`,
      `the newest row ${JSON.stringify(top)}: wanted done, ${done.program_time_s.toFixed(3)} s, estimate ${est.toFixed(3)} s`);
    await shot(page, '31-history');
  });

  await run('tool-refused', async () => {
    const before = fs.readFileSync(m.table, 'utf8');
    await loadRun('slow.ngc');
    await waitFor(page, 'slow.ngc running', (s) => s.state === 'running' && s.vel > 0, 5000);
    await page.click('[data-tab="tools"]');
    await page.waitForFunction(() => document.querySelectorAll('#tool-table tbody tr').length === 8, { timeout: 5000 });
    await page.select('#tool-t', '3');
    await page.$eval('#tool-z', (e) => { e.value = '1'; });
    await click(page, '#tool-apply');
    await page.waitForFunction(() => document.querySelector('#tool-msg').classList.contains('refused'), { timeout: 5000 })
      .catch(async () => { throw new Error(`no refusal: ${await page.$eval('#tool-msg', (e) => e.textContent)}`); });
    const said = await page.$eval('#tool-msg', (e) => e.textContent);
    check(/^G10 L1 P3 Z1\b.*: cannot run MDI while running/.test(said), `the refusal shown: ${said}`);
    await shot(page, '32-tool-refused');
    await click(page, '#stop');
    await waitFor(page, 'stopped', (s) => s.state === 'idle', 10000);
    check(fs.readFileSync(m.table, 'utf8') === before, 'the tool table file changed after a refused edit');
    // the stopped job is the history's newest line
    await page.click('[data-tab="history"]');
    await page.waitForFunction(() => {
      const r = document.querySelector('#history-table tbody tr');
      return r && /slow\.ngc/.test(r.cells[1].textContent) && /^stopped/.test(r.cells[2].textContent);
    }, { timeout: 5000 }).catch(async () => { throw new Error(`history rows ${JSON.stringify(await row('#history-table'))}`); });
  });
  await page.close().catch(() => {});
  const rc = await stopServer(srv);
  if (rc !== 0) console.log(`# the tools server's exit: ${rc}`);
}
