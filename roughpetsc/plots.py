"""Figures of a solve (``-plot PATH.png``): pressure and gap maps of the last step, A* against p* of a load path.

Drawn with matplotlib's Agg canvas through :class:`matplotlib.figure.Figure`
(no pyplot, no display, no global backend state); the format follows the
file's suffix.
"""

import os


def plot_solution(path, grid, pressure, gap, steps):
    """Write the figure of a solve to ``path`` (atomically).

    Parameters
    ----------
    path : str
        The figure file; its suffix names the format (png, pdf, svg, ...).
    grid : surfaces.Grid
        The cell (length units), for the axes of the maps.
    pressure, gap : ndarray (n0, n1)
        Fields of the last step, pressure and length units.
    steps : list of dict
        Step summaries (``pstar``, ``A``, ``A_corrected``); with more than one,
        a third panel shows the contact area against the load.
    """
    from matplotlib.figure import Figure
    import numpy as np

    from . import io

    panels = 3 if len(steps) > 1 else 2
    figure = Figure(figsize=(4.2 * panels, 3.8), layout="constrained")
    axes = figure.subplots(1, panels)
    extent = (0.0, grid.l1, grid.l0, 0.0)  # axis 0 (rows, y) downwards as stored
    last = steps[-1]
    maps = ((pressure, "pressure p", "magma", f"p* = {last['pstar']:.4g}, A* = {last['A']:.4g}"),
            # Gaps span decades; the map shows them on a square-root scale so the contact edges stay visible.
            (np.sqrt(np.maximum(gap, 0.0)), "sqrt(gap g)", "viridis", "gap (square-root scale)"))
    for ax, (field, label, colours, title) in zip(axes, maps):
        image = ax.imshow(field, extent=extent, cmap=colours, interpolation="nearest")
        ax.set(xlabel="x", ylabel="y", title=title)
        figure.colorbar(image, ax=ax, label=label, shrink=0.85)
    if panels == 3:
        ax = axes[2]
        pstar = [s["pstar"] for s in steps]
        ax.plot(pstar, [s["A"] for s in steps], "o-", markersize=3, label="A* (node count)")
        ax.plot(pstar, [s["A_corrected"] for s in steps], "s--", markersize=3, label="A* corrected")
        ax.set(xlabel="p* = pbar / sqrt(m0p)", ylabel="A*", title="contact area against load")
        ax.legend()
        ax.grid(alpha=0.3)
    suffix = os.path.splitext(path)[1].lower().lstrip(".")
    with io.atomic_path(path) as temporary:
        figure.savefig(temporary, format=suffix, dpi=110)
