#!/usr/bin/env bash
# Install what roughpetsc needs on a Debian bookworm machine, idempotently:
# the Debian PETSc/SLEPc/MPI/FFTW stack (apt, once) and a virtualenv .venv that
# sees it (--system-site-packages) with roughpetsc installed in editable mode.
# Safe to run again: every step is skipped when already done.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(python3-petsc4py python3-slepc4py python3-mpi4py python3-mpi4py-fft python3-pyfftw
          python3-h5py-mpi python3-scipy python3-matplotlib python3-numba python3-pytest python3-venv python3-pip
          libpetsc-real3.18-dev libslepc-real3.18-dev openmpi-bin)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "bootstrap: installing ${missing[*]}" >&2
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [ ! -x .venv/bin/python ] || ! .venv/bin/python -c "import petsc4py, roughpetsc" 2>/dev/null; then
  echo "bootstrap: creating .venv (system site packages) and installing roughpetsc" >&2
  /usr/bin/python3 -m venv --system-site-packages .venv
  # --no-deps: numpy, petsc4py & co. come from Debian and must not be upgraded by pip.
  .venv/bin/python -m pip install --quiet --no-deps --no-build-isolation -e . >/dev/null
fi
