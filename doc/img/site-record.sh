#!/bin/sh
# SPDX-License-Identifier: ISC
# Redraws the commissioning record of doc/commissioning.md (doc/img/report_cover.png and
# report_zone.png) from a fresh run of the site dry run (doc/site.md): psvirt's three
# rooms (config/example/site.conf), psensd at 600 times real time, a day
# session on the east zone at 10:00 and on the north zone at 14:00, each
# accepted while the day runs, the south zone left uncalibrated, then each
# zone's acceptance tests and the report.  About 100 s; needs a built tree
# (make) and TCP port 1502 free.  Prints what doc/commissioning.md quotes.
set -e
cd "$(dirname "$0")/../.."
B=build/bin
S=build/site.sock
rm -f build/site.db build/site.db-wal build/site.db-shm build/site-report.pdf
"$B/psvirt" -f config/example/site.conf --tcp 127.0.0.1:1502 --speed 600 \
	-D gain=0.5 -D noise=0.002 -D task_noise=2 -D min_level=0.1 \
	-D east:gain=0.4 -D "south:faults=open 12:00-12:20" > build/site-psvirt.log 2>&1 &
V=$!
trap 'kill $V 2> /dev/null || true' EXIT
sleep 0.3
timeout 86 "$B/psensd" -f config/example/site.conf -t 06:00 -x 600 2> build/site-psensd.log &
P=$!
until "$B/psensctl" -s "$S" ping > /dev/null 2>&1; do sleep 0.1; done

# the room's clock, HH:MM, from psensd
room_time() { "$B/psensctl" -s "$S" -j status | sed -n 's/.*"time":"\([0-9:]*\)".*/\1/p'; }
# a day session on zone $1 once the room's clock passes $2, then accepted
day_session() {
	until [ "$(room_time)" \> "$2" ]; do sleep 0.2; done
	"$B/psensctl" -s "$S" calibrate "$1" day 0.3 > /dev/null
	until "$B/psensctl" -s "$S" calibrate "$1" status | grep -q 'state: done\|state: aborted'; do sleep 0.5; done
	"$B/psensctl" -s "$S" calibrate "$1" status | grep 'message:'
	"$B/psensctl" -s "$S" calibrate "$1" accept | grep 'message:'
}
day_session east 09:59
day_session north 13:59
wait $P || true
kill $V 2> /dev/null || true
wait $V 2> /dev/null || true
trap - EXIT
cat build/site-psensd.log
for z in north east south; do "$B/psensctl" -d build/site.db accept-test $z || true; done
R="$B/psensctl -d build/site.db report -c config/example/site.conf --site"
$R "Dry-run site (psvirt)" -o build/site-report.pdf || true
$R "Dry-run site (psvirt)" --page 1 -o doc/img/report_cover.png || true
$R "Dry-run site (psvirt)" --page 2 -o doc/img/report_zone.png || true
