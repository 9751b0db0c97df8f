#!/usr/bin/env bash
# Install the peer libraries (Tamaas, ContactMechanics) into their own virtualenv
# /work/main/.peers-venv (gitignored), WITHOUT system site packages, so that the
# peers' numpy never meets Debian's numpy that petsc4py is built against.
# Idempotent: re-running only checks that the imports still work.
#   bash studies/peers/install.sh [VENV_DIR]
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
VENV="${1:-$ROOT/.peers-venv}"
PY=/usr/bin/python3   # Debian's 3.11: all peer wheels exist for cp311

check() {
    "$VENV/bin/python" - <<'PY'
import importlib.metadata as md
import tamaas, ContactMechanics, muGrid, SurfaceTopography, NuMPI  # noqa: F401
from muGrid import FFTEngine  # noqa: F401  (ContactMechanics >= 1.8 uses muGrid's FFT)
for d in ("tamaas", "ContactMechanics", "muGrid", "SurfaceTopography", "NuMPI", "numpy", "scipy"):
    try:
        print(f"{d:18s} {md.version(d)}")
    except md.PackageNotFoundError:
        print(f"{d:18s} ?")
PY
}

if [ -x "$VENV/bin/python" ] && check >/dev/null 2>&1; then
    echo "peers venv $VENV already complete"; check; exit 0
fi

if [ ! -x "$VENV/bin/python" ]; then
    # python3-venv provides ensurepip for Debian's interpreter
    if ! "$PY" -c "import ensurepip" >/dev/null 2>&1; then
        apt-get update && apt-get install -y python3-venv
    fi
    "$PY" -m venv "$VENV"
fi
"$VENV/bin/pip" install -q --upgrade pip
# All of these are binary wheels on PyPI for cp311/manylinux (no compiler needed).
# --only-binary keeps pip from silently falling back to a long source build.
# Do NOT install the separate muFFT package: ContactMechanics 1.8 takes its FFT
# from muGrid >= 1.0 (muGrid.FFTEngine), and the old muFFT 0.95 wheel ships its
# own muGrid/__init__.py that overwrites muGrid 1.x's and hides FFTEngine.
"$VENV/bin/pip" uninstall -y -q muFFT >/dev/null 2>&1 || true
"$VENV/bin/pip" install -q --only-binary=:all: \
    "tamaas==2.9.*" "ContactMechanics==1.8.*" "muGrid>=1.0" SurfaceTopography NuMPI numpy scipy
# repair muGrid if an earlier install let muFFT overwrite it
"$VENV/bin/python" -c "from muGrid import FFTEngine" >/dev/null 2>&1 || \
    "$VENV/bin/pip" install -q --only-binary=:all: --force-reinstall --no-deps "muGrid>=1.0"
check
