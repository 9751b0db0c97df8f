#!/bin/bash
# The BEM ensembles behind studies/ensemble_figures.py (issue 6, item 5): the dissertation, ch. 7.3-7.4 (groups 1-3)
# and ch. 8 (groups 18-27). One `mpiexec -n 2` ensemble at a time (one surface per rank), each resumable:
# rerun this script (or one stage of it) after a kill and the finished surfaces are kept; a larger
# -ensemble_size extends a file, a smaller one (>= the surfaces it holds) finalises it. The files (~0.1 MB each)
# are tracked by git: commit them after a session and a fresh clone on a new machine resumes where it stopped.
#
#   bash studies/ensemble_runs.sh            # all stages, in order of priority
#   bash studies/ensemble_runs.sh g18 g01    # only the named stages
#   G18_SIZE=50 bash studies/ensemble_runs.sh g18   # more surfaces for a group (same for G01_SIZE, ...)
#
# Sizes were chosen for ~75 min of wall time on 2 cores shared with other jobs (measured: one 512^2 surface
# along the 95-step history = 11,000 operator applications, ~35 s of CPU alone, 100-190 s of wall per rank
# under the load of the time). The surfaces of a group differ little (A* of two group-18 surfaces within
# 0.002 at every step), so a few surfaces per group give the mean to ~1e-3, and the grid matters more: the
# dissertation used 1024^2 for groups 1-4 and 18-22 and 2048^2 for groups 23-27, 50 surfaces per group.
#   group 18        : 512^2, 6 surfaces, the 95-step history (7.11) with Delta_1 = 0.2/30 (erratum, docs/conventions.md)
#   group 18 @ 1024 : 4 surfaces on the dissertation's grid, 33 steps (below): the grid effect on A*
#   groups 18, 22, 23, 27 @ 2048 : 33 steps, 2 surfaces by default (stages g18_2048 ...; group 18 ran 6
#                     with G18_2048_SIZE=6): with the BCCG active set one 2048^2 surface along the 33
#                     steps takes ~250 s of CPU
#   groups 1, 2     : 512^2, 6 surfaces, the 95-step history
#   groups 22,23,27 : 512^2, 4 surfaces, 33 of the 95 history steps
#   groups 19-21, 24-26 : 512^2, 2 surfaces, 33 steps
#   group 3         : 1024^2 (k_s = 256 <= Nyquist/2), 2 surfaces, only the steps its figures need (7.15,
#                     7.19, 7.21): every second history step of the early stage (15 steps, p* <= 0.2) and
#                     of the nearly-complete stage (10 steps, p* = 2.2 ... 4): a 1024^2 surface along 33
#                     steps took ~670 s of wall per rank here, along 95 it would take ~30 min
#   ch7             : groups 1-4 at 1024^2, 50 surfaces each (CH7_SIZE), the 33 steps (groups 3 and 4: the
#                     steps their figures need, as below); not in the default stages: run it by name
#   ch8, ch8_2048   : groups 18-30 at 1024^2 (CH8_GROUPS: which, in what order) and groups 23-27 at 2048^2, 50
#                     surfaces each (CH8_SIZE), the 33 steps; run by name (groups 28-30 are ours: alpha^p > 3).
#                     Measured: a 1024^2 surface 53-156 s on one core, a 2048^2 one 310-430 s; ch8_2048 with
#                     CH8_SIZE=10 took 2.7 h of wall on 2 ranks (10 surfaces for each of groups 23-27)
#   group 4         : not run by default (k_s = 512 is the Nyquist wavenumber of 1024^2, two nodes per
#                     shortest wavelength; stage g04 runs 2 surfaces at 1024^2)
# The 33 steps: every third step of (7.11) counted back from p* = 4 (indices 94, 91, ..., 1) plus
# p* = 2.0028 (index 74). A step's solution does not depend on the path (unique QP solution), only the
# warm start does; 33 steps cost ~1/2.7 of 95.
# (Measured here: one 1024^2 surface along the 33 steps took ~670 s of wall per rank, ~10x a 512^2 one.)
# Solver: the default (Polonsky-Keer, Fourier preconditioner), -kkt_rtol 1e-8 (the default).
# After g01: `ensemble_figures.py --extras` (single process) solves the four field pictures of Figs.
# 3.9/3.10 (everything else the figures need, the FD bandwidths included, is in the ensemble files).
# Files of format roughpetsc-ensemble-1 (before the FD bandwidths were stored) are read by the figures
# but not resumed: a stage whose file is of that format needs a new file (move the old one away).
set -u
cd "$(dirname "$0")/.."
source tools/env.sh
OUT=studies/output/ensembles
mkdir -p "$OUT/logs"
PY=.venv/bin/python
EARLY_LATE=0.013333333333333334,0.02666666666666667,0.04,0.05333333333333334,0.06666666666666667,0.08,0.09333333333333334,0.10666666666666667,0.12000000000000001,0.13333333333333333,0.14666666666666667,0.16,0.17333333333333334,0.18666666666666668,0.2,2.2,2.4,2.6,2.8,3.0,3.2,3.4000000000000004,3.6,3.8,4.0
SUBSET=0.013333333333333334,0.03333333333333333,0.05333333333333334,0.07333333333333333,0.09333333333333334,0.11333333333333334,0.13333333333333333,0.15333333333333335,0.17333333333333334,0.19333333333333336,0.22156530274382313,0.2583505455879408,0.30124303570563205,0.35125672506178196,0.4095739063713783,0.4775731617688036,0.5568619516377231,0.6493146139813717,0.7571166726148741,0.8828165015978889,1.0293855672228454,1.2002886716421488,1.3995658586503064,1.6319279178230526,1.902867744672317,2.0028318169182757,2.2,2.5,2.8,3.1,3.4000000000000004,3.7,4.0

