#!/usr/bin/env python3
# SPDX-License-Identifier: ISC
"""Stand-ins for Radiance's vwrays, rfluxmtx and rpict (called by the name
they are linked as), for tests on machines without Radiance.  Each checks
its command line as Radiance's manual pages define it and answers with
pictures made by the real programs: the placement fixture's.

  vwrays [-d | -ff] view options -x N -y N
      -d prints the dimensions as options ("-x N -y N -ld-"), -ff writes
      N x N rays (origin, direction) as raw floats (the origin the view's
      -vp, which is what lets rfluxmtx below find the pose).
  rfluxmtx [options] - receiver.rad -i system.oct
      options: -ffc (float rays in, RGBE pictures out), the -x -y (and -ld)
      vwrays -d printed, -o spec with a %d format, rcontrib's -ab -ad -as
      -aa -lw -lr -c -n; the sender '-' reads x * y rays (24 bytes each);
      the receiver's #@rfluxmtx h= lines give the bins (u 1, r1 or r 145,
      r2 577, kf 145); writes the fixture's dc_%03d.hdr of the pose whose
      position the rays start from, one picture a bin.
  rpict -vta -vp x y z -vd x y z -vu x y z -vh a -vv a -x N -y N [options] octree
      writes the pose's elec_128.hdr to standard output.

Environment: STUB_SRC the folder of the fixture's poses (pN/dc_*.hdr,
elec_128.hdr), STUB_CANDS their candidates.txt, STUB_LOG a folder where
each call appends a line to calls (program, pose, most renderers running
at once during it: counted at its start and at its end, so that two calls
that overlap at all are seen however late a loaded machine starts one) and keeps running/ up to date, STUB_SLEEP seconds each
rendering call lasts, STUB_FAIL a pose whose rfluxmtx or rpict (STUB_FAIL_PROG,
default rfluxmtx) fails half-way."""
import os
import re
import shutil
import struct
import sys
import time

prog = os.path.basename(sys.argv[0])
args = sys.argv[1:]


def die(msg):
    sys.stderr.write('%s (stub): %s\n' % (prog, msg))
    sys.exit(1)


def num(v, what):
    try:
        return float(v)
    except ValueError:
        die('%s: %r is not a number' % (what, v))


VIEW_ARITY = {'-vp': 3, '-vd': 3, '-vu': 3, '-vh': 1, '-vv': 1, '-vs': 1, '-vl': 1, '-vo': 1, '-va': 1}


def view_and_size(argv, allowed):
    """Parse view options, -x/-y and the other options in allowed (name: arity)."""
    view, opts, i = {}, {}, 0
    while i < len(argv):
        a = argv[i]
        if a in ('-vta', '-vtv', '-vth', '-vtl', '-vtc', '-vts', '-vtr'):
            view['type'] = a
            i += 1
        elif a in VIEW_ARITY:
            n = VIEW_ARITY[a]
            if i + n >= len(argv):
                die('%s needs %d value(s)' % (a, n))
            view[a] = [num(v, a) for v in argv[i + 1:i + 1 + n]]
            i += 1 + n
        elif a in allowed:
            n = allowed[a]
            if i + n >= len(argv) + (1 if n == 0 else 0):
                die('%s needs %d value(s)' % (a, n))
            opts[a] = argv[i + 1:i + 1 + n]
            i += 1 + n
        else:
            return view, opts, argv[i:]
    return view, opts, []


def check_view(view):
    for k in ('type', '-vp', '-vd', '-vu', '-vh', '-vv'):
        if k not in view:
            die('the view has no %s' % k)
    if view['type'] != '-vta':
        die('expected an angular fisheye (-vta), got %s' % view['type'])


def pose_at(pos):
    for line in open(os.environ['STUB_CANDS']):
        m = re.match(r'\s*(\S+)\s.*-vp\s+(\S+)\s+(\S+)\s+(\S+)', line)
        if m and all(abs(float(m.group(k + 2)) - pos[k]) < 1e-5 for k in range(3)):
            return m.group(1)
    die('no pose of the fixture at %r' % (pos,))


def log(pose, how):
    d = os.environ.get('STUB_LOG')
    if not d:
        return
    with open(os.path.join(d, 'calls'), 'a') as f:
        f.write('%s %s %s\n' % (prog, pose, how))


