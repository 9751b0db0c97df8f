"""How far the dissertation's ensembles are: surfaces finished against the target, rank-hours spent and to go.

    .venv/bin/python studies/ensemble_status.py [--target 50]

One line per ensemble of the stages of ``studies/ensemble_runs.sh`` (ch7: groups 1-4 at 1024^2; ch8: groups
18-30 at 1024^2; ch8_2048: groups 23-27 at 2048^2), read from ``studies/output/ensembles/groupNN_N<grid>.h5``
(tracked by git, so this tells a fresh clone where the runs stand). Rank-hours spent are the recorded times of
the finished surfaces (:meth:`Ens.rank_hours`); the hours to go are the missing surfaces times the mean time of a
surface of the same file, else of the files on the same grid, else of the nearest grid scaled by N^2 log N
(both marked ``~``), else unknown. Times were measured on a machine shared with other jobs: an estimate, not a
promise.
"""

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from ensemble_common import OUT, Ens  # noqa: E402

STAGES = (("ch7", (1, 2, 3, 4), 1024), ("ch8", tuple(range(18, 31)), 1024), ("ch8_2048", (27, 23, 25, 24, 26), 2048))


def read(group, n):
    """The ensemble file of a group on the n x n grid, or None if there is none yet."""
    path = os.path.join(OUT, f"group{group:02d}_N{n}.h5")
    return Ens(path) if os.path.exists(path) else None


def mean_surface_hours(ensembles):
    """Mean rank-hours of one finished surface over the ensembles given, or NaN if they hold none."""
    surfaces = sum(e.n for e in ensembles)
    return sum(e.rank_hours() for e in ensembles) / surfaces if surfaces else float("nan")


def status(target):
    """Rows (stage, group, N, finished, converged steps, steps, rank-hours spent, to go, estimated?)."""
    found = {(group, n): read(group, n) for _, groups, n in STAGES for group in groups}
    per_grid = {n: mean_surface_hours([e for (_, m), e in found.items() if m == n and e is not None and e.n])
                for _, _, n in STAGES}
    measured = {n: hours for n, hours in per_grid.items() if not np.isnan(hours)}
    for n, hours in per_grid.items():
        if np.isnan(hours) and measured:
            # A grid with no surface yet: the nearest measured grid scaled as the FFTs that dominate, N^2 log N
            # (4.4 from 1024^2 to 2048^2; group 23's logs measured 4.5: ~410 s against ~90 s a surface).
            m = min(measured, key=lambda m: abs(np.log(m / n)))
            per_grid[n] = measured[m] * (n / m) ** 2 * np.log(n) / np.log(m)
    rows = []
    for stage, groups, n in STAGES:
        for group in groups:
            e = found[(group, n)]
            done = e.n if e is not None else 0
            own = e is not None and e.n > 0
            each = e.rank_hours() / e.n if own else per_grid[n]
            steps = int(e.converged.sum()) if own else 0
            rows.append((stage, group, n, done, steps, done * (e.p.size if own else 0),
                         e.rank_hours() if own else 0.0, max(target - done, 0) * each, not own))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--target", type=int, default=50, help="surfaces per ensemble (default 50)")
    args = parser.parse_args()
    rows = status(args.target)
    print(f"{'stage':9s} {'group':>5s} {'grid':>6s} {'surfaces':>9s} {'converged':>11s} {'rank-h':>7s} {'to go':>7s}")
    for stage, group, n, done, converged, steps, spent, to_go, estimated in rows:
        go = "?" if np.isnan(to_go) else f"{'~' if estimated and to_go else ''}{to_go:.2f}"
        print(f"{stage:9s} {group:5d} {n:5d}^2 {done:4d}/{args.target:<4d} {converged:5d}/{steps:<5d} "
              f"{spent:7.2f} {go:>7s}")
    spent = sum(r[6] for r in rows)
    to_go = sum(r[7] for r in rows)
    done = sum(r[3] for r in rows)
    print(f"total: {done}/{len(rows) * args.target} surfaces, {spent:.2f} rank-hours spent, "
          f"{'?' if np.isnan(to_go) else f'{to_go:.1f}'} rank-hours to go "
          f"({'?' if np.isnan(to_go) else f'{to_go / 2:.1f}'} h of wall on 2 ranks)")


if __name__ == "__main__":
    main()
