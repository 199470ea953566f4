#!/usr/bin/env python3
"""Writes the .ps11test files of this folder (run by hand: python3 generate.py; CI only runs the
files). Two kinds of expectations, kept apart in every file:

* hardware results: colours Windows drivers produced in Wine's d3d9/d3d8 visual tests
  (dlls/d3d9/tests/visual.c at wine-9.7-99-g25c58e68876: test_signed_formats, cnd_test,
  constant_clamp_ps_test, test_color_clamping, projected_textures_test), copied from the tests'
  tables with the tests' own tolerances, for the classes that stand for that hardware;
* model results: what docs/precision.md's rules give for the classes no public measurement covers
  (geforce3/geforce4 never ran these tests: they need ps_1_4), computed here in Python from the
  written rules (exact integers for fx8/fx12, float32 for float), independently of the C++ code.
"""
import os
import struct
from fractions import Fraction

HERE = os.path.dirname(os.path.abspath(__file__))


def f32(x):
    return struct.unpack('f', struct.pack('f', float(x)))[0]


def rhe(q):
    """round half to even of a Fraction."""
    fl = q.numerator // q.denominator
    r = q - fl
    if r > Fraction(1, 2) or (r == Fraction(1, 2) and fl % 2 == 1):
        fl += 1
    return fl


# ---- signed decode rules (docs/precision.md "Signed texels") ----
def decode(rule, s, bits):
    top = 1 << (bits - 1)
    if rule == 'snorm':
        return Fraction(max(s, -(top - 1)), top - 1)
    if rule == 'unclamped':
        return Fraction(s, top - 1)
    if rule == 'asymmetric':
        return Fraction(s, top if s < 0 else top - 1)
    if rule == 'widen8':
        if bits >= 8:
            return decode('snorm', s, bits)
        u = s & ((1 << bits) - 1)
        wide, filled = 0, 0
        while filled < 8:
            wide = (wide << bits) | u
            filled += bits
        wide >>= filled - 8
        s8 = wide - 256 if wide & 0x80 else wide
        return decode('snorm', s8, 8)
    raise ValueError(rule)


CLASSES = {
    # name: (profile, MaxValue, signed rule)
    'geforce4': ('fx8', 1, 'snorm'),
    'geforce3': ('fx8', 1, 'snorm'),
    'radeon8500': ('fx12', 8, 'unclamped'),
    'd3d9': ('float', 65504, 'asymmetric'),
    'geforce7': ('float', 65504, 'widen8'),
}
GRID = {'fx8': 255, 'fx12': 4080}


class Machine:
    """Register values of one profile: grid integers (fx) or float32 (float)."""

    def __init__(self, cls):
        self.profile, self.maxv, self.rule = CLASSES[cls]
        self.fx = self.profile in GRID
        self.G = GRID.get(self.profile, 1)

    def clamp(self, v):
        if self.fx:
            m = rhe(Fraction(self.maxv) * self.G)
            return max(-m, min(m, v))
        return max(-f32(self.maxv), min(f32(self.maxv), v))

    def const(self, c):  # constants: clamped to [-1, 1] on load, fx: rounded to the grid
        c = max(-1.0, min(1.0, c))
        return rhe(Fraction(c) * self.G) if self.fx else f32(c)

    def texel(self, value):  # a sampled value (Fraction), clamped to ±M like a register
        return self.clamp(rhe(value * self.G) if self.fx else f32(float(value)))

    def mad(self, a, b, c):
        if self.fx:  # (k0·k1 + 2G·k2)/(4G²) with k = 2n, rounded once
            return self.clamp(rhe(Fraction(a * b + self.G * c, self.G)))
        return self.clamp(f32(f32(a * b) + c))

    def mul(self, a, b):
        return self.clamp(rhe(Fraction(a * b, self.G))) if self.fx else self.clamp(f32(a * b))

    def add(self, a, b):
        return self.clamp(a + b) if self.fx else self.clamp(f32(a + b))

    def neg(self, a):
        return -a

    def gt_half(self, a):  # cnd's r0.a > 0.5
        return 2 * a > self.G if self.fx else a > 0.5

    def byte(self, v):  # an 8-bit render-target write
        if self.profile == 'fx8':
            return max(0, min(255, v))
        if self.profile == 'fx12':
            return rhe(Fraction(max(0, min(4080, v)), 16))
        return rhe(Fraction(max(0.0, min(1.0, v))) * 255)


