#!/usr/bin/env python3
"""tofguard's message authentication for Python (docs/security.md): verifies
an authenticated_message_t (e.g. from SAFETY_STATUS_AUTH) the way
tofguard/auth/message_verifier.hpp does, and signs one the way
tofguard/auth/message_signer.hpp does. Standard library only: no LCM
bindings are needed, the envelope is decoded here (LCM's encoding:
big-endian, strings with a 32-bit length that counts a trailing NUL).

As a module:
    key = read_key_file("/etc/tofguard/auth.key")
    verifier = Verifier(key, max_age_us=250_000)
    payload = verifier.open(data, "SAFETY_STATUS", now_utime)   # raises Refused
    status = decode_safety_status(payload)

As a tool (used by the tests against the C++ side):
    tofguard_auth.py verify --key FILE --channel CH [--now-utime US] [--max-age-ms MS] FILE...
        one line per envelope file: "accepted <payload hex>" or "refused: <why>"
    tofguard_auth.py sign --key FILE --channel CH --utime US --seq N PAYLOAD_FILE OUT_FILE
"""
import argparse
import hashlib
import hmac
import os
import stat
import struct
import sys
import time
from collections import namedtuple

# LCM fingerprints (the first 8 bytes of every encoded message); checked
# against the generated C++ types by tests/auth/auth_interop_test.
AUTHENTICATED_MESSAGE_FINGERPRINT = None  # filled in below
SAFETY_STATUS_FINGERPRINT = 0x47A089C6D448A345

KEY_BYTES = 32
TAG_BYTES = 32

Envelope = namedtuple("Envelope", "utime seq channel key_id payload tag")


class Refused(Exception):
    """The message may not be used: the text says why, in one line."""


def _lcm_fingerprint(base_hash):
    # LCM's rule: the type's base hash rotated left by one bit (64-bit).
    return ((base_hash << 1) & 0xFFFFFFFFFFFFFFFF) + ((base_hash >> 63) & 1)


def _lcm_base_hash(fields):
    """LCM 1.3's base hash of a struct from (type, name, is_dynamic_array)."""
    v = 0x12345678

    def signed64(x):
        x &= 0xFFFFFFFFFFFFFFFF
        return x - (1 << 64) if x >= (1 << 63) else x

    def hash_update(v, c):
        v = signed64((v << 8) ^ (v >> 55)) + c
        return signed64(v)

    def hash_string(v, s):
        v = hash_update(v, len(s))
        for ch in s.encode():
            v = hash_update(v, ch - 256 if ch >= 128 else ch)
        return v

    primitives = {"int8_t", "int16_t", "int32_t", "int64_t", "byte", "float", "double", "string", "boolean"}
    for typ, name, dims in fields:
        v = hash_string(v, name)
        if typ in primitives:
            v = hash_string(v, typ)
        v = hash_update(v, len(dims))
        for mode, size in dims:
            v = hash_update(v, mode)
            v = hash_string(v, size)
    return v & 0xFFFFFFFFFFFFFFFF


# authenticated_message_t's fields, as in lcmtypes/authenticated_message_t.lcm
# (dimension mode 0 = constant size, 1 = variable size).
AUTHENTICATED_MESSAGE_FINGERPRINT = _lcm_fingerprint(
    _lcm_base_hash([
        ("int64_t", "utime", []),
        ("int64_t", "seq", []),
        ("string", "channel", []),
        ("string", "key_id", []),
        ("int32_t", "payload_size", []),
        ("byte", "payload", [(1, "payload_size")]),
        ("byte", "tag", [(0, "32")]),
    ]))


def read_key_file(path):
    """The 32-byte key from a tofguard-keygen file; raises Refused naming
    the file when it is missing, open to group/others, owned by another user
    or not 64 hex digits."""
    try:
        st = os.stat(path)
    except OSError:
        raise Refused("%s: no such key file (make one with tofguard-keygen %s)" % (path, path))
    if not stat.S_ISREG(st.st_mode):
        raise Refused("%s: not a regular file" % path)
    if st.st_mode & 0o077:
        raise Refused("%s: key file is open to group or others (mode 0%o); chmod 600 %s" %
                      (path, st.st_mode & 0o777, path))
    if st.st_uid != os.geteuid():
        raise Refused("%s: key file is owned by uid %d, not by the user reading it (uid %d)" %
                      (path, st.st_uid, os.geteuid()))
    with open(path, "rb") as f:
        text = f.read().rstrip(b"\r\n")
    try:
        key = bytes.fromhex(text.decode("ascii"))
    except (UnicodeDecodeError, ValueError):
        key = b""
    if len(text) != 2 * KEY_BYTES or len(key) != KEY_BYTES:
        raise Refused("%s: expected 64 hex digits (a 32-byte key from tofguard-keygen), got %d characters" %
                      (path, len(text)))
    return key


