#!/usr/bin/python3
# SPDX-License-Identifier: ISC
# The options a program's --help names against those its man page names in
# SYNOPSIS and in the OPTIONS headings (the lines after .TP); a parenthesis
# in the help (old spellings, other programs' options) does not count.
#   opts.py PROGRAM MANPAGE   prints "help-only: ... man-only: ..." and exits 1 on a difference
import re, subprocess, sys

OPT = r'(?<![\w/\\-])(--[a-z][a-z0-9-]+|-[A-Za-z0-9])(?![\w-])'

def help_opts(prog):
    out = subprocess.run([prog, '--help'], capture_output=True, text=True).stdout
    # a parenthesis names old spellings or other programs' options
    return set(re.findall(OPT, re.sub(r'\([^()\n]*\)', '', out)))

def man_opts(path):
    lines = open(path).read().split('\n')
    found, sec = set(), None
    for i, line in enumerate(lines):
        if line.startswith('.SH'):
            sec = line[4:].strip().strip('"')
            continue
        text = re.sub(r'\\f[BIRP]', '', line.replace('\\-', '-').replace('\\e', ''))
        if sec == 'SYNOPSIS' or (sec == 'OPTIONS' and i > 0 and lines[i - 1].startswith('.TP')):
            found |= set(re.findall(OPT, text))
    return found

h, m = help_opts(sys.argv[1]), man_opts(sys.argv[2])
print('help-only: %s man-only: %s' % (' '.join(sorted(h - m)) or '-', ' '.join(sorted(m - h)) or '-'))
sys.exit(0 if h == m else 1)
