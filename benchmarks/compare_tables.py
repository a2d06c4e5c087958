"""Two ``motionlab evaluate --csv`` files record by record: Table 1 on a GPU against the CPU's.

For the records (method × target × animation) of both files, prints per numeric column the
largest relative difference ``|a - b| / max(|a|, |b|)`` (the time column left out: it is the
device's speed), and whether the steps and stop reasons are equal. Exits with status 1 when the
files hold other records, 2 (one line naming the file) when one cannot be read as such a CSV.

Usage::

    python -m motionlab evaluate --device cuda --checkpoint ck.pt --no-ablations --csv gpu.csv
    python -m motionlab evaluate --device cpu --checkpoint ck.pt --no-ablations --csv cpu.csv
    python benchmarks/compare_tables.py cpu.csv gpu.csv
"""

from __future__ import annotations

import argparse
import csv
import sys

KEY = ("row", "target", "animation")
SKIP = {"time"}
NEEDED = (*KEY, "steps", "stop_reason")


def _records(path: str) -> dict[tuple, dict[str, str]]:
    """The records of one ``evaluate --csv`` file by (row, target, animation).

    Raises
    ------
    ValueError naming the file when it cannot be read, lacks a column of :data:`NEEDED` or holds
    no record.
    """
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            missing = [c for c in NEEDED if c not in (reader.fieldnames or [])]
            if missing:
                raise ValueError(f"{path}: not a `motionlab evaluate --csv` file: no column {', '.join(missing)}")
            records = {tuple(r[k] for k in KEY): r for r in reader}
    except (OSError, UnicodeDecodeError) as err:
        raise ValueError(f"{path}: cannot be read ({err})") from None
    if not records:
        raise ValueError(f"{path}: holds no record")
    return records


def _relative(a: str, b: str) -> float:
    x, y = float(a), float(b)
    return 0.0 if x == y else abs(x - y) / max(abs(x), abs(y))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", help="a CSV of motionlab evaluate --csv")
    ap.add_argument("b", help="another, of the same records")
    args = ap.parse_args()
    try:
        a, b = _records(args.a), _records(args.b)
    except ValueError as err:
        print(f"compare_tables: {err}", file=sys.stderr)
        return 2
    if a.keys() != b.keys():
        print(
            f"the files hold other records: {len(a.keys() - b.keys())} only in {args.a}, "
            f"{len(b.keys() - a.keys())} only in {args.b}"
        )
        return 1
    columns = [c for c in next(iter(a.values())) if c not in KEY and c not in SKIP and c != "stop_reason"]
    print(f"{len(a)} records in both files; largest relative difference per column (time left out):")
    for c in columns:
        worst = max(((_relative(a[k][c], b[k][c]), k) for k in a if a[k][c] and b[k][c]), default=(0.0, ()))
        where = f"  ({', '.join(worst[1])})" if worst[0] else ""
        print(f"  {c:12s} {worst[0]:.1e}{where}")
    same = sum(a[k]["steps"] == b[k]["steps"] and a[k]["stop_reason"] == b[k]["stop_reason"] for k in a)
    print(f"steps and stop reason equal in {same} of {len(a)} records")
    return 0


if __name__ == "__main__":
    sys.exit(main())
