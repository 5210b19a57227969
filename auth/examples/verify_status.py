#!/usr/bin/env python3
"""What a robot controller written in Python does with SAFETY_STATUS_AUTH
(docs/security.md), shown on an LCM log (lcm-logger's file format; no LCM
bindings needed): every SAFETY_STATUS_AUTH event is verified with the
deployment's key as it would have been when it arrived (its receive time
in the log is the controller's clock), and one line is printed per event:

    accepted seq=<status seq> motion_allowed=<0|1> reason=<reason>
    refused: <why>

Live, with the `lcm` Python bindings (pip install lcm), the same two calls
go in the subscription handler, with the controller's own clock:

    def on_status(channel, data):
        try:
            status = decode_safety_status(verifier.open(data, "SAFETY_STATUS", time.time_ns() // 1000))
        except Refused as e:
            ...  # count it; the controller's deadline keeps running
    lc.subscribe("SAFETY_STATUS_AUTH", on_status)

Usage: verify_status.py --key FILE [--max-age-ms 250] [--channel SAFETY_STATUS] LOGFILE
"""
import argparse
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from tofguard_auth import Refused, Verifier, decode_safety_status, read_key_file  # noqa: E402

LOG_SYNC = 0xEDA1DA01


def log_events(path):
    """(receive utime, channel, data) of each event of an LCM log."""
    with open(path, "rb") as f:
        while True:
            header = f.read(28)
            if len(header) < 28:
                return
            sync, _number, utime, channel_len, data_len = struct.unpack(">IqqII", header)
            if sync != LOG_SYNC:
                raise ValueError("%s: not an LCM log (bad sync word)" % path)
            channel = f.read(channel_len).decode("utf-8", "replace")
            data = f.read(data_len)
            yield utime, channel, data


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--key", required=True)
    parser.add_argument("--max-age-ms", type=int, default=250)
    parser.add_argument("--channel", default="SAFETY_STATUS")
    parser.add_argument("log")
    args = parser.parse_args(argv)
    try:
        verifier = Verifier(read_key_file(args.key), args.max_age_ms * 1000)
    except Refused as e:
        print(e, file=sys.stderr)
        return 2
    for utime, channel, data in log_events(args.log):
        if channel != args.channel + "_AUTH":
            continue
        try:
            status = decode_safety_status(verifier.open(data, args.channel, utime))
        except Refused as e:
            print("refused: %s" % e)
            continue
        print("accepted seq=%d motion_allowed=%d reason=%s" %
              (status["seq"], 1 if status["motion_allowed"] else 0, status["reason"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
