"""``-mode ensemble``: many random surfaces along one load path, in one resumable HDF5 file.

    mpiexec -n 2 python -m roughpetsc -mode ensemble -options_file options/group18.opts \\
        -ensemble_size 50 -output group18.h5

The parts, the seed rule and why a resumed run ends with the same numbers: docs/runtime.md,
"Ensembles over ranks".
"""

from ..surface.seeds import surface_seed
from ..store import read
from ..store.ensemble_file import FORMAT, STEP_FIELDS, SURFACE_FIELDS, VOLATILE, compare
from .runner import run
from .settings import OPTIONS, EnsembleSettings
from .statistics import EARLY_PMAX, MODEL_NAMES, compute_models, stored_models, stored_statistics

__all__ = ["OPTIONS", "EARLY_PMAX", "FORMAT", "MODEL_NAMES", "STEP_FIELDS", "SURFACE_FIELDS", "VOLATILE",
           "EnsembleSettings", "compare", "compute_models", "read", "run", "stored_models", "stored_statistics",
           "surface_seed"]
