"""``-mode ensemble``: many random surfaces along one load path, in one resumable HDF5 file.

    mpiexec -n 2 python -m roughpetsc -mode ensemble -options_file options/group18.opts \\
        -ensemble_size 50 -output group18.h5

The engine of the dissertation's ensembles (ch. 7.3 and 8), in four parts:

* :mod:`.settings`: the option table (:data:`OPTIONS`, also what ``-help`` prints), the frozen
  :class:`~.settings.EnsembleSettings`, the configuration a resumed file must match;
* :mod:`.scheduler`: the work counter that deals surfaces dynamically to groups of ranks;
* :mod:`.runner`: the run (groups, solves, progress, resume; world rank 0 owns the file);
* :mod:`.statistics`: the step statistics and the statistical models stored beside the BEM.

The file's layout, writer and reader are :mod:`roughpetsc.store.ensemble_file`; the white-noise seed of surface
``i`` is :func:`roughpetsc.seeds.surface_seed` ``(ensemble_seed, i)``, the rule ``-mode stats`` uses too.
Surfaces are stored in index (seed) order and the statistics are taken in that order, so a resumed run
ends with the same numbers as an uninterrupted one (wall times, run numbers and the run log excepted:
:data:`VOLATILE`).
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