def sext(v, bits):
    v &= (1 << bits) - 1
    return v - (1 << bits) if v & (1 << (bits - 1)) else v


# ---- formats: word -> per channel ('s', code, bits) signed or ('u', num, den) ----
def channels(fmt, w):
    one = ('u', 1, 1)
    if fmt == 'V8U8':
        return [('s', sext(w, 8), 8), ('s', sext(w >> 8, 8), 8), one, one]
    if fmt == 'V16U16':
        return [('s', sext(w, 16), 16), ('s', sext(w >> 16, 16), 16), one, one]
    if fmt == 'Q8W8V8U8':
        return [('s', sext(w >> (8 * i), 8), 8) for i in range(4)]
    if fmt == 'X8L8V8U8':
        return [('s', sext(w, 8), 8), ('s', sext(w >> 8, 8), 8), ('u', (w >> 16) & 0xff, 255), one]
    if fmt == 'L6V5U5':
        return [('s', sext(w, 5), 5), ('s', sext(w >> 5, 5), 5), ('u', (w >> 10) & 63, 63), one]
    raise ValueError(fmt)


def value(rule, ch):
    return decode(rule, ch[1], ch[2]) if ch[0] == 's' else Fraction(ch[1], ch[2])


# ---- Wine's test_signed_formats data (texel rows, expected tables, tolerances) ----
SIGNED = {
    'V8U8': ([[0x0000, 0x7f7f, 0x8880, 0x0000], [0x0080, 0x8000, 0x7f00, 0x007f],
              [0x193b, 0xe8c8, 0x0808, 0xf8f8], [0x4444, 0xc0c0, 0xa066, 0x22e0]], 1, 0, False),
    'V16U16': ([[0x00000000, 0x7fff7fff, 0x88008000, 0x00000000], [0x00008000, 0x80000000, 0x7fff0000, 0x00007fff],
                [0x19993bbb, 0xe800c800, 0x08880888, 0xf800f800], [0x44444444, 0xc000c000, 0xa0006666, 0x2222e000]],
               1, 0, False),
    'Q8W8V8U8': ([[0x00000000, 0xff7f7f7f, 0x7f008880, 0x817f0000], [0x10000080, 0x20008000, 0x30007f00, 0x4000007f],
                  [0x5020193b, 0x6028e8c8, 0x70020808, 0x807ff8f8], [0x90414444, 0xa000c0c0, 0x8261a066, 0x834922e0]],
                 1, 0, True),
    'X8L8V8U8': ([[0x00000000, 0x00ff7f7f, 0x00008880, 0x00ff0000], [0x00000080, 0x00008000, 0x00007f00, 0x0000007f],
                  [0x0041193b, 0x0051e8c8, 0x00040808, 0x00fff8f8], [0x00824444, 0x0000c0c0, 0x00c2a066, 0x009222e0]],
                 1, 0, True),
    'L6V5U5': ([[0x0000, 0xfdef, 0x0230, 0xfc00], [0x0010, 0x0200, 0x01e0, 0x000f],
                [0x4067, 0x53b9, 0x0421, 0xffff], [0x8108, 0x0318, 0xc28c, 0x909c]], 4, 7, True),
}
EXPECTED = [[0x808080, 0xfefeff, 0x010780, 0x8080ff], [0x018080, 0x800180, 0x80fe80, 0xfe8080],
            [0xba98a0, 0x4767a8, 0x888881, 0x7878ff], [0xc3c3c0, 0x3f3f80, 0xe51fe1, 0x5fa2c8]]
EXPECTED_ALPHA = [[0x808000, 0x7f7f00, 0xffff00, 0x000000], [0x909000, 0xa0a000, 0xb0b000, 0xc0c000],
                  [0xd0d000, 0xe0e000, 0xf0f000, 0x000000], [0x101000, 0x202000, 0x010100, 0x020200]]
# GeForce 7 (Wine's comment in test_signed_formats): L6V5U5 U/V 15 -> 0xfb, -7 -> 0x4d, -3 -> 0x6e.
GEFORCE7_L6V5U5 = {15: 0xfb, -7: 0x4d, -3: 0x6e}


# The shader of test_signed_formats: r0 = t0 · 0.5 + 0.5.
SIGNED_SHADER = """[pixel shader]
ps_1_1
def c0, 0.5, 0.5, 0.5, 0.5
tex t0
mad r0, t0, c0, c0
"""


