#!/usr/bin/python3
"""Writes the bad-input robustness cases into DIR (generated so that no large or
binary file is committed). Each case is NAME.ngc plus a line in DIR/cases.txt:
NAME EXIT [substring the first diagnostic must contain]; EXIT "x" means 0 or 2
(the point is only: no crash, no hang, no undefined behaviour)."""
import os
import random
import sys

out = sys.argv[1]
os.makedirs(out, exist_ok=True)
cases = []


def case(name, data, code, sub=""):
    mode = "wb" if isinstance(data, bytes) else "w"
    with open(os.path.join(out, name + ".ngc"), mode) as f:
        f.write(data)
    cases.append(f"{name} {code} {sub}".rstrip())


# Programs cut short, as a copy interrupted mid-transfer would be.
case("trunc_midline", "G21 G90\nG1 X1 F100\nG1 X2 Y", 2)
case("trunc_midword", "G21 G90\nG1 X1 F100\nG", 2)
case("trunc_midcomment", "G21\nG0 X1 (move to the", 2, "comment")
case("trunc_midexpr", "G21\n#1=[1+[2*", 2)
case("trunc_midexpr_call", "G21\nG0 X[sin[", 2)
case("trunc_if_block", "G21\no1 if [1]\nG0 X1\n", 2)
case("trunc_while_block", "G21\n#1=0\no2 while [#1 LT 3]\n#1=[#1+1]\n", 2)
case("trunc_sub_block", "G21\no100 sub\nG0 X1\n", 2)
case("trunc_oword_name", "G21\no1", 2)
case("unterminated_comment", "G21\n(no closing paren\nG0 X1\nM2\n", 2, "comment")
# Binary garbage: NUL, 0xFF, lone carriage returns, short and long lines.
for seed in range(6):
    r = random.Random(seed)
    body = bytearray(b"\x00\xff\r" if seed % 2 == 0 else b"G0 X1\r\xff\x00\n")
    for _ in range(2000 + 500 * seed):
        body.append(10 if r.random() < 0.03 * (seed + 1) else r.randrange(256))
    case(f"garbage_{seed}", bytes(body), 2)
