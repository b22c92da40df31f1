# SPDX-License-Identifier: ISC
# Shared helpers for system tests: TAP output, temporary directories,
# waiting for readiness, stopping by PID.  Source it first:  . "$(dirname "$0")/lib.sh"
set -u
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
TOP=${TOP:-$(pwd)}
_tap_n=0
_tap_failed=0
ok()      { _tap_n=$((_tap_n + 1)); echo "ok $_tap_n - $*"; }
not_ok()  { _tap_n=$((_tap_n + 1)); _tap_failed=$((_tap_failed + 1)); echo "not ok $_tap_n - $*"; }
skip()    { _tap_n=$((_tap_n + 1)); echo "ok $_tap_n # SKIP $*"; }
# check DESCRIPTION COMMAND...: ok when the command succeeds
check()   { _check_d=$1; shift; if "$@"; then ok "$_check_d"; else not_ok "$_check_d"; fi; }
# skip_all REASON: the whole file cannot run here
skip_all() { echo "$*"; exit 77; }
diag()    { echo "# $*"; }
done_testing() { echo "1..$_tap_n"; [ "$_tap_failed" = 0 ]; }

# A fresh temporary directory removed on exit; short, for socket paths.
TMP=$(mktemp -d /tmp/pst.XXXXXX)
_cleanup_pids=""
_cleanup() {
	for p in $_cleanup_pids; do kill "$p" 2>/dev/null; done
	sleep 0.05
	for p in $_cleanup_pids; do kill -9 "$p" 2>/dev/null; done
	rm -rf "$TMP"
}
trap _cleanup EXIT
# remember a PID to stop on exit
track_pid() { _cleanup_pids="$_cleanup_pids $1"; }
# wait_for SECONDS COMMAND...: poll (every 20 ms) until the command succeeds
# (bounded by the clock, not by a count of tries: a command that is itself
# slow, e.g. a status request to a loaded daemon, must not stretch the wait)
wait_for() {
	# the deadline in ms (awk once, for a fractional SECONDS)
	_end=$(( $(date +%s%N) / 1000000 + $(awk -v t="$1" 'BEGIN { printf "%d", t * 1000 }') )); shift
	while :; do
		"$@" 2>/dev/null && return 0
		[ $(( $(date +%s%N) / 1000000 )) -lt "$_end" ] || return 1
		sleep 0.02
	done
}
# free_port: an unused TCP port on 127.0.0.1
free_port() {
	/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'
}
# free_udp_port: a UDP port on the loopback that is free now (BACnet/IP)
free_udp_port() {
	/usr/bin/python3 -c 'import socket; s=socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'
}
# example_results: the example scene copied to $TMP/example and its results
# precomputed (no rendering) in $TMP/state/ofb.results
example_results() {
	mkdir -p "$TMP/example" "$TMP/state"
	cp -R config/example/ofb config/example/ofb.scene "$TMP/example/"
	"$BIN/psscene" -q -N -o "$TMP/state/ofb.results" "$TMP/example/ofb.scene"
}

