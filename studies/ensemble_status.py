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
from collections import namedtuple

import numpy as np

from ensemble_common import load_ensembles

STAGES = (("ch7", (1, 2, 3, 4), 1024), ("ch8", tuple(range(18, 31)), 1024), ("ch8_2048", (27, 23, 25, 24, 26), 2048))

Row = namedtuple("Row", "stage group n done converged steps spent to_go estimated")


def mean_surface_hours(ensembles):
    """Mean rank-hours of one finished surface over the ensembles given, or NaN if they hold none."""
    surfaces = sum(e.n for e in ensembles)
    return sum(e.rank_hours() for e in ensembles) / surfaces if surfaces else float("nan")


def status(target):
    """One :class:`Row` per ensemble of :data:`STAGES`, in their order."""
    found = load_ensembles()    # only files holding finished surfaces, keyed by (group, N)
    per_grid = {n: mean_surface_hours([e for (_, m), e in found.items() if m == n]) for _, _, n in STAGES}
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
            e = found.get((group, n))
            if e is None:
                rows.append(Row(stage, group, n, 0, 0, 0, 0.0, target * per_grid[n], True))
                continue
            spent = e.rank_hours()
            rows.append(Row(stage, group, n, e.n, int(e.converged.sum()), e.n * e.p.size, spent,
                            max(target - e.n, 0) * spent / e.n, False))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--target", type=int, default=50, help="surfaces per ensemble (default 50)")
    args = parser.parse_args()
    rows = status(args.target)
    print(f"{'stage':9s} {'group':>5s} {'grid':>6s} {'surfaces':>9s} {'converged':>11s} {'rank-h':>7s} {'to go':>7s}")
    for r in rows:
        go = "?" if np.isnan(r.to_go) else f"{'~' if r.estimated and r.to_go else ''}{r.to_go:.2f}"
        print(f"{r.stage:9s} {r.group:5d} {r.n:5d}^2 {r.done:4d}/{args.target:<4d} {r.converged:5d}/{r.steps:<5d} "
              f"{r.spent:7.2f} {go:>7s}")
    spent = sum(r.spent for r in rows)
    to_go = sum(r.to_go for r in rows)
    done = sum(r.done for r in rows)
    print(f"total: {done}/{len(rows) * args.target} surfaces, {spent:.2f} rank-hours spent, "
          f"{'?' if np.isnan(to_go) else f'{to_go:.1f}'} rank-hours to go "
          f"({'?' if np.isnan(to_go) else f'{to_go / 2:.1f}'} h of wall on 2 ranks)")


if __name__ == "__main__":
    main()
