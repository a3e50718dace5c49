#!/usr/bin/python3
"""gen-program.py --seed S [--blocks N] [--units mm|in] [--motion]

Writes to stdout a random RS274/NGC program of about N lines that LinuxCNC's rs274
accepts (with simpockets.tbl): every arc is geometrically valid, F is set before
feeds, parameters are defined before they are read, loops terminate. It covers
G0-G3 (IJK and R, helices, all planes, G90.1/G91.1), G5/G5.1 splines, G5.2/G5.3 NURBS, G4, G10 L2/L20,
G17-G19, G20/G21, G28/G30, G43/G43.2/G49, G52, G53, G54-G59.3, G61/G61.1/G64 P Q, canned cycles
G73 G81-G89 with R L Q P and G98/G99, G90/G91, G92/G92.1/G92.2/G92.3, G93/G94/G95,
G7/G8 (X words as diameters), G33/G33.1 (spindle-synchronised feeds, rigid taps), G76,
G38.2-G38.5 (probing), M66 (wait for an input), M70/M72 (modal state save and
restore), M0-M9 M30 M48/M49, S T M6 F, comments,
MSG and DEBUG with parameters, numbered and named parameters, expressions with every
operator and function, O-word subroutines with arguments and return values,
Fanuc-style subroutines (O8000 ... M99 after the program end, M98 P8000 [L n]),
if/elseif/else, while, do-while, repeat, break and continue. The same seed always gives the same program.

How validity is kept without simulating the interpreter:
  * geometry parameters (#100-#109) are assigned once, at the top level, with
    values known here; scratch parameters only ever hold bounded values (every
    assignment is reduced by MOD or SIN) and feed DEBUG text, conditions and motion
    whose validity does not depend on them;
  * the current position is tracked while it is known; when an offset change, a
    subroutine or a loop makes it unknown, arcs take their end points relative to
    the current position parameters #5420-#5422 instead;
  * subroutines run in a fixed modal state that the caller sets before each call,
    and change no modal state themselves.
"""
import argparse
import math
import random

AXES = "XYZ"
# plane -> (first axis, second axis, helix axis) and the matching IJK letters
PLANES = {17: ("X", "Y", "Z", "I", "J"), 18: ("Z", "X", "Y", "K", "I"),
          19: ("Y", "Z", "X", "J", "K")}
POSITION_PARAM = {"X": 5420, "Y": 5421, "Z": 5422}
TOOLS = [t for t in range(1, 17) if t != 13]   # the tools simpockets.tbl holds
GEOM_PARAMS = range(100, 110)
SCRATCH = range(500, 512)
GLOBAL_NAMES = ["_depth", "_Stock_Top", "_count", "_ratio", "_gv_a"]
READONLY = ["#<_x>", "#<_y>", "#<_z>", "#<_feed>", "#<_rpm>", "#<_metric>",
            "#<_imperial>", "#<_absolute>", "#<_incremental>", "#<_current_tool>",
            "#5420", "#5421", "#5422", "#5400"]


def num(v, places=4):
    """A G-code number: fixed point, trailing zeros dropped."""
    s = "%.*f" % (places, v)
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


class Scope:
    """Parameters a stretch of code may read: names known defined, sub arguments."""

    def __init__(self, nargs=0, parent_globals=None):
        self.nargs = nargs
        self.local_names = []
        self.globals = parent_globals if parent_globals is not None else []