# psensd_section PERIOD [STALE_AFTER]: the usual [psensd] section, for a
# configuration in $TMP run from $TMP: the results of example_results, the
# database state/${DB:-psensd.db}, the socket "sock"
psensd_section() {
	printf '[psensd]\nresults = state/ofb.results\ndatabase = state/%s\nsocket = sock\nperiod = %s\n' \
		"${DB:-psensd.db}" "$1"
	[ $# -lt 2 ] || printf 'stale_after = %s\n' "$2"
}

# loopback_office: the plainest site, one zone office on the loopback room
# (a sensor point and a dimmed lamp), for a test whose subject is elsewhere
loopback_office() {
	printf '[device room]\ndriver = loopback\n[point sensor]\ndevice = room\nrole = sensor\n'
	printf '[point lamp]\ndevice = room\nrole = dim\n[zone office]\nsensor = sensor\ndim = lamp\n'
}
# file_zones N: a [psensd] section and N zones z0 .. zN-1 on the file
# driver (15 zones a device: the driver takes 32 points), each with its
# sensor's file $TMP/files/sZ holding 1.Z and a dim point
file_zones() {
	mkdir -p "$TMP/files"
	printf '[psensd]\nresults = state/ofb.results\nsocket = sock\nperiod = 60\nsafe_level = 1\n'
	_z=0
	while [ $_z -lt "$1" ]; do
		[ $((_z % 15)) = 0 ] && printf '[device files%d]\ndriver = file\ndir = files\n' $((_z / 15))
		echo "1.$_z" > "$TMP/files/s$_z"
		printf '[point s%d]\ndevice = files%d\nrole = sensor\npath = s%d\n' $_z $((_z / 15)) $_z
		printf '[point d%d]\ndevice = files%d\nrole = dim\npath = d%d\n' $_z $((_z / 15)) $_z
		printf '[zone z%d]\nsensor = s%d\ndim = d%d\ntarget_lux = 500\nsensor_gain = 0.5\n' $_z $_z $_z
		_z=$((_z + 1))
	done
}

# psvirt_dali ARGS...: psvirt with its virtual DALI-2 bus on a TCP port the
# kernel picks (a Foxtron DALInet), the room from $TMP/ofb.results
# (peers/common.sh: make_results), its other options ARGS; waits until it
# serves and sets pv (its pid, stopped on exit) and port (the bus's port)
psvirt_dali() {
	rm -f "$TMP/ready"
	"$BIN/psvirt" --results "$TMP/ofb.results" --dali-tcp 127.0.0.1:0 --ready-file "$TMP/ready" "$@" \
		> "$TMP/pv.out" 2> "$TMP/pv.err" &
	pv=$!; track_pid $pv
	wait_for 10 test -s "$TMP/ready" || not_ok "psvirt did not start: $(cat "$TMP/pv.err")"
	port=$(sed -n 's/^dali-tcp //p' "$TMP/ready")
}

# psvirt_devices [SIMULATED]: the [device io] (psvirt's Modbus module on
# port $mb) and [device dali] (its DALI bus, a Foxtron DALInet on $port)
# sections; with an argument, each says `simulated = SIMULATED` (the
# record then says the site was simulated)
psvirt_devices() {
	_sim=${1:+"simulated = $1
"}
	printf '[device io]\ndriver = modbus\n%shost = 127.0.0.1\nport = %s\ntimeout = 0.5\n' "$_sim" "$mb"
	printf '[device dali]\ndriver = dali_usb\n%stransport = foxtron\ndevice = 127.0.0.1:%s\ntimeout = 0.5\n' "$_sim" "$port"
}

# dali2_light ADDRESS T_REPORT [LINE...]: [point light], the 304 light
# sensor of control device ADDRESS (10-bit, saturating at 1023), reporting
# every T_REPORT s; each LINE ("key = value") goes into the point too
dali2_light() {
	printf '[point light]\ndevice = dali\nrole = sensor\ndevice_address = %s\nreport_time = %s\n' "$1" "$2"
	shift 2
	for _l in "$@"; do printf '%s\n' "$_l"; done
	printf 'valid_max = 1023\nsensor_saturation = 1023\n'
}
# dali2_occupancy ADDRESS [T_REPORT]: [point occupancy], the 303 of
# control device ADDRESS as the zone's occupancy input
dali2_occupancy() {
	printf '[point occupancy]\ndevice = dali\nrole = input\naction = occupancy\ndevice_address = %s\n' "$1"
	[ $# -lt 2 ] || printf 'report_time = %s\n' "$2"
}

# dali2_office: the task meter (psvirt's register 100), the gear as one
# broadcast point and the zone on the multisensor's points, setpoint
# control at 500 lx with the room's sensor gain in 304 counts (0.5 V x
# 102.3 counts per volt); a test appends its own zone keys
dali2_office() {
	cat <<EOD
[point lux]
device = io
role = task
table = holding_register
address = 100
type = u32
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = light
task = lux
dim = ballasts
input = occupancy
algorithm = setpoint
target_lux = 500
min_level = 0.1
sensor_gain = 51.15
EOD
}

# dalibus_pty LOG ARGS...: the emulated DALI bus (peers/dalibus.py, written
# from the standards' facts) behind an interface on a pty, its path in
# $TMP/pty, its output in LOG, its other options ARGS (--codec, --gear,
# --devices, ...); waits until the pty is there and sets bus (its pid,
# stopped on exit)
dalibus_pty() {
	_log=$1; shift
	rm -f "$TMP/pty"
	python3 "$(dirname "$0")/peers/dalibus.py" --pty "$TMP/pty" "$@" > "$_log" 2>&1 &
	bus=$!; track_pid $bus
	wait_for 10 test -s "$TMP/pty" || not_ok "the DALI bus emulator did not start"
}

# DALI tests: dali_arc U prints the arc power level for a light output U
# (0..1) by the standard logarithmic curve (IEC 62386-102; doc/hardware.md
# section 2), nearest in ratio, 0 for off, clamped to 1..254.
dali_arc() {
	awk -v u="$1" 'BEGIN { if (u <= 0) { print 0; exit } n = 1 + (253 / 3) * (log(100 * u) / log(10) + 1); n = int(n + 0.5); if (n < 1) n = 1; if (n > 254) n = 254; print n }'
}
# dali_room: the loopback room the DALI tests close their loop through (its
# sensor, gain 0.5 V per unit, 2 mV noise); written before [device dali]
dali_room() {
	printf '[device room]\ndriver = loopback\ngain = 0.5\nnoise = 0.002\n'
}
# dali_room_zone: the sections after [device dali]: the room's sensor and
# lamp, the DALI gear as one broadcast point, and the zone dimming both
# (its sensor gain the room's, a 10 % minimum)
dali_room_zone() {
	cat <<EOD
[point sensor]
device = room
role = sensor
[point lamp]
device = room
role = dim
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = sensor
dim = lamp ballasts
sensor_gain = 0.5
min_level = 0.1
EOD
}

# The emulators (tests/emu, doc/emulation.md) run through umockdev's preload.
# PRE: the preload library; EMU_ASAN: ASAN_OPTIONS that let the preload come
# before a sanitizer's runtime (doc/emulation.md pitfall 10).
PRE=libumockdev-preload.so.0
EMU_ASAN="${ASAN_OPTIONS:-}${ASAN_OPTIONS:+:}verify_asan_link_order=0"
# preload_ok: the preload can be loaded; need_preload: skip the file if not
preload_ok() { ! LD_PRELOAD=$PRE true 2>&1 | grep -q "cannot be preloaded"; }
need_preload() { preload_ok || skip_all "$PRE is not installed (umockdev)"; }

# gpio_light_point: a TSL230R on gpiochip line 3 of device "io", its divider
# pins on lines 4 and 5, 1 kHz reading 1.0 (the emulated chip's sensor)
gpio_light_point() {
	cat <<'EOP'
[point light]
device = io
role = sensor
kind = frequency
line = 3
gate = 0.4
factor = 0.001
max_rate = 2000
s2 = 4
s3 = 5
valid_min = 0.01
valid_max = 1000
EOP
}

# virt_now READY_MS START_S SPEED: psvirt's room time now (seconds from
# midnight), its clock having started at START_S when its ready file
# appeared (READY_MS, ms since the epoch; psvirt starts its clock just
# before it writes the file).  Tests start psensd with -t at this time
# ("$(hhmm "$v")"): at 3600x a sanitizer build's slow start would otherwise
# leave psensd's clock up to an hour behind psvirt's, its sun elsewhere.
# psensd then runs behind by v mod 60 s and its own start-up (at 3600x,
# under a sanitizer, up to half an hour): clock_lag measures it.
virt_now() {
	_now=$(( $(date +%s%N) / 1000000 ))
	awk -v now="$_now" -v r="$1" -v s="$2" -v x="$3" 'BEGIN { printf "%d", s + x * (now - r) / 1000 }'
}
hhmm() { printf "%02d:%02d" $(($1 / 3600)) $(($1 % 3600 / 60)); }

# clock_lag READY_MS START_S SPEED SOCKET: how many seconds of room time
# psvirt's clock (as for virt_now) is ahead of psensd's, psensd's read from
# its control socket (status "now") and psvirt's computed right after the
# reply: a few ms of shell, a minute or so of room time at 3600x.
clock_lag() {
	_j=$("$BIN/psensctl" -s "$4" -j status 2>/dev/null)
	_v=$(virt_now "$1" "$2" "$3")
	_p=$(printf '%s\n' "$_j" | sed -n 's/.*"now": *\([0-9.e+-]*\).*/\1/p' | head -n 1)
	awk -v v="$_v" -v p="$_p" 'BEGIN { if (p == "") exit 1; printf "%d", v - p }'
}
