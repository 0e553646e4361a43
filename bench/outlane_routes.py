#!/usr/bin/env python3
"""How balls reach the left outlane, from a `pinball sim --trace` CSV.

For every lost ball: the cause (the bench's rule, bench/drain_cause.h: where
the ball last went down past the flippers' pivot line), and for a left
outlane drain whether the ball came down the left passage in the 3 s before
(the lane at x < 50 mm between y 480 and 880 mm on boards/mit1993.board),
the seconds since a flipper last touched it, and the obstacle contacts in
between. Standard library only; `--json` prints one object.

    build/release/pinball sim boards/mit1993.board --controller FILE --balls 60 \
        --max-ball-time 60 --trace /tmp/trace.csv
    python3 bench/outlane_routes.py /tmp/trace.csv --json
"""
import argparse
import collections
import csv
import json
import statistics
import sys


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("trace", help="pinball sim --trace CSV (t,x,y,vx,vy,event)")
    p.add_argument("--pivot-line-m", type=float, default=0.160, help="the flippers' pivot line y (m)")
    p.add_argument("--left-pivot-m", type=float, default=0.165, help="the leftmost pivot's x (m)")
    p.add_argument("--passage", type=float, nargs=3, default=[0.050, 0.480, 0.880],
                   metavar=("X_MAX", "Y_MIN", "Y_MAX"), help="the left passage's box (m)")
    p.add_argument("--window-s", type=float, default=3.0, help="how far back a passage counts (s)")
    p.add_argument("--json", action="store_true", help="one JSON object on stdout")
    a = p.parse_args()

    try:
        f = open(a.trace, newline="")
    except OSError as e:
        print(f"outlane_routes: {a.trace}: {e.strerror}", file=sys.stderr)
        return 1
    rows = csv.reader(f)
    if next(rows, None) != ["t", "x", "y", "vx", "vy", "event"]:
        print(f"outlane_routes: {a.trace}: not a pinball sim --trace CSV (header t,x,y,vx,vy,event)", file=sys.stderr)
        return 1

    steps = collections.deque()  # (t, x, y, vy) of the last window
    prev = None
    crossing_x = None
    touched_s = None
    contacts = 0  # obstacle contacts (first step of each) since the last flipper touch
    touching = set()
    causes = collections.Counter()
    via_passage = 0
    since_touch_s = []
    contacts_since = []
    for r in rows:
        try:
            if len(r) != 6:
                raise ValueError(f"{len(r)} fields, not 6")
            t, x, y, vy, event = float(r[0]), float(r[1]), float(r[2]), float(r[4]), r[5]
        except ValueError as e:
            print(f"outlane_routes: {a.trace}:{rows.line_num}: not a trace row ({e}); nothing printed",
                  file=sys.stderr)
            return 1
        if event == "launch":
            crossing_x, touched_s, contacts, prev = None, None, 0, None
            steps.clear()
        hits = {e for e in event.split("|") if e.startswith("hit:")} if event else set()
        if any(e.startswith(("push:", "flipper:")) for e in event.split("|")) or any(
                "flipper" in h for h in hits):
            touched_s, contacts = t, 0
        contacts += len(hits - touching)
        touching = hits
        steps.append((t, x, y, vy))
        while steps and steps[0][0] < t - a.window_s:
            steps.popleft()
        if prev is not None and prev[1] >= a.pivot_line_m > y:
            crossing_x = x
            crossing = (t, touched_s, contacts, [s for s in steps])
        if "lost" in event:
            if crossing_x is None:
                causes["other"] += 1
            elif crossing_x >= a.left_pivot_m:
                causes["centre_or_right"] += 1
            else:
                causes["left_outlane"] += 1
                t_cross, touch, n_contacts, window = crossing
                x_max, y_min, y_max = a.passage
                if any(px < x_max and y_min < py < y_max and pvy < 0 for _, px, py, pvy in window):
                    via_passage += 1
                if touch is not None:
                    since_touch_s.append(t_cross - touch)
                    contacts_since.append(n_contacts)
            crossing_x, prev = None, None
            continue
        prev = (x, y)

    def quartiles(v):
        if not v:
            return None
        q = statistics.quantiles(v, n=4) if len(v) > 1 else [v[0]] * 3
        return {"q1": q[0], "median": q[1], "q3": q[2]}

    out = {
        "trace": a.trace,
        "drains": sum(causes.values()),
        "left_outlane": causes["left_outlane"],
        "centre_or_right": causes["centre_or_right"],
        "other": causes["other"],
        "left_outlane_via_passage": via_passage,
        "passage_window_s": a.window_s,
        "s_from_last_flipper_touch": quartiles(since_touch_s),
        "contacts_from_last_flipper_touch": quartiles(contacts_since),
    }
    if a.json:
        print(json.dumps(out))
    else:
        print(f"{out['drains']} drains: {out['left_outlane']} left outlane ({via_passage} down the left passage "
              f"in the {a.window_s:g} s before), {out['centre_or_right']} centre or right, {out['other']} other")
        for k in ("s_from_last_flipper_touch", "contacts_from_last_flipper_touch"):
            if out[k]:
                print(f"{k}: median {out[k]['median']:.3g} (quartiles {out[k]['q1']:.3g}, {out[k]['q3']:.3g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
