"""The seed rule of every ensemble: one (master seed, index) means one surface in every mode.

Realisation ``i`` of an ensemble with master seed ``S`` (``-ensemble_seed``) is the fractal surface
(7.1)-(7.2) of the ``-surface_*`` options with the white-noise seed

    seed_i = SeedSequence(S, spawn_key=(i,)).generate_state(1, uint32)[0] & 0x7fffffff,

the first word of ``numpy.random.SeedSequence(S).spawn(i + 1)[i]`` cut to 31 bits (so that ``-mode solve
-surface_seed seed_i`` rebuilds it). ``-mode stats -stats_ensemble n`` and ``-mode ensemble -ensemble_size n`` both
use it (docs/conventions.md, "Seeds"); children of a SeedSequence are independent streams, unlike consecutive seeds.
"""

import numpy as np

SEED_BITS = 0x7FFFFFFF
RULE = ("seed_i = SeedSequence(ensemble_seed, spawn_key=(i,)).generate_state(1, uint32)[0] & 0x7fffffff; "
        "surface = -surface_seed seed_i")


def surface_seed(master, index):
    """The white-noise seed of realisation ``index`` of the ensemble with master seed ``master``.

    Parameters
    ----------
    master, index : int
        Master seed and realisation, >= 0.

    Returns
    -------
    int
        In [0, 2**31): the first 31-bit word of ``SeedSequence(master).spawn(index + 1)[index]``.
    """
    sequence = np.random.SeedSequence(master, spawn_key=(index,))
    return int(sequence.generate_state(1, np.uint32)[0] & SEED_BITS)


def surface_seeds(master, count):
    """The seeds of realisations ``0 .. count - 1`` in index order (:func:`surface_seed`)."""
    return [surface_seed(master, index) for index in range(count)]
