// SPDX-License-Identifier: ISC
// psensd's on-site console: plain JavaScript, no framework.  Every action is
// a control request line (psensctl's) POSTed to /api/request and answered
// with the control socket's JSON; the live state is its status reply,
// streamed as server-sent events from /api/events.
'use strict';

const $ = (id) => document.getElementById(id);
const HOURS = 4;
let es = null;          // the live stream
let last = null;        // the last status reply
let pid = null;         // psensd's pid: a new one means it restarted
let zone = null;        // the zone shown, or null for the list
let hist = null;        // its chart: {t:[], level:[], est:[], meas:[]}
let retry = null;
let calRunning = false; // the zone shown had a session running at the last update
let calMsg = '';         // the running session's message at the last update
let lastGood = null;    // when the last status arrived (the browser's clock)
let stale = false;      // psensd has not answered since lastGood
let updateS = 1;        // [web] update: seconds between status events
let quiet = null;       // the timer that notices a stream gone silent

function show(which) {
  for (const id of ['login', 'zones', 'zone'])
    $(id).hidden = id !== which;
  $('logout').hidden = which === 'login';
}

let toastTimer = null;
function toast(text, isError) {
  const m = $('msg');
  m.textContent = text;
  m.className = 'toast' + (isError ? ' error' : '');
  m.hidden = false;
  clearTimeout(toastTimer);
  toastTimer = setTimeout(() => { m.hidden = true; }, isError ? 8000 : 4000);
}

function setConn(state, text) {
  const c = $('conn');
  c.className = 'badge ' + state;
  c.textContent = text;
}

async function post(path, fields) {
  const body = new URLSearchParams(fields).toString();
  return fetch(path, { method: 'POST', credentials: 'same-origin', body,
    headers: { 'Content-Type': 'application/x-www-form-urlencoded', 'X-PSD': '1' } });
}

// One control request: the reply's JSON, or null after saying why.
async function request(line) {
  let r;
  try {
    r = await post('api/request', { line });
  } catch (e) {
    toast('psensd does not answer: ' + e.message, true);
    markStale();
    return null;
  }
  const o = await r.json().catch(() => ({ ok: false, error: 'not a reply psensd sends' }));
  if (r.status === 401) {
    loggedOut(o.error);
    return null;
  }
  if (!o.ok) {
    toast(o.error || 'refused', true);
    return null;
  }
  return o;
}

function loggedOut(why) {
  if (es) { es.close(); es = null; }
  clearTimeout(retry);
  clearTimeout(quiet);
  setConn('off', 'logged out');
  $('login-msg').textContent = !why ? ''
    : /expired/.test(why) ? 'Your session has expired: log in again.'
    : /invalid/.test(why) ? 'Your session is no longer valid (logged out, or a new password): log in again.'
    : /not logged in/.test(why) ? 'Log in to go on.' : why;
  show('login');
  $('password').focus();
}

// ---- the live stream ------------------------------------------------------
// The stream broke, or went silent: the lights may no longer be at the
// level last shown (psensd drives them to its stop or safe level when it
// stops or fails, and the page cannot know which), so every figure shown
// is marked stale and the stream is opened again.
function lost() {
  if (es) { es.close(); es = null; }
  clearTimeout(quiet);
  setConn('reconnecting', 'reconnecting…');
  markStale();
  clearTimeout(retry);
  retry = setTimeout(recheck, 1500);
}

// A few updates missed (an open connection to a psensd that has stopped
// answering, or a network that dropped it without a word).
function expectUpdate() {
  const wait = (3 * updateS + 5) * 1000;
  clearTimeout(quiet);
  quiet = setTimeout(silent, wait, performance.now() + wait);
}

// The timer ran at least a second late: the page itself was asleep (a
// background tab, a phone's screen off, a starved CPU), and the updates
// that came meanwhile are still queued: they go first, one more second.
function silent(due) {
  if (performance.now() - due > 1000) {
    quiet = setTimeout(silent, 1000, performance.now() + 1000);
    return;
  }
  lost();
}

