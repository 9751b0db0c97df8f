#!/bin/bash
# The adhesive BEM cycles behind studies/output/adhesion/rough_cycles.md (issue 36, item 4 (c)-(d)), in order of
# priority, one niced process at a time. Every stage is resumable (studies/adhesion_rough_cycles.py: a case file
# per finished cycle, a checkpoint inside an unfinished one): rerun this script, or the stages named, after a kill.
# The case files (~20 kB) are tracked by git; the checkpoints are not (except the one the partial campaign stopped
# in, committed with it, so that the first stage resumes there).
#
#   bash studies/adhesion_rough_runs.sh > rough_runs.log 2>&1 &     # all stages
#   bash studies/adhesion_rough_runs.sh n1024_r100_a n1024_r50_20     # only the named stages
#
# Measured (group #1, process CPU time, under a load of 10-14 on the 2 shared cores, where one process got
# 10-33 % of a core): a partial cycle (approach from out of contact to p* = 2 and back to g* = 0.6, ~90 steps)
# takes 0.021-0.023 core-hours at 512^2 and 0.144 at 1024^2 (sigma0/E* = 1/100); a full cycle at 512^2 and
# 1/20 (167 steps, not let go at g* = 10.7) 0.09. The first 2048^2 solve of the path took 708 operator
# applications and 349 s: a 2048^2 cycle would take about 1 core-hour, out of reach for ten surfaces here.
#   n512        : 512^2, 10 surfaces, sigma0/E* = 1/100, 1/50, 1/20 (partial cycles)
#   n1024_r100_a: 1024^2, surfaces 1-5 at 1/100 (the best resolved cohesive zone)
#   n1024_r50_20: 1024^2, surfaces 1-3 at 1/50 and 1/20 (the grid sequence where the zone is narrower)
#   full_512    : 512^2, full cycles (retraction until the contact lets go) at 1/100 and 1/50, 10 surfaces:
#                 their pull-off lies beyond g* = 0.6
#   n1024_r100_b: 1024^2, surfaces 6-10 at 1/100
#   n1024_rest  : 1024^2, surfaces 4-10 at 1/50 and 1/20
#   full_1024   : 1024^2, full cycles at 1/100 and 1/50, 10 surfaces: the pull-off and dissipated energy on a
#                 second grid (measured 0.07-0.08 core-hours a cycle at 1/100, 0.11-0.12 at 1/50)
#   n2048       : 2048^2, the third grid, surfaces 1-10 at 1/100, then 1/50 and 1/20 (measured 0.7-1 core-hour
#                 a cycle at 1/100, 0.45 at 1/50; resumable across sessions through its checkpoints, whose gap
#                 field is compressed so that the one a session ends in can be committed)
set -u
cd "$(dirname "$0")/.."
source tools/env.sh
run() { nice -n 10 .venv/bin/python studies/adhesion_rough_cycles.py "$@"; }
ALL="1 2 3 4 5 6 7 8 9 10"
stage() {
  case "$1" in
    n512) run --sizes 512 --ratios 100 50 20 --seeds $ALL ;;
    n1024_r100_a) run --sizes 1024 --ratios 100 --seeds 1 2 3 4 5 ;;
    n1024_r100_b) run --sizes 1024 --ratios 100 --seeds 6 7 8 9 10 ;;
    n1024_r50_20) run --sizes 1024 --ratios 50 20 --seeds 1 2 3 ;;
    full_512) run --protocol full --sizes 512 --ratios 100 50 --seeds $ALL ;;
    n1024_rest) run --sizes 1024 --ratios 50 20 --seeds 4 5 6 7 8 9 10 ;;
    full_1024) run --protocol full --sizes 1024 --ratios 100 50 --seeds $ALL ;;
    n2048) run --sizes 2048 --ratios 100 --seeds $ALL && run --sizes 2048 --ratios 50 20 --seeds $ALL ;;
    *) echo "unknown stage $1" >&2; return 2 ;;
  esac
}
for s in ${@:-n512 n1024_r100_a n1024_r50_20 full_512 n1024_r100_b n1024_rest}; do
  echo "=== stage $s: $(date)"
  stage "$s"
done
echo "=== done: $(date)"
