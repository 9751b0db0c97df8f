"""The contact layer: the problems (elastic, adhesive), their results and certificates, the laws and the loads.

A problem owns its surface, its operator (from :func:`roughpetsc.elastic.make_operator`) and its units; it
knows its energy, its gradient and how to certify a solution (:meth:`certify`), not how to solve. The
solvers (:mod:`roughpetsc.solvers`) depend on this layer, never the reverse.
"""

from ..lazy import exports

__getattr__, __dir__, __all__ = exports(__name__, {
    "ContactProblem": ("problem", "ContactProblem"),
    "AdhesiveProblem": ("adhesive", "AdhesiveProblem"),
    "Result": ("result", "Result"),
    "measure": ("result", "measure"),
    "KKTReport": ("certificate", "KKTReport"),
    "report": ("certificate", "report"),
    "CompositeCriterion": ("certificate", "CompositeCriterion"),
    "Dugdale": ("laws", "Dugdale"),
    "Exponential": ("laws", "Exponential"),
    "make_law": ("laws", "make_law"),
    "tabor_parameter": ("laws", "tabor_parameter"),
    "summit_radius": ("adhesive", "summit_radius"),
    "approach_retraction": ("adhesive", "approach_retraction"),
    "dissipated_energy": ("adhesive", "dissipated_energy"),
    "load_history": ("loads", "history"),
})