function connect() {
  if (es) es.close();
  es = new EventSource('api/events');
  es.addEventListener('stream', (e) => {
    let o;
    try { o = JSON.parse(e.data); } catch (err) { return; }
    if (Number.isFinite(o.update_s) && o.update_s > 0) updateS = o.update_s;
  });
  es.addEventListener('status', (e) => {
    let o;
    try { o = JSON.parse(e.data); } catch (err) { return; }
    setConn('live', 'live');
    expectUpdate();
    lastGood = new Date();
    stale = false;
    update(o);
  });
  // closed or broken: psensd stopped or restarting, the network, or the session gone
  es.onerror = lost;
}

function markStale() {
  if (stale || !last) return;
  stale = true;
  update(last);
}

// "HH:MM:SS" of the browser's clock
const hms = (d) => [d.getHours(), d.getMinutes(), d.getSeconds()].map((v) => String(v).padStart(2, '0')).join(':');

// What a stale figure says instead of the level.
function staleNote() {
  return 'psensd has not answered since ' + (lastGood ? hms(lastGood) : 'the page opened') +
    ': the level is unknown (psensd drives the lights to its stop or safe level when it stops or fails)';
}

async function recheck() {
  let r;
  try {
    r = await fetch('api/session', { credentials: 'same-origin' });
  } catch (e) {
    setConn('reconnecting', 'reconnecting…');
    markStale();
    retry = setTimeout(recheck, 1500);
    return;
  }
  if (r.status === 401) {
    const o = await r.json().catch(() => ({}));
    loggedOut(o.error);
    return;
  }
  connect();
}

function fmt(v, digits, unit) {
  if (v === null || v === undefined || Number.isNaN(v)) return '–';
  return v.toFixed(digits) + (unit ? ' ' + unit : '');
}
const pct = (v) => fmt(v === null || v === undefined ? v : 100 * v, 0, '%');

function update(o) {
  if (pid !== null && o.pid !== pid) {
    toast('psensd restarted (pid ' + o.pid + '): the console goes on');
    if (zone) loadHistory(zone);   // its chart starts again with it
  }
  pid = o.pid;
  last = o;
  $('clock').textContent = o.time + (o.clock === 'simulated' ? ' (simulated)' : '') + (stale ? ', at the last answer' : '');
  simulatedNote(o.zones);
  if (zone) {
    const z = o.zones.find((x) => x.name === zone);
    if (z) renderZone(z); else { toast('no zone ' + zone, true); go(null); }
  } else {
    renderList(o.zones);
  }
}

// The zones whose devices are simulated (the status's simulated: what
// simulates them, as the commissioning record names it).
function simulatedNote(zones) {
  const sim = zones.filter((z) => z.simulated);
  const p = $('simulated');
  p.hidden = sim.length === 0;
  p.textContent = sim.length === 0 ? '' : 'Simulated, not a building: ' +
    sim.map((z) => z.name + ' (' + z.simulated + ')').join(', ') + '.';
}

function renderList(zones) {
  const ul = $('zone-list');
  ul.replaceChildren(...zones.map((z) => {
    const li = document.createElement('li');
    const a = document.createElement('a');
    a.href = '#zone=' + encodeURIComponent(z.name);
    a.dataset.zone = z.name;
    if (stale) a.classList.add('stale');
    const s = stale ? {} : z.sample || {};
    const state = stale ? '<span class="badge off">stale</span>'
      : z.fault ? '<span class="badge bad">fault</span>'
      : z.override ? '<span class="badge">override</span>'
      : z.calibration ? '<span class="badge">calibrating</span>' : '';
    const sim = z.simulated ? '<span class="badge sim">simulated</span>' : '';
    a.innerHTML = '<div class="name"><span></span>' + sim + state + '</div>' +
      '<div class="nums"><span><span class="big level">' + (stale ? 'unknown' : pct(z.level)) + '</span><br><span class="muted">output</span></span>' +
      '<span><span class="big">' + fmt(s.est_task_lux, 0) + '</span><br><span class="muted">estimate lx</span></span>' +
      '<span><span class="big">' + fmt(s.task_lux, 0) + '</span><br><span class="muted">measured lx</span></span></div>' +
      (stale ? '<div class="stale-note muted"></div>' : '');
    a.querySelector('.name span').textContent = z.name;
    if (stale) a.querySelector('.stale-note').textContent = staleNote();
    li.append(a);
    return li;
  }));
}

