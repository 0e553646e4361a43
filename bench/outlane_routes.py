#!/usr/bin/env python3
"""How balls reach the left outlane, from a `pinball sim --trace` CSV.

For every lost ball: the cause (the bench's rule, bench/drain_cause.h: where
the ball last went down past the flippers' pivot line), and for a left
outlane drain whether the ball came down the left passage in the 3 s before
(the lane at x < 50 mm between y 480 and 880 mm on boards/mit1993.board),
the seconds since a flipper last touched it, and the obstacle contacts in
between. And per flipper, its shots by direction: each shot's exit velocity
(the first step after the ball leaves the bat, at least --shot-speed-mps and
upward) in --shot-bin-deg bins, and what came next: the next flipper touch,
a left-outlane or other drain, or a new launch (a ball cut or back in the
chute). Standard library only; `--json` prints one object.

    build/release/pinball sim boards/mit1993.board --controller FILE --balls 60 \
        --max-ball-time 60 --trace /tmp/trace.csv
    python3 bench/outlane_routes.py /tmp/trace.csv --json
"""
import argparse
import collections
import json
import math
import statistics
import sys

import sim_trace


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("trace", help="pinball sim --trace CSV (t,x,y,vx,vy,event)")
    p.add_argument("--pivot-line-m", type=float, default=0.160, help="the flippers' pivot line y (m)")
    p.add_argument("--left-pivot-m", type=float, default=0.165, help="the leftmost pivot's x (m)")
    p.add_argument("--passage", type=float, nargs=3, default=[0.050, 0.480, 0.880],
                   metavar=("X_MAX", "Y_MIN", "Y_MAX"), help="the left passage's box (m)")
    p.add_argument("--window-s", type=float, default=3.0, help="how far back a passage counts (s)")
    p.add_argument("--shot-speed-mps", type=float, default=1.5, help="the slowest exit that counts as a shot (m/s)")
    p.add_argument("--shot-bin-deg", type=float, default=10.0, help="the shot table's direction bins (deg)")
    p.add_argument("--json", action="store_true", help="one JSON object on stdout")
    a = p.parse_args()

    try:
        return report(a, sim_trace.steps(a.trace))
    except sim_trace.TraceError as e:
        print(f"outlane_routes: {e}; nothing printed", file=sys.stderr)
        return 1


def report(a, rows) -> int:

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
    on_bat = None  # the flipper the ball touched at the last step, until it leaves
    shot = None  # the open shot: (flipper, direction bin, t)
    shot_outcomes = collections.defaultdict(lambda: collections.defaultdict(collections.Counter))
    shot_seconds = collections.defaultdict(collections.Counter)

    def close_shot(outcome, t_end):
        flipper, b, t0 = shot
        shot_outcomes[flipper][b][outcome] += 1
        shot_seconds[flipper][b] += t_end - t0

    for t, x, y, vx, vy, event in rows:
        if event == "launch":
            crossing_x, touched_s, contacts, prev = None, None, 0, None
            steps.clear()
            if shot:
                close_shot("launched", t)
            shot, on_bat = None, None
        hits = {e for e in event.split("|") if e.startswith("hit:")} if event else set()
        bats = [e.split(":", 1)[1] for e in event.split("|") if e.startswith(("push:", "flipper:"))] + [
            h[4:] for h in hits if "flipper" in h]
        if bats:
            touched_s, contacts = t, 0
            if shot:
                close_shot("returned", t)
            shot, on_bat = None, bats[0]
        elif on_bat is not None:
            if math.hypot(vx, vy) >= a.shot_speed_mps and vy > 0:
                shot = (on_bat, math.floor(math.degrees(math.atan2(vy, vx)) / a.shot_bin_deg), t)
            on_bat = None
        contacts += len(hits - touching)
        touching = hits
        steps.append((t, x, y, vy))
        while steps and steps[0][0] < t - a.window_s:
            steps.popleft()
        if prev is not None and prev[1] >= a.pivot_line_m > y:
            crossing_x = x
            crossing = (t, touched_s, contacts, [s for s in steps])
        if "lost" in event:
            cause = "other" if crossing_x is None else (
                "centre_or_right" if crossing_x >= a.left_pivot_m else "left_outlane")
            causes[cause] += 1
            if shot:
                close_shot(cause, t)
            shot, on_bat = None, None
            if cause == "left_outlane":
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

    shots = {}
    for flipper in sorted(shot_outcomes):
        shots[flipper] = []
        for b in sorted(shot_outcomes[flipper]):
            n = shot_outcomes[flipper][b]
            total = sum(n.values())
            shots[flipper].append({
                "deg_from": b * a.shot_bin_deg, "deg_to": (b + 1) * a.shot_bin_deg, "shots": total,
                "left_outlane": n["left_outlane"], "centre_or_right": n["centre_or_right"], "other": n["other"],
                "returned": n["returned"], "launched": n["launched"],
                "mean_s_to_outcome": shot_seconds[flipper][b] / total,
            })

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
        "shot_speed_mps": a.shot_speed_mps,
        "shot_bin_deg": a.shot_bin_deg,
        "shots": shots,
    }
    if a.json:
        print(json.dumps(out))
    else:
        print(f"{out['drains']} drains: {out['left_outlane']} left outlane ({via_passage} down the left passage "
              f"in the {a.window_s:g} s before), {out['centre_or_right']} centre or right, {out['other']} other")
        for k in ("s_from_last_flipper_touch", "contacts_from_last_flipper_touch"):
            if out[k]:
                print(f"{k}: median {out[k]['median']:.3g} (quartiles {out[k]['q1']:.3g}, {out[k]['q3']:.3g})")
        for flipper, bins in shots.items():
            print(f"{flipper} shots (at least {a.shot_speed_mps:g} m/s, upward), by direction: "
                  "shots, then the share that drained down the left outlane before the next flipper touch")
            for b in bins:
                print(f"  {b['deg_from']:5.0f} to {b['deg_to']:4.0f} deg: {b['shots']:6d}  "
                      f"{b['left_outlane'] / b['shots']:.3f}  (mean {b['mean_s_to_outcome']:.2f} s to the outcome)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
