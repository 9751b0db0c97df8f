"""Figures of a solve (``-plot PATH.png``): pressure and gap maps of the last step, A* against p* of a load path,
the mean pressure against the mean gap of an adhesive path. Drawn through :class:`matplotlib.figure.Figure`
(no pyplot, no global backend state); the format follows the file's suffix.
"""

import os


def plot_solution(path, grid, pressure, gap, steps, adhesion=None):
    """Write the figure of a solve to ``path`` (atomically).

    ``pressure``, ``gap``: the last step's fields (pressure and length units). ``steps``: the step summaries;
    with more than one, a third panel shows A* against p*, or with ``adhesion`` (the run's adhesion summary)
    pbar against gbar.
    """
    from matplotlib.figure import Figure
    import numpy as np

    from ..store import outputs as io

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
    if panels == 3 and adhesion is not None:
        draw_cycle(axes[2], steps, adhesion)
    elif panels == 3:
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


def draw_cycle(ax, steps, adhesion):
    """pbar against the mean gap of an adhesive path, in step order: approach (gap closing) and retraction."""
    gaps = [s["gbar"] for s in steps]
    pbars = [s["pbar"] for s in steps]
    for k in range(1, len(steps)):
        closing = gaps[k] < gaps[k - 1]
        ax.plot(gaps[k - 1:k + 1], pbars[k - 1:k + 1], "-", color="tab:blue" if closing else "tab:red",
                label=("approach" if closing else "retraction"))
    ax.plot(gaps, pbars, "k.", markersize=4)
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    ax.legend(unique.values(), unique.keys())
    ax.axhline(0.0, color="0.5", linewidth=0.8)
    energy = adhesion.get("dissipated_energy")
    title = f"{adhesion['law']} adhesion" + (f"\ndissipated {energy:.3g} per unit area" if energy is not None else "")
    ax.set(xlabel="mean gap gbar", ylabel="mean pressure pbar (tension < 0)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