case("nul_in_line", b"G21\nG0 X1\x00Y2\nM2\n", 2)
case("ff_in_comment", b"G21\n(\xff\xfe)\nG0 X\xff\nM2\n", 2)
# rs274 takes a lone \r as white space: this is one legal line "G21 G0 X1 M2".
case("lone_cr", b"G21\rG0 X1\rM2\r", 0)
# Very long lines (100 kB): comment, number, words, brackets.
K = 100_000
case("long_comment", "G21\n(" + "x" * K + ")\nM2\n", 2, "too long")
case("long_number", "G21\nG0 X1" + "1" * K + "\nM2\n", 2, "too long")
case("long_words", "G21\nG0" + " X1" * (K // 3) + "\nM2\n", 2, "too long")
case("long_brackets", "G21\n#1=" + "[" * K + "1" + "]" * K + "\nM2\n", 2)
case("long_open_brackets", "G21\n#1=" + "[" * K + "\nM2\n", 2)
case("long_no_newline", "x" * K, 2)
# Recursion with no way out.
case("self_recursion", "G21\no100 sub\nG0 X1\no100 call\no100 endsub\no100 call\nM2\n",
     2, "subroutine levels")
case("mutual_recursion", "G21\no100 sub\no200 call\no100 endsub\n"
     "o200 sub\no100 call\no200 endsub\no100 call\nM2\n", 2, "subroutine levels")
# Runaway loops; the runner passes a small --max-loops, the diagnostic names the line.
case("runaway_while", "G21\n#1=0\no1 while [1]\n#1=[#1+1]\no1 endwhile\nM2\n", 2, "line 3")
case("runaway_while_1block", "G21\no1 while [1]\no1 endwhile\nM2\n", 2, "line 2")
case("runaway_do", "G21\no1 do\n#1=1\no1 while [1]\nM2\n", 2, "line 2")
case("runaway_repeat", "G21\no1 repeat [1000000000]\n#1=1\no1 endrepeat\nM2\n", 2, "line 2")
case("runaway_in_sub", "G21\no100 sub\no101 while [1]\nG0 X1\no101 endwhile\n"
     "o100 endsub\no100 call\nM2\n", 2, "line 3")
# A false test skips to the first end line of that name; a second one below
# sends control back to the head for ever, running no iteration (found by the
# fuzzer; rs274 loops too). Each such lap counts against the limit.
case("runaway_while_second_end", "G21\no1 while [0]\no1 endwhile\nG0 X1\no1 endwhile\nM2\n",
     2, "line 2")
case("runaway_repeat_second_end", "G21\no1 repeat [0]\no1 endrepeat\nG0 X1\no1 endrepeat\nM2\n",
     2, "line 2")
# Runaway cycles: G76 cuts until its depth reaches K, which a large degression
# R puts astronomically far away, and H adds spring passes without bound.
case("runaway_g76_degression", "G18 G21 G90\nS600 M3\nG0 X20 Z3\n"
     "G76 P2.5 Z-28 I-1.2 J0.3 K1.53 R551 H2\nM2\n", 2, "G76 would cut more than")
case("runaway_g76_spring", "G18 G21 G90\nS600 M3\nG0 X20 Z3\n"
     "G76 P2.5 Z-28 I-1.2 J0.3 K1.53 H2000000000\nM2\n", 2, "G76 would cut more than")
# Degenerate files.
case("empty", "", 2)
case("only_percent", "%\n", 2)
case("only_percent_twice", "%\n%\n", 0)
case("only_comments", "(a)\n; b\n(c)\n", 2)
case("blank_1M", "\n" * 1_000_000, 2)
case("blank_1M_then_end", "\n" * 1_000_000 + "M2\n", 0)
# Out-of-range numbers where an integer is meant, and arithmetic that overflows:
# undefined behaviour in C if converted blindly (UBSan catches it under make sanitize).
HUGE = ["G99999999999999999999 X1", "G1e30", "M99999999999999999999",
        "T99999999999999999999 M6", "N99999999999999999999 G0 X1", "G4 P1e300",
        "S99999999999999999999 M3", "S-1e300 M3", "G1 X1 F1e308", "#[1e30]=1",
        "#1=#[99999999999]", "#1=#[-1e30]",
        "o99999999999999999999 sub\no99999999999999999999 endsub",
        "o1 repeat [1e30]\no1 endrepeat", "o1 repeat [-1e30]\no1 endrepeat",
        "G10 L2 P1e30 X1", "G10 L1 P1e30 Z1", "G41 D1e30", "G43 H1e30",
        "#1=[1/0]", "#1=[SQRT[-1]]", "#1=[ACOS[2]]", "#1=[LN[0]]", "#1=[-1 MOD 0]",
        "#1=[2 ** 1e10]", "#1=[FIX[1e300]]", "#1=[ROUND[1e300]]",
        "G0 X[1e308*10]", "G2 X1 Y0 R1e-300 F10", "G2 X1e300 Y0 R1 F10",
        "G83 X1 Y1 Z-1 R1 Q1e-300 F10", "G81 X1 Y1 Z-1 R1 L1e30 F10",
        "G73 X1 Y1 Z-1 R1 Q0.5 F10 L99999999999", "M66 P1e30 L0", "M62 P1e30",
        "G64 P1e300 Q-1", "G10 L20 P-1e30 X1", "G91 G0 X1e308\nG0 X1e308",
        "G20 G0 X1e307", "M19 R1e300"]
for i, line in enumerate(HUGE):
    case(f"huge_{i:02d}", "G21\n" + line + "\nM2\n", "x")

with open(os.path.join(out, "cases.txt"), "w") as f:
    f.write("\n".join(cases) + "\n")