def key_id_of(key):
    return hashlib.sha256(b"tofguard key id" + key).digest()[:8].hex()


def tagged_bytes(utime, seq, channel, key_id, payload):
    """The bytes the tag covers (message_tag.hpp's tagged_bytes, version 1)."""
    def field(b):
        return struct.pack(">I", len(b)) + b
    return (b"tofguard-auth-v1" + struct.pack(">qq", utime, seq) + field(channel.encode()) +
            field(key_id.encode()) + field(payload))


def compute_tag(key, utime, seq, channel, key_id, payload):
    return hmac.new(key, tagged_bytes(utime, seq, channel, key_id, payload), hashlib.sha256).digest()


def _lcm_string(b):
    return struct.pack(">i", len(b) + 1) + b + b"\0"


def encode_envelope(e):
    return (struct.pack(">Q", AUTHENTICATED_MESSAGE_FINGERPRINT) + struct.pack(">qq", e.utime, e.seq) +
            _lcm_string(e.channel.encode()) + _lcm_string(e.key_id.encode()) +
            struct.pack(">i", len(e.payload)) + e.payload + e.tag)


class _Reader:
    def __init__(self, data):
        self.data, self.at = data, 0

    def take(self, n):
        if n < 0 or self.at + n > len(self.data):
            raise Refused("truncated authenticated_message_t")
        b = self.data[self.at:self.at + n]
        self.at += n
        return b

    def unpack(self, fmt):
        return struct.unpack(fmt, self.take(struct.calcsize(fmt)))[0]

    def string(self):
        n = self.unpack(">i")
        b = self.take(n)
        if n < 1 or b[-1:] != b"\0":
            raise Refused("malformed string in authenticated_message_t")
        try:
            return b[:-1].decode("utf-8")
        except UnicodeDecodeError:
            raise Refused("string in authenticated_message_t is not UTF-8")


def decode_envelope(data):
    r = _Reader(data)
    if r.unpack(">Q") != AUTHENTICATED_MESSAGE_FINGERPRINT:
        raise Refused("not an authenticated_message_t (wrong fingerprint)")
    utime, seq = r.unpack(">q"), r.unpack(">q")
    channel, key_id = r.string(), r.string()
    size = r.unpack(">i")
    payload = r.take(size)
    tag = r.take(TAG_BYTES)
    if r.at != len(data):
        raise Refused("trailing bytes after authenticated_message_t")
    return Envelope(utime, seq, channel, key_id, payload, tag)


def sign(key, channel, payload, utime, seq):
    """An encoded authenticated_message_t (as MessageSigner makes it)."""
    key_id = key_id_of(key)
    tag = compute_tag(key, utime, seq, channel, key_id, payload)
    return encode_envelope(Envelope(utime, seq, channel, key_id, payload, tag))


