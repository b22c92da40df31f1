// SPDX-License-Identifier: ISC
// An outside BACnet/IP client (@bacnet-js/client, pinned in package.json)
// reading a large device whole: the Device's Object_List in one
// ReadProperty (the library sets SA and acks the segments itself), with
// max-APDU 1476 and 480, checked against the list read an element at a
// time; ReadPropertyMultiple of the Device's ALL (its Object_List inside);
// the Device's segmentation properties; and a request accepting only 2
// segments, which psensd must abort with buffer-overflow (reason 1).
// Prints TAP lines and "# object_list_ms N" for the whole read.
// usage: node bacnet-seg-peer.js SERVER_PORT DEVICE_INSTANCE MIN_OBJECTS
'use strict';
const { ObjectType, PropertyIdentifier: P, MaxApduLengthAccepted: A, MaxSegmentsAccepted: S } = require('@bacnet-js/client');

const [port, device, least] = process.argv.slice(2).map(Number);
const server = { address: `127.0.0.1:${port}` };
const client = require('./bacnet-client.js')();
let n = 0, failed = 0;
const ok = (cond, what) => { n++; if (!cond) failed++; console.log(`${cond ? 'ok' : 'not ok'} ${n} - ${what}`); };
const key = (o) => `${o.type}:${o.instance}`;

async function errorOf(p) {
	try { await p; return 'none'; } catch (e) { return String(e.message || e); }
}

async function main() {
	await new Promise((r) => client.on('listening', r));
	const dev = { type: ObjectType.DEVICE, instance: device };
	const count = (await client.readProperty(server, dev, P.OBJECT_LIST, { arrayIndex: 0 })).values[0].value;
	ok(count >= least, `Object_List[0]: ${count} objects (at least ${least})`);
	// the list an element at a time: what the whole read must equal
	const byIndex = [];
	for (let i = 1; i <= count; i++)
		byIndex.push(key((await client.readProperty(server, dev, P.OBJECT_LIST, { arrayIndex: i })).values[0].value));
	for (const apdu of [A.OCTETS_1476, A.OCTETS_480]) {
		const t0 = process.hrtime.bigint();
		const r = await client.readProperty(server, dev, P.OBJECT_LIST, { maxApdu: apdu });
		const ms = Number(process.hrtime.bigint() - t0) / 1e6;
		const whole = r.values.map((v) => key(v.value));
		const octets = 5 * count;
		ok(whole.length === count && whole.every((k, i) => k === byIndex[i]),
			`Object_List whole in one ReadProperty, max APDU ${apdu === A.OCTETS_480 ? 480 : 1476}: ${whole.length} identifiers, ` +
			`equal to the ${count} read by index (some ${Math.ceil(octets / ((apdu === A.OCTETS_480 ? 480 : 1476) - 5))} segments)`);
		console.log(`# object_list_ms ${apdu === A.OCTETS_480 ? 480 : 1476} ${ms.toFixed(1)}`);
	}
	const all = await client.readPropertyMultiple(server, [{ objectId: dev, properties: [{ id: P.ALL, index: 0xffffffff }] }]);
	const vals = new Map(all.values[0].values.map((v) => [v.id, v.value]));
	const list = vals.get(P.OBJECT_LIST) || [];
	ok(list.length === count, `ReadPropertyMultiple ALL on the Device: its Object_List of ${list.length} inside`);
	// ALL of the first 60 objects in one ReadPropertyMultiple: many kB, in segments
	const objs = (await client.readProperty(server, dev, P.OBJECT_LIST)).values.map((v) => v.value).slice(0, 60);
	const many = await client.readPropertyMultiple(server,
		objs.map((o) => ({ objectId: o, properties: [{ id: P.ALL, index: 0xffffffff }] })));
	const named = many.values.filter((r, i) => key(r.objectId) === key(objs[i]) &&
		r.values.some((v) => v.id === P.OBJECT_NAME && typeof v.value[0].value === 'string'));
	ok(many.values.length === 60 && named.length === 60,
		`ReadPropertyMultiple ALL of 60 objects at once: ${many.values.length} results, ${named.length} named in order`);
	const seg = vals.get(P.SEGMENTATION_SUPPORTED), mseg = vals.get(P.MAX_SEGMENTS_ACCEPTED), tseg = vals.get(P.APDU_SEGMENT_TIMEOUT);
	ok(seg && seg[0].value === 1, `Segmentation_Supported: segmented-transmit (${seg ? seg[0].value : '-'})`);
	ok(mseg && mseg[0].value === 1, `Max_Segments_Accepted: 1, segmented requests refused (${mseg ? mseg[0].value : '-'})`);
	ok(tseg && tseg[0].value === 2000, `APDU_Segment_Timeout: 2000 ms (${tseg ? tseg[0].value : '-'})`);
	const two = await errorOf(client.readProperty(server, dev, P.OBJECT_LIST, { maxSegments: S.SEGMENTS_2 }));
	ok(/Abort.*Reason:1\b/.test(two), `Object_List with at most 2 segments accepted: Abort buffer-overflow (${two})`);
	// and the server still answers after it
	const again = await client.readProperty(server, dev, P.OBJECT_LIST, { arrayIndex: 0 });
	ok(again.values[0].value === count, 'an ordinary request answered after the abort');
}

main().then(() => {
	console.log(`1..${n}`);
	client.close();
	process.exit(failed ? 1 : 0);
}, (e) => {
	console.log(`not ok ${n + 1} - ${e.stack || e}`);
	console.log(`1..${n + 1}`);
	client.close();
	process.exit(1);
});
