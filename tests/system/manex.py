#!/usr/bin/python3
# SPDX-License-Identifier: ISC
# Every EXAMPLE(S) line of a man page, classified for 525-man-examples.sh.
#   manex.py PAGE...   prints one line a command: KIND<TAB>PAGE<TAB>TEXT
# KIND is RUN (run it; exit 0), BG (a server started with &: run in the
# background for the block's later lines), SERVER (runs until stopped:
# started, still running after a while, stopped), CONF (a configuration
# block, TEXT its file with \n for newlines: psensd -n checks it), END (the
# end of a block: stop its background servers), or SKIP:reason.  Lines of a
# block that are not commands (the output after a "$ " line) are not listed.
import re, sys

PROGRAMS = {'psens', 'mksens', 'psfilter', 'psscene', 'pssky', 'pspng', 'psshare',
            'psensd', 'psensctl', 'psvirt', 'psplace', 'mbpoll', 'socat', 'mkdir'}

def unroff(line):
    line = line.replace('\\\\', '\x00').replace('\\-', '-').replace('\\e', '\\').replace('\\&', '')
    line = line.replace('\x00', '\\')
    line = line.replace('\\(em', '--').replace('\\(mu', 'x')
    return re.sub(r'\\f[BIRP]', '', line)

def blocks(path):
    sec, block, out = None, None, []
    for raw in open(path).read().split('\n'):
        if raw.startswith('.SH'):
            sec = raw[4:].strip().strip('"')
            continue
        if sec not in ('EXAMPLE', 'EXAMPLES'):
            continue
        if raw.startswith('.nf'):
            block = []
        elif raw.startswith('.fi'):
            if block:
                out.append(block)
            block = None
        elif block is not None and not raw.startswith('.'):
            block.append(unroff(raw))
    return out

def joined(lines):
    """lines with their continuations (a trailing backslash) joined"""
    out, cur = [], None
    for l in lines:
        cur = l if cur is None else cur + ' ' + l.strip()
        if cur.endswith('\\'):
            cur = cur[:-1].rstrip()
            continue
        out.append(cur)
        cur = None
    if cur is not None:
        out.append(cur)
    return out

def kind(cmd):
    words = cmd.split()
    prog = words[0] if words else ''
    if prog == 'make':
        return 'SKIP:builds the tree and runs its simulated day: tests/system/091 runs it'
    if prog not in PROGRAMS and not cmd.startswith('echo '):
        return 'SKIP:%s is not a psensd program' % prog
    if cmd.rstrip().endswith('&'):
        return 'BG'
    if prog == 'psvirt' and '-h' not in words and '-V' not in words:
        return 'SERVER'
    if prog == 'psensd' and not {'-s', '-n', '-L', '-h', '-V'} & set(words):
        return 'SERVER'
    return 'RUN'

for page in sys.argv[1:]:
    for b in blocks(page):
        b = [l.strip() if l.lstrip().startswith(('$ ', '# ')) else l for l in b]
        prompt = any(l.startswith('$ ') or l.startswith('# ') for l in b)
        if prompt:
            cmds = []
            for l in joined(b):
                if l.startswith('$ '):
                    cmds.append(l[2:])
                elif l.startswith('# '):
                    print('SKIP:needs root (and systemd)\t%s\t%s' % (page, l[2:]))
            for c in cmds:
                print('%s\t%s\t%s' % (kind(c), page, c))
        elif b and b[0].split() and (b[0].split()[0] in PROGRAMS or b[0].split()[0] == 'make'):
            for c in joined(b):
                if c.strip():
                    print('%s\t%s\t%s' % (kind(c), page, c))
        elif any(re.match(r'\s*\[[a-z]', l) for l in b):
            print('CONF\t%s\t%s' % (page, '\\n'.join(b)))
        else:
            for l in b:
                if l.strip():
                    print('SKIP:not a command\t%s\t%s' % (page, l))
        print('END\t%s\t' % page)
