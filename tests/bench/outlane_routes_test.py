#!/usr/bin/env python3
"""bench/outlane_routes.py on a hand-made trace: one ball down the left
passage into the outlane 2.5 s after a flipper push, one down the middle;
the shots by direction (one from the left bat that drains down the left
outlane, one from the right bat that comes back, one too slow to count);
and the refusals of a missing file and of a file that is no trace."""
import json
import tempfile

from script_test import check, check_refuses_what_is_no_trace, run, write_trace

rows = [
    # ball 1: pushed at 1.0 s, two obstacles, down the passage, past the pivot line at x 0.02 at 3.5 s
    (0.0, 0.49, 0.054, 0, 4.6, "launch"),
    (1.0, 0.20, 0.17, -1, 2, "push:left_flipper"),
    (1.5, 0.17, 0.79, -1, 2, "hit:bumper_left"),  # leaves the bat at 2.24 m/s, 116.6 deg
    (1.6, 0.15, 0.80, 0, 1, "hit:bumper_left"),  # the same contact, one step on: not counted again
    (2.0, 0.05, 1.00, -1, 0, "hit:top_left_arc"),
    (2.5, 0.03, 0.70, 0, -1, ""),
    (3.0, 0.03, 0.50, 0, -1, ""),
    (3.4, 0.02, 0.17, 0, -1, ""),
    (3.5, 0.02, 0.15, 0, -1, ""),
    (3.6, 0.03, 0.02, 0, -1, "hit:drain|lost"),
    # ball 2: pushed at 5.0 s, down the middle at 6.1 s
    (4.0, 0.49, 0.054, 0, 4.6, "launch"),
    (5.0, 0.30, 0.20, 0, 1, "push:right_flipper"),
    (5.1, 0.30, 0.25, 0.5, 3.0, ""),  # leaves the bat at 80.5 deg
    (5.5, 0.30, 0.21, 0, -1, "flipper:right_flipper"),  # back on the bat 0.4 s later
    (5.6, 0.30, 0.22, 0, 1, ""),  # leaves at 1 m/s: no shot
    (6.0, 0.25, 0.17, 0, -1, ""),
    (6.1, 0.25, 0.15, 0, -1, ""),
    (6.2, 0.25, 0.02, 0, -1, "hit:drain|lost"),
]
with tempfile.TemporaryDirectory() as d:
    trace = write_trace(d, rows)
    r = run(trace, "--json")
    check(r.returncode == 0, "exit 0 on a trace: " + r.stderr)
    j = json.loads(r.stdout)
    check(j["drains"] == 2 and j["left_outlane"] == 1 and j["centre_or_right"] == 1, f"the causes: {j}")
    check(j["left_outlane_via_passage"] == 1, f"down the passage: {j}")
    check(abs(j["s_from_last_flipper_touch"]["median"] - 2.5) < 1e-9, f"2.5 s from the push: {j}")
    check(j["contacts_from_last_flipper_touch"]["median"] == 2, f"two contacts: {j}")
    left, right = j["shots"]["left_flipper"], j["shots"]["right_flipper"]
    check(len(left) == 1 and left[0]["deg_from"] == 110 and left[0]["shots"] == 1 and left[0]["left_outlane"] == 1
          and abs(left[0]["mean_s_to_outcome"] - 2.1) < 1e-9, f"the left bat's shot: {left}")
    check(len(right) == 1 and right[0]["deg_from"] == 80 and right[0]["returned"] == 1
          and right[0]["left_outlane"] == 0 and abs(right[0]["mean_s_to_outcome"] - 0.4) < 1e-9,
          f"the right bat's shot: {right}")
    text = run(trace)
    check(text.returncode == 0 and "1 left outlane (1 down the left passage" in text.stdout, text.stdout)

    check_refuses_what_is_no_trace(d)
print("outlane_routes: all checks passed")
