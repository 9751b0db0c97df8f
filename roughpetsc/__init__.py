"""roughpetsc: elastic contact of rough surfaces with PETSc/TAO.

Data flow: options -> surface -> operator -> problem -> solver -> results -> files.
The statistical models (:mod:`roughpetsc.models`) depend on spectral moments only.

One thread per MPI rank: unless the environment says otherwise, the BLAS and
OpenMP thread pools are limited to one thread before numpy loads them (this
takes effect when roughpetsc is imported before numpy, as ``python -m
roughpetsc`` does). A threaded BLAS splits our long dot products over the
cores that the other ranks need: on 2 cores it made one 512^2 load history
11 % slower alone and two of them side by side 40 % slower. FFTW's threads
are an option of their own (``-fft_threads``).
"""

import os

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")
del _variable

__version__ = "0.1.0"