function value(label, text, id) {
  const d = document.createElement('div');
  const dt = document.createElement('dt');
  const dd = document.createElement('dd');
  dt.textContent = label;
  dd.textContent = text;
  if (id) dd.id = id;
  d.append(dt, dd);
  return d;
}

function renderZone(z) {
  const s = stale ? {} : z.sample || {};
  $('z-name').textContent = z.name;
  $('z-stale').hidden = !stale;
  $('z-stale').textContent = stale ? staleNote() : '';
  $('z-sim').hidden = !z.simulated;
  $('z-sim').textContent = z.simulated ? 'Simulated: this zone\'s devices are ' + z.simulated + '\'s, not a building\'s.' : '';
  $('z-fault').hidden = stale || !z.fault;
  $('z-fault').textContent = z.fault ? 'Fault: ' + z.fault + ' (at the safe level ' + pct(z.safe_level) + ')' : '';
  if (stale) {   // nothing below is known now
    $('z-values').replaceChildren(value('output', 'unknown', 'v-level'), value('estimate', '–', 'v-est'),
      value('measured', '–', 'v-meas'));
    return;
  }
  const v = [
    value('output', pct(z.level), 'v-level'),
    value('target', fmt(z.target_lux, 0, 'lx')),
    value('sensor', fmt(s.sensor_v, 3, 'V') + ' (' + z.sensor + ')'),
    value('estimate', fmt(s.est_task_lux, 0, 'lx'), 'v-est'),
    value('measured', fmt(s.task_lux, 0, 'lx'), 'v-meas'),
    value('drift', z.drift === undefined ? '–' : (z.drift ? 'FLAGGED ' : '') + fmt(z.drift_pct, 1, '%')),
    value('faults', z.fault ? 'now' : z.fault_steps + ' of ' + z.steps + ' steps'),
    value('override', z.override ? pct(z.override.level) + ', ' + Math.ceil(z.override.remaining_s / 60) + ' min left' : 'none', 'v-override'),
  ];
  if (z.occupied !== undefined) v.push(value('occupancy', z.occupied ? 'occupied' : 'vacant'));
  $('z-values').replaceChildren(...v);
  guide(z);
  if (z.calibration) {
    $('cal-box').hidden = false;
    $('cal-title').textContent = z.calibration.kind + ' session';
    $('cal-state').textContent = 'running';
    $('cal-state').className = 'badge';
    if (z.calibration.message) $('cal-msg').textContent = z.calibration.message;
    calSteps(z.calibration.kind, 'running');
    calRunning = true;
    // a new message says a level settled or a sample was taken (a typed
    // one waits for the sensor's next reading): the table from the session
    if (z.calibration.message !== calMsg) {
      calMsg = z.calibration.message;
      request('calibrate ' + z.name + ' status').then((o) => { if (o) renderCal(o.calibration); });
    }
  } else if (calRunning) {   // it ended: its outcome, from the session itself
    calRunning = false;
    request('calibrate ' + z.name + ' status').then((o) => { if (o) renderCal(o.calibration); });
  }
  if (hist && Number.isFinite(s.t) && (hist.t.length === 0 || s.t > hist.t[hist.t.length - 1])) {
    hist.t.push(s.t); hist.tod.push(s.t % 86400); hist.level.push(s.level);
    hist.est.push(s.est_task_lux); hist.meas.push(s.task_lux);
    drawChart();
  }
}

