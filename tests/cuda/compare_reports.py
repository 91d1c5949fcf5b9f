#!/usr/bin/env python3
"""Whether two runs of `snag check --out` wrote the same reports, timings and the run's own
settings (backend, threads) aside: pairs.csv byte for byte, frames.csv without its seconds
column, report.json without times. Prints NAME same, or NAME DIFFERENT and the first difference;
exits 0 when the same, 1 when not, 2 when a report is missing or unreadable.

    compare_reports.py NAME DIR_A DIR_B
"""
import csv
import json
import sys

IGNORED_KEYS = {'seconds', 'times', 'backend', 'backend_requested', 'threads', 'created',
                'elapsed_seconds'}


def frames_rows(folder):
    with open(folder + '/frames.csv', newline='') as f:
        rows = list(csv.reader(f))
    drop = rows[0].index('seconds') if rows and 'seconds' in rows[0] else None
    return [[c for i, c in enumerate(r) if i != drop] for r in rows]


def stripped(value):
    if isinstance(value, dict):
        return {k: stripped(v) for k, v in value.items()
                if k not in IGNORED_KEYS and not k.endswith('_seconds')}
    if isinstance(value, list):
        return [stripped(v) for v in value]
    return value


def first_unequal(xs, ys):
    """Index of the first element where two lists differ (the shorter one's length when one
    is the other's start)."""
    return next((i for i, (x, y) in enumerate(zip(xs, ys)) if x != y), min(len(xs), len(ys)))


def first_difference(a, b, path='report.json'):
    if type(a) is not type(b):
        return f'{path}: {a!r} against {b!r}'
    if isinstance(a, dict):
        for k in list(a) + [k for k in b if k not in a]:
            if k not in a or k not in b:
                return f'{path}.{k}: present in one run only'
            d = first_difference(a[k], b[k], f'{path}.{k}')
            if d:
                return d
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return f'{path}: {len(a)} elements against {len(b)}'
        for i, (x, y) in enumerate(zip(a, b)):
            d = first_difference(x, y, f'{path}[{i}]')
            if d:
                return d
        return None
    return None if a == b else f'{path}: {a!r} against {b!r}'


def main():
    name, a, b = sys.argv[1:4]
    try:
        with open(a + '/pairs.csv') as f:
            pairs_a = f.read()
        with open(b + '/pairs.csv') as f:
            pairs_b = f.read()
        rows_a, rows_b = frames_rows(a), frames_rows(b)
        with open(a + '/report.json') as f:
            json_a = stripped(json.load(f))
        with open(b + '/report.json') as f:
            json_b = stripped(json.load(f))
    except (OSError, ValueError) as error:
        print(name, 'UNREADABLE', error)
        return 2
    difference = None
    if pairs_a != pairs_b:
        lines_a, lines_b = pairs_a.splitlines(), pairs_b.splitlines()
        at = first_unequal(lines_a, lines_b)
        difference = f'pairs.csv line {at + 1} ({len(lines_a)} lines against {len(lines_b)})'
    elif rows_a != rows_b:
        difference = f'frames.csv row {first_unequal(rows_a, rows_b) + 1}'
    else:
        difference = first_difference(json_a, json_b)
    if difference:
        print(name, 'DIFFERENT', difference)
        return 1
    print(name, 'same')
    return 0


if __name__ == '__main__':
    sys.exit(main())
