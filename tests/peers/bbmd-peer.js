// SPDX-License-Identifier: ISC
// A tiny BBMD (ANSI/ASHRAE 135 Annex J) on a raw UDP socket, for
// tests/system/642: it checks the foreign-device registration psensd sends,
// octet by octet, refuses the first with a BVLC-Result NAK, takes the next,
// expects psensd's I-Am as a Distribute-Broadcast-To-Network, forwards it a
// Who-Is from another address (Forwarded-NPDU) and expects the I-Am back the
// same way, and times the renewal against the Time-to-Live.  TAP on stdout.
//
//   node bbmd-peer.js PORT DEVICE TTL
'use strict';
const dgram = require('dgram');

const [port, device, ttl] = process.argv.slice(2).map(Number);
let n = 0, failed = 0;
function ok(cond, what) {
	n++;
	if (!cond) failed++;
	console.log(`${cond ? 'ok' : 'not ok'} ${n} - ${what}`);
}
const hex = (b) => Buffer.from(b).toString('hex').replace(/(..)/g, '$1 ').trim();

const regs = [], dbtn = [];
let psensd = null, whoIsSent = 0;
const s = dgram.createSocket('udp4');
// an I-Am of the device: BVLL 0x81 0x09, NPDU version 1 control 0, APDU
// unconfirmed (0x10) i-Am (0x00), [application 12] object identifier
function isIAm(m) {
	const id = ((8 << 22) | device) >>> 0;
	return m.length >= 13 && m[0] === 0x81 && m[1] === 0x09 && m.readUInt16BE(2) === m.length && m[4] === 1 &&
		m[5] === 0 && m[6] === 0x10 && m[7] === 0x00 && m[8] === 0xc4 && m.readUInt32BE(9) === id;
}
s.on('message', (m, r) => {
	const t = Date.now();
	psensd = r;
	if (m.length >= 2 && m[0] === 0x81 && m[1] === 0x05) {
		regs.push({ t, m: Buffer.from(m) });
		// the first refused (Register-Foreign-Device NAK, 0x0030), the rest taken
		const code = regs.length === 1 ? 0x0030 : 0x0000;
		s.send(Buffer.from([0x81, 0x00, 0x00, 0x06, code >> 8, code & 255]), r.port, r.address);
	} else if (m.length >= 2 && m[0] === 0x81 && m[1] === 0x09) {
		dbtn.push({ t, m: Buffer.from(m) });
		if (dbtn.length === 1) {
			// a Who-Is broadcast on another network, as this BBMD forwards it:
			// Forwarded-NPDU (0x04) from 10.9.8.7:47808
			whoIsSent = Date.now();
			s.send(Buffer.from([0x81, 0x04, 0x00, 0x0e, 10, 9, 8, 7, 0xba, 0xc0, 0x01, 0x00, 0x10, 0x08]),
				r.port, r.address);
		}
	}
});
s.bind(port, '127.0.0.1');

function finish() {
	const want = [0x81, 0x05, 0x00, 0x06, ttl >> 8, ttl & 255];
	ok(regs.length >= 1 && regs[0].m.equals(Buffer.from(want)),
		`Register-Foreign-Device: ${regs.length ? hex(regs[0].m) : 'none'} (want ${hex(want)}: BVLL 0x81 0x05, length 6, TTL ${ttl})`);
	const retry = regs.length >= 2 ? (regs[1].t - regs[0].t) / 1000 : NaN;
	ok(retry >= 0.8 && retry <= 5, `after the NAK, tried again with a backoff: ${retry.toFixed(2)} s later`);
	ok(regs.length >= 2 && regs.every((x) => x.m.equals(Buffer.from(want))), `every registration the same octets (${regs.length})`);
	const ann = dbtn.filter((x) => x.t >= (regs.length >= 2 ? regs[1].t : Infinity));
	ok(ann.length >= 1 && isIAm(ann[0].m),
		`registered: I-Am as Distribute-Broadcast-To-Network (${ann.length ? hex(ann[0].m) : 'none'})`);
	ok(dbtn.every((x) => isIAm(x.m)), `nothing but I-Am is broadcast (${dbtn.length})`);
	const back = whoIsSent ? dbtn.slice(1) : []; // after the announcement: the answer to the Who-Is
	ok(back.length >= 1 && isIAm(back[0].m), `a forwarded Who-Is: its I-Am broadcast through the BBMD (${back.length})`);
	const renew = regs.length >= 3 ? (regs[2].t - regs[1].t) / 1000 : NaN;
	ok(renew >= ttl / 2 - 1 && renew < ttl, `renewed ${renew.toFixed(2)} s after the registration, before the TTL (${ttl} s) ran out`);
	console.log(`1..${n}`);
	s.close();
	process.exit(failed ? 1 : 0);
}
// the NAK, its retry, the renewal at half the TTL, and a margin
const deadline = setTimeout(finish, (ttl + 8) * 1000);
setInterval(() => {
	if (regs.length >= 3 && dbtn.length >= 2) {
		clearTimeout(deadline);
		finish();
	}
}, 100);
