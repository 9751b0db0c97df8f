"""The moments and bandwidths recorded for every surface a run solves (solve and ensemble modes).

One function, so that a load path's file and an ensemble's file describe a surface by the same numbers.
"""

from . import spectra


def surface_moments(grid, heights, E_star, finite_differences=False):
    """Moments and bandwidths of one surface, the isotropic means of x and y.

    Parameters
    ----------
    grid : Grid
    heights, E_star : ndarray, float
        Heights [length] on ``grid`` and the composite modulus E* (1.6) [pressure].
    finite_differences : bool
        Also ``alpha_h_fd``, ``alpha_p_fd`` from the finite-difference moments (7.6)/(7.7) ("Num" of Table 7.7).

    Returns
    -------
    dict
        ``m0h m2h m4h m6h`` [length^2 / length^n] (2.12), ``m0p m2p m4p`` [pressure^2 / length^n] of p_c (2.47),
        ``alpha_h`` (2.16), ``alpha_p`` (2.54) [-].
    """
    if finite_differences:
        summary = spectra.surface_moment_summary(grid, heights, E_star)
        mh, mp = spectra.isotropic_mean(summary["h_spectral"]), spectra.isotropic_mean(summary["p_spectral"])
    else:
        mh = spectra.isotropic_mean(spectra.spectral_moments(grid, heights))
        pressure = spectra.pressure_surface(grid, heights, E_star)
        mp = spectra.isotropic_mean(spectra.spectral_moments(grid, pressure, (0, 2, 4)))
    moments = {f"m{n}h": mh[n] for n in sorted(mh)}
    moments.update({f"m{n}p": mp[n] for n in sorted(mp)})
    moments["alpha_h"] = spectra.bandwidth(mh[0], mh[2], mh[4])
    moments["alpha_p"] = spectra.bandwidth(mp[0], mp[2], mp[4])
    if finite_differences:
        moments["alpha_h_fd"], moments["alpha_p_fd"] = summary["alpha_h"], summary["alpha_p"]
    return moments
