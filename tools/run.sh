#!/usr/bin/env bash
# The main job: install what is missing, then solve the embedded default problem on 2 ranks.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/bootstrap.sh
source tools/env.sh
exec mpiexec -n 2 .venv/bin/python -m roughpetsc "$@"