// The simulation's guidance for a session: night or day at the sensor,
// what the model expects at the task now.
function guide(z) {
  const s = z.sample || {};
  const parts = [];
  if (Number.isFinite(s.daylight_v)) {
    if (s.daylight_v < 0.01) parts.push('Night at the sensor (daylight ' + fmt(s.daylight_v, 3, 'V') + '): a night session can run.');
    else parts.push('Daylight at the sensor: ' + fmt(s.daylight_v, 3, 'V') + ' (a night session needs darkness; a day session takes readings now).');
  }
  if (Number.isFinite(s.est_task_lux)) parts.push('The model expects ' + fmt(s.est_task_lux, 0, 'lx') + ' at the task now.');
  $('cal-guide').textContent = parts.join(' ');
}

// ---- the chart --------------------------------------------------------------
async function loadHistory(name) {
  hist = { t: [], tod: [], level: [], est: [], meas: [] };
  let r;
  try { r = await fetch('api/history?zone=' + encodeURIComponent(name), { credentials: 'same-origin' }); }
  catch (e) { return; }
  if (!r.ok) return;
  const o = await r.json();
  hist = { t: o.t, tod: o.tod_s, level: o.level, est: o.est_task_lux, meas: o.task_lux };
  drawChart();
}

function hhmm(tod) {
  const m = Math.floor(((tod % 86400) + 86400) % 86400 / 60);
  return String(Math.floor(m / 60)).padStart(2, '0') + ':' + String(m % 60).padStart(2, '0');
}

