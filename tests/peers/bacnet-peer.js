// SPDX-License-Identifier: ISC
// An outside BACnet/IP client (@bacnet-js/client, pinned in package.json)
// against psensd's BACnet server: discovery (Who-Is with a range, I-Am),
// the Device's Object_List, every object's properties with
// ReadPropertyMultiple (ALL), a Lighting Output's Present_Value with
// ReadProperty, a write at priority 8 and its relinquish (when writes are
// on, else the refusal), COV subscriptions (unconfirmed with a lifetime,
// confirmed, one refused, the notification after a write, a cancel), and
// the errors for an unknown object and property.  Prints TAP lines ("ok N - ..." / "not ok N - ...") and
// "# rp_ms p50 p99 max" for 200 ReadProperty round trips.
// With WRITES 2 (psensd's zone in a sensor fault at its safe level of
// 100 %): a write at priority 1 is taken, and the light stays at 100 %.
// usage: node bacnet-peer.js SERVER_PORT DEVICE_INSTANCE WRITES(0|1|2)
'use strict';
// the library has no Who-Has request of its own: its Who-Has parameter
// encoder (and its I-Have decoder, the 'iHave' event) over a 2-octet NPDU
// and APDU header
const WhoHas = require('@bacnet-js/client/dist/lib/services/WhoHas').default;
const { ObjectType, PropertyIdentifier: P, ErrorClass, ErrorCode } = require('@bacnet-js/client');

const [port, device, writes] = process.argv.slice(2).map(Number);
const server = { address: `127.0.0.1:${port}` };
const client = require('./bacnet-client.js')();
let n = 0, failed = 0;
const ok = (cond, what) => { n++; if (!cond) failed++; console.log(`${cond ? 'ok' : 'not ok'} ${n} - ${what}`); };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

function whoIs(low, high) {
	return new Promise((resolve) => {
		const seen = [];
		const on = (msg) => seen.push(msg.payload);
		client.on('iAm', on);
		client.whoIs(server, { lowLimit: low, highLimit: high });
		setTimeout(() => { client.removeListener('iAm', on); resolve(seen); }, 1500);
	});
}

// the error a request ended in: "CLASS:CODE" from the library's message
async function errorOf(p) {
	try { await p; return 'none'; } catch (e) { return String(e.message || e); }
}

// the zone in a fault: Status_Flags says so, a BMS write cannot move the light
async function fault() {
	const lo = { type: ObjectType.LIGHTING_OUTPUT, instance: 1 };
	const flags = async () => (await client.readProperty(server, lo, P.STATUS_FLAGS)).values[0].value.value[0];
	let f = 0;
	for (let i = 0; i < 50 && !f; i++) {
		f = await flags();
		if (!f) await sleep(100);
	}
	// the library gives bit i of the bit string as 1 << i: fault is bit 1
	ok(f === 2, `Status_Flags: fault, and only fault (${f})`);
	const real = (v) => [{ type: 4 /* REAL */, value: v }];
	const wr = await errorOf(client.writeProperty(server, lo, P.PRESENT_VALUE, real(20), { priority: 1 }));
	ok(wr === 'none', `WriteProperty 20 % at priority 1 during the fault is taken (${wr})`);
	const seen = new Set();
	for (let i = 0; i < 10; i++) {
		seen.add((await client.readProperty(server, lo, P.PRESENT_VALUE)).values[0].value);
		await sleep(100);
	}
	ok(seen.size === 1 && seen.has(100), `the light stays at the safe level: Present_Value ${[...seen].join(', ')}`);
	const pa = await client.readProperty(server, lo, P.PRIORITY_ARRAY, { arrayIndex: 1 });
	ok(pa.values[0].value === 20, `Priority_Array[1] holds the command (${pa.values[0].value})`);
	const rel = await errorOf(client.writeProperty(server, lo, P.PRESENT_VALUE, [{ type: 0, value: null }], { priority: 1 }));
	ok(rel === 'none', `relinquished (${rel})`);
	console.log(`1..${n}`);
	client.close();
	process.exit(failed ? 1 : 0);
}