def madsigned(cls, fmt, w):
    m = Machine(cls)
    c = m.const(0.5)
    chans = channels(fmt, w)
    return [m.byte(m.mad(m.texel(value(m.rule, ch)), c, c)) for ch in chans]


def rgbword(b):
    return (b[0] << 16) | (b[1] << 8) | b[2]


def texture_block(fmt, rows, digits):
    out = ['[texture 0]', 'size 4 4', 'format ' + fmt, 'level 0']
    for r in rows:
        out.append(' '.join('0x%0*x' % (digits, w) for w in r))
    return '\n'.join(out)


def write(name, text):
    with open(os.path.join(HERE, name), 'w') as f:
        f.write(text)


def signed_file(fmt):
    rows, slop, slop_broken, blue = SIGNED[fmt]
    digits = 4 if fmt in ('V8U8', 'L6V5U5') else 8
    lines = []
    # Hardware: the classes that stand for D3D9-class parts and the R200 ran the test on Windows.
    for y in range(4):
        for x in range(4):
            want = EXPECTED[y][x] | (0 if blue else 0xff)
            cls = 'd3d9'
            lines.append('if(%s) probe %d %d rgb 0x%06x tol %d' % (cls, x, y, want, slop))
    # geforce7: the table with the broken slop, and the three values Wine's comment records.
    for y in range(4):
        for x in range(4):
            want = EXPECTED[y][x] | (0 if blue else 0xff)
            tol = slop_broken if fmt == 'L6V5U5' else slop
            lines.append('if(geforce7) probe %d %d rgb 0x%06x tol %d' % (x, y, want, tol))
    if fmt == 'L6V5U5':
        for y in range(4):
            for x in range(4):
                w = rows[y][x]
                u, v = sext(w, 5), sext(w >> 5, 5)
                for ch, s in ((0, u), (1, v)):
                    if s in GEFORCE7_L6V5U5:
                        # One channel of the pixel: compare only it (the other channels as modelled).
                        model = madsigned('geforce7', fmt, w)
                        model[ch] = GEFORCE7_L6V5U5[s]
                        lines.append('if(geforce7) probe %d %d rgb 0x%06x tol 1   %% Wine: GeForce 7 gives 0x%02x for %d'
                                     % (x, y, rgbword(model), GEFORCE7_L6V5U5[s], s))
    # radeon8500: R200 hardware ran the test (Wine marks its Q = -128 result broken, see the alpha
    # file); the table with the test's tolerance (broken slop for L6V5U5, whose R200 result no
    # comment records).
    for y in range(4):
        for x in range(4):
            want = EXPECTED[y][x] | (0 if blue else 0xff)
            tol = slop_broken if fmt == 'L6V5U5' else slop
            lines.append('if(radeon8500) probe %d %d rgb 0x%06x tol %d' % (x, y, want, tol))
    # Model: the 1.1-class cards, exact.
    for y in range(4):
        for x in range(4):
            lines.append('if(geforce4, geforce3) probe %d %d rgb 0x%06x tol 0'
                         % (x, y, rgbword(madsigned('geforce4', fmt, rows[y][x]))))
    # Every class agrees with its own model exactly (the model values of the hardware classes
    # lie within the tolerances above; these pin the rule itself).
    for cls in ('d3d9', 'geforce7', 'radeon8500'):
        for y in range(4):
            for x in range(4):
                lines.append('if(%s) probe %d %d rgb 0x%06x tol 0' % (cls, x, y, rgbword(madsigned(cls, fmt, rows[y][x]))))
    header = f"""% Wine's test_signed_formats ({fmt}): `mad r0, t0, c0, c0` (c0 = 0.5) over a 4x4 {fmt} texture,
% point-sampled 1:1, probed at every texel (dlls/d3d9/tests/visual.c, wine-9.7-99-g25c58e68876).
% Hardware results (the test's table, tolerance {slop}{', broken slop %d' % slop_broken if slop_broken else ''}): d3d9, and radeon8500 and geforce7
% where Wine records how those parts differ. Model results (exact, tests/shaders/hardware/
% generate.py from docs/precision.md "Signed texels"): geforce4/geforce3 (no public measurement:
% the test needs ps_1_4), and every class's own rule at tol 0.
% ps11 test --hardware CLASS runs one class (ctest runs the folder once per class).
"""
    text = header + f"""
[render target]
size 4 4

{texture_block(fmt, rows, digits)}

{SIGNED_SHADER}
[test]
draw quad
""" + '\n'.join(lines) + '\n'
    write('signed_%s.ps11test' % fmt.lower(), text)


