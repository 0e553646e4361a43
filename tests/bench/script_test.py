"""What the tests of the bench's Python scripts share: running the script
under test (its path is the test's first argument) and failing on a check."""
import os
import subprocess
import sys

SCRIPT = sys.argv[1]


def run(*args):
    """The script under test with these arguments: its exit code, stdout and stderr."""
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


def check(condition, what):
    """Exits 1 naming `what` unless `condition` holds."""
    if not condition:
        print("FAILED:", what, file=sys.stderr)
        sys.exit(1)


def write_trace(folder, rows, name="trace.csv"):
    """A `pinball sim --trace` CSV of these (t, x, y, vx, vy, event) rows in `folder`: its path."""
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        f.write("t,x,y,vx,vy,event\n")
        for r in rows:
            f.write(",".join(str(v) for v in r) + "\n")
    return path


def check_refuses_what_is_no_trace(folder):
    """The script under test exits 1, printing nothing, naming the file (and the line), for a missing
    file, a CSV that is no trace and a trace cut in the middle of a row."""
    missing = run(os.path.join(folder, "no_such.csv"))
    check(missing.returncode == 1 and "no_such.csv" in missing.stderr and not missing.stdout, "a missing file")
    other = os.path.join(folder, "other.csv")
    with open(other, "w") as f:
        f.write("a,b\n1,2\n")
    wrong = run(other)
    check(wrong.returncode == 1 and "other.csv" in wrong.stderr and "header" in wrong.stderr, "not a trace")
    truncated = os.path.join(folder, "truncated.csv")
    with open(truncated, "w") as f:
        f.write("t,x,y,vx,vy,event\n0,0.49,0.054,0,4.6,launch\n0.5,0.4\n")
    cut = run(truncated, "--json")
    check(cut.returncode == 1 and "truncated.csv:3" in cut.stderr and not cut.stdout, "a truncated row: " + cut.stderr)
