#!/usr/bin/env python3
"""Decodes messages that the generated C++ types encoded (lcm_python_sample)
with the generated Python bindings (build/release/src/bus/python): the
fingerprints and every field must agree across the two languages.

Usage: lcm_python_decode_test.py SAMPLE_EXE PYTHON_BINDINGS_DIR WORK_DIR
"""
import os
import subprocess
import sys


def main():
    sample_exe, bindings, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    subprocess.run([sample_exe, work], check=True)
    sys.path.insert(0, bindings)
    from pinball_lcm import lcmt_pinball_flipper_command, lcmt_pinball_game_event

    with open(os.path.join(work, "game_event.bin"), "rb") as f:
        e = lcmt_pinball_game_event.decode(f.read())
    assert e.utime == 1234567890123, e.utime
    assert e.seq == 42 and e.ball == 7, (e.seq, e.ball)
    assert e.kind == lcmt_pinball_game_event.KIND_SCORE == 3, e.kind
    assert e.points == 250.5 and e.ball_time_s == 3.25, (e.points, e.ball_time_s)

    with open(os.path.join(work, "flipper_command.bin"), "rb") as f:
        c = lcmt_pinball_flipper_command.decode(f.read())
    assert (c.utime, c.seq, c.projection_seq, c.flipper) == (-5, 9, -1, 1), (c.utime, c.seq, c.projection_seq)
    assert c.energize is True, c.energize
    assert c.cause == lcmt_pinball_flipper_command.CAUSE_CAMERA_STALL, c.cause

    # A message of the other type is refused by its fingerprint.
    with open(os.path.join(work, "game_event.bin"), "rb") as f:
        try:
            lcmt_pinball_flipper_command.decode(f.read())
        except ValueError:
            pass
        else:
            raise AssertionError("a game event decoded as a flipper command")
    # And the Python encoder gives the C++ encoder's bytes.
    with open(os.path.join(work, "game_event.bin"), "rb") as f:
        assert e.encode() == f.read()
    print("decoded 2 messages; fingerprints and fields agree with C++")


if __name__ == "__main__":
    main()