def alpha_file():
    rows = SIGNED['Q8W8V8U8'][0]

    def run(cls, w):
        m = Machine(cls)
        c0, one, zero = m.const(0.5), m.const(1.0), m.const(0.0)
        a = m.texel(value(m.rule, channels('Q8W8V8U8', w)[3]))
        rgb = m.mad(a, c0, c0)                        # mad r0.rgb, t0.a, c0, c0
        ra = m.add(m.neg(a), m.neg(c0))               # sub r0.a, -t0.a, c0
        ra = one if m.gt_half(ra) else zero           # cnd r0.a, r0.a, c1.a, c2.a
        r1 = m.mul(one, rgb)                          # mul r1.rgb, c1, r0 (c1.rg = 1)
        red = m.mad(ra, zero, r1)                     # mad r0.rgb, r0.a, c2, r1
        blue = m.mad(ra, one, m.mul(zero, rgb))
        return [m.byte(red), m.byte(red), m.byte(blue)]

    lines = []
    for y in range(4):
        for x in range(4):
            if (y, x) == (2, 3):
                continue
            lines.append('if(d3d9, geforce7, radeon8500) probe %d %d rgb 0x%06x tol 1' % (x, y, EXPECTED_ALPHA[y][x]))
    lines.append('if(d3d9, geforce7) probe 3 2 rgb 0x000000 tol 1   % Q = -128 reads -1.0 exactly')
    lines.append('if(radeon8500) probe 3 2 rgb 0x0000ff tol 0   % r200: -128/127 < -1 survives, cnd fires')
    for cls in ('geforce4', 'radeon8500', 'd3d9', 'geforce7'):
        cond = 'geforce4, geforce3' if cls == 'geforce4' else cls
        for y in range(4):
            for x in range(4):
                lines.append('if(%s) probe %d %d rgb 0x%06x tol 0' % (cond, x, y, rgbword(run(cls, rows[y][x]))))
    text = """% Wine's test_signed_formats, alpha shader, Q8W8V8U8: the Q channel into r and g, and blue = 1
% exactly when the sampled alpha is below -1.0 (dlls/d3d9/tests/visual.c, wine-9.7-99-g25c58e68876).
% Hardware: the table (tol 1) on d3d9, geforce7 and radeon8500, except texel (3, 2) (Q = -128):
% 0x000000 on correct parts; Wine's comment: "AMD's r200 is broken though and returns a value
% < -1.0 for -128", which with its [-8, 8] registers makes the cnd fire (blue). Model rows (tol 0,
% generate.py): every class's own rule.

[render target]
size 4 4

""" + texture_block('Q8W8V8U8', rows, 8) + """

[pixel shader]
ps_1_1
def c0, 0.5, 0.5, 0.5, 0.5
def c1, 1.0, 1.0, 0.0, 1.0
def c2, 0.0, 0.0, 1.0, 0.0
tex t0
mad r0.rgb, t0.a, c0, c0
sub r0.a, -t0.a, c0
cnd r0.a, r0.a, c1.a, c2.a
mul r1.rgb, c1, r0
mad r0.rgb, r0.a, c2, r1

[test]
draw quad
""" + '\n'.join(lines) + '\n'
    write('signed_q8w8v8u8_alpha.ps11test', text)


# ---- Wine's cnd_test: plain, co-issued colour cnd, co-issued alpha cnd with r1 = c0 + c0 = 2 ----
CND_SHADERS_13 = {
    'plain': """def c0, 1, 0, 0, 0
texcoord t0
mov r0, t0
dp3 r1, r0, c0
mov r0.a, r1.a
cnd r0, r0.a, c1, c2""",
    'coissue': """def c0, 1, 0, 0, 0
def c3, 0.5, 0.5, 0.5, 0
texcoord t0
mov r0, t0
sub r0, r0, c3
add r1, c0, c0
dp3 r1, r0, r1
mov r0.a, r1.a
+cnd r0.xyz, r0.a, c1, c2""",
    'coissue_alpha': """def c0, 1, 0, 0, 0
def c3, 0.5, 0.5, 0.5, 0
texcoord t0
mov r0, t0
sub r0, r0, c3
add r1, c0, c0
dp3 r1, r0, r1
mov r0, r1
mov r0.xyz, r1.a
+cnd r0.a, r0.a, c1, c2
mov r0.xyz, r0.a""",
}
CND_SHADERS_14 = {
    'plain': """def c0, 0, 0, 0, 1
texcrd r0.xyz, t0
mov r0.a, c0.a
cnd r0, r0, c1, c2""",
    'coissue': """def c0, 0, 0, 0, 1
texcrd r0.xyz, t0
mov r0.a, c0.a
+cnd r0.xyz, r0, c1, c2""",
    'coissue_alpha': """def c0, 0, 0, 0, 1
texcrd r0.xyz, t0
mov r0.a, r0.x
mov r1.xyz, c0.a
+cnd r1.a, r0.a, c1, c2
mov r0.xyz, r1.a
mov r0.a, c0.a""",
}
CND_CONSTS = {'plain': ((0, 0, 0, 0), (1, 1, 1, 1)), 'coissue': ((0, 1, 0, 0), (1, 0, 1, 1)),
              'coissue_alpha': ((0, 1, 0, 0), (1, 0, 1, 1))}
