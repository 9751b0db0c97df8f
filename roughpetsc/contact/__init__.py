"""The contact layer: the problems (elastic, adhesive), their results and certificates, the laws and the loads.

A problem owns its surface, operator and units, and certifies a solution; it does not solve. The solvers
(:mod:`roughpetsc.solvers`) depend on this layer, never the reverse.
"""

from ..lazy import exports

__getattr__, __dir__, __all__ = exports(__name__, {
    "problem": "ContactProblem",
    "adhesive": "AdhesiveProblem summit_radius approach_retraction dissipated_energy",
    "result": "Result measure",
    "certificate": "KKTReport report CompositeCriterion",
    "laws": "Dugdale Exponential make_law tabor_parameter",
}, renamed={"load_history": ("loads", "history")})
