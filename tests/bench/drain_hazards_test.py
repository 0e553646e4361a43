#!/usr/bin/env python3
"""bench/drain_hazards.py on a hand-made transfer CSV: the drain rates, the
points a second and both bounds against closed forms; and the refusals of a
missing file, a file of other columns, a world without the spastic flipper
and a malformed row."""
import json
import math
import os
import tempfile

from script_test import check, run

HEADER = ("world,family,value,stepper,controller,status,balls,mean_score_per_ball,ratio_to_spastic,"
          "mean_ball_time_s,drains_left_outlane,drains_right_outlane,drains_centre,drains_other,drains_left_table")


def write(d, name, lines):
    path = os.path.join(d, name)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


# spastic: 10 balls of 30 s (5 ball minutes), 5 outlane and 5 centre drains, 3000 points a ball;
# the controller: 10 balls of 45 s (7.5 minutes), 6 outlane, 1 centre, 3 cut at 60 s, 9000 points a ball.
SPASTIC = "model,nominal,0,thesis,spastic,played,10,3000,1,30,4,1,5,0,0"
LEARNED = "model,nominal,0,thesis,learned,played,10,9000,3,45,6,0,1,0,0"
with tempfile.TemporaryDirectory() as d:
    good = write(d, "t.csv", [HEADER, SPASTIC, LEARNED, "skipped,x,0,thesis,learned,skipped,0,0,0,0,0,0,0,0,0"])
    r = run(good, "--json")
    check(r.returncode == 0, "exit 0 on a transfer CSV: " + r.stderr)
    j = json.loads(r.stdout)
    check(len(j["cells"]) == 1, f"one cell besides the spastic flipper's; a skipped cell ignored: {j}")
    c = j["cells"][0]
    check(abs(c["spastic"]["outlane_per_min"] - 1.0) < 1e-12 and abs(c["spastic"]["centre_per_min"] - 1.0) < 1e-12,
          f"spastic rates: {c}")
    check(abs(c["this"]["outlane_per_min"] - 0.8) < 1e-12 and abs(c["this"]["points_per_s"] - 200) < 1e-12,
          f"the controller's rates: {c}")
    h = 0.8 / 60.0
    check(abs(c["ratio_without_centre_drains"] - 200 * (1 - math.exp(-h * 60)) / h / 3000) < 1e-9, f"capped bound: {c}")
    check(abs(c["ratio_without_centre_drains_or_cap"] - (200 / 0.8) / (100 / 2.0)) < 1e-9, f"uncapped bound: {c}")
    all_h = (0.8 + 1 / 7.5) / 60.0
    check(abs(c["life_by_rates_s"] - (1 - math.exp(-all_h * 60)) / all_h) < 1e-9, f"life by rates: {c}")
    check(j["cells_whose_bound_is_below_target"] == [], f"2.75x is above 2.5x: {j}")
    at3 = json.loads(run(good, "--json", "--target-ratio", "3").stdout)
    check(at3["cells_whose_bound_is_below_target"] == ["model/learned"] and
          at3["cells_whose_uncapped_bound_is_below_target"] == [], f"2.75x and 5x against 3x: {at3}")
    text = run(good)
    check(text.returncode == 0 and "0 of 1 cells stay below 2.5x" in text.stdout, text.stdout)

    missing = run(os.path.join(d, "no_such.csv"))
    check(missing.returncode == 1 and "no_such.csv" in missing.stderr and not missing.stdout, "a missing file")
    other = write(d, "other.csv", ["a,b", "1,2"])
    wrong = run(other)
    check(wrong.returncode == 1 and "other.csv" in wrong.stderr and "world" in wrong.stderr, "not a transfer CSV")
    alone = write(d, "alone.csv", [HEADER, LEARNED])
    no_base = run(alone)
    check(no_base.returncode == 1 and "no spastic cell" in no_base.stderr and not no_base.stdout, no_base.stderr)
    bad = write(d, "bad.csv", [HEADER, SPASTIC, LEARNED.replace("9000", "nine")])
    malformed = run(bad, "--json")
    check(malformed.returncode == 1 and "bad.csv:3" in malformed.stderr and not malformed.stdout, malformed.stderr)
print("drain_hazards: all checks passed")