class Verifier:
    """message_verifier.hpp's MessageVerifier: the same checks in the same
    order, the same refusals."""

    def __init__(self, key, max_age_us):
        self.key, self.key_id, self.max_age_us = key, key_id_of(key), max_age_us
        self.last_seq = {}

    def open(self, data, channel, now_utime):
        """The payload bytes of an accepted envelope; raises Refused."""
        e = decode_envelope(data)
        if e.channel != channel:
            raise Refused("signed for channel '%s', not '%s'" % (e.channel, channel))
        if e.key_id != self.key_id:
            raise Refused("signed with key %s, not this deployment's key %s (wrong key file?)" %
                          (e.key_id, self.key_id))
        expected = compute_tag(self.key, e.utime, e.seq, e.channel, e.key_id, e.payload)
        if not hmac.compare_digest(expected, e.tag):
            raise Refused("tag does not match (forged or altered)")
        age_us = now_utime - e.utime
        if abs(age_us) > self.max_age_us:
            raise Refused("stale: sent %d ms ago by this receiver's clock, beyond the +-%d ms accepted (a replay, "
                          "or the clocks disagree)" % ((abs(age_us) // 1000) * (1 if age_us >= 0 else -1), self.max_age_us // 1000))
        last = self.last_seq.get(channel)
        if last is not None and e.seq <= last:
            raise Refused("replayed: seq %d is not above the last accepted %d" % (e.seq, last))
        self.last_seq[channel] = e.seq
        return e.payload


def decode_safety_status(payload):
    """safety_status_t (lcmtypes/safety_status_t.lcm) as a dict."""
    r = _Reader(payload)
    if r.unpack(">Q") != SAFETY_STATUS_FINGERPRINT:
        raise Refused("payload is not a safety_status_t (wrong fingerprint)")
    status = {
        "utime": r.unpack(">q"),
        "seq": r.unpack(">q"),
        "motion_allowed": r.unpack(">b") != 0,
        "stop": r.unpack(">b"),
        "latched": r.unpack(">b") != 0,
        "cause": r.unpack(">b"),
        "reason": r.string(),
        "since_utime": r.unpack(">q"),
    }
    if r.at != len(payload):
        raise Refused("payload is not one safety_status_t (trailing bytes)")
    return status


# speed_limit_t's fields, as in lcmtypes/speed_limit_t.lcm.
SPEED_LIMIT_FINGERPRINT = _lcm_fingerprint(
    _lcm_base_hash([
        ("int64_t", "utime", []),
        ("int64_t", "seq", []),
        ("string", "camera_id", []),
        ("double", "max_arm_speed_m_s", []),
        ("int8_t", "set_by", []),
        ("string", "body_region", []),
        ("double", "separation_m", []),
        ("double", "arm_speed_m_s", []),
        ("int32_t", "valid_for_ms", []),
        ("string", "reason", []),
    ]))


def decode_speed_limit(payload):
    """speed_limit_t (lcmtypes/speed_limit_t.lcm) as a dict. A controller
    keeps the arm's fastest surface point at or below max_arm_speed_m_s of the
    newest verified limit, for valid_for_ms after its arrival on its own
    clock, and at 0 without one (docs/security.md, "The speed limit")."""
    r = _Reader(payload)
    if r.unpack(">Q") != SPEED_LIMIT_FINGERPRINT:
        raise Refused("payload is not a speed_limit_t (wrong fingerprint)")
    limit = {
        "utime": r.unpack(">q"),
        "seq": r.unpack(">q"),
        "camera_id": r.string(),
        "max_arm_speed_m_s": r.unpack(">d"),
        "set_by": r.unpack(">b"),
        "body_region": r.string(),
        "separation_m": r.unpack(">d"),
        "arm_speed_m_s": r.unpack(">d"),
        "valid_for_ms": r.unpack(">i"),
        "reason": r.string(),
    }
    if r.at != len(payload):
        raise Refused("payload is not one speed_limit_t (trailing bytes)")
    if not (limit["max_arm_speed_m_s"] >= 0) or limit["valid_for_ms"] <= 0:
        raise Refused("speed_limit_t: max_arm_speed_m_s must be >= 0 and valid_for_ms > 0")
    return limit


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    v = sub.add_parser("verify")
    v.add_argument("--key", required=True)
    v.add_argument("--channel", required=True)
    v.add_argument("--now-utime", type=int, default=None)
    v.add_argument("--max-age-ms", type=int, default=250)
    v.add_argument("files", nargs="+")
    s = sub.add_parser("sign")
    s.add_argument("--key", required=True)
    s.add_argument("--channel", required=True)
    s.add_argument("--utime", type=int, required=True)
    s.add_argument("--seq", type=int, required=True)
    s.add_argument("payload_file")
    s.add_argument("out_file")
    args = parser.parse_args(argv)
    try:
        key = read_key_file(args.key)
    except Refused as e:
        print(e, file=sys.stderr)
        return 2
    if args.command == "sign":
        with open(args.payload_file, "rb") as f:
            payload = f.read()
        with open(args.out_file, "wb") as f:
            f.write(sign(key, args.channel, payload, args.utime, args.seq))
        return 0
    verifier = Verifier(key, args.max_age_ms * 1000)
    for path in args.files:
        with open(path, "rb") as f:
            data = f.read()
        now = args.now_utime if args.now_utime is not None else int(time.time() * 1e6)
        try:
            print("accepted " + verifier.open(data, args.channel, now).hex())
        except Refused as e:
            print("refused: %s" % e)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
