#!/usr/bin/python3
"""Checks a `candump -L` capture of a CAN master's start-up of NODES
(can-master-test, or cnc-run run --backend socketcan):
per node the SDO configuration in order, each request answered before the
next; then NMT start; then the CiA 402 walk (0x06, 0x07, 0x0F) in RPDO 1;
then the cyclic rhythm: every SYNC preceded by one RPDO per node and
answered by one TPDO per node, TPDOs matched to SYNCs by order, each carrying
the target of the RPDO before its SYNC once the drive is enabled.
--strict: a TPDO may come at most one SYNC late (real hosts, KVM);
--lenient: any number of SYNCs late (qemu TCG: the drives' processes are
scheduled in bursts), but never before its SYNC, and the capture must hold
a TPDO for nearly every SYNC.
--period-ms P: the SYNC period the master runs at (0x60C2:01), default 4.
--servo: the drives run a servo plant (cnc-drive-sim --config), whose
actual trails the target: TPDO values are not compared with the targets.
--guard INI: the master is cnc-run with that INI's [CAN] guarding keys: each
drive is also told to guard it (0x1006, 0x1016:01, 0x1400:05, 0x6007, 0x605E
after 0x1017) and the master's own heartbeat (MASTER_NODE) runs after NMT start.
Usage: check-startup.py [--strict|--lenient] [--period-ms P] [--guard INI] CAPTURE NODE..."""
import configparser
import sys

OP_ENABLED = 0x27  # statusword & 0x6F in Operation enabled
MISSING_MAX = 2    # TPDOs of one node the end of the capture may cut off
COMPARE_VALUES = True  # slew plant: a TPDO's actual is the target before its SYNC

SDO_SEQUENCE = [  # (command byte, index, sub, value) the master sends
    (0x40, 0x1000, 0, None),
    (0x2F, 0x6060, 0, 8),
    (0x2F, 0x60C2, 1, "period"), (0x2F, 0x60C2, 2, 0xFD),
    (0x2F, 0x1600, 0, 0), (0x23, 0x1600, 1, 0x60400010), (0x23, 0x1600, 2, 0x607A0020),
    (0x2F, 0x1600, 0, 2),
    (0x2F, 0x1A00, 0, 0), (0x23, 0x1A00, 1, 0x60410010), (0x23, 0x1A00, 2, 0x60640020),
    (0x2F, 0x1A00, 0, 2),
    (0x2B, 0x1017, 0, 50),
    (0x40, 0x6061, 0, None),
]


def frames(path):
    for line in open(path):
        parts = line.split()
        if len(parts) != 3 or "#" not in parts[2]:
            continue
        ident, data = parts[2].split("#", 1)
        yield int(ident, 16), bytes.fromhex(data) if data and data[0] != "R" else b""


def sdo_request(data):
    value = int.from_bytes(data[4:8], "little") if data[0] != 0x40 else None
    return (data[0], int.from_bytes(data[1:3], "little"), data[3], value)


def guard_keys(ini):
    """The [CAN] guarding keys of a cnc-run INI, with cnc-run's defaults."""
    cp = configparser.ConfigParser(inline_comment_prefixes=None, strict=False)
    cp.optionxform = str.upper
    cp.read(ini)
    can = cp["CAN"] if cp.has_section("CAN") else {}
    get = lambda k, d: int(can.get(k, d))
    # each drive brakes at its axis's acceleration limit, in counts/s^2
    dec = {}
    for sec in cp.sections():
        a = cp[sec]
        if sec.startswith("AXIS_") and "NODE_ID" in a and "COUNTS_PER_MM" in a:
            dec[int(a["NODE_ID"])] = int(float(a["MAX_ACCELERATION"]) * float(a["COUNTS_PER_MM"]))
    return {"node": get("MASTER_NODE", 127), "consumer": get("HEARTBEAT_CONSUMER_MS", 150),
            "rpdo": get("RPDO_TIMEOUT_MS", 100), "abort": get("ABORT_CONNECTION_OPTION", 3),
            "reaction": get("FAULT_REACTION_OPTION", 2), "dec": dec}


def expected_sdos(period_ms, guard, node):
    seq = [(c, i, s, period_ms if v == "period" else v) for c, i, s, v in SDO_SEQUENCE]
    if guard and guard["node"]:
        at = seq.index((0x2B, 0x1017, 0, 50)) + 1
        seq[at:at] = [(0x23, 0x1006, 0, period_ms * 1000),
                      (0x23, 0x1016, 1, guard["node"] << 16 | guard["consumer"]),
                      (0x2B, 0x1400, 5, guard["rpdo"]), (0x2B, 0x6007, 0, guard["abort"]),
                      (0x2B, 0x605E, 0, guard["reaction"])]
        if guard["dec"].get(node):
            seq.insert(at + 5, (0x23, 0x6085, 0, guard["dec"][node]))
    return seq


