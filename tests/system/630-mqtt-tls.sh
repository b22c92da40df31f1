#!/bin/sh
# SPDX-License-Identifier: ISC
# MQTT over TLS against a real mosquitto: a CA, a server certificate for
# 127.0.0.1 and a client certificate made here with openssl; the broker
# requires the client certificate and a user and password (mosquitto_passwd).
# psensd -n refuses a group- or world-writable password file (file:line),
# and psensd a world-readable one (its mode named), as ssh does with keys;
# the right password publishes; a wrong one is refused by the broker and
# psensd goes on controlling without publishing.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h | grep -q "^mqtt: .*not compiled in" && skip_all "psensd built without MQTT (WITH_MQTT=no)"
MOSQ=$(command -v mosquitto || echo /usr/sbin/mosquitto)
[ -x "$MOSQ" ] || skip_all "mosquitto not installed"
command -v mosquitto_sub > /dev/null || skip_all "mosquitto-clients not installed"
command -v openssl > /dev/null || skip_all "openssl not installed"
example_results
C="$TMP/pki"; mkdir -p "$C"
(
	cd "$C" || exit 1
	openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=psensd-test-ca -keyout ca.key -out ca.crt
	openssl req -newkey rsa:2048 -nodes -subj /CN=127.0.0.1 -keyout server.key -out server.csr
	printf 'subjectAltName=IP:127.0.0.1\n' > san.ext
	openssl x509 -req -in server.csr -CA ca.crt -CAkey ca.key -CAcreateserial -days 2 -extfile san.ext -out server.crt
	openssl req -newkey rsa:2048 -nodes -subj /CN=psensd -keyout client.key -out client.csr
	openssl x509 -req -in client.csr -CA ca.crt -CAkey ca.key -CAcreateserial -days 2 -out client.crt
) > "$TMP/openssl.log" 2>&1
check "openssl made a CA, a server and a client certificate" test -s "$C/client.crt" -a -s "$C/server.crt"
chmod 644 "$C"/*.key
mosquitto_passwd -b -c "$TMP/passwd" psensd right-secret 2> /dev/null
mosquitto_passwd -b "$TMP/passwd" watcher watch 2> /dev/null
P=$(free_port)
cat > "$TMP/mosquitto.conf" << EOC
listener $P 127.0.0.1
cafile $C/ca.crt
certfile $C/server.crt
keyfile $C/server.key
require_certificate true
allow_anonymous false
password_file $TMP/passwd
user $(id -un)
EOC
"$MOSQ" -c "$TMP/mosquitto.conf" 2> "$TMP/mosquitto.err" & track_pid $!
TLS="-h 127.0.0.1 -p $P --cafile $C/ca.crt --cert $C/client.crt --key $C/client.key"
wait_for 5 mosquitto_pub $TLS -u watcher -P watch -t probe -n
check "mosquitto speaks TLS on 127.0.0.1:$P" mosquitto_pub $TLS -u watcher -P watch -t probe -n
check "it refuses a client without a password" sh -c "! mosquitto_pub $TLS -t probe -n 2> /dev/null"

conf() {   # conf PASSWORD
	printf '%s\n' "$1" > "$TMP/secret"; chmod 600 "$TMP/secret"
	sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/psensd.db\nsocket = $TMP/sock|; /^faults = /d" \
		config/psensd.conf > "$TMP/psensd.conf"
	printf '\n[mqtt]\nhost = 127.0.0.1\nport = %s\nsite = tls\nuser = psensd\npassword_file = secret\ncafile = pki/ca.crt\ncertfile = pki/client.crt\nkeyfile = pki/client.key\n' "$P" >> "$TMP/psensd.conf"
}
conf right-secret
check "psensd -n accepts the [mqtt] section" sh -c "\"$BIN/psensd\" -n -f \"$TMP/psensd.conf\" > /dev/null"
line=$(grep -n '^password_file' "$TMP/psensd.conf" | cut -d: -f1)
chmod 620 "$TMP/secret"
"$BIN/psensd" -n -f "$TMP/psensd.conf" > /dev/null 2> "$TMP/n.err"; rc=$?
check "a group-writable password file: refused at $TMP/psensd.conf:$line ($(cat "$TMP/n.err"))" \
	sh -c "[ $rc = 1 ] && grep -q 'psensd.conf:$line: password_file: .* is writable by its group' '$TMP/n.err'"
chmod 602 "$TMP/secret"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > /dev/null 2> "$TMP/ww.err"; rc=$?
check "a world-writable one: psensd will not start (exit $rc)" sh -c "[ $rc = 1 ] && grep -q 'writable by everyone' '$TMP/ww.err'"
# as ssh does with a private key: a password everyone may read is refused at start,
# with the file and its mode named; one its group may read (640) is accepted
chmod 604 "$TMP/secret"
timeout 20 "$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > /dev/null 2> "$TMP/wr.err"; rc=$?
check "a world-readable one: psensd will not start (exit $rc: $(cat "$TMP/wr.err"))" \
	sh -c "[ $rc = 1 ] && grep -q 'psensd.conf:$line: password_file: .*/secret is readable by everyone (mode 0604)' '$TMP/wr.err'"
chmod 640 "$TMP/secret"
check "a group-readable one (640): accepted" sh -c "\"$BIN/psensd\" -n -f \"$TMP/psensd.conf\" > /dev/null"
chmod 600 "$TMP/secret"

mosquitto_sub $TLS -u watcher -P watch -q 1 -v -t 'psensd/tls/#' > "$TMP/sub.log" &
track_pid $!
# subscribed before psensd publishes its first sample
wait_for 10 sh -c "mosquitto_pub $TLS -u watcher -P watch -t psensd/tls/probe -m x && grep -q '^psensd/tls/probe' '$TMP/sub.log'"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > /dev/null 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 grep -q '^psensd/tls/office/state' "$TMP/sub.log"
check "the right password and certificate: samples arrive over TLS" grep -q '^psensd/tls/office/state {"id":1,' "$TMP/sub.log"
check "status online" grep -q '^psensd/tls/status online' "$TMP/sub.log"
kill $PID; wait $PID; rc=$?
check "psensd exits 0 on SIGTERM (no sanitizer report)" test "$rc" = 0

conf wrong-secret
sleep 0.5
: > "$TMP/sub.log"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > /dev/null 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 grep -q "refused the connection" "$TMP/err"
check "a wrong password: the broker refuses ($(grep -o 'refused the connection.*' "$TMP/err" | head -n 1))" \
	grep -q "refused the connection: .*\(not authorised\|Bad user\)" "$TMP/err"
sleep 1
check "nothing is published with it" test ! -s "$TMP/sub.log"
check "psensd goes on controlling" sh -c "\"$BIN/psensctl\" -s \"$TMP/sock\" status office > /dev/null"
kill $PID; wait $PID; rc=$?
check "and exits 0 on SIGTERM" test "$rc" = 0
done_testing