D3D9_CLASSES = 'd3d9, geforce7, radeon8500'  # every class that runs ps_1_4 ran cnd_test's hardware


def cnd_probes(kind, minor):
    """(condition, x, y, rgb, tol, comment) of one quadrant 320x240, Wine's probe points moved
    into it (x 158/162 -> u 0.494/0.506, x 238/242 -> u 0.744/0.756; y 118/122 -> v 0.508/0.492)."""
    P = []
    if minor == 4:
        table = {'plain': {(158, 118): 0xff00ff, (162, 118): 0x0000ff, (158, 122): 0xffffff, (162, 122): 0x00ffff},
                 'coissue': {(158, 118): 0xffffff, (162, 118): 0x00ffff, (158, 122): 0xff00ff, (162, 122): 0x0000ff},
                 'coissue_alpha': {(158, 118): 0xffffff, (158, 122): 0xffffff, (162, 118): 0x000000,
                                   (162, 122): 0x000000}}[kind]
        for (x, y), c in table.items():
            P.append(('', x, y, c, 0, 'Wine (exact), every ps_1_4 part'))
        return P
    if kind == 'plain':
        for y in (118, 122):
            P.append(('', 158, y, 0xffffff, 0, 'Wine (exact): u < 0.5 -> c2'))
            P.append(('', 162, y, 0x000000, 1, 'Wine (+-1): u > 0.5 -> c1'))
    elif kind == 'coissue':
        for x in (158, 162):
            for y in (118, 122):
                P.append((D3D9_CLASSES.replace('geforce7, ', ''), x, y, 0x00ff00, 1,
                          'Wine: a co-issued colour cnd always gives c1'))
                P.append(('geforce7', x, y, 0xff00ff, 1, 'Wine: "The Win7 nvidia driver always selects c2"'))
                P.append(('geforce4, geforce3', x, y, 0x00ff00, 0,
                          'model: parallel read of r0.a = 1 (texcoord w) -> c1'))
    else:
        for y in (118, 122):
            P.append((D3D9_CLASSES, 238, y, 0xffffff, 1, 'Wine: 2u - 1 < 0.5 -> c2.a'))
            P.append((D3D9_CLASSES, 242, y, 0x000000, 1, 'Wine: 2u - 1 > 0.5 (needs r1 = 2.0) -> c1.a'))
            P.append(('geforce4, geforce3', 238, y, 0xffffff, 0, 'model: MaxValue 1 clamps c0 + c0 to 1'))
            P.append(('geforce4, geforce3', 242, y, 0xffffff, 0, 'model: u - 0.5 never exceeds 0.5'))
    return P