# run NAME GROUP N SIZE LOADS
run() {
    local name=$1 group=$2 n=$3 size=$4 loads=$5
    local file="$OUT/${name}.h5"
    echo "=== $(date +%H:%M:%S) $name: group $group, ${n}^2, $size surfaces, loads ${loads:0:10}" | tee -a "$OUT/logs/runs.log"
    local start=$(date +%s)
    mpiexec -n 2 $PY -m roughpetsc -mode ensemble -options_file "options/group${group}.opts" -surface_N "$n" \
        -ensemble_size "$size" -ensemble_loads "$loads" -output "$file" >>"$OUT/logs/${name}.log" 2>&1
    local status=$?
    echo "=== $(date +%H:%M:%S) $name: exit $status after $(( $(date +%s) - start )) s" | tee -a "$OUT/logs/runs.log"
}

stage() {
    case $1 in
        g18)      run group18_N512 18 512 "${G18_SIZE:-6}" history ;;
        g01)      run group01_N512 01 512 "${G01_SIZE:-6}" history ;;
        g02)      run group02_N512 02 512 "${G02_SIZE:-6}" history ;;
        g22|g23|g27) v=G${1#g}_SIZE; run "group${1#g}_N512" "${1#g}" 512 "${!v:-4}" "$SUBSET" ;;
        g19|g20|g21|g24|g25|g26) v=G${1#g}_SIZE; run "group${1#g}_N512" "${1#g}" 512 "${!v:-2}" "$SUBSET" ;;
        g03)      run group03_N1024 03 1024 "${G03_SIZE:-2}" "$EARLY_LATE" ;;
        g04)      run group04_N1024 04 1024 "${G04_SIZE:-2}" "$EARLY_LATE" ;;
        g18_1024) run group18_N1024 18 1024 "${G18_1024_SIZE:-4}" "$SUBSET" ;;
        g18_2048|g22_2048|g23_2048|g27_2048)
                  g=${1%_2048}; g=${g#g}; v=G${g}_2048_SIZE
                  run "group${g}_N2048" "$g" 2048 "${!v:-2}" "$SUBSET" ;;
        ch7)      # issue 14, item 3: chapter 7 at the dissertation's scale, 50 surfaces a group at 1024^2
                  # (measured: a group-#1 surface along the 33 steps, 59 s on one core). The BEM of chapter 7 is
                  # that of groups 1-4 (sec. 7.4: "only 50 surfaces from rough surface groups #1 and #2 ... are
                  # selected"; groups 3 and 4 in Figs 7.15, 7.19, 7.21); groups 5-17 enter Tables 7.2-7.6 by
                  # their moments alone: studies/surface_statistics.py --realisations 50 --realisations-2048 50
                  for g in 01 02 03 04; do
                      loads=$SUBSET; [[ $g == 03 || $g == 04 ]] && loads=$EARLY_LATE
                      run "group${g}_N1024" "$g" 1024 "${CH7_SIZE:-50}" "$loads"
                  done ;;
        ch8)      # issue 14, items 3-4: chapter 8 at 1024^2, 50 surfaces a group (CH8_SIZE): the dissertation's
                  # groups 18-27 (it ran 23-27 at 2048^2: stage ch8_2048) and our groups 28-30 (alpha^p 3.7,
                  # 3.2, 4.3, beyond its fit's alpha^p < 3)
                  for g in ${CH8_GROUPS:-18 19 20 21 22 23 24 25 26 27 28 29 30}; do
                      run "group${g}_N1024" "$g" 1024 "${CH8_SIZE:-50}" "$SUBSET"
                  done ;;
        ch8_2048) # the groups of k_s = 128 on the dissertation's grid, those the fit needs most first
                  for g in 27 23 25 24 26; do
                      run "group${g}_N2048" "$g" 2048 "${CH8_SIZE:-50}" "$SUBSET"
                  done ;;
        extras)   echo "=== $(date +%H:%M:%S) extras" | tee -a "$OUT/logs/runs.log"
                  $PY studies/ensemble_figures.py --extras >>"$OUT/logs/extras.log" 2>&1 ;;
        *) echo "unknown stage $1" >&2; return 2 ;;
    esac
}

STAGES=("$@")
if [ ${#STAGES[@]} -eq 0 ]; then
    STAGES=(g18 g18_1024 g01 extras g22 g23 g27 g02 g19 g20 g21 g24 g25 g26 g03 g18_2048 g22_2048 g23_2048
            g27_2048 extras)
fi
for s in "${STAGES[@]}"; do
    stage "$s"
done
