"""roughpetsc: elastic contact of rough surfaces with PETSc/TAO.

Data flow: options -> surface -> operator -> problem -> solver -> results -> files.
The statistical models (:mod:`roughpetsc.models`) depend on spectral moments only.
"""

__version__ = "0.1.0"