class Gen:
    def __init__(self, seed, blocks, units):
        self.r = random.Random(seed)
        self.blocks = blocks
        self.out = []
        self.home_units = units or self.r.choice(["mm", "mm", "in"])
        self.units = self.home_units
        self.dist = 90
        self.ijk_abs = False
        self.plane = 17
        self.feed_mode = 94
        self.spindle = 0               # 0 off, 3 cw, 4 ccw
        self.pos = {a: None for a in AXES}
        self.geom = {}
        self.next_label = 100
        self.next_counter = 1000
        self.subs = []                 # (call name, nargs, returns a value)
        # Fanuc-style subs draw from a generator of their own, so a seed
        # without them gives the program it gave before they were added
        self.r98 = random.Random(seed * 7919 + 98)
        self.fanuc = []                # their numbers, defined after M30/M2
        self.depth = 0                 # control-structure nesting of the code now
        self.scope = Scope(0, [])
        self.value_defined = False
        self.in_repeat = 0

    # ---- output helpers -----------------------------------------------------
    def emit(self, text):
        """One line; plain blocks sometimes get lower case, an N word, a comment."""
        r = self.r
        if r.random() < 0.03:
            text = text.lower()
        if not text.startswith(("(", "o", "O")):
            if r.random() < 0.05:
                text = "N%d %s" % (10 * (len(self.out) + 1), text)
            if r.random() < 0.04:
                text += " (%s)" % r.choice(["rough", "finish", "check", "x side", "1.5 mm"])
            elif r.random() < 0.03:
                text += " ; " + r.choice(["note", "tidy up", "was G1"])
        self.out.append("  " * self.depth + text)

    def s(self):
        """Scale of a length: 1 in mm, 1/25.4 in inch."""
        return 1.0 if self.units == "mm" else 1 / 25.4

    def places(self):
        return 4 if self.units == "mm" else 5

    def n(self, v):
        return num(v, self.places())

    def feed(self):
        if self.feed_mode == 95:
            return num(self.r.choice([0.05, 0.1, 0.15, 0.2]) * self.s(), 5)
        if self.feed_mode == 93:
            return num(self.r.uniform(0.5, 30), 3)
        return num(self.r.choice([100, 250, 400, 600, 1200, 1500]) * self.s(), 3)

    def label(self):
        self.next_label += 1
        if self.r.random() < 0.3:
            return "o<l%d>" % self.next_label
        return "o%d" % self.next_label

    # ---- expressions ----------------------------------------------------------
    def leaf(self):
        r = self.r
        c = r.random()
        if c < 0.35:
            v = num(r.uniform(-20, 20), r.choice([0, 1, 3]))
            # a binary operator may not be followed by a sign: "[1 - -2]" is an error
            return "[%s]" % v if v.startswith("-") else v
        if c < 0.55:
            return "#%d" % r.choice(SCRATCH)
        if c < 0.65 and self.geom:
            return "#%d" % r.choice(sorted(self.geom))
        if c < 0.75 and self.scope.nargs:
            return "#%d" % r.randint(1, self.scope.nargs)
        if c < 0.82 and self.scope.local_names:
            return "#<%s>" % r.choice(self.scope.local_names)
        if c < 0.9:
            return "#<%s>" % r.choice(GLOBAL_NAMES)
        return r.choice(READONLY)

    def expr(self, depth=2):
        """A bracketed expression that never fails and stays finite."""
        r = self.r
        if depth <= 0 or r.random() < 0.25:
            return "[%s]" % self.leaf() if r.random() < 0.3 else self.leaf()
        e = lambda: self.expr(depth - 1)
        c = r.random()
        if c < 0.45:
            ops = ["+", "-", "*", "+", "-", "EQ", "NE", "GT", "GE", "LT", "LE",
                   "AND", "OR", "XOR"]
            parts = [["", e()]]
            for _ in range(r.randint(1, 3)):
                op = r.choice(ops + ["/", "MOD", "**"])
                if op == "/":
                    parts.append(["/", "[ABS[%s] + 1]" % e()])
                elif op == "MOD":
                    parts.append(["MOD", "[ABS[%s] + 1]" % e()])
                elif op == "**":
                    parts[-1][1] = "[ABS[%s] + 0.5]" % parts[-1][1]
                    parts.append(["**", r.choice(["2", "3", "0.5", "[1/3]"])])
                else:
                    parts.append([op, e()])
            parts = [(op + " " + v) if op else v for op, v in parts]
            return "[%s]" % " ".join(parts)
        fn = r.choice(["ABS", "SIN", "COS", "TAN", "ATAN", "ACOS", "ASIN", "SQRT",
                       "LN", "EXP", "ROUND", "FIX", "FUP", "EXISTS", "NEG"])
        if fn == "TAN":
            return "TAN[ABS[%s] MOD 80]" % e()
        if fn == "ATAN":
            return "ATAN[%s]/[%s]" % (e(), e())
        if fn == "ACOS":
            return "ACOS[SIN[%s]]" % e()
        if fn == "ASIN":
            return "ASIN[COS[%s]]" % e()
        if fn == "SQRT":
            return "SQRT[ABS[%s]]" % e()
        if fn == "LN":
            return "LN[ABS[%s] + 1]" % e()
        if fn == "EXP":
            return "EXP[SIN[%s]]" % e()
        if fn == "EXISTS":
            name = r.choice(GLOBAL_NAMES + ["_never_set", "nope"] +
                            self.scope.local_names)
            return "EXISTS[#<%s>]" % name
        if fn == "NEG":
            return "[-%s]" % e()
        return "%s[%s]" % (fn, e())

    def cond(self, depth=2):
        while True:
            e = self.expr(depth)
            if len(e) <= 120:
                return e

    def bounded(self, depth=2):
        """An expression whose value is within +-100 whatever the parameters hold,
        short enough that the block stays within rs274's 256-character limit."""
        while True:
            e = self.bounded1(depth)
            if len(e) <= 100:
                return e

    def bounded1(self, depth):
        r = self.r
        k = r.choice(["97", "10", "3.5", "[ABS[%s] + 2]" % self.leaf()])
        if r.random() < 0.7:
            return "[%s MOD %s]" % (self.expr(depth), k)
        return "[SIN[%s] * %s]" % (self.expr(depth), r.choice(["50", "7.25", "1"]))

    # ---- statements -------------------------------------------------------------
    def st_assign(self):
        r = self.r
        c = r.random()
        if c < 0.5:
            self.emit("#%d = %s" % (r.choice(SCRATCH), self.bounded()))
        elif c < 0.7 and self.depth == 0 and len(self.scope.local_names) < 6:
            name = r.choice(["tmp", "width", "Pass", "step", "k"]) + str(len(
                self.scope.local_names))
            self.emit("#<%s> = %s" % (name, self.bounded()))
            self.scope.local_names.append(name)
        elif c < 0.8 and self.scope.local_names:
            self.emit("#<%s> = %s" % (r.choice(self.scope.local_names), self.bounded()))
        elif c < 0.9:
            self.emit("#<%s> = %s" % (r.choice(GLOBAL_NAMES), self.bounded()))
        else:
            # two on one line: both right-hand sides see the values from before
            a, b = r.sample(list(SCRATCH), 2)
            self.emit("#%d = %s #%d = [#%d + 1]" % (a, self.bounded(), b, a))

    def st_message(self):
        r = self.r
        c = r.random()
        if c < 0.3:
            self.emit("(MSG, %s)" % r.choice(["Roughing pass", "Check the clamp",
                                             "Finish 0.2 mm", "Next: drill"]))
        elif c < 0.8:
            bits = ["%s=%s" % (w, self.leaf()) for w in
                    r.sample(["a", "depth", "n", "val", "r"], r.randint(1, 3))]
            self.emit("(DEBUG, %s)" % " ".join(bits))
        elif c < 0.9:
            bits = ["%s %s" % (w, self.leaf()) for w in
                    r.sample(["pass", "z", "count"], r.randint(1, 2))]
            self.emit("(PRINT,%s)" % " ".join(bits))
        else:
            self.emit("(%s)" % r.choice(["plain comment", "T1 is 1/8 end mill",
                                         "G1 X0 in a comment", "-- section --"]))

    def ensure_feed_ready(self):
        """Feeds need a rate; G95 also a turning spindle."""
        if self.feed_mode == 95 and self.spindle == 0:
            self.emit("S%d M3" % self.r.choice([800, 1200, 3000]))
            self.spindle = 3

    def st_straight(self):
        r = self.r
        g = r.choice(["G0", "G1", "G1", "G1"])
        words, s = [], self.s()
        for a in r.sample(AXES, r.randint(1, 3)):
            if self.dist == 91:
                d = r.uniform(-15, 15) * s
                words.append(a + self.n(d))
                if self.pos[a] is not None:
                    self.pos[a] += float(self.n(d))
            elif r.random() < 0.12 and self.geom:
                p = r.choice(sorted(self.geom))
                off = round(r.uniform(-5, 5), 2)
                words.append("%s[#%d + %s]" % (a, p, num(off)))
                self.pos[a] = self.geom[p] + off
            elif r.random() < 0.08:
                words.append("%s[%s]" % (a, self.bounded()))
                self.pos[a] = None
            else:
                v = float(self.n(r.uniform(-40, 40) * s if a != "Z" else
                                 r.uniform(-5, 10) * s))
                words.append(a + self.n(v))
                self.pos[a] = v
        if r.random() < 0.04:
            words.append(r.choice("ABC") + num(r.uniform(-90, 90), 2))
        line = " ".join([g] + words)
        if g == "G1":
            self.ensure_feed_ready()
            if self.feed_mode == 93 or r.random() < 0.1:
                line += " F" + self.feed()
        self.emit(line)

    def arc_words(self):
        """Words of a valid arc in the current plane, updating the position."""
        r = self.r
        a1, a2, a3, l1, l2 = PLANES[self.plane]
        s = self.s()
        known = self.dist == 91 or all(self.pos[a] is not None for a in (a1, a2))
        use_r = r.random() < 0.35
        turns = None
        if use_r:
            chord = r.uniform(1, 30) * s
            phi = r.uniform(0, 2 * math.pi)
            d1, d2 = float(self.n(chord * math.cos(phi))), float(self.n(chord * math.sin(phi)))
            chord = math.hypot(d1, d2)
            rad = chord / 2 * r.uniform(1.05, 3)
            rad = -rad if r.random() < 0.3 else rad
            centre = None
        else:
            rad0 = r.uniform(0.8, 25) * s
            phi = r.uniform(0, 2 * math.pi)
            c1, c2 = float(self.n(rad0 * math.cos(phi))), float(self.n(rad0 * math.sin(phi)))
            rad0 = math.hypot(c1, c2)
            if r.random() < 0.15:
                d1 = d2 = 0.0                       # full circle
                if r.random() < 0.5:
                    turns = r.randint(1, 3)
            else:
                th = r.uniform(0, 2 * math.pi)
                d1 = float(self.n(c1 + rad0 * math.cos(th)))
                d2 = float(self.n(c2 + rad0 * math.sin(th)))
                if math.hypot(d1, d2) < 0.05 * s:
                    d1 = d2 = 0.0
            centre = (c1, c2)
        helix = r.random() < 0.25
        d3 = float(self.n(r.uniform(-3, 3) * s)) if helix else 0.0
        words = []
        for ax, d in ((a1, d1), (a2, d2), (a3, d3)):
            if ax == a3 and not helix:
                continue
            if self.dist == 91:
                words.append(ax + self.n(d))
            elif self.pos[ax] is not None and r.random() < 0.85:
                words.append(ax + self.n(self.pos[ax] + d))
            else:
                words.append("%s[#%d + %s]" % (ax, POSITION_PARAM[ax], self.n(d)))
        if centre is None:
            words.append("R" + self.n(rad))
        else:
            for letter, ax, c in ((l1, a1, centre[0]), (l2, a2, centre[1])):
                if not self.ijk_abs:
                    words.append(letter + self.n(c))
                elif self.pos[ax] is not None:
                    words.append(letter + self.n(self.pos[ax] + c))
                else:
                    words.append("%s[#%d + %s]" % (letter, POSITION_PARAM[ax], self.n(c)))
            if turns:
                words.append("P%d" % turns)
        for ax, d in ((a1, d1), (a2, d2), (a3, d3)):
            if self.pos[ax] is not None:
                self.pos[ax] += d
        del known
        return words

    def st_arc(self):
        g = self.r.choice(["G2", "G3"])
        words = self.arc_words()
        self.ensure_feed_ready()
        line = " ".join([g] + words)
        if self.feed_mode == 93 or self.r.random() < 0.1:
            line += " F" + self.feed()
        self.emit(line)

    def st_cycle(self):
        """A canned cycle in G17, G94, then a few repeats at other holes."""
        r = self.r
        if self.plane != 17 or self.feed_mode != 94 or self.depth > 0 and r.random() < 0.5:
            return self.st_straight()
        s = self.s()
        g = r.choice(["G81", "G82", "G83", "G73", "G74", "G84", "G85", "G86", "G87",
                      "G88", "G89"])
        # G74 taps left-handed: the spindle must turn counterclockwise
        want = 4 if g == "G74" else 3
        if g in ("G74", "G84", "G86", "G87", "G88") and self.spindle != want:
            self.emit("M%d S%d" % (want, r.choice([500, 900])))
            self.spindle = want
        self.emit(r.choice(["G98", "G99"]))
        words = [g]
        if self.dist == 90:
            rr = r.uniform(0.5, 3) * s
            z = -r.uniform(0.5, 8) * s
            for a in "XY":
                v = float(self.n(r.uniform(-40, 40) * s))
                words.append(a + self.n(v))
                self.pos[a] = v
        else:
            rr = r.uniform(-2, 2) * s
            z = -r.uniform(0.5, 6) * s
            for a in "XY":
                words.append(a + self.n(r.uniform(-10, 10) * s))
                self.pos[a] = None
            # rs274 takes no L (repeats) with G74
            if g != "G74" and r.random() < 0.5:
                words.append("L%d" % r.randint(2, 4))
        words += ["Z" + self.n(z), "R" + self.n(rr)]
        if g in ("G83", "G73"):
            words.append("Q" + self.n(r.uniform(0.3, 2) * s))
        if g in ("G82", "G86", "G88", "G89"):
            words.append("P" + num(r.uniform(0.1, 1), 2))
        if g == "G87":
            words += ["I" + self.n(0.5 * s), "J0", "K" + self.n(rr - 0.5 * s)]
        words.append("F" + self.feed())
        self.emit(" ".join(words))
        for _ in range(r.randint(0, 3)):
            if self.dist == 90:
                v = float(self.n(r.uniform(-40, 40) * s))
                self.emit("X" + self.n(v))
                self.pos["X"] = v
            else:
                self.emit("Y" + self.n(r.uniform(-10, 10) * s))
        if r.random() < 0.7:
            self.emit("G80")
        self.pos["Z"] = None

    def st_modal(self):
        """A modal change valid anywhere at the top level."""
        r = self.r
        c = r.randint(0, 14)
        if c in (0, 13, 14):
            self.set_plane(r.choice([17, 18, 19]))
        elif c == 1:
            self.set_dist(91 if self.dist == 90 else 90)
        elif c == 2:
            self.ijk_abs = not self.ijk_abs
            self.emit("G90.1" if self.ijk_abs else "G91.1")
        elif c == 3:
            self.set_feed_mode(r.choice([93, 94, 95]))
        elif c == 4:
            self.emit(r.choice(["G61", "G61.1", "G64", "G64 P%s" % self.n(0.02 * self.s()),
                                "G64 P%s Q%s" % (self.n(0.05 * self.s()),
                                                 self.n(0.01 * self.s()))]))
        elif c == 5:
            self.spindle = r.choice([3, 4])
            self.emit("S%d M%d" % (r.choice([1000, 2400, 8000]), self.spindle))
        elif c == 6:
            self.emit(r.choice(["M7", "M8", "M9", "M9"]))
        elif c == 7:
            self.emit(r.choice(["M48", "M49", "M48"]))
        elif c == 8:
            if self.feed_mode != 95:
                self.spindle = 0
                self.emit("M5")
        elif c == 9:
            self.emit("F" + self.feed())
        elif c == 10:
            self.emit(r.choice(["M0", "M1"]))
        elif c == 11:
            if r.random() < 0.7:
                self.emit("S%d" % r.choice([500, 1500, 3000]))
            else:   # wait for an input; #5399 holds what rs274's stand-in reports
                self.emit(r.choice(["M66 P%d L0" % r.randint(0, 3), "M66 E%d" % r.randint(0, 3),
                                    "M66 P%d L%d Q%s" % (r.randint(0, 3), r.randint(1, 4),
                                                         num(r.uniform(0.5, 3), 1))]))
                self.emit("(DEBUG, input result #5399)")
        else:
            self.emit("G4 P%s" % num(r.uniform(0, 1.5), 2))

    def set_plane(self, p):
        if p != self.plane or self.r.random() < 0.2:
            self.emit("G%d" % p)
        self.plane = p

    def set_dist(self, d):
        self.emit("G%d" % d)
        self.dist = d

    def set_feed_mode(self, m):
        if m == 95 and self.spindle == 0:
            self.emit("S1000 M3")
            self.spindle = 3
        line = "G%d" % m
        self.feed_mode = m
        if m != 93:
            line += " F" + self.feed()
        self.emit(line)

    def set_units(self, u):
        self.emit("G20" if u == "in" else "G21")
        if u != self.units:
            k = 25.4 if u == "mm" else 1 / 25.4
            for a in AXES:
                if self.pos[a] is not None:
                    self.pos[a] *= k
            self.units = u
        if self.feed_mode != 93:
            self.emit("F" + self.feed())

    def forget_position(self, axes=AXES):
        for a in axes:
            self.pos[a] = None

    def st_offsets(self):
        """Work offsets, G92, G52, tool length, machine moves and homing."""
        r = self.r
        s = self.s()
        c = r.randint(0, 9)
        if c == 0:
            self.emit("G10 L2 P%d X%s Y%s Z%s" % (r.randint(0, 9), self.n(r.uniform(-20, 20) * s),
                                                self.n(r.uniform(-20, 20) * s), self.n(r.uniform(-3, 3) * s)))
        elif c == 1:
            axes = r.sample(AXES, r.randint(1, 3))
            self.emit("G10 L20 P%d %s" % (r.randint(0, 9), " ".join(
                a + self.n(r.uniform(-10, 10) * s) for a in axes)))
        elif c == 2:
            self.emit(r.choice(["G54", "G55", "G56", "G57", "G58", "G59", "G59.1",
                                "G59.2", "G59.3", "G54"]))
        elif c == 3:
            self.emit("G92 " + " ".join(a + self.n(r.uniform(-10, 10) * s)
                                        for a in r.sample(AXES, r.randint(1, 3))))
        elif c == 4:
            self.emit(r.choice(["G92.1", "G92.2", "G92.3"]))
        elif c == 5:
            if r.random() < 0.5:
                self.emit("G52 X%s Y%s" % (self.n(r.uniform(-10, 10) * s), self.n(r.uniform(-10, 10) * s)))
            else:
                self.emit("G52 X0 Y0 Z0")
        elif c == 6:
            t = r.choice(TOOLS)
            self.emit(r.choice(["T%d M6" % t, "M6 T%d" % t, "T%d M6 G43" % t]))
            self.spindle = 0            # a tool change stops the spindle
            if r.random() < 0.5:
                self.emit("G43 H%d" % r.choice(TOOLS + [0]))
        elif c == 7:
            self.emit(r.choice(["G43", "G49", "G43 H%d" % r.choice(TOOLS),
                                "G43.2 H%d" % r.choice(TOOLS)]))
        elif c == 8:
            if self.dist == 91:
                return self.st_straight()
            self.emit("G53 G%d Z%s" % (r.choice([0, 1]) if self.feed_mode == 94 else 0,
                                        self.n(r.uniform(-5, 0) * s)))
        else:
            g = r.choice(["G28", "G30"])
            if r.random() < 0.5 and self.dist == 90:
                self.emit("%s Z%s" % (g, self.n(r.uniform(0, 10) * s)))
            else:
                self.emit(g)
        self.forget_position()

    def st_anchor(self):
        if self.dist != 90:
            return self.st_straight()
        s = self.s()
        vals = [float(self.n(self.r.uniform(-30, 30) * s)) for _ in range(2)]
        z = float(self.n(self.r.uniform(1, 10) * s))
        self.emit("G0 X%s Y%s Z%s" % (self.n(vals[0]), self.n(vals[1]), self.n(z)))
        self.pos = {"X": vals[0], "Y": vals[1], "Z": z}

    # ---- control flow -----------------------------------------------------------
    def body(self, n, loop=None, no_continue=False):
        """n statements at one deeper level; `loop` is the label break/continue use."""
        self.depth += 1
        self.forget_position()          # a loop comes back here from elsewhere
        for _ in range(n):
            c = self.r.random()
            if loop and c < 0.12:
                lab = self.label()
                self.emit("%s if [%s]" % (lab, self.cond(1)))
                self.depth += 1
                self.emit("%s %s" % (loop, "break" if no_continue else
                                     self.r.choice(["break", "continue"])))
                self.depth -= 1
                self.emit("%s endif" % lab)
            else:
                self.simple_statement(inner=True)
        self.depth -= 1
        self.forget_position()

    def st_if(self):
        r = self.r
        lab = self.label()
        self.emit("%s if [%s]" % (lab, self.cond()))
        self.body(r.randint(1, 3))
        for _ in range(r.randint(0, 2)):
            self.emit("%s elseif [%s]" % (lab, self.cond()))
            self.body(r.randint(1, 2))
        if r.random() < 0.5:
            self.emit("%s else" % lab)
            self.body(r.randint(1, 2))
        self.emit("%s endif" % lab)

    def counter(self):
        self.next_counter += 1
        return "#%d" % self.next_counter

    def st_loop(self):
        r = self.r
        lab = self.label()
        kind = r.choice(["while", "do", "repeat"])
        n = r.randint(1, 4)
        if kind == "repeat":
            self.emit("%s repeat [%s]" % (lab, r.choice([str(n), "[%d + 0.0]" % n])))
            self.in_repeat += 1
            self.body(r.randint(1, 3))
            self.in_repeat -= 1
            self.emit("%s endrepeat" % lab)
            return
        cnt = self.counter()
        self.emit("%s = 0" % cnt)
        self.emit("%s %s" % (lab, "while [%s LT %d]" % (cnt, n) if kind == "while" else "do"))
        self.depth += 1
        self.emit("%s = [%s + 1]" % (cnt, cnt))
        self.depth -= 1
        # rs274 loops forever on `continue` in a do-while inside a repeat
        self.body(r.randint(1, 3), loop=lab,
                  no_continue=kind == "do" and self.in_repeat > 0)
        if kind == "while":
            self.emit("%s endwhile" % lab)
        else:
            self.emit("%s while [%s LT %d]" % (lab, cnt, n))

    def sub_entry_state(self):
        """Subroutine bodies run in G17 G90 G91.1 G94, home units."""
        if self.units != self.home_units:
            self.set_units(self.home_units)
        if self.plane != 17:
            self.set_plane(17)
        if self.dist != 90:
            self.set_dist(90)
        if self.ijk_abs:
            self.emit("G91.1")
            self.ijk_abs = False
        if self.feed_mode != 94:
            self.set_feed_mode(94)

    def st_call(self):
        r = self.r
        if self.fanuc and self.depth == 0 and self.r98.random() < 0.4:
            return self.st_m98()
        if not self.subs or self.depth > 0:
            return self.st_message()
        name, nargs, returns = r.choice(self.subs)
        self.sub_entry_state()
        args = " ".join("[%s]" % (self.n(r.uniform(-10, 10)) if r.random() < 0.6
                                  else self.bounded(1)) for _ in range(nargs))
        self.emit(("%s call %s" % (name, args)).rstrip())
        self.forget_position()
        if returns:
            self.value_defined = True
            if r.random() < 0.6:
                self.emit("#%d = [#<_value> MOD 50]" % r.choice(SCRATCH))

    def st_m98(self):
        """M98 P.. [L..]: the sub shares #1-#30 with the caller and reads none."""
        self.sub_entry_state()
        reps = self.r98.choice(["", "", " L1", " L2", " L3"])
        m = "M98"
        if self.r98.random() < 0.25:
            # the M from a parameter: rs274 decides on its value as it reads
            # the line (#9: one character, as "three characters on" needs)
            self.emit("#9 = 98")
            m = "M#9"
        self.emit("%s P%s%s" % (m, self.r98.choice(self.fanuc), reps))
        self.forget_position()

    def open_sub_body(self, first_line, nargs):
        """A sub's first line and 2-6 statements, from the modal state a call
        may find; returns what the caller restores once the sub is closed."""
        saved = (self.scope, self.depth, dict(self.pos))
        self.scope = Scope(nargs, GLOBAL_NAMES)
        self.emit(first_line)
        self.depth = 1
        self.units, self.plane, self.dist, self.ijk_abs = self.home_units, 17, 90, False
        self.feed_mode = 94
        self.forget_position()
        for _ in range(self.r.randint(2, 6)):
            self.simple_statement(inner=True, in_sub=True)
        return saved

    def define_fanuc(self, number):
        """O<number> ... M99, after the program end (rs274 would run into it)."""
        saved = self.open_sub_body("O%s" % number, 0)
        self.depth = 0
        if self.r98.random() < 0.25:
            self.emit("#9 = 99")
            self.emit("M#9")
        else:
            self.emit("M99")
        self.scope, self.depth, self.pos = saved

    def define_sub(self, idx):
        r = self.r
        name = r.choice(["o<contour%d>" % idx, "o<Pocket_%d>" % idx, "o%d" % (9000 + idx)])
        nargs = r.randint(0, 4)
        returns = r.random() < 0.6
        saved = self.open_sub_body("%s sub" % name, nargs)
        if returns and r.random() < 0.5:
            lab = self.label()
            self.emit("%s if [%s]" % (lab, self.cond(1)))
            self.depth += 1
            self.emit("%s return [%s]" % (name, self.bounded()))
            self.depth -= 1
            self.emit("%s endif" % lab)
            self.simple_statement(inner=True, in_sub=True)
        self.depth = 0
        self.emit("%s endsub%s" % (name, " [%s]" % self.bounded() if returns else ""))
        self.scope, self.depth, self.pos = saved
        self.subs.append((name, nargs, returns))

    # ---- the program -----------------------------------------------------------
    def simple_statement(self, inner=False, in_sub=False):
        r = self.r
        c = r.random()
        if c < 0.28:
            return self.st_straight()
        if c < 0.46:
            return self.st_arc()
        if c < 0.58:
            return self.st_assign()
        if c < 0.66:
            return self.st_message()
        if inner:
            if c < 0.72 and self.depth < 3:
                return self.st_if()
            if c < 0.78 and self.depth < 3:
                return self.st_loop()
            return self.st_straight()
        if c < 0.70:
            return self.st_cycle()
        if c < 0.78:
            return self.st_modal()
        if c < 0.82:
            return self.st_offsets()
        if c < 0.85:
            return self.st_anchor()
        if c < 0.89:
            return self.st_if()
        if c < 0.93:
            return self.st_loop()
        if c < 0.97:
            return self.st_call()
        if c < 0.985:
            return self.st_units_episode()
        if c < 0.99:
            return self.st_diameter_episode()
        if c < 0.994:
            return self.st_probe_episode()
        if c < 0.996:
            return self.st_sync_episode()
        if c < 0.997:
            return self.st_spline()
        if c < 0.998:
            return self.st_nurbs()
        if c < 0.9985:
            return self.st_thread()
        if c < 0.999:
            return self.st_lathe_cycle_episode()
        return self.st_state_episode()

    def st_state_episode(self):
        """M70, some moves in another distance mode or plane, M72: the modes
        come back (and F, rounded to one decimal, if a move changed it)."""
        r = self.r
        dist, plane = self.dist, self.plane
        self.emit("M70")
        if r.random() < 0.6:
            self.set_dist(91 if self.dist == 90 else 90)
        if r.random() < 0.4:
            self.set_plane(r.choice([17, 18, 19]))
        for _ in range(r.randint(1, 3)):
            self.simple_statement(inner=True)
        self.emit("M72")
        self.dist, self.plane = dist, plane

    def lathe_profile(self, arcs=True):
        """A profile that runs towards -a and +b (a, b: Z and X of a G71,
        X and -Z of a G72 before its quarter turn), lines and R arcs, none
        reversing direction (no pockets: rs274 2.9 can loop for ever on
        some): [(g, a, b, r)], and the largest b."""
        # the same numbers in inch: rs274's tolerances are absolute, and on
        # profiles 25 times smaller it loops for ever more often
        r, s = self.r, 1.0
        a, b = r.uniform(-5, 5) * s, r.uniform(0, 5) * s
        segs, top, flat = [("G1", a, b, None)], b, False
        for _ in range(r.randint(2, 5)):
            # two lines in a row along Z meet nowhere: rs274 refuses them
            da = -r.uniform(1, 5) * s
            db = r.uniform(0.3, 3) * s if flat or r.random() < 0.7 else 0
            flat = db == 0
            na, nb = float(self.n(a + da)), float(self.n(b + db))
            seg = ("G1", na, nb, None)
            chord = math.hypot(na - a, nb - b)
            if arcs and r.random() < 0.4 and chord > 1.5 * s:
                g = r.choice(["G2", "G3"])
                rad = float(self.n(chord / 2 * r.uniform(1.1, 3)))
                # rs274's centre of an R arc, and its test that the arc keeps
                # to one side of it (with some margin)
                mid = complex(a + na, b + nb) / 2
                d = 1j * math.sqrt((rad * rad - chord * chord / 4) / (chord * chord)) \
                    * complex(na - a, nb - b)
                c = mid + d if g == "G3" else mid - d
                e1, e2 = b - c.imag, nb - c.imag
                if (g == "G3" and e1 >= 0.05 and e2 >= 0.05) or \
                        (g == "G2" and e1 <= -0.05 and e2 <= -0.05):
                    seg = (g, na, nb, rad)
            segs.append(seg)
            a, b = na, nb
            top = max(top, b)
        segs.append(("G1", a, float(self.n(top + r.uniform(0.5, 2) * s)), None))
        return segs, max(top, segs[-1][2])

    def st_lathe_cycle_episode(self):
        """G71/G72 roughing (and their .1/.2 forms) and G70 finishing of a
        profile subroutine defined right here, in G18, G90 and G94, from a
        point clear of it; the current point is then known no more."""
        r, s = self.r, 1.0
        if self.depth:
            return self.st_straight()
        face = r.random() < 0.4
        # arcs only along Z: rs274 2.9 loops for ever on some G72 faces with arcs
        segs, top = self.lathe_profile(arcs=not face)
        # a G72 profile is a G71 one turned a quarter: Z = -b, X = a
        xz = (lambda a, b: (a, -b)) if face else (lambda a, b: (b, a))
        self.lathe_subs = getattr(self, "lathe_subs", 0) + 1
        name = "o%d" % (7000 + self.lathe_subs)   # G7x's Q names subs by number
        self.emit("%s sub" % name)
        self.depth = 1
        for g, a, b, rad in segs:
            x, z = xz(a, b)
            self.emit("%s X%s Z%s%s" % (g, self.n(x), self.n(z),
                                        " R" + self.n(rad) if rad else ""))
        self.depth = 0
        self.emit("%s endsub" % name)
        self.set_plane(18)
        if self.dist != 90:
            self.set_dist(90)
        if self.feed_mode == 93:
            self.set_feed_mode(94)
        self.ensure_feed_ready()
        x, z = xz(segs[0][1] + r.uniform(0.5, 2) * s, top + r.uniform(0.5, 2) * s)
        start = "X%s Z%s" % (self.n(x), self.n(z))
        # not G71.1/G72.1: rs274 2.9 loops for ever on some plain profiles there
        g = r.choice(["G72", "G72.2"] if face else ["G71", "G71.2"])
        words = [start, "D" + self.n(r.uniform(0, 0.3) * s)]
        words.append("I" + self.n(r.uniform(0.3, 1.5) * s))
        if r.random() < 0.7:
            words.append("R" + self.n(r.uniform(0.1, 0.6) * s))
        self.emit("%s Q%s %s" % (g, name[1:], " ".join(words)))
        if r.random() < 0.7:
            words = [start]
            if r.random() < 0.5:
                words += ["P%d" % r.randint(1, 3), "D" + self.n(r.uniform(0.2, 1) * s),
                          "E" + self.n(r.uniform(0, 0.2) * s)]
            self.emit("G70 Q%s %s" % (name[1:], " ".join(words)))
        self.forget_position(("X", "Z"))
        self.emit("G80")

    def st_thread(self):
        """A G76 threading cycle along Z (outside or bored, maybe tapered, with
        a compound angle, degression and spring passes); the spindle turns."""
        r = self.r
        s = self.s()
        if self.spindle == 0:
            self.spindle = r.choice([3, 4])
            self.emit("S%d M%d" % (r.choice([300, 600]), self.spindle))
        j = r.uniform(0.05, 0.3) * s
        words = ["P" + self.n(r.choice([0.5, 1, 1.5, 2]) * s),
                 "Z" + self.n(r.uniform(-20, 20) * s),
                 "I" + self.n(r.choice([-1, 1]) * r.uniform(0.5, 2) * s),
                 "J" + self.n(j), "K" + self.n(j * r.uniform(2, 6))]
        if r.random() < 0.3:
            words.append("X" + self.n(r.uniform(-20, 20) * s))
        if r.random() < 0.5:
            words.append("Q" + num(r.uniform(0, 30), 1))
        if r.random() < 0.3:
            words.append("R" + num(r.uniform(1, 2.5), 2))
        if r.random() < 0.3:
            words.append("H%d" % r.randint(0, 3))
        if r.random() < 0.3:
            words += ["E" + self.n(r.uniform(0.2, 2) * s), "L%d" % r.randint(0, 3)]
        r.shuffle(words)
        self.emit("G76 " + " ".join(words))
        self.forget_position(("X", "Z"))
        self.emit("G80")

    def st_spline(self):
        """A G5 (cubic, P Q; I J optional) or G5.1 (quadratic, I J) spline in
        the XY plane; it ends at its end point and leaves the motion mode."""
        r = self.r
        self.set_plane(17)
        self.ensure_feed_ready()
        s, words = self.s(), []
        for a in ("X", "Y"):
            if self.dist == 91:
                d = r.uniform(-15, 15) * s
                words.append(a + self.n(d))
                if self.pos[a] is not None:
                    self.pos[a] += float(self.n(d))
            else:
                v = float(self.n(r.uniform(-40, 40) * s))
                words.append(a + self.n(v))
                self.pos[a] = v
        vec = lambda: [self.n(r.uniform(-10, 10) * s) for _ in range(2)]
        if r.random() < 0.5:
            g, i, j = "G5.1", *vec()
            words += ["I" + i, "J" + j]
        else:
            g, (p, q) = "G5", vec()
            if r.random() < 0.7:
                i, j = vec()
                words += ["I" + i, "J" + j]
            words += ["P" + p, "Q" + q]
        line = " ".join([g] + words)
        if self.feed_mode == 93:
            line += " F" + self.feed()
        self.emit(line)

    def st_nurbs(self):
        """A G5.2/G5.3 NURBS: the first block may be P alone (the start's
        weight), every point X Y with P > 0, L the order on any of them, other
        lines between; G91 counts every point from where the curve starts.
        After G5.3 the motion mode is none, as after G80."""
        r = self.r
        self.ensure_feed_ready()
        s = self.s()
        order = r.choice([3, 3, 4, 5])
        count = r.randint(order - 1, order + 5)   # points after the start
        start = {a: self.pos[a] for a in ("X", "Y")}
        first = "G5.2"
        if r.random() < 0.3:
            first += " P" + num(r.uniform(0.3, 3), 3)
            if order > 3:
                first += " L%d" % order
            if self.feed_mode != 95:
                first += " F" + self.feed()
            self.emit(first)
            first = ""
        last = None
        for k in range(count):
            words = []
            for a in ("X", "Y"):
                v = float(self.n(r.uniform(-15, 15) * s if self.dist == 91
                                 else r.uniform(-40, 40) * s))
                words.append(a + self.n(v))
            last = words
            words.append("P" + num(r.uniform(0.3, 3), 3))
            if first and order > 3:
                words.append("L%d" % order)
            if first and self.feed_mode != 95:
                words.append("F" + self.feed())
            self.emit(" ".join(([first] if first else []) + words))
            first = ""
            if r.random() < 0.1:
                self.emit(r.choice(["(nurbs)", "M8", "M9", "S%d" % r.choice([500, 900])]))
        self.emit("G5.3")
        for a, w in zip(("X", "Y"), last):
            v = float(w[1:])
            if self.dist != 91:
                self.pos[a] = v
            else:
                self.pos[a] = None if start[a] is None else start[a] + v

    def st_sync_episode(self):
        """G33 feeds (K per turn, on every line) and G33.1 taps, which end where
        they started; both modes are modal, and the spindle must turn."""
        r = self.r
        if self.spindle == 0:
            self.spindle = r.choice([3, 4])
            self.emit("S%d M%d" % (r.choice([300, 600]), self.spindle))
        prev = None
        for _ in range(r.randint(1, 3)):
            modal = prev is not None and r.random() < 0.3   # axis words and K alone
            g = prev if modal else ("G33.1" if r.random() < 0.4 else "G33")
            axes = r.sample(AXES, r.randint(1, 2))
            scale = 8 if self.dist == 91 else 20
            words = [a + self.n(r.uniform(-scale, scale) * self.s()) for a in axes]
            words.append("K" + num(r.choice([0.5, 0.8, 1, 1.25, 1.5]) * self.s(), 4))
            if g == "G33.1" and r.random() < 0.3:
                words.append("I%d" % r.randint(1, 3))
            self.emit(" ".join(([] if modal else [g]) + words))
            if g == "G33":
                self.forget_position(axes)
            prev = g
        self.emit("G80")

    def st_probe_episode(self):
        """G38.2-G38.5 toward a point away from here, maybe once more in the
        probe mode, then the results read back: rs274's stand-in trips at the
        end and backs off 0.254 mm (0.01 in), so the position is then unknown."""
        r = self.r
        if self.feed_mode == 95:
            self.set_feed_mode(94)
        g = r.choice(["G38.2", "G38.3", "G38.4", "G38.5"])
        words = []
        for a in r.sample(AXES, r.randint(1, 3)):
            if self.dist == 91:
                words.append(a + self.n(r.choice([-1, 1]) * r.uniform(1, 15) * self.s()))
            else:
                here = self.pos[a] if self.pos[a] is not None else 0.0
                words.append(a + self.n(here + r.choice([-1, 1]) * r.uniform(1, 15) * self.s()))
        line = g + " " + " ".join(words)
        if self.feed_mode == 93 or r.random() < 0.3:
            line += " F" + self.feed()
        self.emit(line)
        self.forget_position()
        if r.random() < 0.3:   # the probe mode is modal: axis words alone probe again
            self.emit("%s%s" % (r.choice(AXES), self.n(r.uniform(-20, 20) * self.s())) +
                      (" F" + self.feed() if self.feed_mode == 93 else ""))
        self.emit("(DEBUG, probed #5061 #5062 #5063 tripped #5070 at #5420 #5421 #5422)")
        if r.random() < 0.5:
            self.emit("#<probed_z> = #5063")
        self.emit("G80")

    def st_diameter_episode(self):
        """G7 lathe diameter mode: a few straight moves whose X words are
        diameters (the axis moves half), G7 and G8 alone or on a move's line."""
        r = self.r
        lines = r.randint(1, 3)
        prefix = "G7 " if r.random() < 0.5 else ""
        if not prefix:
            self.emit("G7")
        for k in range(lines + 1):
            last = k == lines
            if last:
                if r.random() < 0.5:
                    self.emit("G8")
                    return
                prefix = "G8 "   # this line's X is a radius again
            g = r.choice(["G0", "G1"])
            words, scale = [], 1 if last else 2
            for a in r.sample(AXES, r.randint(1, 3)):
                if self.dist == 91:
                    w = self.n(r.uniform(-15, 15) * self.s() * (scale if a == "X" else 1))
                    words.append(a + w)
                    if self.pos[a] is not None:
                        self.pos[a] += float(w) / (scale if a == "X" else 1)
                else:
                    v = r.uniform(-40, 40) * self.s() if a != "Z" else r.uniform(-5, 10) * self.s()
                    w = self.n(v * (scale if a == "X" else 1))
                    words.append(a + w)
                    self.pos[a] = float(w) / (scale if a == "X" else 1)
            if g == "G1":
                self.ensure_feed_ready()
            line = prefix + " ".join([g] + words)
            if g == "G1" and self.feed_mode == 93:
                line += " F" + self.feed()
            self.emit(line)
            prefix = ""

    def st_units_episode(self):
        """A few moves in the other unit system, then back."""
        other = "in" if self.units == "mm" else "mm"
        self.set_units(other)
        for _ in range(self.r.randint(1, 3)):
            self.simple_statement(inner=True)
        self.set_units(self.home_units)

    def header(self):
        r = self.r
        self.out.append("(gen-program.py seed program, %s)" % self.home_units)
        self.emit("G%d G17 G90 G94 G40 G49 G80" % (20 if self.home_units == "in" else 21))
        for name in GLOBAL_NAMES:
            self.emit("#<%s> = %s" % (name, num(r.uniform(-5, 5), 3)))
        for p in GEOM_PARAMS:
            if r.random() < 0.5:
                v = round(r.uniform(-20, 20) * self.s(), 3)
                self.geom[p] = v
                self.emit("#%d = %s" % (p, num(v, 3)))
        for i in range(r.randint(1, 3)):
            self.define_sub(i)
        if self.r98.random() < 0.5:
            self.fanuc = ["%d" % (8000 + i) for i in range(self.r98.randint(1, 2))]
        self.emit("T%d M6" % r.choice(TOOLS))
        self.emit("G43")
        self.emit("S%d M3" % r.choice([1000, 3000, 6000]))
        self.spindle = 3
        self.emit("F" + self.feed())
        self.st_anchor()

    def generate(self):
        self.header()
        while len(self.out) < self.blocks - 3:
            self.simple_statement()
        self.emit("G80 G90 G94")
        self.emit("M5 M9")
        self.emit(self.r.choice(["M30", "M2"]))
        for number in self.fanuc:
            self.define_fanuc(number)
        return "\n".join(self.out) + "\n"


