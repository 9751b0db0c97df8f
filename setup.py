"""roughpetsc: PETSc-based elastic contact of rough surfaces and statistical contact models."""

from setuptools import find_packages, setup

setup(
    name="roughpetsc",
    version="0.1.0",
    description="Elastic contact of rough surfaces with PETSc/TAO, FFTW and MPI; statistical contact models",
    packages=find_packages(include=["roughpetsc", "roughpetsc.*"]),
    # The presets (-options_file solvers/NAME.opts, options/groupNN.opts) work from any folder of an installed copy.
    package_data={"roughpetsc": ["presets/solvers/*.opts", "presets/options/*.opts", "models/README.md"]},
    python_requires=">=3.9",
    # On Debian these come from apt (tools/bootstrap.sh); elsewhere see README "Install from PyPI sources".
    install_requires=["numpy", "scipy", "petsc4py", "mpi4py", "mpi4py-fft", "pyfftw", "h5py", "matplotlib", "numba"],
    entry_points={"console_scripts": ["roughpetsc=roughpetsc.app.cli:main"]},
)
