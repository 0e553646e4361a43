#!/usr/bin/env python3
"""Writes the damaged LCM logs of lcm/ and the good one of good/lcm/ (checked in; rerun to remake them).

LCM's log format (lcm-logger, liblcm's eventlog.c), integers big-endian:
  uint32 sync 0xEDA1DA01, int64 event number, int64 timestamp (us),
  int32 channel length, int32 data length, channel bytes, data bytes.
`pinball replay` must refuse every one of them with exit 1, naming the file
and the byte where the damage starts (tests/daemon/replay_test.cpp).
"""
import hashlib
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
BAD = os.path.join(HERE, "lcm")
GOOD = os.path.join(HERE, "good", "lcm")
CHANNEL = b"PINBALL_OBSERVATION"


def event(number, data, channel=CHANNEL, data_len=None, sync=0xEDA1DA01):
    n = len(data) if data_len is None else data_len
    return struct.pack(">IqqII", sync, number, 1700000000000000 + 5000 * number, len(channel), n) + channel + data


def payload(number):
    return hashlib.sha256(b"obs%d" % number).digest()[:20]


def good(n):
    return b"".join(event(i, payload(i)) for i in range(n))


def good_other(n):
    return b"".join(event(i, payload(i), channel=b"PINBALL_NOTES") for i in range(n))


LOGS = {
    # 0 bytes.
    "empty.lcmlog": b"",
    # 64 bytes of noise: no event header at byte 0.
    "random_bytes.lcmlog": hashlib.sha256(b"a").digest() + hashlib.sha256(b"b").digest(),
    # Two whole events (67 bytes each), then 12 bytes of a third header: damage at byte 134.
    "truncated_header.lcmlog": good(2) + event(2, payload(2))[:12],
    # Two whole events, then a header and 5 of its 39 channel and data bytes: damage at byte 134.
    "truncated_payload.lcmlog": good(2) + event(2, payload(2))[:33],
    # One event of 51 bytes whose data length says 0x7fffffff (crashed liblcm 1.3.1): damage at byte 0.
    "huge_length.lcmlog": event(0, b"\x00\x01\x02\x03", data_len=0x7FFFFFFF),
    # Two whole events, then one whose channel length is 0x7fffffff: damage at byte 134.
    "huge_channel_length.lcmlog": good(2) + struct.pack(">IqqII", 0xEDA1DA01, 2, 0, 0x7FFFFFFF, 4) + b"abcd",
    # Three events, the second's sync word overwritten: damage at byte 67.
    "bad_sync_mid_file.lcmlog": event(0, payload(0)) + event(1, payload(1), sync=0xDEADBEEF) + event(2, payload(2)),
}

# Whole and well formed, on a channel replay does not read: it must load.
GOOD_LOGS = {"two_events.lcmlog": good_other(2)}

if __name__ == "__main__":
    os.makedirs(GOOD, exist_ok=True)
    for folder, logs in ((BAD, LOGS), (GOOD, GOOD_LOGS)):
        for name, data in logs.items():
            with open(os.path.join(folder, name), "wb") as f:
                f.write(data)
            print(f"{os.path.relpath(folder, HERE)}/{name}: {len(data)} bytes")
