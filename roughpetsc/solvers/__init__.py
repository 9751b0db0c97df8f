"""The solver layer: one facade, one stopping rule, one load-path driver, backends registered by name.

Its modules, one concept each, and how a new solver is added: docs/solvers.md.
"""

from .protocol import Backend, BackendSettings, Guess, Outcome
from .registry import backend_names, make_backend, option_tables, register, unregister
from . import pk, bound_qp, root_find, almm, gap_cg, adhesive_almm  # noqa: F401  (each registers its backend)
from .facade import Solver
from .load_path import drive, load_path
from .stopping import StoppingRule

__all__ = ["Backend", "BackendSettings", "Guess", "Outcome", "Solver", "StoppingRule", "backend_names", "drive",
           "load_path", "make_backend", "option_tables", "register", "unregister"]
