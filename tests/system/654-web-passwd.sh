#!/bin/sh
# SPDX-License-Identifier: ISC
# The web console's password file (psensd.conf(5) [web] password_file):
# a file that is not a hash, or a [web] without one, names the command
# that makes one (psensctl web-passwd FILE, an existing command); and
# psensctl web-passwd on a terminal asks twice and writes nothing when the
# two differ (a pseudo-terminal driven by python3).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h 2>&1 | grep -q "web:.*not compiled in" && skip_all "psensd is built without the web console"
command -v python3 > /dev/null || skip_all "python3 is not installed"
B=$(cd "$BIN" && pwd)
conf() {  # conf [web] LINES...
	psensd_section 60; loopback_office; cat <<EOC
[web]
bind = 127.0.0.1:$(free_port)
EOC
	for l in "$@"; do echo "$l"; done
}
echo "secret password" > "$TMP/clear.pass"; chmod 600 "$TMP/clear.pass"
conf "password_file = clear.pass" > "$TMP/clear.conf"
conf > "$TMP/none.conf"
cd "$TMP" || exit 1
"$B/psensd" -f clear.conf -n 2> err.clear; rc=$?
check "a password in clear is refused (exit $rc)" [ "$rc" -ne 0 ]
check "... naming psensctl web-passwd FILE" grep -q "psensctl web-passwd FILE" err.clear
check "... and no option psensd lacks" sh -c "! grep -q -- '--hash-password' err.clear"
"$B/psensd" -f none.conf -n 2> err.none; rc=$?
check "a [web] without password_file is refused (exit $rc)" [ "$rc" -ne 0 ]
check "... naming psensctl web-passwd FILE" grep -q "psensctl web-passwd FILE" err.none
# onterm.py PSENSCTL FILE ANSWER...: psensctl web-passwd FILE on a pseudo-terminal,
# each ANSWER typed at a prompt; prints the prompts and the exit status
cat > onterm.py <<'EOP'
import os, pty, sys
pid, fd = pty.fork()
if pid == 0:
    os.execv(sys.argv[1], [sys.argv[1], "web-passwd", sys.argv[2]])
out = b""
answers = sys.argv[3:]
# a prompt is answered once: only text after the last answer can be the
# next prompt (the newline psensctl writes after an answer would leave the
# old prompt at the end, and an answer typed before the next prompt's
# TCSAFLUSH is dropped: the run would hang)
since = 0
while True:
    try:
        b = os.read(fd, 1024)
    except OSError:
        break
    if not b:
        break
    out += b
    if answers and out[since:].rstrip().endswith(b":"):
        os.write(fd, answers.pop(0).encode() + b"\n")
        out += b"\n"
        since = len(out)
_, st = os.waitpid(pid, 0)
sys.stdout.write(out.decode(errors="replace"))
print("exit %d" % os.waitstatus_to_exitcode(st))
EOP
timeout 30 python3 onterm.py "$B/psensctl" mismatch.pass "lux meter 42" "lux meter 43" > tty.mismatch
check "on a terminal two different passwords are refused" grep -q "exit 1" tty.mismatch
check "... asked twice" sh -c "[ \$(grep -o -e \"the web console's password: \" -e 'the same password again: ' tty.mismatch | wc -l) -eq 2 ]"
check "... saying they differ" grep -q "differ" tty.mismatch
check "... and no file written" [ ! -e mismatch.pass ]
timeout 30 python3 onterm.py "$B/psensctl" same.pass "lux meter 42" "lux meter 42" > tty.same
check "the same password twice is written" sh -c "grep -q 'exit 0' tty.same && grep -q '^pbkdf2-sha256' same.pass"
printf 'lux meter 42\n' | "$B/psensctl" web-passwd piped.pass > /dev/null 2>&1
check "from a pipe one line is enough" grep -q '^pbkdf2-sha256' piped.pass
done_testing
