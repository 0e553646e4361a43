"""What the tests of the bench's Python scripts share: running the script
under test (its path is the test's first argument) and failing on a check."""
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
