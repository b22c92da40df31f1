#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""Compare what an MQTT subscriber received (mosquitto_sub -v lines:
"topic payload") with the sample logs of the psensd instances that
published it.  Usage: mqttcheck.py SUBLOG SITE=DB[:UPTO]...

For each site: every sample id of the database (the rows with a zone, up to
UPTO when given) must have arrived on psensd/<site>/<zone>/state with that
zone and say what the log's row of that id says (its room time t and sensor
reading: a message the log does not hold, say one published before the row
was committed and lost in a crash, is a phantom); the first arrivals must be
in id order; duplicates (the same id again) are counted, not refused.  A sample not received whose id is beyond the
site's persisted cursor (mqtt_cursor) is pending, not lost: psensd stopped
before the broker acknowledged it and sends it at its next start; it is
reported, and fails the check only with --no-pending.  Prints one line per
site and exits 1 on any loss or disorder."""
import json
import sqlite3
import sys

args = sys.argv[1:]
strict = "--no-pending" in args
args = [a for a in args if a != "--no-pending"]
sub, pairs = args[0], args[1:]
got = {}
for line in open(sub, encoding="utf-8", errors="replace"):
    topic, _, payload = line.rstrip("\n").partition(" ")
    parts = topic.split("/")
    if len(parts) != 4 or parts[0] != "psensd" or parts[3] != "state":
        continue
    try:
        m = json.loads(payload)
    except ValueError:
        print("not JSON on %s: %s" % (topic, payload[:80]))
        sys.exit(1)
    if m.get("zone") != parts[2] or m.get("site") != parts[1]:
        print("zone or site of message %s does not match its topic %s" % (m.get("id"), topic))
        sys.exit(1)
    got.setdefault(parts[1], []).append((m["id"], parts[2], m.get("t"), m.get("sensor_v")))

bad = 0
for pair in pairs:
    site, db = pair.split("=", 1)
    upto = None
    if ":" in db:
        db, upto = db.rsplit(":", 1)
        upto = int(upto)
    con = sqlite3.connect(db)
    rows = con.execute(
        "SELECT rowid, zone, t, sensor_v FROM samples WHERE zone IS NOT NULL AND rowid <= ? ORDER BY rowid",
        (upto if upto is not None else 1 << 62,)).fetchall()
    cur = con.execute("SELECT sample FROM mqtt_cursor WHERE site = ?", (site,)).fetchone()
    cursor = cur[0] if cur else 0
    want = {r[0]: r[1] for r in rows}
    logged = {r[0]: (r[2], r[3]) for r in rows}
    seq = got.get(site, [])
    first, seen, dups, wrong, phantom = [], set(), 0, 0, []

    def same(a, b):
        if a is None or b is None:
            return a is None and b is None
        return abs(a - b) <= 1e-9 * max(1.0, abs(b))

    for i, zone, t, v in seq:
        # every message, duplicates too, must be the logged row of its id
        # (ids beyond UPTO are the second run's and are checked without it)
        if upto is None or i <= upto:
            row = logged.get(i)
            if row is None or not same(t, row[0]) or not same(v, row[1]):
                phantom.append(i)
        if i in seen:
            dups += 1
            continue
        seen.add(i)
        first.append(i)
        if want.get(i, zone) != zone:
            wrong += 1
    unseen = sorted(set(want) - seen)
    missing = [i for i in unseen if strict or i <= cursor]
    pending = [i for i in unseen if not strict and i > cursor]
    disorder = sum(1 for a, b in zip(first, first[1:]) if b <= a)
    print("site %s: %d samples logged, %d messages received, %d duplicates, %d missing, "
          "%d pending after the cursor (%d), %d out of order, %d with the wrong zone, "
          "%d not as logged%s%s" % (
              site, len(want), len(seq), dups, len(missing), len(pending), cursor, disorder, wrong,
              len(phantom), " (first missing: %s)" % missing[:5] if missing else "",
              " (first not as logged: %s)" % phantom[:5] if phantom else ""))
    if missing or disorder or wrong or phantom or not want:
        bad = 1
sys.exit(bad)
