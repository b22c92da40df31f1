// SPDX-License-Identifier: ISC
// The BACnet/IP client every peer uses (@bacnet-js/client), on the loopback,
// bound to the peer's own port from the test (PEER_PORT): the library takes
// port 0 for its default 47808, and with SO_REUSEADDR two peers running at
// once would share it and each lose the other's answers.
'use strict';
const Bacnet = require('@bacnet-js/client').default;

module.exports = function peerClient() {
	const p = Number(process.env.PEER_PORT);
	if (!Number.isInteger(p) || p <= 0 || p > 65535) {
		console.log('not ok - PEER_PORT is not a UDP port: ' + process.env.PEER_PORT);
		process.exit(2);
	}
	return new Bacnet({ port: p, reuseAddr: false, interface: '127.0.0.1', broadcastAddress: '127.0.0.1', apduTimeout: 6000 });
};