def cnd_file(kind, minor):
    body = (CND_SHADERS_14 if minor == 4 else CND_SHADERS_13)[kind]
    c1, c2 = CND_CONSTS[kind]
    lines = []
    for cond, x, y, c, tol, why in cnd_probes(kind, minor):
        prefix = 'if(%s) ' % cond if cond else ''
        lines.append('%sprobe %d %d rgb 0x%06x tol %d   %% %s' % (prefix, x, y, c, tol, why))
    text = f"""% Wine's cnd_test, {kind.replace('_', ' ')} pass, ps_1_{minor} (dlls/d3d9/tests/visual.c,
% wine-9.7-99-g25c58e68876; the d3d8 test has the same shaders and results). One quadrant of the
% test's 640x480 target: 320x240, u = x/320 left to right, v = 0 at the bottom, as the test's quad
% gives at D3D9 pixel centres. Hardware rows carry the test's tolerance; model rows (1.1-class
% cards, which never ran the test: it needs ps_1_4) say what docs/precision.md's rules give.
% Run per class with ps11 test --hardware CLASS (ctest does).

[render target]
size 320 240
clear 0xff00ffff

[constants]
c1 {' '.join(str(v) for v in c1)}
c2 {' '.join(str(v) for v in c2)}

[pixel shader]
ps_1_{minor}
{body}

[test]
draw strip xyzrhw
  0 0 0.1 1  0xffffffff 0  t0 0 1
  320 0 0.1 1  0xffffffff 0  t0 1 1
  0 240 0.1 1  0xffffffff 0  t0 0 0
  320 240 0.1 1  0xffffffff 0  t0 1 0
""" + '\n'.join(lines) + '\n'
    write('cnd_%s_ps1%d.ps11test' % (kind, minor), text)


# ---- constant_clamp_ps_test: constants read as clamp(c, -1, 1) in every ps_1_x ----
def constant_clamp_file(minor):
    shader = 'mov r1, c1\nadd r0, r1, c2'
    if minor == 4:
        shader = 'def c2, -0.5, 1.25, 2, 1\n' + shader
    text = f"""% Wine's constant_clamp_ps_test, ps_1_{minor} (dlls/d3d9/tests/visual.c, wine-9.7-99-g25c58e68876):
% c1 = (1.25, -0.5, -1.5, 1) and c2 = (-0.5, 1.25, 2, 1) read as clamp(c, -1, 1) in every ps_1_x
% {'(the def too: "It gets clamped too, although the binary contains the bigger numbers")' if minor == 4 else ''}
% so r0 = (0.5, 0.5, 0): 0x808000 +-1 on the hardware that ran it, and on every class here
% (constants are clamped on load in every profile, docs/precision.md "Inputs").

[render target]
size 4 4
clear 0xff00ffff

[constants]
c1 1.25 -0.5 -1.5 1
c2 -0.5 1.25 2 1

[pixel shader]
ps_1_{minor}
{shader}

[test]
draw quad
probe all rgb 0x808000 tol 1
"""
    write('constant_clamp_ps1%d.ps11test' % minor, text)


# ---- test_color_clamping: v0 + v1 = 2 survives in a ps_1_1 temporary on D3D9-class parts ----
def color_clamping_file():
    text = """% Wine's test_color_clamping (dlls/d3d9/tests/visual.c, wine-9.7-99-g25c58e68876; d3d8 the same):
% `add r0, v0, v1; mul r0, r0, c0` with c0 = 0.25. Left half: diffuse and specular white (the
% test's vs_1_1 case: oD0 = oD1 = 2.0 arrive clamped to 1), so r0 = 2 · 0.25 = 0.5: 0x7f7f7f +-1
% on every part that ran it (no broken() alternative): ps_1_1 temporaries keep 2.0. Right half:
% specular black (the fixed-function vertex case), 1 · 0.25: 0x404040 everywhere. Model rows:
% the 1.1-class cards clamp v0 + v1 to MaxValue 1, so the left half is 0x404040 there.

[render target]
size 8 4
clear 0xff000000

[pixel shader]
ps_1_1
def c0, 0.25, 0.25, 0.25, 0.25
add r0, v0, v1
mul r0, r0, c0

[test]
draw quad diffuse 0xffffffff specular 0xffffffff rect 0 0 4 4
draw quad diffuse 0xffffffff specular 0x00000000 rect 4 0 8 4
if(d3d9, geforce7, radeon8500) probe rect 0 0 4 4 rgb 0x7f7f7f tol 1
if(geforce4, geforce3) probe rect 0 0 4 4 rgb 0x404040 tol 0
probe rect 4 0 8 4 rgb 0x404040 tol 1
"""
    write('color_clamping_ps11.ps11test', text)


