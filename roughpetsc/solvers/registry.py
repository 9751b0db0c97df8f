"""Solver backends by name: each backend module registers its factory in one line.

The names are those of ``-tao_type`` (and of ``Solver(..., tao_type=...)``): the bound-constrained TAO
types, ``almm``, and ``pk`` (also ``none``, ``python``, or no name: the default). A name may mean a
different backend under each control (a bound type is the QP itself under displacement control and a
root find on the separation around it under load control). A new solver or physics registers
``register(name, factory, controls)`` in its own module, imported by :mod:`roughpetsc.solvers`.
"""

from ..errors import ParameterError
from .protocol import BackendSettings
from .tao_options import max_seconds

CONTROLS = ("load", "displacement")
# The backend of Solver(tao_type=None) and of the command line without -tao_type.
DEFAULT_NAME = "pk"

# (name, control) -> factory(problem, control, name, settings) -> backend
_FACTORIES = {}


def register(name, factory, controls=CONTROLS):
    """Make ``factory(problem, control, name, settings)`` the backend of ``name`` under ``controls``.

    Parameters
    ----------
    name : str or sequence of str
        The name, or the names the factory answers to (it receives the one asked for).
    factory : callable
        Returns a backend (:mod:`roughpetsc.solvers.protocol`); ``settings`` is a
        :class:`~roughpetsc.solvers.protocol.BackendSettings`.
    controls : sequence of "load", "displacement"
    """
    for control in controls:
        if control not in CONTROLS:
            raise ParameterError("controls", f"unknown control '{control}' (one of {', '.join(CONTROLS)})")
    for alias in ([name] if isinstance(name, str) else name):
        for control in controls:
            _FACTORIES[(alias, control)] = factory


def unregister(name):
    """Remove ``name`` (a str or a sequence of them) under every control; unknown names are ignored."""
    names = [name] if isinstance(name, str) else list(name)
    for key in [key for key in _FACTORIES if key[0] in names]:
        del _FACTORIES[key]


def backend_names(control=None):
    """The registered names (under ``control``, or under any), in the order they were registered."""
    names = [name for name, mode in _FACTORIES if control in (None, mode)]
    return list(dict.fromkeys(names))


def resolve(name, control):
    """The registered name that ``name`` means under ``control`` (None or "" mean :data:`DEFAULT_NAME`).

    Raises :class:`~roughpetsc.errors.ParameterError` for ``tao_type`` (an unknown name, or a
    backend that does not solve ``control``) or ``control``.
    """
    if control not in CONTROLS:
        raise ParameterError("control", f"the control is 'load' or 'displacement', got '{control}'")
    name = name or DEFAULT_NAME
    if (name, control) in _FACTORIES:
        return name
    if name in backend_names():
        other = "load" if control == "displacement" else "displacement"
        load = "pbar or pstar" if other == "load" else "gbar"
        raise ParameterError("tao_type", f"the solver {name} solves {other} control only (prescribe {load})")
    raise ParameterError("tao_type", f"'{name}' is not a solver of the contact QP; use one of "
                                     f"{', '.join(backend_names())}")


def make_backend(problem, control, name, rtol, prefix=None):
    """The backend ``name`` for ``problem`` under ``control``, its TAO objects under options ``prefix``.

    The solve time limit (``-solve_max_time``) is read here, once, and handed to the backend.
    """
    name = resolve(name, control)
    settings = BackendSettings(rtol=rtol, prefix=prefix, max_seconds=max_seconds(prefix))
    return _FACTORIES[(name, control)](problem, control, name, settings)