class Running:
    """A file in STUB_LOG/running/ while this call renders; the call logged
    at its end with the most calls seen running (of two that overlap, the
    one started first sees the other at its end, or the other, nested in
    it, saw it at its start)."""

    def __init__(self, pose):
        self.pose = pose

    def __enter__(self):
        d = os.path.join(os.environ.get('STUB_LOG', '/tmp'), 'running')
        os.makedirs(d, exist_ok=True)
        self.f = os.path.join(d, str(os.getpid()))
        open(self.f, 'w').close()
        time.sleep(0.05)
        self.n = len(os.listdir(d))
        return self

    def __exit__(self, *a):
        time.sleep(float(os.environ.get('STUB_SLEEP', '0')))
        n = max(self.n, len(os.listdir(os.path.dirname(self.f))))
        os.unlink(self.f)
        log(self.pose, n)


def fails(pose):
    return os.environ.get('STUB_FAIL') == pose and os.environ.get('STUB_FAIL_PROG', 'rfluxmtx') == prog


def vwrays():
    mode = None
    if args and args[0] in ('-d', '-ff', '-fa', '-fd'):
        mode = args[0]
    else:
        die('expected -d or -f{a,f,d} first')
    view, opts, rest = view_and_size(args[1:], {'-x': 1, '-y': 1, '-pa': 1, '-pj': 1})
    if rest:
        die('unexpected %r' % rest)
    check_view(view)
    x, y = int(opts.get('-x', ['512'])[0]), int(opts.get('-y', ['512'])[0])
    if mode == '-d':
        print('-x %d -y %d -ld-' % (x, y))
        return
    if mode != '-ff':
        die('only -ff is mimicked')
    ray = struct.pack('<6f', *(view['-vp'] + view['-vd']))
    out = sys.stdout.buffer
    for _ in range(x * y):
        out.write(ray)


RCONTRIB = {'-ffc': 0, '-x': 1, '-y': 1, '-ld-': 0, '-ld+': 0, '-o': 1, '-ab': 1, '-ad': 1, '-as': 1, '-aa': 1,
            '-lw': 1, '-lr': 1, '-c': 1, '-n': 1, '-v': 0}
BINS = {'u': 1, 'r': 145, 'r1': 145, 'r2': 577, 'kf': 145}


def rfluxmtx():
    view, opts, rest = view_and_size(args, RCONTRIB)
    if view:
        die('view options go to vwrays, not rfluxmtx')
    if '-ffc' not in opts:
        die('expected -ffc (float rays in, pictures out)')
    for k in ('-x', '-y', '-o'):
        if k not in opts:
            die('no %s' % k)
    spec = opts['-o'][0]
    if not re.search(r'%0?\d*d', spec):
        die('-o %s: no %%d format for the bins' % spec)
    if len(rest) != 4 or rest[0] != '-' or rest[2] != '-i':
        die('expected: - receiver.rad -i system.oct, got %r' % rest)
    receiver, octree = rest[1], rest[3]
    if not os.path.isfile(octree):
        die('%s: no such octree' % octree)
    bins = 0
    for line in open(receiver):
        m = re.match(r'#@rfluxmtx\s.*\bh=(\S+)', line)
        if m:
            if m.group(1) not in BINS:
                die('%s: h=%s is not mimicked' % (receiver, m.group(1)))
            bins += BINS[m.group(1)]
    if not bins:
        die('%s: no #@rfluxmtx h= line' % receiver)
    x, y = int(opts['-x'][0]), int(opts['-y'][0])
    data = sys.stdin.buffer.read()
    if len(data) != x * y * 24:
        die('read %d bytes of rays, expected %d x %d x 24' % (len(data), x, y))
    pose = pose_at(struct.unpack('<3f', data[:12]))
    src = os.path.join(os.environ['STUB_SRC'], pose)
    with Running(pose):
        for b in range(bins):
            if fails(pose) and b == 10:
                die('simulated failure')
            shutil.copyfile(os.path.join(src, 'dc_%03d.hdr' % b), spec % b)


def rpict():
    view, opts, rest = view_and_size(args, {'-x': 1, '-y': 1, '-ab': 1, '-ad': 1, '-as': 1, '-aa': 1, '-lw': 1,
                                            '-lr': 1, '-ps': 1, '-pt': 1, '-pj': 1, '-dj': 1})
    check_view(view)
    if len(rest) != 1 or not os.path.isfile(rest[0]):
        die('expected one octree last, got %r' % rest)
    if opts.get('-x') != ['128'] or opts.get('-y') != ['128']:
        die('the fixture\'s electric pictures are 128 x 128, asked %r' % opts)
    pose = pose_at(view['-vp'])
    with Running(pose):
        data = open(os.path.join(os.environ['STUB_SRC'], pose, 'elec_128.hdr'), 'rb').read()
        if fails(pose):
            sys.stdout.buffer.write(data[:len(data) // 2])
            die('simulated failure')
        sys.stdout.buffer.write(data)


{'vwrays': vwrays, 'rfluxmtx': rfluxmtx, 'rpict': rpict}.get(prog, lambda: die('unknown name'))()
