#!/usr/bin/env python3
"""What each controller's drains allow, from a `pinball bench transfer --csv`.

A ball's drains are read as rates: drains of a kind per minute of ball time
(the censored-exponential estimate, so balls cut at the time limit count for
the time they played). For every world and controller it prints those rates
beside the spastic flipper's, the points a second, and a bound: the ratio to
the spastic flipper this controller would reach if it lost no ball down the
centre, its other drain rates and points a second unchanged. Under a constant
rate h a ball cut at T lives (1 - exp(-h T)) / h on average; the script
checks that against the measured mean ball time of every cell. A second
bound drops the cap too, for both players (their mean lives 1/h). A world whose
bound is below --target-ratio cannot reach it by saving centre drains: the
controller must also change where the ball goes after the flippers, or score
faster. Standard library only; `--json` prints one object.

    build/release/pinball bench transfer --identified ID --controller FILE --csv /tmp/t.csv
    python3 bench/drain_hazards.py /tmp/t.csv --json
"""
import argparse
import csv
import json
import math
import sys

NEEDED = ["world", "controller", "balls", "mean_score_per_ball", "ratio_to_spastic", "mean_ball_time_s",
          "drains_left_outlane", "drains_right_outlane", "drains_centre", "drains_other", "drains_left_table"]


def rates(row):
    """Drains per minute of ball time by kind, and points a second."""
    minutes = row["balls"] * row["mean_ball_time_s"] / 60.0
    per_min = (lambda n: n / minutes) if minutes > 0 else (lambda n: 0.0)
    return {
        "outlane_per_min": per_min(row["drains_left_outlane"] + row["drains_right_outlane"]),
        "centre_per_min": per_min(row["drains_centre"]),
        "other_per_min": per_min(row["drains_other"] + row["drains_left_table"]),
        "points_per_s": row["mean_score_per_ball"] / row["mean_ball_time_s"] if row["mean_ball_time_s"] > 0 else 0.0,
    }


def capped_life_s(per_min, cap_s):
    """Mean time of a ball drained at a constant rate and cut at cap_s."""
    h = per_min / 60.0
    return cap_s if h <= 0 else (1.0 - math.exp(-h * cap_s)) / h


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("csv", help="pinball bench transfer --csv output")
    p.add_argument("--max-ball-time", type=float, default=60.0, help="the run's cap on ball time (s)")
    p.add_argument("--target-ratio", type=float, default=2.5, help="the ratio to the spastic flipper to judge by")
    p.add_argument("--json", action="store_true", help="one JSON object on stdout")
    a = p.parse_args()
    if not a.max_ball_time > 0 or not a.target_ratio > 0:
        print("drain_hazards: --max-ball-time and --target-ratio must be > 0", file=sys.stderr)
        return 1

    try:
        f = open(a.csv, newline="")
    except OSError as e:
        print(f"drain_hazards: {a.csv}: {e.strerror}", file=sys.stderr)
        return 1
    reader = csv.DictReader(f)
    missing = [c for c in NEEDED if c not in (reader.fieldnames or [])]
    if missing:
        print(f"drain_hazards: {a.csv}: not a bench transfer CSV (no column {', '.join(missing)})", file=sys.stderr)
        return 1
    worlds = {}  # world -> controller -> row, in the file's order
    for r in reader:
        if r.get("status", "played") != "played":
            continue
        try:
            row = {c: (r[c] if c in ("world", "controller") else float(r[c])) for c in NEEDED}
        except (TypeError, ValueError) as e:
            print(f"drain_hazards: {a.csv}:{reader.line_num}: not a transfer row ({e}); nothing printed",
                  file=sys.stderr)
            return 1
        worlds.setdefault(row["world"], {})[row["controller"]] = row
    if not worlds:
        print(f"drain_hazards: {a.csv}: no played cells", file=sys.stderr)
        return 1

    cells = []
    for world, by_controller in worlds.items():
        spastic = by_controller.get("spastic")
        if spastic is None:
            print(f"drain_hazards: {a.csv}: world {world} has no spastic cell to compare with", file=sys.stderr)
            return 1
        s = rates(spastic)
        for name, row in by_controller.items():
            if name == "spastic":
                continue
            c = rates(row)
            all_per_min = c["outlane_per_min"] + c["centre_per_min"] + c["other_per_min"]
            bound = bound_no_cap = None
            if spastic["mean_score_per_ball"] > 0:
                life = capped_life_s(all_per_min - c["centre_per_min"], a.max_ball_time)
                bound = c["points_per_s"] * life / spastic["mean_score_per_ball"]
                spastic_per_min = s["outlane_per_min"] + s["centre_per_min"] + s["other_per_min"]
                if all_per_min - c["centre_per_min"] > 0 and spastic_per_min > 0:
                    bound_no_cap = (c["points_per_s"] / (all_per_min - c["centre_per_min"])) / (
                        s["points_per_s"] / spastic_per_min)
            cells.append({
                "world": world,
                "controller": name,
                "ratio_to_spastic": row["ratio_to_spastic"],
                "spastic": s,
                "this": c,
                "life_by_rates_s": capped_life_s(all_per_min, a.max_ball_time),
                "life_measured_s": row["mean_ball_time_s"],
                "ratio_without_centre_drains": bound,
                "ratio_without_centre_drains_or_cap": bound_no_cap,
            })

    below = [f"{c['world']}/{c['controller']}" for c in cells
             if c["ratio_without_centre_drains"] is not None and c["ratio_without_centre_drains"] < a.target_ratio]
    below_no_cap = [f"{c['world']}/{c['controller']}" for c in cells
                    if c["ratio_without_centre_drains_or_cap"] is not None
                    and c["ratio_without_centre_drains_or_cap"] < a.target_ratio]
    out = {"csv": a.csv, "max_ball_time_s": a.max_ball_time, "target_ratio": a.target_ratio, "cells": cells,
           "cells_whose_bound_is_below_target": below, "cells_whose_uncapped_bound_is_below_target": below_no_cap}
    if a.json:
        print(json.dumps(out))
        return 0
    print(f"drains per minute of ball time (outlane / centre), points a second; balls cut at {a.max_ball_time:g} s")
    print(f"{'world':24s} {'controller':28s} {'spastic':>15s} {'this':>15s} {'ratio':>6s} {'no centre':>9s}")
    for c in cells:
        s, t = c["spastic"], c["this"]
        bound = c["ratio_without_centre_drains"]
        print(f"{c['world']:24s} {c['controller']:28s} "
              f"{s['outlane_per_min']:4.2f}/{s['centre_per_min']:4.2f} {s['points_per_s']:4.0f} "
              f"{t['outlane_per_min']:4.2f}/{t['centre_per_min']:4.2f} {t['points_per_s']:4.0f} "
              f"{c['ratio_to_spastic']:5.2f}x {'-' if bound is None else f'{bound:8.2f}x'}")
    print(f"{len(below)} of {len(cells)} cells stay below {a.target_ratio:g}x with no centre drain at all; "
          f"{len(below_no_cap)} with no cap on ball time either")
    return 0


if __name__ == "__main__":
    sys.exit(main())
