"""The application layer: the command line, its modes and option tables, presets, plots and progress lines.

Everything here reads options or prints; the layers below (surface, elastic, contact, solvers, store,
models) never import from it.
"""