class MotionGen(Gen):
    """--motion: programs for the motion runtime (`cnc-run run`, the simulated
    mill of rt-config/sim-3axis.ini: X/Y +-500 mm, Z -250..+50 mm). Only the
    language that makes or shapes motion: G0/G1/G2/G3 (IJK and R, full circles
    with P, helices), G17-G19, G61/G61.1/G64 P, G90/G91, G90.1/G91.1, G20/G21,
    feed changes, dwells, canned cycles, loops and subroutines. Feeds are machine
    feeds (300-6000 mm/min) and every move stays within a box of about +-100 mm
    and Z -20..+20 mm (Z 0 of G54 is 100 mm below the machine's): whenever the
    position is unknown or has wandered off (incremental moves, loops, calls,
    cycles) the program re-anchors with an absolute rapid. Tool 1 of rt-config/tools.tbl, no tool changes."""

    BOX_XY, BOX_Z = 80.0, (-15.0, 15.0)   # mm: re-anchor beyond this

    def feed(self):
        return num(self.r.choice([300, 600, 1200, 2000, 3000, 4500, 6000]) * self.s(), 3)

    def st_modal(self):
        r = self.r
        c = r.randint(0, 9)
        if c in (0, 1):
            self.set_plane(r.choice([17, 18, 19]))
        elif c == 2:
            self.set_dist(91 if self.dist == 90 else 90)
        elif c == 3:
            self.ijk_abs = not self.ijk_abs
            self.emit("G90.1" if self.ijk_abs else "G91.1")
        elif c in (4, 5, 6):
            self.emit(r.choice(["G61", "G61.1", "G64", "G64 P%s" % self.n(
                r.choice([0.01, 0.02, 0.05, 0.1, 0.5]) * self.s())]))
        elif c in (7, 8):
            self.emit("F" + self.feed())
        else:
            self.emit("G4 P%s" % num(r.uniform(0, 0.3), 2))

    def st_straight(self):
        """G0/G1 within the box; computed words only from values of known size."""
        r = self.r
        if self.dist == 91 and any(self.pos[a] is None for a in AXES):
            self.set_dist(90)
        g = r.choice(["G0", "G1", "G1", "G1"])
        words, s = [], self.s()
        for a in r.sample(AXES, r.randint(1, 3)):
            if self.dist == 91:
                d = float(self.n(r.uniform(-15, 15) * s if a != "Z" else r.uniform(-4, 4) * s))
                words.append(a + self.n(d))
                self.pos[a] += d
            elif r.random() < 0.12 and self.geom and self.units == self.home_units:
                p = r.choice(sorted(self.geom))
                off = float(self.n(r.uniform(-5, 5) * s))
                words.append("%s[#%d + %s]" % (a, p, self.n(off)))
                self.pos[a] = self.geom[p] + off
            elif r.random() < 0.08 and a != "Z":
                # a scratch value, within +-10 program units
                words.append("%s[#%d MOD 10]" % (a, r.choice(SCRATCH)))
                self.pos[a] = None
            else:
                v = float(self.n(r.uniform(-40, 40) * s if a != "Z" else r.uniform(-5, 10) * s))
                words.append(a + self.n(v))
                self.pos[a] = v
        line = " ".join([g] + words)
        if g == "G1" and r.random() < 0.15:
            line += " F" + self.feed()
        self.emit(line)

    def st_arc(self):
        if self.dist == 91 and any(self.pos[a] is None for a in AXES):
            self.set_dist(90)
        return Gen.st_arc(self)

    def absolute_block(self, fn):
        """Loops, ifs and calls repeat their moves: absolute ones only."""
        if self.dist != 90:
            self.set_dist(90)
        fn()

    def wandered(self):
        lo, hi = (v * self.s() for v in self.BOX_Z)
        for a in AXES:
            v = self.pos[a]
            if v is None:
                return True
            if a == "Z" and not lo <= v <= hi or a != "Z" and abs(v) > self.BOX_XY * self.s():
                return True
        return False

    def simple_statement(self, inner=False, in_sub=False):
        r = self.r
        c = r.random()
        if c < 0.34:
            return self.st_straight()
        if c < 0.58:
            return self.st_arc()
        if c < 0.62:
            return self.st_assign()
        if inner:
            if c < 0.68 and self.depth < 2:
                return self.st_if()
            if c < 0.74 and self.depth < 2:
                return self.st_loop()
            return self.st_straight()
        if c < 0.68:
            return self.st_cycle()
        if c < 0.82:
            return self.st_modal()
        if c < 0.85:
            return self.st_anchor()
        if c < 0.88:
            return self.absolute_block(self.st_if)
        if c < 0.92:
            return self.absolute_block(self.st_loop)
        if c < 0.96:
            return self.absolute_block(self.st_call)
        return self.st_units_episode()

    def header(self):
        r = self.r
        self.out.append("(gen-program.py --motion seed program, %s)" % self.home_units)
        self.emit("G%d G17 G90 G94 G40 G49 G80" % (20 if self.home_units == "in" else 21))
        for name in GLOBAL_NAMES:
            self.emit("#<%s> = %s" % (name, num(r.uniform(-5, 5), 3)))
        for p in GEOM_PARAMS:
            if r.random() < 0.5:
                v = round(r.uniform(-20, 20) * self.s(), 3)
                self.geom[p] = v
                self.emit("#%d = %s" % (p, num(v, 3)))
        for i in range(r.randint(1, 2)):
            self.define_sub(i)
        # Z 0 of the program 100 mm below the machine's: arcs in G18/G19 may
        # rise some 60 mm above their start, and Z travels -250..+50
        self.emit("G10 L2 P1 X0 Y0 Z%s" % self.n(-100 * self.s()))
        self.emit("G54 T1 M6")
        self.emit("G43")
        self.emit("S%d M3" % r.choice([1000, 3000, 6000]))
        self.spindle = 3
        self.emit("F" + self.feed())
        self.emit(r.choice(["G64 P%s" % self.n(r.choice([0.01, 0.05, 0.2]) * self.s()),
                            "G64 P%s" % self.n(0.02 * self.s()), "G61", "G64"]))
        self.st_anchor()

    def generate(self):
        self.header()
        while len(self.out) < self.blocks - 3:
            self.simple_statement()
            if self.wandered():
                if self.dist != 90:
                    self.set_dist(90)
                self.st_anchor()
        self.emit("G80 G90 G94")
        self.emit("M5 M9")
        self.emit(self.r.choice(["M30", "M2"]))
        return "\n".join(self.out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--blocks", type=int, default=200)
    ap.add_argument("--units", choices=["mm", "in"])
    ap.add_argument("--motion", action="store_true",
                    help="a program for cnc-run run on the simulated mill (see MotionGen)")
    a = ap.parse_args()
    gen = MotionGen if a.motion else Gen
    print(gen(a.seed, a.blocks, a.units).generate(), end="")


if __name__ == "__main__":
    main()
