#!/usr/bin/env python3
"""Messages, sizes and bandwidth per LCM channel: from an lcm-logger file, or
heard live on an udpm:// group (e.g. while lcm-logplayer replays a log).

Per channel: the number of messages, their rate (messages over the time from
the first to the last, minus one), the payload (the encoded fields, without
the 8-byte type fingerprint LCM puts in front of every message: what seed
002's Tables I-II count), and LCM's own overhead per message beside it: the
fingerprint, the LC02 header (magic, sequence number, channel name and its
NUL) and IPv4 + UDP (28 bytes). A message bigger than one datagram is sent
in LC03 fragments, each with its own headers: counted as such. ncpar's seal
(the 32-byte trailer with the key's MAC after the encoded fields, see
include/ncpar/auth.h) is overhead too, not payload: it is counted beside
LCM's, so the payload stays the paper's figure.

usage: lcm-bandwidth.py LOGFILE [--channel REGEX]... [--json]
       lcm-bandwidth.py --listen [URL] --seconds S [--channel REGEX]... [--json]
URL defaults to $LCM_DEFAULT_URL, else udpm://239.255.76.67:7667.
"""
import json
import os
import re
import socket
import struct
import sys
import time

USAGE = "usage: lcm-bandwidth.py LOGFILE | --listen [URL] --seconds S [--channel REGEX]... [--json]"
LOG_SYNC = 0xEDA1DA01
LC02, LC03 = 0x4C433032, 0x4C433033
FINGERPRINT = 8
IP_UDP = 28
SEAL = 32                  # ncpar's trailer: magic, sent_ns, salt, 16-byte MAC
SEAL_MAGICS = (b"NCA1", b"NCE1")


def seal_of(body):
    """The bytes of ncpar's seal at the end of an encoded message (0: none)."""
    return SEAL if len(body) >= FINGERPRINT + SEAL and body[-SEAL:-SEAL + 4] in SEAL_MAGICS else 0
MAX_DATAGRAM = 65507   # a message up to this (with its LC02 header) is not fragmented
FRAG_PAYLOAD = 65507 - 20  # LC03 header is 20 bytes before the data of each fragment


def wire_overhead(channel, size):
    """Bytes LCM and UDP/IP add to one message of `size` encoded bytes
    (fingerprint included in size)."""
    short = 8 + len(channel) + 1
    if short + size <= MAX_DATAGRAM:
        return FINGERPRINT + short + IP_UDP
    body = len(channel) + 1 + size
    frags = (body + FRAG_PAYLOAD - 1) // FRAG_PAYLOAD
    return FINGERPRINT + frags * (20 + IP_UDP) + len(channel) + 1


def read_log(path):
    """(timestamp_s, channel, encoded size, seal bytes) of every event in an LCM log file."""
    data = open(path, "rb").read()
    out, i = [], 0
    while i + 28 <= len(data):
        sync, _, utime, clen, dlen = struct.unpack_from(">Iqqii", data, i)
        if sync != LOG_SYNC or clen < 0 or dlen < 0:
            sys.exit("lcm-bandwidth: %s: not an LCM log at byte %d" % (path, i))
        i += 28
        ch = data[i:i + clen].decode(errors="replace")
        body = data[i + clen:i + clen + dlen]
        i += clen + dlen
        if i > len(data):
            break   # the logger was stopped mid-event
        out.append((utime * 1e-6, ch, dlen, seal_of(body)))
    return out


def parse_url(url):
    m = re.match(r"^udpm://([0-9.]+):(\d+)", url or "")
    if not m:
        sys.exit("lcm-bandwidth: only udpm://GROUP:PORT URLs are understood, not %r" % url)
    return m.group(1), int(m.group(2))