function whoHas(objectId, objectName) {
	return new Promise((resolve) => {
		const seen = [];
		const on = (msg) => seen.push(msg.payload);
		client.on('iHave', on);
		const buf = { buffer: Buffer.alloc(1482), offset: 4 };
		buf.buffer.set([0x01, 0x00, 0x10, 0x07], 4);   // NPDU version 1; unconfirmed who-Has (7)
		buf.offset = 8;
		WhoHas.encode(buf, -1, -1, objectId, objectName);
		client.sendBvlc(server, buf);
		setTimeout(() => { client.removeListener('iHave', on); resolve(seen); }, 1500);
	});
}

async function main() {
	await new Promise((r) => client.on('listening', r));
	if (writes === 2)
		return fault();
	const hit = await whoIs(device, device);
	ok(hit.length === 1 && hit[0].deviceId === device, `Who-Is ${device}-${device}: one I-Am from device ${device}`);
	ok(hit.length === 1 && hit[0].maxApdu === 1476 && hit[0].segmentation === 1,
		`I-Am: max APDU 1476, segmented-transmit (${hit.length ? hit[0].maxApdu + ', ' + hit[0].segmentation : 'none'})`);
	const miss = await whoIs(device + 1, device + 10);
	ok(miss.length === 0, `Who-Is ${device + 1}-${device + 10}: no I-Am (${miss.length})`);
	const all = await whoIs();
	ok(all.length === 1, 'Who-Is without a range: an I-Am');

	const dev = { type: ObjectType.DEVICE, instance: device };
	const list = await client.readProperty(server, dev, P.OBJECT_LIST);
	const objs = list.values.map((v) => v.value);
	ok(objs.length >= 5 && objs[0].type === ObjectType.DEVICE && objs[0].instance === device,
		`Object_List: ${objs.length} objects, the Device first`);
	const count = await client.readProperty(server, dev, P.OBJECT_LIST, { arrayIndex: 0 });
	ok(count.values[0].value === objs.length, `Object_List[0] is its length (${count.values[0].value})`);
	const los = objs.filter((o) => o.type === ObjectType.LIGHTING_OUTPUT);
	const ais = objs.filter((o) => o.type === ObjectType.ANALOG_INPUT);
	const bis = objs.filter((o) => o.type === ObjectType.BINARY_INPUT);
	const msis = objs.filter((o) => o.type === ObjectType.MULTI_STATE_INPUT);
	const avs = objs.filter((o) => o.type === ObjectType.ANALOG_VALUE);
	const bvs = objs.filter((o) => o.type === ObjectType.BINARY_VALUE);
	// the point model: per zone at least the estimate, signal, actual level, hours (AI),
	// the fault (BI), the control state (MSI); the target (AV) and daylight control (BV)
	ok(los.length >= 1 && ais.length >= 4 * los.length && bis.length >= los.length && msis.length >= los.length &&
		avs.length >= los.length && bvs.length === los.length &&
		objs.length === 1 + los.length + ais.length + bis.length + msis.length + avs.length + bvs.length,
		`${los.length} Lighting Output(s), ${ais.length} Analog, ${bis.length} Binary, ${msis.length} Multi-state Inputs, ` +
		`${avs.length} Analog and ${bvs.length} Binary Values`);

	// every object's properties, one ReadPropertyMultiple (ALL) each
	let props = 0, errs = 0;
	const names = new Set();
	for (const o of objs) {
		const r = await client.readPropertyMultiple(server, [{ objectId: o, properties: [{ id: P.ALL, index: 0xffffffff }] }]);
		for (const v of r.values[0].values) {
			props++;
			if (v.value.length && v.value[0].value && v.value[0].value.errorClass !== undefined) errs++;
			if (v.id === P.OBJECT_NAME) names.add(v.value[0].value);
		}
	}
	ok(props > 0 && errs === 0, `ReadPropertyMultiple ALL on every object: ${props} properties, ${errs} errors`);
	ok(names.size === objs.length, `Object_Name unique across the device (${names.size} of ${objs.length})`);

	const byName = await whoHas(null, 'office light level');
	ok(byName.length === 1 && byName[0].objectId.type === ObjectType.LIGHTING_OUTPUT && byName[0].objectId.instance === 1 &&
		byName[0].deviceId.instance === device, `Who-Has 'office light level': I-Have (lighting-output, 1) from device ${device} (${byName.length})`);
	const byId = await whoHas({ type: ObjectType.ANALOG_INPUT, instance: 2 });
	ok(byId.length === 1 && byId[0].objectName === 'office sensor signal',
		`Who-Has (analog-input, 2): I-Have named '${byId.length ? byId[0].objectName : '-'}'`);
	const none = await whoHas(null, 'no such object');
	ok(none.length === 0, `Who-Has a name psensd lacks: no I-Have (${none.length})`);

	const devr = await client.readPropertyMultiple(server, [{ objectId: dev, properties: [
		{ id: P.PROTOCOL_VERSION, index: 0xffffffff }, { id: P.PROTOCOL_REVISION, index: 0xffffffff },
		{ id: P.MAX_APDU_LENGTH_ACCEPTED, index: 0xffffffff }, { id: P.SEGMENTATION_SUPPORTED, index: 0xffffffff }] }]);
	const dv = devr.values[0].values.map((v) => v.value[0].value);
	ok(dv[0] === 1 && dv[1] === 14 && dv[2] === 1476 && dv[3] === 1,
		`Device: Protocol_Version 1, Protocol_Revision 14, Max_APDU 1476, segmented-transmit (${dv.join(' ')})`);

	// ReadProperty round trips: Present_Value of the first Lighting Output
	const lo = los[0];
	const t = [];
	let pv;
	for (let i = 0; i < 200; i++) {
		const t0 = process.hrtime.bigint();
		pv = await client.readProperty(server, lo, P.PRESENT_VALUE);
		t.push(Number(process.hrtime.bigint() - t0) / 1e6);
	}
	t.sort((a, b) => a - b);
	const level = pv.values[0].value;
	ok(typeof level === 'number' && level >= 0 && level <= 100, `Lighting Output ${lo.instance} Present_Value ${level} is 0-100 %`);
	console.log(`# rp_ms p50 ${t[100].toFixed(3)} p99 ${t[197].toFixed(3)} max ${t[199].toFixed(3)}`);

	// COV: an unconfirmed subscription (lifetime 300 s) and a confirmed one
	const notes = [];
	client.on('covNotifyUnconfirmed', (m) => notes.push({ t: process.hrtime.bigint(), p: m.payload, confirmed: false }));
	client.on('covNotify', (m) => notes.push({ t: process.hrtime.bigint(), p: m.payload, confirmed: true }));
	const covOf = (pid) => notes.filter((x) => x.p.subscriberProcessId === pid);
	const pvOf = (x) => x.p.values.find((v) => v.property.id === P.PRESENT_VALUE).value[0].value;
	const sub = await errorOf(client.subscribeCov(server, lo, 71, false, false, 300));
	const subc = await errorOf(client.subscribeCov(server, ais[0], 72, false, true, 0));
	await sleep(300);
	const first = covOf(71);
	ok(sub === 'none' && first.length >= 1 && first[0].p.monitoredObjectId.instance === lo.instance &&
		first[0].p.timeRemaining > 290 && first[0].p.timeRemaining <= 300,
		`SubscribeCOV (unconfirmed, 300 s): taken (${sub}), the first notification at once (${first.length}, ${first.length ? first[0].p.timeRemaining : '-'} s left)`);
	ok(subc === 'none' && covOf(72).length >= 1 && covOf(72)[0].confirmed,
		`SubscribeCOV (confirmed) on Analog Input ${ais[0].instance}: a confirmed notification (${subc}, ${covOf(72).length})`);
	const covErr = await errorOf(client.subscribeCov(server, dev, 73, false, false, 60));
	ok(/Class:1.*Code:45/i.test(covErr), `SubscribeCOV on the Device: optional-functionality-not-supported (${covErr})`);

	// write at priority 8, then relinquish
	const real = (v) => [{ type: 4 /* REAL */, value: v }];
	const t0w = process.hrtime.bigint();
	const wr = await errorOf(client.writeProperty(server, lo, P.PRESENT_VALUE, real(42.5), { priority: 8 }));
	if (writes) {
		ok(wr === 'none', `WriteProperty Present_Value 42.5 at priority 8 accepted (${wr})`);
		const pa = await client.readProperty(server, lo, P.PRIORITY_ARRAY, { arrayIndex: 8 });
		ok(pa.values[0].value === 42.5, `Priority_Array[8] reads 42.5 (${pa.values[0].value})`);
		let seen;
		for (let i = 0; i < 40; i++) {
			seen = (await client.readProperty(server, lo, P.PRESENT_VALUE)).values[0].value;
			if (Math.abs(seen - 42.5) < 1e-3) break;
			await sleep(100);
		}
		ok(Math.abs(seen - 42.5) < 1e-3, `Present_Value follows the write: ${seen}`);
		const cov = covOf(71).find((x) => x.t > t0w && Math.abs(pvOf(x) - 42.5) < 1e-3);
		ok(cov !== undefined, `a COV notification carries 42.5`);
		if (cov) console.log(`# cov_ms ${(Number(cov.t - t0w) / 1e6).toFixed(3)} from the write's request to the notification`);
		const rangeErr = await errorOf(client.writeProperty(server, lo, P.PRESENT_VALUE, real(120), { priority: 8 }));
		ok(/PROPERTY.*VALUE_OUT_OF_RANGE|Class:2.*Code:37/i.test(rangeErr), `120 % is refused: ${rangeErr}`);
		const rel = await errorOf(client.writeProperty(server, lo, P.PRESENT_VALUE, [{ type: 0, value: null }], { priority: 8 }));
		ok(rel === 'none', `relinquish at priority 8 (NULL) accepted (${rel})`);
		const pa2 = await client.readProperty(server, lo, P.PRIORITY_ARRAY, { arrayIndex: 8 });
		ok(pa2.values[0].type === 0, `Priority_Array[8] is NULL again (type ${pa2.values[0].type})`);
	} else {
		ok(/PROPERTY.*WRITE_ACCESS_DENIED|Class:2.*Code:40/i.test(wr), `writes off: WriteProperty refused: ${wr}`);
	}

	const cancel = await errorOf(client.subscribeCov(server, lo, 71, true, false, 0));
	ok(cancel === 'none', `SubscribeCOV cancelled (${cancel})`);

	// errors: an unknown object, an unknown property
	const e1 = await errorOf(client.readProperty(server, { type: ObjectType.ANALOG_VALUE, instance: 77 }, P.PRESENT_VALUE));
	ok(/OBJECT.*UNKNOWN_OBJECT|Class:1.*Code:31/i.test(e1), `unknown object: ${e1}`);
	const e2 = await errorOf(client.readProperty(server, dev, P.PRESENT_VALUE));
	ok(/PROPERTY.*UNKNOWN_PROPERTY|Class:2.*Code:32/i.test(e2), `unknown property: ${e2}`);
	console.log(`1..${n}`);
	client.close();
	process.exit(failed ? 1 : 0);
}
main().catch((e) => { console.log(`not ok ${n + 1} - the peer stopped: ${e.stack || e}`); client.close(); process.exit(1); });
