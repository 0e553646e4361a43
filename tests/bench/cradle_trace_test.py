#!/usr/bin/env python3
"""bench/cradle_trace.py on a hand-made trace: a ball at rest in one crook
four times, between the rests a trip up the lane, a rock in the crook and a
shot up the table; and the refusals of a missing file, of a file that is no
trace and of a row cut short."""
import json
import tempfile

from script_test import check, check_refuses_what_is_no_trace, run, write_trace

REST = (0.342, 0.184)
rows = [
    (0.0, *REST, 0, 0, "launch"),
    (0.2, *REST, 0, 0, ""),  # rest 1
    (0.3, 0.40, 0.25, 1, 1, "hit:right_lane_guide"),  # a trip up the lane
    (1.2, 0.45, 0.36, 0, 1, ""),
    (2.0, 0.40, 0.25, -1, -1, ""),
    (2.3, *REST, 0, 0, ""),
    (2.5, *REST, 0, 0, ""),  # rest 2
    (2.6, 0.350, 0.190, 0.5, 0, ""),  # a rock: 10 mm off
    (2.7, *REST, 0, 0, ""),
    (2.9, *REST, 0, 0, ""),  # rest 3
    (3.0, 0.30, 0.40, 0, 2, "hit:bumper|sensor:lane"),  # a shot up the table
    (3.5, 0.30, 0.60, 0, 0.5, ""),
    (4.0, 0.30, 0.30, 0, -2, ""),
    (4.5, *REST, 0, 0, ""),
    (4.7, *REST, 0, 0, ""),  # rest 4: cut here
]
with tempfile.TemporaryDirectory() as d:
    trace = write_trace(d, rows)
    r = run(trace, "--json")
    check(r.returncode == 0, "exit 0 on a trace: " + r.stderr)
    j = json.loads(r.stdout)
    check(j["rests"] == 4 and j["rocks"] == 1 and j["trips"] == 2 and j["shots_up_the_table"] == 1, f"the cycle: {j}")
    check(j["rest_places_mm"] == [{"x_mm": 342.0, "y_mm": 184.0, "times": 4}], f"one crook: {j['rest_places_mm']}")
    check(abs(j["last_rest_s"] - 4.5) < 1e-9 and abs(j["ball_time_s"] - 4.7) < 1e-9 and not j["lost"], f"the end: {j}")
    check(j["hits_per_trip"] == {"right_lane_guide": 0.5, "bumper": 0.5}, f"the hits: {j['hits_per_trip']}")
    check(abs(j["trip_top_y_m_min_median_max"][2] - 0.60) < 1e-9, f"the shot's top: {j}")
    text = run(trace)
    check(text.returncode == 0 and "1 rocks in the crook" in text.stdout and "2 trips away, 1 of them" in text.stdout,
          text.stdout)

    check_refuses_what_is_no_trace(d)
print("cradle_trace: all checks passed")
