"""Solver backends by problem kind, name and control: each backend module registers its factory in one line.

The names are those of ``-tao_type``; a name may mean a different backend under each control.
"""

from ..errors import ParameterError

CONTROLS = ("load", "displacement")
KINDS = ("contact", "adhesive")
# The backend of Solver(tao_type=None) and of the command line without -tao_type, per problem kind.
DEFAULT_NAMES = {"contact": "pk", "adhesive": "gapcg"}


# (kind, name, control) -> factory(problem, control, name, settings), and backend name -> its option table.
FACTORIES = {}
OPTIONS = {}


def register(name, factory, controls=CONTROLS, kinds=("contact",), options=()):
    """Make ``factory(problem, control, name, settings)`` the backend of ``name`` for ``kinds`` under ``controls``.

    Parameters
    ----------
    name : str or sequence of str
        The name, or the names the factory answers to (it receives the one asked for).
    factory : callable
        Returns a backend (:mod:`roughpetsc.solvers.protocol`).
    controls : sequence of "load", "displacement"
    kinds : sequence of "contact", "adhesive"
    options : sequence of (name, default, help)
        The backend's own options, for ``-help`` and the check of names.
    """
    for control in controls:
        if control not in CONTROLS:
            raise ParameterError("controls", f"unknown control '{control}' (one of {', '.join(CONTROLS)})")
    for kind in kinds:
        if kind not in KINDS:
            raise ParameterError("kinds", f"unknown problem kind '{kind}' (one of {', '.join(KINDS)})")
    names = [name] if isinstance(name, str) else list(name)
    for alias in names:
        for kind in kinds:
            for control in controls:
                FACTORIES[(kind, alias, control)] = factory
    if options:
        OPTIONS[names[0]] = list(options)


def unregister(name):
    """Remove ``name`` (a str or a sequence of them) for every kind and control; unknown names are ignored."""
    names = [name] if isinstance(name, str) else list(name)
    for key in [key for key in FACTORIES if key[1] in names]:
        del FACTORIES[key]
    for alias in names:
        OPTIONS.pop(alias, None)


def backend_names(control=None, kind="contact"):
    """The registered names of ``kind`` (under ``control``, or under any), in the order they were registered."""
    names = [name for k, name, mode in FACTORIES if k == kind and control in (None, mode)]
    return list(dict.fromkeys(names))


def resolve(name, control, kind="contact"):
    """The registered name that ``name`` means for ``kind`` under ``control`` (None or "": the default).

    Raises :class:`~roughpetsc.errors.ParameterError` for an unknown name or control.
    """
    if control not in CONTROLS:
        raise ParameterError("control", f"the control is 'load' or 'displacement', got '{control}'")
    name = name or DEFAULT_NAMES[kind]
    if (kind, name, control) in FACTORIES:
        return name
    if name in backend_names(kind=kind):
        other = "load" if control == "displacement" else "displacement"
        load = "pbar or pstar" if other == "load" else "gbar"
        raise ParameterError("tao_type", f"the solver {name} solves {other} control only (prescribe {load})")
    problem = "the contact QP" if kind == "contact" else "the adhesive problem"
    raise ParameterError("tao_type", f"'{name}' is not a solver of {problem}; use one of "
                                     f"{', '.join(backend_names(kind=kind))}")


def make_backend(problem, control, name, settings):
    """The backend ``name`` for ``problem`` (its ``kind``) under ``control``, built with ``settings``."""
    name = resolve(name, control, problem.kind)
    return FACTORIES[(problem.kind, name, control)](problem, control, name, settings)


def option_tables():
    """``{backend name: [(option, default, help), ...]}`` of every registered backend that declares options."""
    return dict(OPTIONS)