def listen(url, seconds):
    group, port = parse_url(url)
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    if hasattr(socket, "SO_REUSEPORT"):
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
    s.bind(("", port))
    s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                 socket.inet_aton(group) + socket.inet_aton("0.0.0.0"))
    s.settimeout(0.1)
    out, frags = [], {}
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            buf = s.recv(65536)
        except socket.timeout:
            continue
        now = time.monotonic()
        if len(buf) < 8:
            continue
        magic, seq = struct.unpack_from(">II", buf, 0)
        if magic == LC02:
            nul = buf.find(b"\0", 8)
            if nul < 0:
                continue
            out.append((now, buf[8:nul].decode(errors="replace"), len(buf) - nul - 1,
                        seal_of(buf[nul + 1:])))
        elif magic == LC03 and len(buf) >= 20:
            size, _, no, _ = struct.unpack_from(">IIHH", buf, 8)
            if no == 0:
                nul = buf.find(b"\0", 20)
                if nul >= 0:
                    frags[seq] = buf[20:nul].decode(errors="replace")
                    out.append((now, frags[seq], size, 0))
    return out


def summarise(events, patterns):
    chans = {}
    for t, ch, size, seal in events:
        if patterns and not any(re.search(p, ch) for p in patterns):
            continue
        size -= seal
        c = chans.setdefault(ch, {"messages": 0, "t0": t, "t1": t, "bytes": 0, "min": size,
                                  "max": size, "seals": 0})
        c["seals"] += seal
        c["messages"] += 1
        c["t1"] = t
        c["bytes"] += size
        c["min"], c["max"] = min(c["min"], size), max(c["max"], size)
    rows = []
    for ch in sorted(chans):
        c = chans[ch]
        span = c["t1"] - c["t0"]
        rate = (c["messages"] - 1) / span if span > 0 and c["messages"] > 1 else 0.0
        payload = c["bytes"] / c["messages"] - FINGERPRINT
        seal = c["seals"] / c["messages"]
        over = wire_overhead(ch, int(round(c["bytes"] / c["messages"] + seal))) + seal
        rows.append({"channel": ch, "messages": c["messages"], "seconds": span, "per_second": rate,
                     "payload_bytes": payload, "payload_min": c["min"] - FINGERPRINT,
                     "payload_max": c["max"] - FINGERPRINT, "lcm_overhead_bytes": over,
                     "seal_bytes": seal,
                     "payload_kbps": payload * 8 * rate / 1000.0,
                     "wire_kbps": (payload + over) * 8 * rate / 1000.0})
    return rows


def main():
    argv = sys.argv[1:]
    pats, as_json, url, seconds, log = [], False, None, None, None
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--channel" and i + 1 < len(argv):
            pats.append(argv[i + 1])
            i += 1
        elif a == "--json":
            as_json = True
        elif a == "--listen":
            url = os.environ.get("LCM_DEFAULT_URL") or "udpm://239.255.76.67:7667"
            if i + 1 < len(argv) and argv[i + 1].startswith("udpm://"):
                url = argv[i + 1]
                i += 1
        elif a == "--seconds" and i + 1 < len(argv):
            seconds = float(argv[i + 1])
            i += 1
        elif not a.startswith("-") and log is None:
            log = a
        else:
            sys.exit(USAGE)
        i += 1
    if (log is None) == (url is None) or (url is not None and not seconds):
        sys.exit(USAGE)
    rows = summarise(read_log(log) if log else listen(url, seconds), pats)
    if as_json:
        print(json.dumps(rows, indent=1))
        return
    print("%-28s %8s %9s %9s %9s %10s %10s" % ("channel", "messages", "msg/s", "payload B",
                                               "LCM+IP B", "kbit/s", "wire kbit/s"))
    for r in rows:
        print("%-28s %8d %9.1f %9.1f %9d %10.2f %10.2f" % (
            r["channel"], r["messages"], r["per_second"], r["payload_bytes"], r["lcm_overhead_bytes"],
            r["payload_kbps"], r["wire_kbps"]))


if __name__ == "__main__":
    main()
