"""Subsurface stresses (3.26) against exact solutions of the elastic half-space."""

import numpy as np
import pytest

from roughpetsc.errors import ParameterError
from roughpetsc.elastic.stresses import element_influence, free_stresses, max_shear, padded_influence, periodic_stresses, von_mises


def rotated_plane_strain(amplitude, wavenumber, direction, depth, nu, phase):
    """The plane-strain solution of a pressure wave along unit ``direction``, rotated to (x, y).

    Pressure ``P cos(phase)``: along the wave sigma_nn = -P (1 - 2 pi k z) e^{-2 pi k z} cos,
    sigma_zz = -P (1 + 2 pi k z) e cos, tau_nz = -P 2 pi k z e sin, and plane strain across it,
    sigma_tt = nu (sigma_nn + sigma_zz) (Johnson, Contact Mechanics, 1985: a sinusoidal pressure on a
    half-plane).
    """
    kz = 2 * np.pi * wavenumber * depth
    decay = np.exp(-kz)
    nn = -amplitude * (1 - kz) * decay * np.cos(phase)
    zz = -amplitude * (1 + kz) * decay * np.cos(phase)
    nz = -amplitude * kz * decay * np.sin(phase)
    tt = nu * (nn + zz)
    cx, cy = direction
    return {"xx": nn * cx * cx + tt * cy * cy, "yy": nn * cy * cy + tt * cx * cx,
            "xy": (nn - tt) * cx * cy, "zz": zz, "xz": nz * cx, "yz": nz * cy}


@pytest.mark.parametrize("shape, lengths", [((32, 32), (2.0, 2.0)), ((15, 22), (1.5, 2.0))])
@pytest.mark.parametrize("modes", [(0, 3), (2, 2), (5, -1), (-7, 4)])
def test_pressure_wave_matches_the_rotated_plane_strain_solution(modes, shape, lengths):
    nu, amplitude = 0.3, 0.7
    my, mx = modes
    y = np.arange(shape[0])[:, None] * lengths[0] / shape[0]
    x = np.arange(shape[1])[None, :] * lengths[1] / shape[1]
    phase = 2 * np.pi * (mx * x / lengths[1] + my * y / lengths[0])
    pressure = amplitude * np.cos(phase)
    ky, kx = my / lengths[0], mx / lengths[1]
    wavenumber = np.hypot(kx, ky)
    direction = (kx / wavenumber, ky / wavenumber)
    depths = [0.0, 0.05, 0.3]
    for depth, result in zip(depths, periodic_stresses(pressure, lengths, depths, nu)):
        exact = rotated_plane_strain(amplitude, wavenumber, direction, depth, nu, phase)
        for name, field in exact.items():
            assert np.abs(result.components[name] - field).max() < 1e-12 * amplitude, (depth, name)


def test_uniform_pressure_strains_the_half_space_uniaxially():
    nu = 0.25
    (result,) = periodic_stresses(np.full((8, 8), 2.0), (1.0, 1.0), [0.4], nu)
    assert np.allclose(result.components["zz"], -2.0)
    assert np.allclose(result.components["xx"], -2.0 * nu / (1 - nu))
    assert np.allclose(result.von_mises, 2.0 * (1 - 2 * nu) / (1 - nu))


def test_max_shear_of_a_diagonal_state():
    s = {"xx": np.array([-1.0]), "yy": np.array([-0.2]), "zz": np.array([-3.0]),
         "xy": np.array([0.0]), "yz": np.array([0.0]), "xz": np.array([0.0])}
    assert max_shear(s)[0] == pytest.approx(1.4)