function drawChart() {
  const svg = $('chart');
  const W = Math.max(svg.clientWidth, 200), H = Math.max(svg.clientHeight, 120);
  const L = 44, R = 40, T = 8, B = 22;
  svg.setAttribute('viewBox', '0 0 ' + W + ' ' + H);
  const ns = 'http://www.w3.org/2000/svg';
  const el = (tag, attrs, text) => {
    const e = document.createElementNS(ns, tag);
    for (const k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  };
  const kids = [];
  const n = hist.t.length;
  if (n < 2) {
    kids.push(el('text', { x: L, y: H / 2 }, 'the chart fills as samples come in'));
    svg.replaceChildren(...kids);
    return;
  }
  const t1 = hist.t[n - 1], t0 = Math.max(hist.t[0], t1 - HOURS * 3600);
  let lmax = 100;
  for (let i = 0; i < n; i++) {
    if (hist.t[i] < t0) continue;
    for (const v of [hist.est[i], hist.meas[i]]) if (Number.isFinite(v) && v > lmax) lmax = v;
  }
  lmax = Math.ceil(lmax / 250) * 250;
  const x = (t) => L + (W - L - R) * (t - t0) / Math.max(t1 - t0, 1);
  const yl = (v) => T + (H - T - B) * (1 - v / lmax);
  const yp = (v) => T + (H - T - B) * (1 - v);
  for (let k = 0; k <= 4; k++) {
    const y = T + (H - T - B) * k / 4;
    kids.push(el('line', { x1: L, x2: W - R, y1: y, y2: y, class: 'grid' }));
    kids.push(el('text', { x: L - 4, y: y + 4, 'text-anchor': 'end' }, String(Math.round(lmax * (1 - k / 4)))));
    kids.push(el('text', { x: W - R + 4, y: y + 4 }, Math.round(100 * (1 - k / 4)) + '%'));
  }
  const step = (t1 - t0) > 7200 ? 3600 : (t1 - t0) > 1800 ? 900 : 300;
  const off = hist.t[n - 1] - hist.tod[n - 1];   // clock t of the day's midnight
  for (let m = Math.ceil((t0 - off) / step) * step; m + off <= t1; m += step)
    kids.push(el('text', { x: x(m + off), y: H - 6, 'text-anchor': 'middle' }, hhmm(m)));
  const line = (arr, y, cls) => {
    let pts = '';
    const out = [];
    for (let i = 0; i < n; i++) {
      if (hist.t[i] < t0) continue;
      if (Number.isFinite(arr[i])) pts += x(hist.t[i]).toFixed(1) + ',' + y(arr[i]).toFixed(1) + ' ';
      else if (pts) { out.push(el('polyline', { points: pts, class: cls })); pts = ''; }
    }
    if (pts) out.push(el('polyline', { points: pts, class: cls }));
    return out;
  };
  // the estimate wide and pale under the measured line: both show where they agree
  kids.push(...line(hist.level, yp, 'l-level'), ...line(hist.est, yl, 'l-est'), ...line(hist.meas, yl, 'l-meas'));
  svg.replaceChildren(...kids);
  $('chart-span').textContent = hhmm(hist.tod[0] + (t0 - hist.t[0])) + '–' + hhmm(hist.tod[n - 1]);
}

// ---- calibration and acceptance ------------------------------------------
function table(t, head, rows) {
  const tr = (cells, tag) => {
    const r = document.createElement('tr');
    for (const c of cells) {
      const e = document.createElement(tag);
      e.textContent = c;
      if (typeof c === 'string' && /^[-0-9.]/.test(c)) e.className = 'num';
      r.append(e);
    }
    return r;
  };
  t.replaceChildren(tr(head, 'th'), ...rows.map((r) => tr(r, 'td')));
}

// The steps a session in this kind and state takes: readings typed in and
// finish while a day session runs, abort while any runs, accept when done.
function calSteps(kind, state) {
  $('lux-form').hidden = !(kind === 'day' && state === 'running');
  $('cal-finish').hidden = !(kind === 'day' && state === 'running');
  $('cal-abort').hidden = state !== 'running';
  $('cal-accept').hidden = state !== 'done';
}

function renderCal(c) {
  calSteps(c.kind, c.state);
  $('cal-box').hidden = false;
  $('cal-title').textContent = c.kind + ' session' + (c.session ? ' ' + c.session : '');
  const st = $('cal-state');
  st.textContent = c.state;
  st.className = 'badge' + (c.state === 'done' || c.state === 'accepted' ? ' good' : c.state === 'aborted' ? ' bad' : '');
  $('cal-msg').textContent = c.message || '';
  if (c.kind === 'night')
    table($('cal-table'), ['output', 'sensor V', 'lux'], (c.levels || []).map((p) =>
      [pct(p.level), fmt(p.volts, 4), fmt(p.lux, 1)]));
  else
    table($('cal-table'), ['time', 'output', 'sensor V', 'lux'], (c.samples || []).map((p) =>
      [hhmm(p.tod_s), pct(p.level), fmt(p.volts, 4), fmt(p.lux, 1)]));
  let fit = '';
  if (c.gain !== undefined)
    fit = 'gain ' + fmt(c.gain, 4, 'V') + ' ± ' + fmt(c.gain_se, 4) + ', offset ' + fmt(c.offset, 4, 'V') +
      ', R² ' + fmt(c.r2, 5) + ', ' + fmt(c.lux_gain, 1, 'lx') + ' at full output';
  if (c.ratio !== undefined)
    fit = 'measured ' + fmt(c.ratio, 1, 'lx/V') + ' ± ' + fmt(c.ratio_se, 1) + ', the model ' +
      fmt(c.sim_ratio, 1, 'lx/V') + (c.condition ? ' (' + c.condition + ')' : '') + ': ' + fmt(c.error_pct, 1, '%');
  $('cal-fit').textContent = fit;
}

async function cal(words) {
  const o = await request('calibrate ' + zone + ' ' + words);
  if (o) renderCal(o.calibration);
  return o;
}

async function runAccept() {
  $('accept-run').disabled = true;
  const o = await request('accept-test ' + zone);
  $('accept-run').disabled = false;
  if (!o) return;
  const a = o.accept;
  $('accept-box').hidden = false;
  const v = $('accept-verdict');
  v.textContent = a.verdict;
  v.className = 'badge ' + (a.failed ? 'bad' : 'good');
  $('accept-count').textContent = a.tested + ' run, ' + a.failed + ' failed';
  // each figure in its test's unit, the limit as the test judges it, and
  // the acceptance module's own words for what it measured
  table($('accept-table'), ['test', 'verdict', 'value', 'limit', 'samples', 'reason'], a.tests.map((t) =>
    [t.test, t.verdict, fmt(t.value, t.unit === 's' ? 0 : 2, t.unit), t.bound + ' ' + num(t.limit) + ' ' + t.unit,
     String(t.samples), t.measured || '']));
}

// a limit as the configuration states it: 10, 0.5, 300
const num = (v) => (Number.isFinite(v) ? String(Number(v.toPrecision(6))) : '–');

// ---- navigation ---------------------------------------------------------------
function go(name) {
  zone = name;
  if (name) {
    show('zone');
    $('cal-box').hidden = true;
    $('accept-box').hidden = true;
    $('year').hidden = true;
    calRunning = false;
    calMsg = '';
    $('record-zone').href = 'api/record.pdf?zone=' + encodeURIComponent(name);
    $('record-zone').setAttribute('download', 'psensd-record-' + name + '.pdf');
    hist = null;
    loadHistory(name);
    request('calibrate ' + name + ' status').then((o) => {
      if (o && o.calibration && o.calibration.state !== 'idle') renderCal(o.calibration);
    });
  } else {
    show('zones');
  }
  if (last) update(last);
}

function route() {
  const m = /^#zone=(.+)$/.exec(location.hash);
  go(m ? decodeURIComponent(m[1]) : null);
}

async function start() {
  let r;
  try { r = await fetch('api/session', { credentials: 'same-origin' }); }
  catch (e) { setConn('reconnecting', 'reconnecting…'); retry = setTimeout(start, 1500); return; }
  if (r.status === 401) { loggedOut(''); return; }
  route();
  connect();
}

$('login-form').addEventListener('submit', async (e) => {
  e.preventDefault();
  $('login-msg').textContent = '';
  let r;
  try { r = await post('api/login', { password: $('password').value }); }
  catch (err) { $('login-msg').textContent = 'psensd does not answer: ' + err.message; return; }
  const o = await r.json().catch(() => ({}));
  if (!r.ok) {
    $('login-msg').textContent = o.error === 'wrong password' ? 'Wrong password.' : (o.error || 'refused');
    return;
  }
  $('password').value = '';
  start();
});
$('logout').addEventListener('click', async () => {
  await post('api/logout', {}).catch(() => null);
  loggedOut('');
});
$('override-form').addEventListener('submit', async (e) => {
  e.preventDefault();
  // the level is typed in %: a refusal says so in %, not in psensd's 0 to 1
  const typed = $('ov-level').value.trim(), p = Number(typed);
  if (!(p >= 0 && p <= 100)) {
    toast(typed + ' % is outside 0 to 100 %', true);
    return;
  }
  const lv = p / 100, s = Number($('ov-min').value) * 60;
  if (await request('override ' + zone + ' ' + lv + ' ' + s)) toast('override: ' + pct(lv) + ' for ' + s / 60 + ' min');
});
$('ov-release').addEventListener('click', async () => {
  if (await request('release ' + zone)) toast('released: back under control');
});
$('cal-night').addEventListener('click', () => cal('night'));
$('cal-day').addEventListener('click', () => cal('day'));
$('lux-form').addEventListener('submit', async (e) => {
  e.preventDefault();
  if (await cal('lux ' + Number($('lux').value))) $('lux').value = '';
});
$('cal-finish').addEventListener('click', () => cal('finish'));
$('cal-accept').addEventListener('click', () => cal('accept'));
$('cal-abort').addEventListener('click', () => cal('abort'));
$('accept-run').addEventListener('click', runAccept);
$('year-show').addEventListener('click', () => {
  const img = $('year');
  img.onerror = async () => {
    img.hidden = true;
    const r = await fetch(img.src).catch(() => null);
    const o = r ? await r.json().catch(() => ({})) : {};
    toast(o.error || 'the year cannot be drawn', true);
  };
  img.onload = () => { img.hidden = false; };
  img.src = 'api/year.png?zone=' + encodeURIComponent(zone) + '&t=' + Date.now();
});
window.addEventListener('hashchange', route);
window.addEventListener('resize', () => { if (hist) drawChart(); });
start();