# ---- projected_textures_test: D3DTTFF_PROJECTED through ps_1_3 tex and the fixed function ----
PROJ_RUNS = [
    # (name, flags, texcoord components, pixel shader?, quadrant, white rect l t r b, Wine's message)
    ('count4_projected', 'count4 projected', 4, True, 0, (120, 300, 240, 390), 'D3DTTFF_COUNT4 | D3DTTFF_PROJECTED'),
    ('count3_projected', 'count3 projected', 4, True, 1, (400, 360, 480, 420), 'D3DTTFF_COUNT3 | D3DTTFF_PROJECTED'),
    ('ffffffff_4', '0xffffffff', 4, True, 2, (120, 60, 240, 150), '0xffffffff (draws like COUNT4 | PROJECTED)'),
    ('count3_projected_2', 'count3 projected', 2, True, 3, (340, 210, 360, 225),
     'D3DTTFF_COUNT3 | D3DTTFF_PROJECTED (draws non-projected)'),
    ('projected_4', 'projected', 4, True, 0, (120, 300, 240, 390),
     'D3DTTFF_PROJECTED (like COUNT4 | PROJECTED, texcoord has 4 components)'),
    ('projected_3', 'projected', 3, True, 1, (400, 360, 480, 420),
     'D3DTTFF_PROJECTED (like COUNT3 | PROJECTED, texcoord has only 3 components)'),
    ('ffffffff_3', '0xffffffff', 3, True, 2, (80, 120, 160, 180),
     '0xffffffff (like COUNT3 | PROJECTED, texcoord has only 3 components)'),
    ('count1_2', 'count1', 2, True, 3, (340, 210, 360, 225), 'D3DTTFF_COUNT1 (draws non-projected)'),
    ('projected_4_ffp', 'projected', 4, False, 3, (440, 60, 560, 150),
     'D3DTTFF_PROJECTED (like COUNT4 | PROJECTED), fixed-function pixel pipeline'),
]
QUADRANTS = [(-1, -1, 0, 0), (0, -1, 1, 0), (-1, 0, 0, 1), (0, 0, 1, 1)]  # x0 y0 x1 y1 in clip space


def projected_file(run):
    name, flags, comps, ps, quad, (l, t, r, b), message = run
    x0, y0, x1, y1 = QUADRANTS[quad]

    def tc(u, v):
        vals = [u, v, 4, 6][:comps]
        return 't0 ' + ' '.join(str(c) for c in vals)

    verts = [(x0, y0, tc(0, 0)), (x0, y1, tc(0, 4)), (x1, y0, tc(4, 0)), (x1, y1, tc(4, 4))]
    vlines = '\n'.join('  %d %d 0.1  0xffffffff 0  %s' % (x, y, c) for x, y, c in verts)
    probes = []
    for px in (l - 1, l + 1, r + 1, r - 1):
        for py in (t - 1, t + 1, b + 1, b - 1):
            if not (0 <= px < 640 and 0 <= py < 480):
                continue
            inside = px in (l + 1, r - 1) and py in (t + 1, b - 1)
            probes.append('probe %d %d rgba 0x%08x' % (px, py, 0xffffffff if inside else 0xff000000))
    shader = """
[pixel shader]
ps_1_3
tex t0
mov r0, t0
""" if ps else """colorop selectarg1
colorarg1 texture
alphaop selectarg1
alphaarg1 texture
"""
    text = f"""% Wine's projected_textures_test: "{message}" (dlls/d3d9/tests/visual.c,
% wine-9.7-99-g25c58e68876; no vertex shader). A 4x4 L8 texture, white only at texel (1, 1); the
% quad's coordinates run (0..4, 0..4, 4, 6) over one quadrant of the 640x480 target, sent with
% {comps} component{'s' if comps > 1 else ''}. Windows drivers drew texel (1, 1) exactly inside
% ({l}, {t})-({r}, {b}): the probes are the test's check_rect points, white inside, black just outside,
% exact. Projection resolves against the set's components and the texture's dimensions
% (docs/precision.md "Projected coordinates"); the same on every class.

[render target]
size 640 480
clear 0xff203040

[texture 0]
size 4 4
format L8
level 0
0x00 0x00 0x00 0x00
0x00 0xff 0x00 0x00
0x00 0x00 0x00 0x00
0x00 0x00 0x00 0x00

[sampler 0]
filter point
address clamp

[stage 0]
transform {flags}
{shader}
[test]
draw strip xyz
{vlines}
""" + '\n'.join(probes) + '\n'
    write('projected_%s.ps11test' % name, text)