@pytest.mark.parametrize("layout", ["C", "F", "strided"])
def test_von_mises_from_the_principal_stresses(layout):
    """The compiled form against sqrt(((s1 - s2)^2 + (s2 - s3)^2 + (s3 - s1)^2) / 2) of the eigenvalues, for
    components in any memory layout."""
    rng = np.random.default_rng(3)
    arrange = {"C": np.ascontiguousarray, "F": np.asfortranarray, "strided": lambda a: np.repeat(a, 2, 0)[::2]}
    s = {name: arrange[layout](rng.standard_normal((70, 5))) for name in ("xx", "yy", "zz", "xy", "yz", "xz")}
    tensor = np.stack([np.stack([s["xx"], s["xy"], s["xz"]], -1), np.stack([s["xy"], s["yy"], s["yz"]], -1),
                       np.stack([s["xz"], s["yz"], s["zz"]], -1)], -2)
    s1, s2, s3 = np.moveaxis(np.linalg.eigvalsh(tensor), -1, 0)
    expected = np.sqrt(((s1 - s2) ** 2 + (s2 - s3) ** 2 + (s3 - s1) ** 2) / 2)
    assert np.abs(von_mises(s) - expected).max() < 1e-12 * expected.max()


@pytest.mark.parametrize("depths, nu, parameter", [([-1.0], 0.3, "depths"), ([], 0.3, "depths"),
                                                   ([0.1], 0.5, "nu")])
def test_bad_parameters_are_named(depths, nu, parameter):
    with pytest.raises(ParameterError) as error:
        next(periodic_stresses(np.ones((4, 4)), (1.0, 1.0), depths, nu))
    assert error.value.parameter == parameter


def boussinesq_point_load(X, Y, z, nu):
    """Stresses of a unit normal point load on the half-space (Johnson, Contact Mechanics, 1985, (3.1x))."""
    rho, r = np.sqrt(X * X + Y * Y + z * z), np.hypot(X, Y)
    radial = ((1 - 2 * nu) / r ** 2 * (1 - z / rho) - 3 * z * r ** 2 / rho ** 5) / (2 * np.pi)
    hoop = -(1 - 2 * nu) * (1 / r ** 2 * (1 - z / rho) - z / rho ** 3) / (2 * np.pi)
    c, s = X / r, Y / r
    return {"xx": radial * c * c + hoop * s * s, "yy": radial * s * s + hoop * c * c,
            "xy": (radial - hoop) * c * s, "zz": -3 * z ** 3 / (2 * np.pi * rho ** 5),
            "xz": -3 * X * z ** 2 / (2 * np.pi * rho ** 5), "yz": -3 * Y * z ** 2 / (2 * np.pi * rho ** 5)}


@pytest.mark.parametrize("offset", [(5.0, 3.0, 4.0), (1.0, 0.0, 0.3), (2.0, -1.0, 0.7)])
def test_element_influence_integrates_the_point_load(offset):
    from scipy.integrate import dblquad

    X, Y, z = offset
    nu = 0.3
    closed = element_influence(np.array(X), np.array(Y), 1.0, 0.8, z, nu)
    for name, value in closed.items():
        quadrature = dblquad(lambda b, a: boussinesq_point_load(X - a, Y - b, z, nu)[name],
                             -0.5, 0.5, -0.4, 0.4, epsabs=1e-14, epsrel=1e-12)[0]
        assert abs(float(value) - quadrature) < 1e-12, name


@pytest.mark.parametrize("depth", [0.0, 0.35])
def test_padded_influence_is_the_element_influence_at_every_wrapped_offset(depth):
    """The quadrant-and-parity construction against the four-corner sum of each offset on its own."""
    n0, n1, spacing, nu = 5, 4, (0.7, 0.4), 0.3
    rows = np.arange(2 * n0)
    cols = np.arange(2 * n1)
    offset_y = np.where(rows < n0, rows, rows - 2 * n0)[:, None] * spacing[0]
    offset_x = np.where(cols < n1, cols, cols - 2 * n1)[None, :] * spacing[1]
    direct = element_influence(offset_x, offset_y, spacing[1], spacing[0], depth, nu)
    for name, kernel in padded_influence(n0, n1, spacing, depth, nu):
        expected = direct[name].copy()
        expected[n0, :] = 0.0  # offsets that never occur between two nodes
        expected[:, n1] = 0.0
        assert np.abs(kernel - expected).max() <= 1e-14 * np.abs(expected).max(), name


