// SPDX-License-Identifier: ISC
// The web console in a real browser: Debian's chromium, headless, driven
// over the DevTools protocol by puppeteer-core (which downloads no
// browser).  Used by tests/system/650-web.sh, which starts psensd and
// gives this script a way to restart it.  Prints TAP lines.
//
// usage: node web-peer.js URL PASSWORD RESTART ARTEFACTS
//   RESTART: a command run as `sh RESTART HH:MM CONF` that restarts psensd
//   at HH:MM with configuration CONF and returns once it answers
'use strict';
const { execFileSync } = require('child_process');
const path = require('path');
const puppeteer = require('puppeteer-core');

const [url, password, restart, artefacts] = process.argv.slice(2);
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
// wait until fn() is truthy (polled), up to ms; its last value
async function until(fn, ms) {
  const end = Date.now() + ms;
  let v;
  while (!(v = await fn()) && Date.now() < end)
    await sleep(100);
  return v;
}

async function login(page, pw) {
  await page.$eval('#password', (e) => { e.value = ''; });
  await page.type('#password', pw);
  await page.click('#login-form button');
}

async function shot(page, name) {
  await page.screenshot({ path: path.join(artefacts, name + '.png'), fullPage: true });
}

(async () => {
  const browser = await puppeteer.launch({
    executablePath: '/usr/bin/chromium', headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-first-run'],
  });
  try {
    const a = await (await browser.createBrowserContext()).newPage();
    await a.setViewport({ width: 390, height: 844 });
    a.on('pageerror', (e) => console.log('# page error: ' + e.message));

    // 1. a wrong password, then the right one
    await a.goto(url, { waitUntil: 'domcontentloaded' });
    ok(await until(() => visible(a, '#login'), 5000), 'the console opens at its login');
    await login(a, password + 'x');
    const wrong = await until(async () => (await text(a, '#login-msg')) || '', 5000);
    ok(wrong === 'Wrong password.', 'a wrong password is refused: "' + wrong + '"');
    ok(!(await visible(a, '#zones')), '... and shows no zone');
    await login(a, password);
    const tLogin = Date.now();
    ok(await until(() => visible(a, '#zones'), 5000), 'the right password opens the zone list');
    ok(await until(() => a.$('a[data-zone="office"]'), 5000), 'the list has zone office');
    await shot(a, 'phone-zones');

    // 2. the zone live: the sun rises over the loopback room
    // clicked in the page: the list is redrawn at each update, a handle held across one is detached
    await a.$eval('a[data-zone="office"]', (e) => e.click());
    ok(await until(() => visible(a, '#zone'), 5000), 'a zone opens its view');
    await until(async () => /lx/.test((await text(a, '#v-est')) || ''), 5000);
    const est0 = await text(a, '#v-est'), lv0 = await text(a, '#v-level');
    const changed = await until(async () => {
      const e = await text(a, '#v-est'), l = await text(a, '#v-level');
      return e !== est0 && l !== lv0 ? [e, l] : null;
    }, 8000);
    ok(changed, 'the estimate and the output change live as the sun rises: ' + est0 + ', ' + lv0 + ' -> ' +
       (changed ? changed.join(', ') : 'unchanged'));
    ok(await conn(a) === 'live', 'the connection badge says live');
    const pts = await a.$$eval('#chart polyline', (p) => p.length);
    ok(pts >= 2, 'the chart draws its lines (' + pts + ' polylines)');
    await shot(a, 'phone-zone');

    // 3. the login lasts [web] session (10 s here): then the live page
    // goes back to the login, saying so
    const left = 10000 - (Date.now() - tLogin);
    const expired = await until(() => visible(a, '#login'), left + 6000);
    const why = await text(a, '#login-msg');
    ok(expired && /expired/.test(why), 'an expired session returns to the login: "' + why + '" after ' +
       Math.round((Date.now() - tLogin) / 1000) + ' s');

    // 4. psensd restarted with a longer session, at night; log in again
    execFileSync('sh', [restart, '04:00', 'long.conf'], { stdio: 'inherit' });
    await login(a, password);
    ok(await until(() => visible(a, '#zone'), 5000), 'after logging in again the page is back on its zone');

    // a second agent at the same zone
    const b = await (await browser.createBrowserContext()).newPage();
    await b.setViewport({ width: 1280, height: 800 });
    await b.goto(url + '#zone=office', { waitUntil: 'domcontentloaded' });
    await until(() => visible(b, '#login'), 5000);
    await login(b, password);
    ok(await until(() => visible(b, '#zone'), 5000), 'a second agent logs in at the same zone (a link to it)');

    // 5. override and release
    await a.$eval('#ov-level', (e) => { e.value = '50'; });
    await a.$eval('#ov-min', (e) => { e.value = '600'; });   // 100 minutes of the sped-up clock
    await a.click('#ov-go');
    const ov = await until(async () => /^50 %/.test((await text(a, '#v-override')) || '') &&
      (await text(a, '#v-level')) === '50 %', 5000);
    ok(ov, 'override 50 % for 600 min: ' + await text(a, '#v-override') + ', output ' + await text(a, '#v-level'));
    ok(await until(async () => /^50 %/.test((await text(b, '#v-override')) || ''), 5000),
       'the second agent sees the override live');
    await a.click('#ov-release');
    ok(await until(async () => (await text(a, '#v-override')) === 'none', 5000), 'release ends it');
    await a.$eval('#msg', (e) => { e.hidden = true; });
    await a.$eval('#ov-level', (e) => { e.value = '150'; });
    await a.click('#ov-go');
    const bad = await until(async () => (await visible(a, '#msg.error')) && (await text(a, '#msg')), 5000);
    ok(bad === '150 % is outside 0 to 100 %', 'an override of 150 % is refused in the % typed: "' + bad + '"');

    // 6. a night session; the second agent cannot start another
    await a.click('#cal-night');
    ok(await until(async () => (await text(a, '#cal-state')) === 'running', 5000), 'a night session starts');
    await b.click('#cal-night');
    const twice = await until(async () => (await visible(b, '#msg.error')) && (await text(b, '#msg')), 5000);
    ok(/session is running/.test(twice || ''), 'the second agent\'s session at the same zone is refused: "' + twice + '"');
    const night = await until(async () => (await text(a, '#cal-state')) === 'done', 20000);
    ok(night, 'the night session finishes');
    await a.click('#cal-accept');
    ok(await until(async () => (await text(a, '#cal-state')) === 'accepted', 5000),
       'and is accepted: ' + await text(a, '#cal-fit'));
    await shot(a, 'phone-night');

    // 7. psensd restarted under the page: reconnecting, then live again
    const t0 = Date.now();
    const seen = [];
    const watch = setInterval(async () => { const c = await conn(a); if (seen[seen.length - 1] !== c) seen.push(c); }, 50);
    execFileSync('sh', [restart, '08:30', 'long.conf'], { stdio: 'inherit' });
    const back = await until(async () => seen.includes('reconnecting…') && (await conn(a)) === 'live', 15000);
    clearInterval(watch);
    ok(back, 'a restart shows ' + seen.join(' -> ') + ' and recovers in ' + ((Date.now() - t0) / 1000).toFixed(1) + ' s');

    // 8. a day session, the lux meter's readings typed in
    ok(/Daylight at the sensor/.test((await text(a, '#cal-guide')) || ''), 'the guidance says it is day: ' +
       await text(a, '#cal-guide'));
    await a.click('#cal-day');
    ok(await until(async () => (await text(a, '#cal-state')) === 'running', 5000), 'a day session starts');
    const typed = [];
    for (let i = 0; i < 3; i++) {
      const m = String(Math.round(parseFloat(await text(a, '#v-meas'))) + i);
      typed.push(m);
      await a.$eval('#lux', (e, v) => { e.value = v; }, m);
      await a.click('#lux-form button');
      await until(async () => (await a.$$eval('#cal-table tr td:last-child', (c) => c.map((e) => e.textContent)))
        .includes(m + '.0'), 3000);
    }
    const luxes = await a.$$eval('#cal-table tr td:last-child', (c) => c.map((e) => e.textContent));
    ok(typed.every((m) => luxes.includes(m + '.0')), 'the typed readings ' + typed.join(', ') +
       ' lx join its table (lux: ' + luxes.join(', ') + ')');
    await a.click('#cal-finish');
    ok(await until(async () => (await text(a, '#cal-state')) === 'done', 5000), 'finished: ' + await text(a, '#cal-msg'));
    await a.click('#cal-accept');
    ok(await until(async () => (await text(a, '#cal-state')) === 'accepted', 5000), 'and accepted: ' +
       await text(a, '#cal-fit'));

    // 9. the acceptance tests, run and shown with their numbers
    await a.click('#accept-run');
    const verdict = await until(async () => (await visible(a, '#accept-box')) && text(a, '#accept-verdict'), 15000);
    const rows = await a.$$eval('#accept-table tr', (r) => r.length);
    ok(verdict && rows >= 2, 'acceptance: ' + verdict + ', ' + await text(a, '#accept-count') + ', ' + (rows - 1) + ' tests');
    await shot(a, 'phone-accept');
    await b.bringToFront();
    await until(async () => (await a.$$eval('#chart polyline', (p) => p.length)) >= 2, 3000);
    await shot(b, 'desktop-zone');
    await b.goto(url + '#', { waitUntil: 'domcontentloaded' });
    await until(() => b.$('a[data-zone="office"]'), 5000);
    await shot(b, 'desktop-zones');

    // 10. the record, as psensctl report draws it
    const href = await a.$eval('#record-zone', (e) => e.getAttribute('href'));
    const pdf = await a.evaluate(async (h) => {
      const r = await fetch(h);
      const b = new Uint8Array(await r.arrayBuffer());
      return { type: r.headers.get('Content-Type'), disp: r.headers.get('Content-Disposition'),
               head: String.fromCharCode(...b.slice(0, 5)), len: b.length };
    }, href);
    ok(href === 'api/record.pdf?zone=office' && pdf.type === 'application/pdf' && pdf.head === '%PDF-',
       'the zone\'s record downloads as a PDF: ' + href + ', ' + pdf.type + ', ' + pdf.len + ' bytes, "' + pdf.head + '", ' + pdf.disp);
    require('fs').writeFileSync(path.join(artefacts, 'record-office.pdf'), Buffer.from(await a.evaluate(async (h) =>
      Array.from(new Uint8Array(await (await fetch(h)).arrayBuffer())), href)));

    // 11. the year, as psensd -Y -P draws it
    await a.click('#year-show');
    const yr = await until(() => a.$eval('#year', (e) => !e.hidden && e.complete && e.naturalWidth > 0 &&
      [e.naturalWidth, e.naturalHeight]).catch(() => null), 10000);
    ok(yr && yr[0] >= 730, 'the zone\'s year is drawn: ' + (yr ? yr.join(' x ') + ' px' : 'no picture'));
    await a.$eval('#year', (e) => e.scrollIntoView());
    await a.screenshot({ path: path.join(artefacts, 'phone-year.png') });

    // 12. logging out
    await a.click('#logout');
    ok(await until(() => visible(a, '#login'), 5000), 'log out returns to the login');
  } catch (e) {
    ok(false, 'the browser run: ' + e.stack);
  } finally {
    await browser.close();
  }
  console.log('1..' + n);
  process.exit(failed ? 1 : 0);
})();

function conn(page) {
  return text(page, '#conn');
}