# ---- every signed format at -max-1, -max, 0 and +max, per class (model values) ----
EXTREME_FORMATS = {
    # format: (bits of the signed channels, word of one value s in every signed channel)
    'V8U8': (8, lambda s: (s & 0xff) | (s & 0xff) << 8),
    'Q8W8V8U8': (8, lambda s: sum((s & 0xff) << (8 * i) for i in range(4))),
    'X8L8V8U8': (8, lambda s: (s & 0xff) | (s & 0xff) << 8 | 0xff << 16),
    'L6V5U5': (5, lambda s: (s & 31) | (s & 31) << 5 | 63 << 10),
    'V16U16': (16, lambda s: (s & 0xffff) | (s & 0xffff) << 16),
}


def extremes_file(fmt):
    bits, word = EXTREME_FORMATS[fmt]
    top = 1 << (bits - 1)
    values = [-top, -(top - 1), 0, top - 1]  # -max-1, -max, 0, +max
    words = [word(v) for v in values]
    digits = 8 if bits != 8 or fmt != 'V8U8' else 4
    if fmt == 'L6V5U5':
        digits = 4
    lines = []
    for i, (v, w) in enumerate(zip(values, words)):
        lines.append('eval')
        lines.append('  t0 %g 0.5' % ((i + 0.5) / 4))
        for cls in CLASSES:
            m = Machine(cls)
            c = m.const(0.5)
            out = [m.mad(m.texel(value(m.rule, ch)), c, c) for ch in channels(fmt, w)]
            vals = [float(Fraction(o, m.G)) if m.fx else o for o in out]
            tol = '0.00001' if m.fx else '0.000001'
            lines.append('if(%s) probe eval rgba %s tol %s   %% s = %d: %s'
                         % (cls, ' '.join('%.9g' % x for x in vals), tol, v,
                            ', '.join(str(value(m.rule, ch)) for ch in channels(fmt, w))))
    text = f"""% {fmt} at its extremes, per hardware class (docs/precision.md "Signed texels"): a 4x1 texture
% holding s = -max-1, -max, 0, +max in every signed channel, sampled by four evals through Wine's
% `mad r0, t0, c0, c0` (c0 = 0.5). Model values from generate.py (exact rationals per class rule,
% then the class's profile); the comment after each probe gives the decoded r g b a.

[texture 0]
size 4 1
format {fmt}
level 0
{' '.join('0x%0*x' % (digits, w) for w in words)}

{SIGNED_SHADER}
[test]
""" + '\n'.join(lines) + '\n'
    write('signed_extremes_%s.ps11test' % fmt.lower(), text)


# ---- fixed_function_bumpmap_test, luminance part: the factor clamps to [0, 1] ----
def luminance_file(name, lscale, loffset, want, tol, why):
    text = f"""% Wine's fixed_function_bumpmap_test, luminance part (dlls/d3d9/tests/visual.c,
% wine-9.7-99-g25c58e68876): stage 0 BUMPENVMAPLUMINANCE over a 1x1 L6V5U5 texel 0x4000 (U = V = 0,
% L = 16/63), stage 1 SELECTARG1 of a 1x1 X8R8G8B8 texel 0x00ff80c0. LSCALE {lscale}, LOFFSET {loffset}:
% {why}. Windows drivers gave 0x{want:06x} +-{tol}, no other result accepted; the same on every class.

[render target]
size 4 4

[texture 0]
size 1 1
format L6V5U5
level 0
0x4000

[texture 1]
size 1 1
format X8R8G8B8
level 0
0x00ff80c0

[stage 0]
colorop bumpenvmapluminance
colorarg1 texture
colorarg2 current
lscale {lscale}
loffset {loffset}

[stage 1]
colorop selectarg1
colorarg1 texture

[test]
draw quad
probe all rgb 0x{want:06x} tol {tol}
"""
    write('ffp_bumpenvmapluminance_%s.ps11test' % name, text)


if __name__ == '__main__':
    for f in SIGNED:
        signed_file(f)
    alpha_file()
    for kind in ('plain', 'coissue', 'coissue_alpha'):
        for minor in (1, 2, 3, 4):
            cnd_file(kind, minor)
    for minor in (1, 2, 4):
        constant_clamp_file(minor)
    color_clamping_file()
    for f in EXTREME_FORMATS:
        extremes_file(f)
    luminance_file('scale2', '2', '0.1', 0x994c72, 5, 'the factor 0.25 * 2 + 0.1 = 0.6 scales the texel')
    luminance_file('scale10', '10', '10', 0xff80c0, 1, 'the factor 12.5 clamps to 1')
    luminance_file('scale1000', '1000', '-1', 0xff80c0, 1, 'the factor 253 clamps to 1')
    for run in PROJ_RUNS:
        projected_file(run)
