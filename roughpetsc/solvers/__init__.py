"""Solvers of the contact QP (3.41)-(3.44) of the dissertation, under load and displacement control.

One concept per module:

- :mod:`.protocol`: what a backend offers (``solve(target, pressure, guess) -> Outcome``, ``destroy``,
  ``name``, ``tao``, optional ``keeps_displacement``);
- :mod:`.registry`: backends by name (``register``, ``unregister``, ``backend_names``, ``make_backend``);
- backends, each registering itself in one line: :mod:`.pk` (Polonsky-Keer, the TAO python context in
  :mod:`.polonsky_keer`), :mod:`.bound_qp` (any bound-constrained TAO type, displacement control),
  :mod:`.root_find` (load control by a root find on the separation around it), :mod:`.almm` (TAO ALMM);
- :mod:`.objective` (the QP's objective for TAO), :mod:`.tao_options` (options prefix, scoped
  defaults, the time limit);
- :mod:`.solver` (the :class:`Solver` facade), :mod:`.continuation` (warm starts along loads),
  :mod:`.load_path` (a generator of results along loads).

A new solver or physics adds one module that registers its factory and one import line here.
"""

from .protocol import Backend, BackendSettings, Guess, Outcome
from .registry import backend_names, make_backend, register, unregister
from . import pk, bound_qp, root_find, almm  # noqa: F401  (each registers its backend)
from .solver import Solver
from .load_path import load_path

__all__ = ["Backend", "BackendSettings", "Guess", "Outcome", "Solver", "backend_names", "load_path", "make_backend",
           "register", "unregister"]
