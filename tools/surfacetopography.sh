#!/usr/bin/env bash
# The optional extra for instrument files: SurfaceTopography's readers behind -surface_file.
#
# SurfaceTopography >= 1.19 needs numpy 2, and a plain `pip install SurfaceTopography` replaces the Debian
# numpy 1.24 that petsc4py and h5py are built against. This installs the newest release found to run beside
# it, 1.18.0, and its dependencies one by one without theirs (--no-deps), pandas from Debian (PyPI's pandas 3
# is built for numpy 2), then checks that numpy is still Debian's. Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/bootstrap.sh

if ! dpkg-query -W -f='${Status}' python3-pandas 2>/dev/null | grep -q "install ok installed"; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends python3-pandas >/dev/null
fi

numpy_before=$(.venv/bin/python -c "import numpy; print(numpy.__version__, numpy.__file__)")
.venv/bin/python -m pip install --quiet --no-deps \
  SurfaceTopography==1.18.0 muFFT==0.95.0 NuMPI==0.18.1 array-api-compat==1.16.0 igor2==0.5.15 \
  DiscoverVersion==0.4.0 numpyencoder==0.3.2 tifffile==2026.3.3 tiffile==2018.10.18 defusedxml==0.7.1 \
  openpyxl==3.1.5 pydantic==2.14.4 pydantic_core==2.50.5 annotated-types==0.8.0 typing-inspection==0.4.5 \
  typing_extensions==4.16.0 requests==2.34.2 idna==3.20 certifi==2026.10.19.post1 urllib3==2.8.0 chardet==7.7.0
numpy_after=$(.venv/bin/python -c "import numpy; print(numpy.__version__, numpy.__file__)")
if [ "$numpy_before" != "$numpy_after" ]; then
  echo "tools/surfacetopography.sh: numpy changed ($numpy_before -> $numpy_after); remove .venv and run tools/bootstrap.sh" >&2
  exit 1
fi
.venv/bin/python -c "import SurfaceTopography, numpy; print('SurfaceTopography', SurfaceTopography.__version__, 'beside numpy', numpy.__version__)"