def hertz_pressure(n, nodes_per_radius):
    centre = n // 2
    y = (np.arange(n)[:, None] - centre) / nodes_per_radius
    x = (np.arange(n)[None, :] - centre) / nodes_per_radius
    return np.sqrt(np.clip(1 - x * x - y * y, 0, None)), centre


def test_hertz_stresses_on_the_axis():
    """Below a Hertz pressure (p0 = 1, a = 1): sigma_z, sigma_r on the axis, the maximum shear 0.31 p0
    at 0.48 a (nu = 0.3) and the surface radial stress (1 - 2 nu) / 3 p0 at the edge (Johnson 1985, 3.4)."""
    nu, nodes = 0.3, 32
    pressure, centre = hertz_pressure(128, nodes)
    depths = np.linspace(0.40, 0.56, 9)
    shear = []
    for depth, result in zip(depths, free_stresses(pressure, (1 / nodes, 1 / nodes), depths, nu)):
        axis = {name: field[centre:centre + 1, centre:centre + 1] for name, field in result.components.items()}
        sigma_z = -1 / (1 + depth ** 2)
        sigma_r = -((1 + nu) * (1 - depth * np.arctan(1 / depth)) - 0.5 / (1 + depth ** 2))
        assert abs(axis["zz"][0, 0] - sigma_z) < 3e-4 and abs(axis["xx"][0, 0] - sigma_r) < 3e-4
        shear.append(max_shear(axis)[0, 0])
    assert max(shear) == pytest.approx(0.310, abs=1e-3)
    assert depths[int(np.argmax(shear))] == pytest.approx(0.48, abs=0.02)
    (surface,) = free_stresses(pressure, (1 / nodes, 1 / nodes), [0.0], nu)
    assert surface.components["xx"][centre, centre + nodes] == pytest.approx((1 - 2 * nu) / 3, abs=5e-3)


@pytest.mark.mpi
@pytest.mark.slow
@pytest.mark.parametrize("boundary", ["periodic", "free"])
def test_command_line_writes_the_stresses_of_the_last_step(tmp_path, boundary):
    import h5py

    from conftest import run_cli

    args = ["-surface_N", 32, "-surface_ks", 8, "-surface_kl", 2, "-boundary", boundary, "-pstar_list", "0.2,0.6",
            "-kkt_rtol", 1e-13, "-fft_effort", "FFTW_ESTIMATE", "-nu", 0.25]
    plain = tmp_path / "plain.h5"
    assert run_cli(args + ["-output", plain]).returncode == 0
    with h5py.File(plain) as f:
        assert "stresses" not in f  # nothing computed without -stress_depths
    files = []
    for ranks in (1, 2):
        path = tmp_path / f"s{ranks}.h5"
        out = run_cli(args + ["-stress_depths", "0,0.01", "-output", path], ranks=ranks)
        assert out.returncode == 0, out.stdout + out.stderr
        files.append(path)
    with h5py.File(files[0]) as one, h5py.File(files[1]) as two:
        assert list(one["stresses"]) == ["00", "01"]
        assert one["stresses/01"].attrs["depth"] == 0.01
        surface = one["stresses/00"]
        # On the surface sigma_zz = -p (compression positive in p, tension positive in sigma).
        assert np.abs(surface["zz"][()] + one["pressure"][()]).max() < 1e-9 * one["pressure"][()].max()
        for depth in ("00", "01"):
            for name in ("xx", "yy", "zz", "xy", "yz", "xz", "von_mises"):
                a, b = one[f"stresses/{depth}/{name}"][()], two[f"stresses/{depth}/{name}"][()]
                assert np.abs(a - b).max() <= 1e-9 * np.abs(a).max()
            von_mises = one[f"stresses/{depth}/von_mises"][()]
            assert one[f"stresses/{depth}"].attrs["max_von_mises"] == von_mises.max()
