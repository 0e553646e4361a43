"""Reading a `pinball sim --trace` CSV (t,x,y,vx,vy,event), one step a row,
for the bench's Python scripts. Standard library only."""
import csv

HEADER = ["t", "x", "y", "vx", "vy", "event"]


class TraceError(Exception):
    """A file that cannot be read as a trace; str() names the file (and the line)."""


def steps(path):
    """Yields (t, x, y, vx, vy, event) for every row of the trace at `path`, in order.
    Raises TraceError for a file that cannot be opened, has no trace header, or
    has a row that is not six fields with five numbers."""
    try:
        f = open(path, newline="")
    except OSError as e:
        raise TraceError(f"{path}: {e.strerror}") from None
    with f:
        rows = csv.reader(f)
        if next(rows, None) != HEADER:
            raise TraceError(f"{path}: not a pinball sim --trace CSV (header {','.join(HEADER)})")
        for r in rows:
            try:
                if len(r) != 6:
                    raise ValueError(f"{len(r)} fields, not 6")
                yield float(r[0]), float(r[1]), float(r[2]), float(r[3]), float(r[4]), r[5]
            except ValueError as e:
                raise TraceError(f"{path}:{rows.line_num}: not a trace row ({e})") from None