def check(path, nodes, strict, period_ms, guard=None):
    errors = []
    log = list(frames(path))
    nmt = [i for i, (ident, data) in enumerate(log) if ident == 0 and data == b"\x01\x00"]
    if not nmt:
        return ["no NMT start (000#0100)"]
    start = nmt[0]
    for n in nodes:
        expected = expected_sdos(period_ms, guard, n)
        reqs = [(i, sdo_request(d)) for i, (ident, d) in enumerate(log[:start])
                if ident == 0x600 + n]
        got = [r for _, r in reqs]
        if got != expected:
            errors.append(f"node {n}: SDO requests {got} != expected {expected}")
        for (i, req), nxt in zip(reqs, [j for j, _ in reqs[1:]] + [start]):
            answered = any(ident == 0x580 + n and d[1:4] == log[i][1][1:4]
                           for ident, d in log[i + 1:nxt])
            if not answered:
                errors.append(f"node {n}: SDO 0x{req[1]:04X}:{req[2]:02X} unanswered")
                break
        cws = []
        for ident, d in log[start:]:
            if ident == 0x200 + n and (not cws or cws[-1] != d[0]):
                cws.append(d[0])
        walk = [c for c in cws if c in (0x06, 0x07, 0x0F)]
        if walk[:3] != [0x06, 0x07, 0x0F]:
            errors.append(f"node {n}: controlwords {[hex(c) for c in cws]} lack 0x06, 0x07, 0x0F")
    early = [i for i, (ident, _) in enumerate(log) if ident == 0x080 and i < start]
    if early:
        errors.append(f"{len(early)} SYNCs before NMT start")
    syncs = [i for i, (ident, _) in enumerate(log) if ident == 0x080 and i > start]
    if len(syncs) < 200:
        errors.append(f"only {len(syncs)} SYNCs after NMT start")
    errors += check_cycles(log, start, syncs, nodes, strict)
    for n in nodes:
        if not any(ident == 0x700 + n and d == b"\x05" for ident, d in log[start:]):
            errors.append(f"node {n}: no operational heartbeat after NMT start")
    if guard and guard["node"] and not any(ident == 0x700 + guard["node"] and d == b"\x05"
                                           for ident, d in log[start:]):
        errors.append(f"no heartbeat of the master (node {guard['node']}) after NMT start")
    return errors


def check_cycles(log, start, syncs, nodes, strict):
    """Each SYNC is preceded by exactly one RPDO per node; the k-th TPDO of a
    node answers the k-th SYNC and carries the target sent before it."""
    errors = []
    prev, targets, tpdos = start, {n: [] for n in nodes}, {n: 0 for n in nodes}
    for k, s in enumerate(syncs + [len(log)]):
        for ident, d in log[prev + 1:s]:
            n = ident & 0x7F
            if n not in tpdos:
                continue
            if ident == 0x200 + n and s < len(log):
                targets[n].append(int.from_bytes(d[2:6], "little", signed=True))
            if ident == 0x180 + n:
                tpdos[n] += 1
                errors += check_tpdo(n, tpdos[n], k, d, targets[n])
        for n in nodes:
            sent = len(targets[n])
            if s < len(log) and sent != k + 1:
                errors.append(f"SYNC #{k + 1}: {sent - k} RPDOs of node {n} before it")
                targets[n][k + 1:] = []
                targets[n] += [None] * (k + 1 - len(targets[n]))
            if strict and s < len(log) and tpdos[n] < k - 1:
                errors.append(f"after SYNC #{k}: {tpdos[n]} TPDOs of node {n} (strict: "
                              "at most one SYNC late)")
        prev = s
        if len(errors) > 10:
            return errors
    # Lenient: the drives may still owe the answers to the master's last
    # settling SYNCs when the capture ends.
    missing_max = MISSING_MAX if strict else max(MISSING_MAX, len(syncs) // 10)
    for n in nodes:
        if tpdos[n] < len(syncs) - missing_max:
            errors.append(f"node {n}: {tpdos[n]} TPDOs for {len(syncs)} SYNCs")
    return errors


def check_tpdo(n, count, k, data, targets):
    """The count-th TPDO of node n, seen after k SYNCs."""
    if count > k:
        return [f"node {n}: TPDO #{count} before SYNC #{count}"]
    if len(data) < 6:
        return [f"node {n}: TPDO #{count} has {len(data)} bytes, not 6"]
    status = int.from_bytes(data[0:2], "little")
    actual = int.from_bytes(data[2:6], "little", signed=True)
    want = targets[count - 1]
    if COMPARE_VALUES and status & 0x6F == OP_ENABLED and want is not None and actual != want:
        return [f"node {n}: TPDO #{count} actual {actual}, but the RPDO before "
                f"SYNC #{count} said {want}"]
    return []


def main():
    args = sys.argv[1:]
    strict, period_ms, guard = True, 4, None
    while args and args[0] in ("--strict", "--lenient", "--period-ms", "--servo", "--guard"):
        opt = args.pop(0)
        if opt == "--guard":
            guard = guard_keys(args.pop(0))
        elif opt == "--servo":
            global COMPARE_VALUES
            COMPARE_VALUES = False
        elif opt == "--period-ms":
            period_ms = int(args.pop(0))
        else:
            strict = opt == "--strict"
    path, nodes = args[0], [int(a) for a in args[1:]]
    print(f"startup capture: {'strict' if strict else 'lenient'} check "
          f"({'TPDO at most one SYNC late' if strict else 'TPDOs matched to SYNCs by order, any lag'})")
    errors = check(path, nodes, strict, period_ms, guard)
    for e in errors[:12]:
        print("startup capture:", e)
    n = sum(1 for _ in frames(path))
    print(f"startup capture: {n} frames, sequence {'ok' if not errors else 'WRONG'}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
