"""Package names imported on first use (PEP 562), so that importing a package loads neither numpy nor PETSc.

The command line hands PETSc its options (``petsc4py.init(argv)``) before anything imports ``petsc4py.PETSc``.
"""

import importlib


def exports(package, modules, submodules=(), renamed=None):
    """``(__getattr__, __dir__, __all__)`` of ``package`` for ``modules`` = ``{module: "name name ..."}``.

    ``module`` is relative to ``package``; ``renamed`` = ``{public name: (module, name)}``; ``submodules`` are
    subpackages returned as modules.
    """
    table = {name: (module, name) for module, names in modules.items() for name in names.split()}
    table.update(renamed or {})
    namespace = importlib.import_module(package).__dict__

    def __getattr__(name):
        if name in submodules:
            return importlib.import_module(f"{package}.{name}")
        if name in table:
            module, attribute = table[name]
            value = getattr(importlib.import_module(f"{package}.{module}"), attribute)
            namespace[name] = value  # later look-ups skip __getattr__
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    names = sorted(table) + list(submodules)

    def __dir__():
        return sorted(set(namespace) | set(names))

    return __getattr__, __dir__, names
