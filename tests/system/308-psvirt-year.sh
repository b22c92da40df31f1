#!/bin/sh
# SPDX-License-Identifier: ISC
# psvirt playing the year ([simulate] year = yes): the registers a site's
# tools read (mbpoll, the Modbus peer) follow the hourly series psscene wrote
# into the results, on two dates (an overcast 5 July and 12 January) at an
# hour's middle (12:30: the hour's own values) and between two hours (13:00:
# their mean, the room being linear between hours).  With no noise and the
# clock stopped (--speed 0), from the results' numbers alone:
#   truth (HR 203, f32)  = task_lux(hour) + output x electric_task_lux
#   sensor (IR 0)        = 0.5 V per unit x (sensor(hour) + output x
#                          electric_sensor_response), 0..65535 = 0..10 V
#   meter (HR 100, u32)  = the truth, rounded
#   rooftop (HR 210 u32, 212 f32) = horizontal_lux(hour), the weather's
#                          global horizontal illuminance
# where output is the lamps' level the room reports (HR 202 / 10000).
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
need mbpoll
example_results
R=$TMP/state/ofb.results
sed "s|^results = .*|results = $R|; s|^database = .*|database = $TMP/state/psensd.db|; s|^scene = .*|scene = $TMP/example/ofb.scene|; s/^faults = .*//; s/^\[simulate\]/[simulate]\nyear = yes/" \
	config/psensd.conf > "$TMP/year.conf"
# hour M D H: "sensor task" of the results' hour (standard time, its middle)
hour() { awk -v m="$1" -v d="$2" -v h="$3" '/^\[year_hours\]/ { f = 1; next } /^\[/ { f = 0 }
	f && /^h[0-9]/ { split($0, kv, " = "); split(kv[2], v, " ")
		if (v[1] == m && v[2] == d && v[3] == h) { print v[4], v[5], v[8]; exit } }' "$R"; }
ES=$(awk '/^electric_sensor_response = / { print $3; exit }' "$R")
EL=$(awk '/^electric_task_lux = / { print $3; exit }' "$R")
check "the results carry the electric condition ($ES, $EL)" test -n "$ES" -a -n "$EL"
reg() {   # reg TYPE ADDR [mbpoll options]: one value
	_t=$1; _a=$2; shift 2
	mbpoll -m tcp -p "$port" -a 1 -0 -1 -q "$@" -t "$_t" -r "$_a" -c 1 127.0.0.1 | sed -n "s/^\[$_a\]:[[:space:]]*\([-0-9.]*\).*/\1/p"
}
# at DATE M D HH:MM: the registers against the hours H1 (and H2, averaged)
at() {
	date=$1 m=$2 d=$3 t=$4 h1=$5 h2=$6
	a=$(hour "$m" "$d" "$h1"); b=$(hour "$m" "$d" "$h2")
	check "$date: the results have hours $h1 and $h2 ($a; $b)" test -n "$a" -a -n "$b"
	s=$(echo "$a $b" | awk -v h1="$h1" -v h2="$h2" '{ print h1 == h2 ? $1 : ($1 + $4) / 2 }')
	l=$(echo "$a $b" | awk -v h1="$h1" -v h2="$h2" '{ print h1 == h2 ? $2 : ($2 + $5) / 2 }')
	g=$(echo "$a $b" | awk -v h1="$h1" -v h2="$h2" '{ print h1 == h2 ? $3 : ($3 + $6) / 2 }')
	port=$(free_port)
	rm -f "$TMP/ready"
	"$BIN/psvirt" -f "$TMP/year.conf" --date "$date" --start "$t" --speed 0 --tcp "127.0.0.1:$port" \
		--ready-file "$TMP/ready" -o noise=0 -o task_noise=0 -o fade_rate=0 -o lag_tau=0 \
		> "$TMP/pv.out" 2> "$TMP/pv.err" &
	pv=$!
	track_pid $pv
	check "$date $t: psvirt ready" wait_for 10 test -s "$TMP/ready"
	out=$(reg 4 202); truth=$(reg 4:float 203 -B); ai=$(reg 3 0); meter=$(reg 4:int 100 -B)
	roof=$(reg 4:int 210 -B); rooff=$(reg 4:float 212 -B)
	kill "$pv"; wait "$pv"
	o=$(awk -v o="$out" 'BEGIN { print o / 10000 }')
	want=$(awk -v l="$l" -v o="$o" -v e="$EL" 'BEGIN { printf "%.4f", l + o * e }')
	check "$date $t: truth $truth lx = $l + $o x $EL = $want" near "$truth" "$want" 0.01
	check "$date $t: meter $meter lx = the truth rounded" near "$meter" "$want" 0.51
	check "$date $t: rooftop $roof lx (u32) = the weather's $g lx" near "$roof" "$g" 0.51
	# mbpoll prints 6 significant digits: half a unit of the sixth (0.05 lx
	# at 10 to 100 klx, 0.5 lx above), plus the f32's own rounding
	tol=$(awk -v g="$g" 'BEGIN { printf "%g", 0.5 * 10 ^ (int(log(g) / log(10)) - 5) + 0.01 }')
	check "$date $t: rooftop $rooff lx (f32) = $g lx (within $tol)" near "$rooff" "$g" "$tol"
	wantv=$(awk -v s="$s" -v o="$o" -v e="$ES" 'BEGIN { v = 0.5 * (s + o * e); if (v > 10) v = 10; printf "%.1f", v / 10 * 65535 }')
	check "$date $t: sensor $ai counts = 0.5 x ($s + $o x $ES) V = $wantv" near "$ai" "$wantv" 1
}
at 07-05 7 5 12:30 12.5 12.5
at 07-05 7 5 13:00 12.5 13.5
at 01-12 1 12 12:30 12.5 12.5
at 01-12 1 12 13:00 12.5 13.5
# the two dates differ: the room plays the date, not one profile
j=$(hour 1 12 12.5); u=$(hour 7 5 12.5)
check "12 January and 5 July differ at 12:30 ($j; $u)" test "$j" != "$u"
done_testing
