// SPDX-License-Identifier: ISC
// The web console says what it knows and what it does not, in a real
// browser (Debian's chromium, headless, puppeteer-core): psensd stopped
// under the open page (every tile stale, the level unknown, the time of the
// last answer), psensd started again (the page live again, never reloaded),
// psensd silent behind an open connection (SIGSTOP: stale, then live),
// a loopback room shown as simulated, an override typed in % refused in %,
// and the acceptance table with a unit on every figure and each test's
// reason.  Used by tests/system/657-web-stale-units.sh.  Prints TAP lines.
//
// usage: node web-stale-peer.js URL PASSWORD CONTROL
//   CONTROL: a script run as `sh CONTROL stop` (psensd stopped, returns once
//   it has exited), `sh CONTROL start` (returns once it answers), and `sh
//   CONTROL pause` and `resume` (SIGSTOP and SIGCONT)
'use strict';
const { execFileSync } = require('child_process');
const puppeteer = require('puppeteer-core');

const [url, password, control] = process.argv.slice(2);
let n = 0, failed = 0;
function ok(cond, what) {
  n++;
  if (!cond) failed++;
  console.log((cond ? 'ok ' : 'not ok ') + n + ' - ' + what);
  return cond;
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const text = (page, sel) => page.$eval(sel, (e) => e.textContent).catch(() => null);
const visible = (page, sel) => page.$eval(sel, (e) => !e.hidden && e.getClientRects().length > 0).catch(() => false);
async function until(fn, ms) {
  const end = Date.now() + ms;
  let v;
  while (!(v = await fn()) && Date.now() < end)
    await sleep(100);
  return v;
}
// seconds of the local day of a Date, and of an "HH:MM:SS" text
const sod = (d) => d.getHours() * 3600 + d.getMinutes() * 60 + d.getSeconds();
const hms = (s) => { const m = /(\d\d):(\d\d):(\d\d)/.exec(s || ''); return m ? 3600 * m[1] + 60 * m[2] + 1 * m[3] : NaN; };
const tile = '#zone-list a[data-zone="office"]';

(async () => {
  const browser = await puppeteer.launch({
    executablePath: '/usr/bin/chromium', headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-first-run'],
  });
  try {
    const a = await (await browser.createBrowserContext()).newPage();
    await a.setViewport({ width: 390, height: 844 });
    a.on('pageerror', (e) => console.log('# page error: ' + e.message));
    await a.goto(url, { waitUntil: 'domcontentloaded' });
    await until(() => visible(a, '#login'), 5000);
    await a.type('#password', password);
    await a.click('#login-form button');
    ok(await until(() => a.$(tile), 5000), 'logged in, the list has zone office');
    // a mark a reload would lose
    await a.evaluate(() => { window.notReloaded = true; });

    // 1. the loopback room is simulated: the tile and the list say so
    const sim = await text(a, tile + ' .sim');
    ok(sim === 'simulated', 'the tile of the loopback room says it is simulated: "' + sim + '"');
    const note = (await visible(a, '#simulated')) ? await text(a, '#simulated') : '';
    ok(/office/.test(note) && /loopback/.test(note), 'the list names the zone and what simulates it: "' + note + '"');

    // 2. psensd stopped under the page: no level shown as if current
    const lv0 = await until(async () => { const t = await text(a, tile + ' .level'); return /^\d+ %$/.test(t) && t; }, 5000);
    ok(lv0, 'the tile shows the output while psensd runs: ' + lv0);
    const before = new Date();
    execFileSync('sh', [control, 'stop'], { stdio: 'inherit' });
    const after = new Date();
    const stale = await until(async () => (await text(a, tile + ' .level')) === 'unknown' &&
      (await a.$eval(tile, (e) => e.classList.contains('stale')).catch(() => false)), 10000);
    const lvStale = await text(a, tile + ' .level');
    ok(stale, 'psensd stopped: the tile says the level is unknown, not ' + lv0 + ': "' + lvStale + '"');
    const why = await text(a, tile + ' .stale-note');
    const t = hms(why);
    // its last answer came after the page opened and before psensd exited
    ok(t >= sod(before) - 60 && t <= sod(after) + 1, 'the tile gives the time of the last answer, ' +
       'at most when psensd stopped (' + after.toTimeString().slice(0, 8) + '): "' + why + '"');
    ok(/safe|stop/.test(why || ''), '... and says where psensd leaves the lights: "' + why + '"');
    // the zone's own page, opened while psensd is down, says the same
    await a.evaluate(() => { location.hash = '#zone=office'; });   // the tile is redrawn at each update
    await until(() => visible(a, '#zone'), 5000);
    const zl = await text(a, '#v-level');
    ok(zl === 'unknown', 'the zone opened while psensd is down: output "' + zl + '"');
    await a.evaluate(() => { location.hash = ''; });

    // 3. psensd started again: the page live again, by itself
    execFileSync('sh', [control, 'start'], { stdio: 'inherit' });
    const back = await until(async () => {
      const l = await text(a, tile + ' .level');
      return /^\d+ %$/.test(l || '') && !(await a.$eval(tile, (e) => e.classList.contains('stale'))) &&
        (await text(a, '#conn')) === 'live' && l;
    }, 15000);
    ok(back, 'psensd back: the tile shows the output again (' + back + '), the badge says ' + await text(a, '#conn'));
    ok(await a.evaluate(() => window.notReloaded === true), '... without a reload');

    // 3b. psensd alive but not answering (stopped by SIGSTOP): the stream
    // stays open and silent; the page notices the missing updates
    execFileSync('sh', [control, 'pause'], { stdio: 'inherit' });
    const hung = await until(async () => (await text(a, tile + ' .level')) === 'unknown', 30000);
    ok(hung, 'psensd silent with its connection open: the tile says "' + await text(a, tile + ' .level') + '"');
    execFileSync('sh', [control, 'resume'], { stdio: 'inherit' });
    const woke = await until(async () => { const l = await text(a, tile + ' .level'); return /^\d+ %$/.test(l || '') && l; }, 30000);
    ok(woke, 'psensd answering again: the tile shows ' + woke);

    // 4. an override typed in %: refused in %, never sent
    await a.evaluate(() => { location.hash = '#zone=office'; });   // the tile is redrawn at each update
    await until(() => visible(a, '#zone'), 5000);
    await a.$eval('#msg', (e) => { e.hidden = true; });
    await a.$eval('#ov-level', (e) => { e.value = '150'; });
    await a.click('#ov-go');
    const bad = await until(async () => (await visible(a, '#msg.error')) && (await text(a, '#msg')), 5000);
    ok(bad === '150 % is outside 0 to 100 %', 'an override of 150 % is refused in %: "' + bad + '"');

    // 5. the acceptance table: units and reasons, the module's own texts
    let reply = null;
    a.on('response', async (r) => {
      if (!/api\/request$/.test(r.url())) return;
      const o = await r.json().catch(() => null);
      if (o && o.accept) reply = o.accept;
    });
    await a.click('#accept-run');
    await until(async () => reply && (await visible(a, '#accept-box')), 20000);
    const head = await a.$$eval('#accept-table th', (c) => c.map((e) => e.textContent));
    const rows = await a.$$eval('#accept-table tr', (r) => r.slice(1).map((tr) =>
      Array.from(tr.children).map((c) => c.textContent)));
    ok(head.includes('reason'), 'the table has a reason column: ' + head.join(' | '));
    const col = (name) => head.indexOf(name);
    // each test's unit and the limit's sense (daemon/accept.h): rms and
    // light output in %, the task in % of the target, gaps and holds in s
    const want = {
      verification: ['%', 'at most 10 %'], 'full daylight': ['%', 'at most 35 %'],
      'low daylight': ['%', 'at least 90 %'], cycling: ['s', 'at least 300 s'],
    };
    ok(reply && rows.length === reply.tests.length && rows.length >= 4, 'a row for each test (' + rows.length + ')');
    for (const r of rows) {
      const name = r[col('test')], w = want[name], m = reply ? reply.tests.find((x) => x.test === name) : null;
      if (!w || !m) { ok(false, 'an expected test: ' + name); continue; }
      const v = r[col('value')], l = r[col('limit')];
      const vOk = m.value === null ? v === '–' : new RegExp('^-?[0-9.]+ ' + (w[0] === '%' ? '%' : 's') + '$').test(v);
      ok(vOk, name + ': its value in ' + w[0] + ': "' + v + '" (' + m.value + ')');
      ok(l === w[1], name + ': its limit "' + l + '" (want "' + w[1] + '")');
      ok(r[col('reason')] === m.measured && m.measured.length > 20, name + ': ' + r[col('verdict')] +
         ' because "' + r[col('reason')] + '"');
    }
  } catch (e) {
    ok(false, 'the browser run: ' + e.stack);
  } finally {
    await browser.close();
  }
  console.log('1..' + n);
  process.exit(failed ? 1 : 0);
})();
