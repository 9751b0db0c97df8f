#!/usr/bin/env bash
# The test suite: serial pytest, then the MPI tests under mpiexec -n 2.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/bootstrap.sh
source tools/env.sh
.venv/bin/python -m pytest -q tests "$@"
