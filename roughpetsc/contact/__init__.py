"""The contact layer: the problems (elastic, adhesive), their results and certificates, the laws and the loads.

A problem owns its surface, its operator (from :func:`roughpetsc.elastic.make_operator`) and its units; it
knows its energy, its gradient and how to certify a solution (:meth:`certify`), not how to solve. The
solvers (:mod:`roughpetsc.solvers`) depend on this layer, never the reverse.
"""

from ..lazy import exports

__getattr__, __dir__, __all__ = exports(__name__, {
    "problem": "ContactProblem",
    "adhesive": "AdhesiveProblem summit_radius approach_retraction dissipated_energy",
    "result": "Result measure",
    "certificate": "KKTReport report CompositeCriterion",
    "laws": "Dugdale Exponential make_law tabor_parameter",
}, renamed={"load_history": ("loads", "history")})
