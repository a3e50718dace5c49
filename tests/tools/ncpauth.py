"""ncpar's seal on LCM messages, from Python's standard library, for the
test tools that forge, replay and tamper (see include/ncpar/auth.h):

    encoding | "NCA1" | sent_ns (>q) | salt (>I) | HMAC-SHA256(key,
        b"ncpar-lcm-1\\0" + channel + b"\\0" + encoding + magic..salt)[:16]

Plain messages only (an encrypted status is cnc-ctl's to read)."""
import hashlib
import hmac
import os
import struct
import time

DOMAIN = b"ncpar-lcm-1\0"
TRAILER = 32


def key_path(explicit=None):
    """The key file as ncp_auth_key_path finds it."""
    if explicit:
        return explicit
    xdg = os.environ.get("XDG_CONFIG_HOME", "")
    if xdg.startswith("/"):
        return os.path.join(xdg, "ncpar", "lcm.key")
    return os.path.join(os.environ["HOME"], ".config", "ncpar", "lcm.key")


def load_key(path=None):
    data = open(key_path(path), "rb").read()
    if len(data) == 32:
        return data
    return bytes.fromhex(data.decode().strip())


def seal(key, channel, body, sent_ns=None, salt=0x5A5A5A5A):
    if isinstance(channel, str):
        channel = channel.encode()
    head = b"NCA1" + struct.pack(">qI", time.time_ns() if sent_ns is None else sent_ns, salt)
    mac = hmac.new(key, DOMAIN + channel + b"\0" + body + head, hashlib.sha256).digest()[:16]
    return body + head + mac


def unseal(key, channel, msg):
    """The encoding of a plain sealed message, or None when its seal is wrong."""
    if len(msg) < TRAILER or msg[-TRAILER:-TRAILER + 4] != b"NCA1":
        return None
    if isinstance(channel, str):
        channel = channel.encode()
    body, head, mac = msg[:-TRAILER], msg[-TRAILER:-16], msg[-16:]
    want = hmac.new(key, DOMAIN + channel + b"\0" + body + head, hashlib.sha256).digest()[:16]
    return body if hmac.compare_digest(mac, want) else None


def ensure_key(fallback_dir):
    """The key file the binaries will find, made (0600, folder 0700) when
    missing; with neither XDG_CONFIG_HOME nor HOME set (a bare test guest),
    XDG_CONFIG_HOME is set to fallback_dir for this process and its children."""
    if not os.environ.get("XDG_CONFIG_HOME", "").startswith("/") and not os.environ.get("HOME"):
        os.environ["XDG_CONFIG_HOME"] = os.path.abspath(fallback_dir)
    path = key_path()
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), mode=0o700, exist_ok=True)
        try:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        except FileExistsError:
            return path
        with os.fdopen(fd, "wb") as f:
            f.write(os.urandom(32))
    return path
