#!/usr/bin/env python3
"""The path a cradle cycle repeats, from one ball's `pinball sim --trace`.

A rest is the ball slower than --still-mps for at least --rest-s (lying in the
crook of a raised bat). Between two rests the ball either rocked (it stayed
within --rock-m of where it lay) or made a trip: out and back to a rest, a
shot up the table when it rose --shot-height-m above the lowest rest. The
script prints the rests (where the ball lay: the same point each time, to the
millimetre, is what makes the cycle repeatable), the trips (how long each
took, where it turned, which obstacles it hit on the way) and when the ball
last rested. Standard library only; `--json` prints one object.

    build/release/pinball sim boards/mit1993.board --world twin --controller controllers/cradle.json \\
      --balls 1 --seed 2 --max-ball-time 600 --trace /tmp/ball.csv
    python3 bench/cradle_trace.py /tmp/ball.csv
"""
import argparse
import collections
import json
import math
import statistics
import sys

import sim_trace


def rests(rows, still_mps, rest_s):
    """(start, end, x, y) of every stretch slower than still_mps for at least rest_s."""
    out, start = [], None
    for i, (t, x, y, vx, vy, _) in enumerate(rows):
        still = math.hypot(vx, vy) < still_mps
        if still and start is None:
            start = i
        if (not still or i == len(rows) - 1) and start is not None:
            end = i
            if rows[end][0] - rows[start][0] >= rest_s:
                xs = [r[1] for r in rows[start:end]]
                ys = [r[2] for r in rows[start:end]]
                out.append((rows[start][0], rows[end][0], statistics.fmean(xs), statistics.fmean(ys)))
            start = None
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("trace")
    p.add_argument("--still-mps", type=float, default=0.02)
    p.add_argument("--rest-s", type=float, default=0.1)
    p.add_argument("--shot-height-m", type=float, default=0.25)
    p.add_argument("--rock-m", type=float, default=0.02)
    p.add_argument("--json", action="store_true")
    a = p.parse_args()
    try:
        rows = list(sim_trace.steps(a.trace))
    except sim_trace.TraceError as e:
        print(f"cradle_trace: {e}; nothing printed", file=sys.stderr)
        return 1
    if not rows:
        print(f"cradle_trace: {a.trace}: no steps", file=sys.stderr)
        return 1
    found = rests(rows, a.still_mps, a.rest_s)
    if not found:
        print(f"cradle_trace: {a.trace}: the ball never rested {a.rest_s} s below {a.still_mps} m/s: no cradle",
              file=sys.stderr)
        return 1
    floor_y = min(r[3] for r in found)
    index = {t: i for i, (t, *_rest) in enumerate(rows)}
    trips, rocks = [], 0
    for (s0, e0, x0, y0), (s1, e1, x1, y1) in zip(found, found[1:]):
        between = rows[index[e0]:index[s1] + 1]
        far = max(math.hypot(r[1] - x0, r[2] - y0) for r in between)
        if far < a.rock_m:
            rocks += 1
            continue
        top = max(between, key=lambda r: r[2])
        hits = collections.Counter(e.split(":", 1)[1] for r in between for e in r[5].split("|") if e.startswith("hit:"))
        trips.append({"from_s": e0, "back_s": s1, "away_s": s1 - e0, "top_x_m": top[1], "top_y_m": top[2],
                      "shot": top[2] - floor_y >= a.shot_height_m, "hits": hits})
    by_place = collections.Counter((round(r[2], 3), round(r[3], 3)) for r in found)
    end_t = rows[-1][0]
    shots = [t for t in trips if t["shot"]]

    def quantiles(values):
        values = sorted(values)
        return [values[0], values[len(values) // 2], values[-1]] if values else None

    hits_per_trip = sum((t["hits"] for t in trips), collections.Counter())
    report = {
        "trace": a.trace,
        "ball_time_s": end_t - rows[0][0],
        "lost": any("lost" in r[5].split("|") for r in rows),
        "rests": len(found),
        "rest_places_mm": [{"x_mm": k[0] * 1e3, "y_mm": k[1] * 1e3, "times": n} for k, n in by_place.most_common()],
        "share_of_time_at_rest": sum(e - s for s, e, _, _ in found) / max(end_t - rows[0][0], 1e-9),
        "rocks": rocks,
        "trips": len(trips),
        "shots_up_the_table": len(shots),
        "trip_away_s_min_median_max": quantiles([t["away_s"] for t in trips]),
        "trip_top_x_m_min_median_max": quantiles([t["top_x_m"] for t in trips]),
        "trip_top_y_m_min_median_max": quantiles([t["top_y_m"] for t in trips]),
        "hits_per_trip": {k: v / len(trips) for k, v in hits_per_trip.most_common()} if trips else {},
        "last_rest_s": found[-1][0],
    }
    if a.json:
        print(json.dumps(report, indent=2))
        return 0
    print(f"{a.trace}: {report['ball_time_s']:.1f} s of ball time, {'lost' if report['lost'] else 'not lost'}, "
          f"last rest at {report['last_rest_s']:.1f} s")
    print(f"rests {report['rests']} ({100 * report['share_of_time_at_rest']:.0f} % of the time), at:")
    for place in report["rest_places_mm"][:6]:
        print(f"  ({place['x_mm']:.0f}, {place['y_mm']:.0f}) mm  x{place['times']}")
    print(f"between rests: {rocks} rocks in the crook (under {a.rock_m * 1e3:.0f} mm), {len(trips)} trips away, "
          f"{len(shots)} of them up the table ({a.shot_height_m:.2f} m above the rest)")
    if trips:
        q = report
        print("  a trip: away {:.2f} / {:.2f} / {:.2f} s (min / median / max), its top at x {:.3f} / {:.3f} / {:.3f} m, "
              "y {:.3f} / {:.3f} / {:.3f} m".format(*q["trip_away_s_min_median_max"], *q["trip_top_x_m_min_median_max"],
                                                   *q["trip_top_y_m_min_median_max"]))
        print("  hits per trip: " + ", ".join(f"{k} {v:.2f}" for k, v in list(q["hits_per_trip"].items())[:8]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
