// SPDX-License-Identifier: ISC
// An outside BACnet/IP client (@bacnet-js/client, pinned in package.json)
// against psensd's writable Values (doc/bacnet-pics.md): the zone's target
// lux (Analog Value) and its daylight control (Binary Value), commandable
// with a priority array.  Prints TAP lines ("ok N - ..." / "not ok N - ...").
// usage: node bacnet-values-peer.js SERVER_PORT DEVICE_INSTANCE MODE E_LUX
//   MODE 1: writes = lighting-output target daylighting.  Priority_Array and
//     Relinquish_Default read back; writes at priorities 12 and 8, each
//     relinquished (Present_Value follows the highest); writes outside
//     target_min 50 .. target_max 1500 (the test's [bacnet]) and other out-of-range writes
//     refused; a write to an Analog Input denied; with daylight control off,
//     the Lighting Output's level is target / E_LUX (the electric task lux at
//     full output) and follows a new target.
//   MODE 0: writes = lighting-output: the target and daylight control are
//     write-access-denied, their Priority_Array stays NULL.
//   MODE 2: MODE 1's writes, the zone in a sensor fault at its safe level of
//     100 %: the writes are taken, the light stays at 100 %.
//   MODE 3: MODE 1's writes: 321 lx at priority 16, left in force.
//   MODE 4: writes = vacancy-hold, a zone with an occupancy input: its
//     vacancy hold (Analog Value 2) read and written, 120 s at priority 8.
'use strict';
const { ObjectType, PropertyIdentifier: P } = require('@bacnet-js/client');

const [port, device, mode, elux] = process.argv.slice(2).map(Number);
const server = { address: `127.0.0.1:${port}` };
const client = require('./bacnet-client.js')();
let n = 0, failed = 0;
const ok = (cond, what) => { n++; if (!cond) failed++; console.log(`${cond ? 'ok' : 'not ok'} ${n} - ${what}`); };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const real = (v) => [{ type: 4 /* REAL */, value: v }];
const enumv = (v) => [{ type: 9 /* ENUMERATED */, value: v }];
const nul = [{ type: 0, value: null }];
async function errorOf(p) {
	try { await p; return 'none'; } catch (e) { return String(e.message || e); }
}
const OUT_OF_RANGE = /PROPERTY.*VALUE_OUT_OF_RANGE|Class:2.*Code:37/i;
const DENIED = /PROPERTY.*WRITE_ACCESS_DENIED|Class:2.*Code:40/i;

const read = async (o, prop, idx) =>
	(await client.readProperty(server, o, prop, idx === undefined ? undefined : { arrayIndex: idx })).values;
const pv = async (o) => (await read(o, P.PRESENT_VALUE))[0].value;
// poll o's Present_Value until want(v) (4 s at most): the last value seen
async function until(o, want) {
	let v;
	for (let i = 0; i < 40; i++) {
		v = await pv(o);
		if (want(v)) break;
		await sleep(100);
	}
	return v;
}
const near = (a, b, eps) => Math.abs(a - b) <= eps;

