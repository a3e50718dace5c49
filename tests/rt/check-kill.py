#!/usr/bin/python3
"""Judges a `candump -L` capture of a master killed mid-move (tests/rt/can-kill):
for every drive NODE, after the master's last frame (its heartbeat, SYNC,
RPDO or NMT):
  - the drive was moving when the master died (its last TPDOs before differ);
  - it sends an EMCY (0x8130 heartbeat, 0x8700 SYNC, 0x8250 RPDO timeout)
    no later than the heartbeat consumer time after the master's last
    heartbeat (plus --slack ms for the capture's own timing);
  - it brakes at its quick stop deceleration (0x6085 = the axis's
    MAX_ACCELERATION x COUNTS_PER_MM) to Switch on disabled, within the
    ramp's time (speed / deceleration) plus the slack after its EMCY;
  - and stays there: no TPDO after that moves it.
usage: check-kill.py --consumer MS --slack MS INI CAPTURE NODE..."""
import argparse
import configparser
import sys

LOSS_CODES = {0x8130: "heartbeat consumer", 0x8700: "SYNC lost", 0x8250: "RPDO timeout"}


def frames(path):
    for line in open(path):
        parts = line.split()
        if len(parts) != 3 or "#" not in parts[2]:
            continue
        ident, data = parts[2].split("#", 1)
        yield float(parts[0].strip("()")), int(ident, 16), bytes.fromhex(data) if data else b""


def axes_of(ini):
    cp = configparser.ConfigParser(strict=False)
    cp.optionxform = str.upper
    cp.read(ini)
    out = {}
    for sec in cp.sections():
        a = cp[sec]
        if sec.startswith("AXIS_") and "NODE_ID" in a:
            out[int(a["NODE_ID"])] = (float(a["MAX_ACCELERATION"]), float(a["COUNTS_PER_MM"]))
    master = int(cp["CAN"].get("MASTER_NODE", 127)) if cp.has_section("CAN") else 127
    period_s = float(cp["EMCMOT"].get("SERVO_PERIOD", 1000000)) * 1e-9
    return out, master, period_s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--consumer", type=float, required=True)
    ap.add_argument("--slack", type=float, required=True)
    ap.add_argument("ini")
    ap.add_argument("capture")
    ap.add_argument("nodes", type=int, nargs="+")
    a = ap.parse_args()
    axes, master, period_s = axes_of(a.ini)
    log = list(frames(a.capture))
    nodes = set(a.nodes)
    from_master = [t for t, i, _ in log if i in (0x000, 0x080, 0x700 + master)
                   or (0x200 <= i < 0x280 and (i & 0x7F) in nodes)]
    hbs = [t for t, i, _ in log if i == 0x700 + master]
    if not from_master or not hbs:
        print("kill capture: no frames of the master (or none of its heartbeats)")
        return 1
    t_dead, t_hb = from_master[-1], hbs[-1]
    print(f"kill capture: master's last frame at +0 ms, its last heartbeat "
          f"{(t_hb - t_dead) * 1000:+.1f} ms")
    errors = []
    for n in a.nodes:
        tp = [(t, int.from_bytes(d[0:2], "little"), int.from_bytes(d[2:6], "little", signed=True))
              for t, i, d in log if i == 0x180 + n and len(d) >= 6]
        emcy = [(t, int.from_bytes(d[0:2], "little")) for t, i, d in log
                if i == 0x080 + n and len(d) >= 2]
        before = [p for t, _, p in tp if t <= t_dead]
        if len(before) < 2 or before[-1] == before[-2]:
            errors.append(f"node {n}: not moving when the master died (TPDOs {before[-2:]})")
            continue
        if not emcy:
            errors.append(f"node {n}: no EMCY after the master died")
            continue
        t_e, code = emcy[0]
        react_ms = (t_e - t_hb) * 1000
        if t_e < t_dead:
            errors.append(f"node {n}: EMCY 0x{code:04X} before the master died")
        if code not in LOSS_CODES:
            errors.append(f"node {n}: EMCY 0x{code:04X} is not a lost-master code")
        if react_ms > a.consumer + a.slack:
            errors.append(f"node {n}: EMCY {react_ms:.1f} ms after the master's last heartbeat "
                          f"(consumer time {a.consumer:.0f} ms + {a.slack:.0f})")
        after = [(t, s, p) for t, s, p in tp if t >= t_e]
        stopped = [k for k, (_, s, _) in enumerate(after) if s & 0x4F == 0x40]
        if not stopped:
            errors.append(f"node {n}: never reached Switch on disabled after its EMCY "
                          f"({len(after)} TPDOs, last statusword "
                          f"0x{after[-1][1] if after else 0:04X})")
            continue
        t_stop, _, p_stop = after[stopped[0]]
        # one TPDO per SYNC: the capture's own timestamps bunch up under load
        speed = abs(before[-1] - before[-2]) / period_s
        acc, cpm = axes[n]
        ramp_ms = speed / (acc * cpm) * 1000
        took_ms = (t_stop - t_e) * 1000
        travel = abs(p_stop - before[-1]) / cpm
        if took_ms > ramp_ms + a.slack:
            errors.append(f"node {n}: at standstill {took_ms:.1f} ms after its EMCY, the ramp "
                          f"needs {ramp_ms:.1f} ms (+ {a.slack:.0f})")
        later = [p for t, _, p in tp if t > t_stop and p != p_stop]
        if later:
            errors.append(f"node {n}: moved again after it stopped (to {later[0]} counts)")
        print(f"kill capture: node {n}: EMCY 0x{code:04X} ({LOSS_CODES.get(code, '?')}) "
              f"{react_ms:.1f} ms after the last heartbeat (consumer {a.consumer:.0f} ms); "
              f"braked from {speed / cpm:.1f} mm/s over {travel:.3f} mm in {took_ms:.1f} ms "
              f"(ramp {ramp_ms:.1f} ms); Switch on disabled, still")
    for e in errors:
        print("kill capture:", e)
    print(f"kill capture: {len(a.nodes)} drives, {'all stopped on their own' if not errors else 'WRONG'}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
