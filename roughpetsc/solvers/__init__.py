"""The solver layer: one facade, one stopping rule, one load-path driver, backends registered by name.

One concept per module:

- :mod:`.protocol`: what a problem offers the solvers, and what a backend offers the facade
  (``solve(target, unknown, guess) -> Outcome``, ``destroy``, ``name``, ``tao``);
- :mod:`.registry`: backends by problem kind, name and control (``register``, ``backend_names``,
  ``make_backend``), with the option table each declares;
- :mod:`.stopping`: the stopping rule of every backend (tolerance, fresh confirmation, limits, stagnation,
  best iterate) and the TAO convergence test that carries it;
- :mod:`.options`: the per-solver options manager (options pushed under a prefix, removed at the end),
  scoped defaults, ``setFromOptions`` with a clear error, the TAO ``python`` type;
- :mod:`.facade` (the :class:`Solver`), :mod:`.load_path` (:func:`drive` and the generator :func:`load_path`);
- backends, each registering itself in one line: :mod:`.pk` (Polonsky-Keer, the TAO python context in
  :mod:`.polonsky_keer`), :mod:`.bound_qp` (any bound-constrained TAO type, displacement control),
  :mod:`.root_find` (load control by a root find on the separation around it), :mod:`.almm` (TAO ALMM),
  :mod:`.gap_cg` and :mod:`.adhesive_almm` (the adhesive problem);
- :mod:`.preconditioner` (the Fourier preconditioner).

A new solver or physics adds one module that registers its factory and one import line here.
"""

from .protocol import Backend, BackendSettings, Guess, Outcome
from .registry import backend_names, make_backend, option_tables, register, unregister
from . import pk, bound_qp, root_find, almm, gap_cg, adhesive_almm  # noqa: F401  (each registers its backend)
from .facade import Solver
from .load_path import drive, load_path
from .stopping import StoppingRule

__all__ = ["Backend", "BackendSettings", "Guess", "Outcome", "Solver", "StoppingRule", "backend_names", "drive",
           "load_path", "make_backend", "option_tables", "register", "unregister"]