async function main() {
	await new Promise((r) => client.on('listening', r));
	const dev = { type: ObjectType.DEVICE, instance: device };
	const objs = (await read(dev, P.OBJECT_LIST)).map((v) => v.value);
	const named = {};
	for (const o of objs)
		if (o.type !== ObjectType.DEVICE) named[(await read(o, P.OBJECT_NAME))[0].value] = o;
	const target = named['office target lux'], day = named['office daylight control'];
	const lo = named['office light level'], signal = named['office sensor signal'];
	ok(target && target.type === ObjectType.ANALOG_VALUE && day && day.type === ObjectType.BINARY_VALUE && lo,
		`'office target lux' an Analog Value, 'office daylight control' a Binary Value (${JSON.stringify([target, day])})`);
	if (!target || !day || !lo) return;
	const rd = (await read(target, P.RELINQUISH_DEFAULT))[0].value;
	const pa = await read(target, P.PRIORITY_ARRAY);
	ok(rd === 500 && pa.length === 16 && pa.every((v) => v.type === 0),
		`target: Relinquish_Default ${rd} (the configured 500), Priority_Array 16 NULLs (${pa.length})`);
	const units = (await read(target, P.UNITS))[0].value;
	const min = (await read(target, P.MIN_PRES_VALUE))[0].value;
	const max = (await read(target, P.MAX_PRES_VALUE))[0].value;
	ok(units === 37 && min === 50 && max === 1500,
		`target: Units luxes (${units}), Min_Pres_Value ${min}, Max_Pres_Value ${max} ([bacnet] target_min, target_max)`);
	const drd = (await read(day, P.RELINQUISH_DEFAULT))[0].value;
	ok(drd === 1 && (await pv(day)) === 1, `daylight control: Relinquish_Default active (${drd}), Present_Value active`);

	if (mode === 0) {
		const w1 = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, real(300), { priority: 8 }));
		ok(DENIED.test(w1), `target not opened by [bacnet] writes: ${w1}`);
		const w2 = await errorOf(client.writeProperty(server, day, P.PRESENT_VALUE, enumv(0), { priority: 8 }));
		ok(DENIED.test(w2), `daylight control not opened: ${w2}`);
		const p8 = (await read(target, P.PRIORITY_ARRAY, 8))[0];
		ok(p8.type === 0 && (await pv(target)) === 500, `nothing written: Priority_Array[8] NULL, Present_Value 500`);
		return;
	}

	if (mode === 4) { // the vacancy hold of a zone with an occupancy input
		const hold = named['office vacancy hold'];
		ok(hold && hold.type === ObjectType.ANALOG_VALUE && hold.instance === 2,
			`'office vacancy hold' is Analog Value 2 (${JSON.stringify(hold)})`);
		if (!hold) return;
		const hrd = (await read(hold, P.RELINQUISH_DEFAULT))[0].value;
		const hu = (await read(hold, P.UNITS))[0].value;
		ok(hrd === 900 && hu === 73, `vacancy hold: Relinquish_Default ${hrd} (the configured 900), Units seconds (${hu})`);
		const big = await errorOf(client.writeProperty(server, hold, P.PRESENT_VALUE, real(90000), { priority: 8 }));
		ok(OUT_OF_RANGE.test(big), `90000 s (past a day) refused: ${big}`);
		const w = await errorOf(client.writeProperty(server, hold, P.PRESENT_VALUE, real(120), { priority: 8 }));
		ok(w === 'none' && (await until(hold, (v) => v === 120)) === 120, `120 s at priority 8: Present_Value 120 (${w})`);
		return;
	}

	if (mode === 3) { // a write left in force: the shell restarts psensd
		const w = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, real(321), { priority: 16 }));
		ok(w === 'none' && (await until(target, (v) => v === 321)) === 321, `321 lx at priority 16, left in force (${w})`);
		return;
	}

	if (mode === 2) { // the fault: the safe level holds whatever is written
		let f = 0;
		for (let i = 0; i < 50 && f !== 2; i++) {
			f = (await read(lo, P.STATUS_FLAGS))[0].value.value[0];
			if (f !== 2) await sleep(100);
		}
		ok(f === 2, `the zone is in its fault (Status_Flags ${f})`);
		const w1 = await errorOf(client.writeProperty(server, day, P.PRESENT_VALUE, enumv(0), { priority: 1 }));
		const w2 = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, real(100), { priority: 1 }));
		ok(w1 === 'none' && w2 === 'none', `daylight control off and target 100 lx at priority 1 taken (${w1}, ${w2})`);
		const t = await until(target, (v) => v === 100);
		ok(t === 100, `target's Present_Value 100 (${t})`);
		const seen = new Set();
		for (let i = 0; i < 10; i++) {
			seen.add(await pv(lo));
			await sleep(100);
		}
		ok(seen.size === 1 && seen.has(100), `the light stays at the safe level: ${[...seen].join(', ')} %`);
		await client.writeProperty(server, day, P.PRESENT_VALUE, nul, { priority: 1 });
		await client.writeProperty(server, target, P.PRESENT_VALUE, nul, { priority: 1 });
		ok((await until(target, (v) => v === 500)) === 500, 'relinquished: the configured target again');
		return;
	}

	// priorities: 300 at 12, 650 at 8 (wins), relinquish 8 (300), relinquish 12 (500)
	const w12 = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, real(300), { priority: 12 }));
	ok(w12 === 'none' && (await until(target, (v) => v === 300)) === 300, `300 lx at priority 12: Present_Value 300 (${w12})`);
	const w8 = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, real(650), { priority: 8 }));
	ok(w8 === 'none' && (await until(target, (v) => v === 650)) === 650, `650 lx at priority 8 wins: Present_Value 650 (${w8})`);
	const arr = (await read(target, P.PRIORITY_ARRAY)).map((v) => (v.type === 0 ? null : v.value));
	ok(arr[7] === 650 && arr[11] === 300 && arr.filter((v) => v !== null).length === 2,
		`Priority_Array: [8] 650, [12] 300, the rest NULL (${JSON.stringify(arr)})`);
	const r8 = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, nul, { priority: 8 }));
	ok(r8 === 'none' && (await until(target, (v) => v === 300)) === 300, `relinquish 8: Present_Value 300 again (${r8})`);
	const r12 = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, nul, { priority: 12 }));
	ok(r12 === 'none' && (await until(target, (v) => v === 500)) === 500, `relinquish 12: Relinquish_Default 500 (${r12})`);

	const big = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, real(1600), { priority: 8 }));
	ok(OUT_OF_RANGE.test(big), `1600 lx (past target_max 1500) refused: ${big}`);
	const low = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, real(40), { priority: 8 }));
	ok(OUT_OF_RANGE.test(low), `40 lx (below target_min 50) refused: ${low}`);
	const two = await errorOf(client.writeProperty(server, day, P.PRESENT_VALUE, enumv(2), { priority: 8 }));
	ok(OUT_OF_RANGE.test(two), `daylight control 2 (not a BACnetBinaryPV) refused: ${two}`);
	const ai = await errorOf(client.writeProperty(server, signal, P.PRESENT_VALUE, real(1), { priority: 8 }));
	ok(DENIED.test(ai), `an Analog Input (the sensor signal) is not writable: ${ai}`);
	const p8 = (await read(target, P.PRIORITY_ARRAY, 8))[0];
	ok(p8.type === 0 && (await pv(target)) === 500, 'the refused writes left Priority_Array[8] NULL, Present_Value 500');

	// daylight control off: the level is target / E, and follows the target
	const t1 = Math.round(0.3 * elux), t2 = Math.round(0.6 * elux);
	const d0 = await errorOf(client.writeProperty(server, day, P.PRESENT_VALUE, enumv(0), { priority: 10 }));
	const a1 = await errorOf(client.writeProperty(server, target, P.PRESENT_VALUE, real(t1), { priority: 10 }));
	const want1 = 100 * t1 / elux, want2 = 100 * t2 / elux;
	const l1 = await until(lo, (v) => near(v, want1, 1e-3));
	ok(d0 === 'none' && a1 === 'none' && near(l1, want1, 1e-3),
		`daylight control off, target ${t1} lx: the light at ${l1.toFixed(4)} % = 100 x ${t1} / ${elux} (${want1.toFixed(4)})`);
	await client.writeProperty(server, target, P.PRESENT_VALUE, real(t2), { priority: 10 });
	const l2 = await until(lo, (v) => near(v, want2, 1e-3));
	ok(near(l2, want2, 1e-3), `target ${t2} lx: the light follows to ${l2.toFixed(4)} % (${want2.toFixed(4)})`);
	console.log(`# fixed_level_pct ${t1} ${l1} ${t2} ${l2}`);
	const dpv = await pv(day);
	ok(dpv === 0, `daylight control's Present_Value inactive (${dpv})`);
	await client.writeProperty(server, day, P.PRESENT_VALUE, nul, { priority: 10 });
	const l3 = await until(lo, (v) => !near(v, want2, 0.5));
	ok(!near(l3, want2, 0.5), `daylight control relinquished (on): the control's own level ${l3.toFixed(2)} %`);
	await client.writeProperty(server, target, P.PRESENT_VALUE, nul, { priority: 10 });
	ok((await until(target, (v) => v === 500)) === 500 && (await pv(day)) === 1, 'everything relinquished: 500 lx, daylight control on');
}
main()
	.catch((e) => { n++; failed++; console.log(`not ok ${n} - the peer stopped: ${e.stack || e}`); })
	.finally(() => { console.log(`1..${n}`); client.close(); process.exit(failed ? 1 : 0); });
