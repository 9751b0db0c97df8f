"""Fig. 7.1: one realisation of each of the surface groups #1, #4, #9 and #12 of Table 7.1.

    .venv/bin/python studies/realisations_fig7_1.py [--groups 1 4 9 12] [--seed 1]

Each surface is generated on its group's grid (options/groupNN.opts: 1024^2 nodes on the unit cell, m2^h = 2e-4)
by the generator its preset names ((7.2)-(7.5), ``xu``) with the white-noise seed ``--seed`` (seed 1 is the first
realisation of studies/surface_statistics.py), and drawn as h / sqrt(m0^h) over the cell, m0^h (2.13) that of the
realisation. One seed for every group: the same white noise, so the panels differ by the spectrum alone. Writes
studies/output/statistics/fig7_1_realisations.png.
"""

import argparse
import os

import numpy as np

from roughpetsc import Grid, fractal, fractal_group, spectral_moments

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output", "statistics")


def realisation(number, seed):
    """(heights, group) of realisation ``seed`` of surface group ``number``."""
    group = fractal_group(number)
    grid = Grid(group["n"], group["n"], group["length"], group["length"])
    heights = fractal(grid, group["k_l"], group["k_s"], group["hurst"], group["m2"], seed, group["generator"])
    return heights, grid, group


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--groups", type=int, nargs="+", default=[1, 4, 9, 12])
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(OUT, exist_ok=True)
    fig, axes = plt.subplots(1, len(args.groups), figsize=(4.6 * len(args.groups), 4.4), squeeze=False)
    for k, (axis, number) in enumerate(zip(axes[0], args.groups)):
        heights, grid, group = realisation(number, args.seed)
        m0 = spectral_moments(grid, heights)["x"][0]  # the variance (2.13), the same along y
        image = axis.imshow(heights / np.sqrt(m0), cmap="terrain", origin="lower",
                            extent=(0, group["length"], 0, group["length"]))
        fig.colorbar(image, ax=axis, shrink=0.75, label="h / sqrt(m0^h)")
        axis.set_title(f"({'abcdefgh'[k]}) group #{number}: (k_l, k_s, H) = ({group['k_l']:g}, {group['k_s']:g}, "
                       f"{group['hurst']:g})\n{group['n']}^2 nodes, sqrt(m0^h) = {np.sqrt(m0):.3g}", fontsize=9)
        axis.set(xlabel="x", ylabel="y")
        print(f"group {number}: {group['n']}^2, seed {args.seed}, sqrt(m0^h) = {np.sqrt(m0):.4g}, "
              f"max |h| / sqrt(m0^h) = {np.abs(heights).max() / np.sqrt(m0):.2f}")
    fig.suptitle(f"Fig. 7.1: one realisation (seed {args.seed}) of surface groups "
                 + ", ".join(f"#{n}" for n in args.groups))
    fig.tight_layout()
    path = os.path.join(OUT, "fig7_1_realisations.png")
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
