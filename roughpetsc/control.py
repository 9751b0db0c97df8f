"""The solver facade under its historical name: :mod:`roughpetsc.solvers` holds the solvers.

``from roughpetsc.control import Solver`` keeps working for the studies that use it.
"""

from .solvers import Solver, load_path

__all__ = ["Solver", "load_path"]
