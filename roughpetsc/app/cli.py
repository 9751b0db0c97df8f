"""The command line: options database in, a run out.

    mpiexec -n 2 python -m roughpetsc                     # the embedded default problem
    mpiexec -n 2 python -m roughpetsc -tao_type bqnls     # load control: BQNLS in an augmented Lagrangian
    python -m roughpetsc -pstar_list 0.1,0.5,1 -json out.json -output out.h5

Exit status: 0 success, 2 bad input (one message, no output file), 3 a solve did not converge (files flag it),
130 interrupted by Ctrl-C or SIGTERM (the finished steps are written; -resume continues).
"""

from contextlib import contextmanager
import os
import signal
import sys
import traceback

from .. import ensemble
from . import solve_mode, stats_mode
from ..errors import ParameterError, UserError
from .settings import GENERAL_OPTIONS, user_message
from . import models_mode
from .presets import PRESET_FOLDERS, ROOT, preset_names
from .terminal import launcher_rank

# The modes of -mode, in -help order. Each module has OPTIONS (its -help table) and run(options, comm), which
# does the whole mode and returns the exit status, or its result (status 0).
MODES = {"solve": solve_mode, "stats": stats_mode, "models": models_mode, "ensemble": ensemble}


def all_options():
    """``{name: default}`` of every option of roughpetsc (the solvers' too: call it once PETSc is initialised)."""
    from .surface_options import SURFACE_OPTIONS

    table = GENERAL_OPTIONS + SURFACE_OPTIONS + [option for module in MODES.values() for option in module.OPTIONS]
    return {name: default for name, default, _ in table + solve_mode.solver_options()}


def format_help(title, option_table):
    """Lines of -help for a table of ``(name, default, help)``."""
    return "\n".join([title] + [f"  -{name} <{default}>: {text}" for name, default, text in option_table])


def presets_help():
    """The -help block listing the preset files."""
    return "\n".join([f"Presets (-options_file FOLDER/NAME.opts; looked up in the current folder, then in {ROOT}):"]
                     + [f"  {folder}/: " + (" ".join(preset_names(folder)) or "(none installed)")
                        for folder in PRESET_FOLDERS])


def print_help():
    """Our options, the solvers' (each declared by its backend) and the presets."""
    from .surface_options import SURFACE_OPTIONS

    blocks = [format_help("roughpetsc options (python -m roughpetsc [options]; PETSc's options follow):",
                          GENERAL_OPTIONS), format_help("Surface:", SURFACE_OPTIONS)]
    for mode, module in MODES.items():
        blocks.append(format_help(f"Mode {mode}:", module.OPTIONS))
        if module is solve_mode:
            blocks.append(format_help("Solver options (each read by its solver, under its options prefix):",
                                      solve_mode.solver_options()))
            blocks.append(solve_mode.SOLVER_HELP)
    blocks.append(presets_help())
    print("\n\n".join(blocks) + "\n", flush=True)


@contextmanager
def held_output(hold):
    """Hold what is written to file descriptor 1 (C's stdout too) in the block, and print it after our -help.

    PETSc prints its -help while it is initialised, which ours needs (the solvers' tables import PETSc).
    """
    if not hold:
        yield
        return
    import ctypes
    import tempfile

    sys.stdout.flush()
    libc = ctypes.CDLL(None)
    with tempfile.TemporaryFile() as held:
        saved = os.dup(1)
        os.dup2(held.fileno(), 1)
        try:
            yield
        finally:
            libc.fflush(None)
            os.dup2(saved, 1)
            os.close(saved)
            held.seek(0)
            text = held.read()
        print_help()
        sys.stdout.buffer.write(text)
        sys.stdout.flush()


def resolve_presets(argv):
    """``argv`` with each ``-options_file PATH`` not found here resolved against :data:`ROOT`.

    Runs before PETSc reads the files; finds ``solvers/pk.opts`` or the bare ``pk``. Returns ``(argv, message)``:
    a file found nowhere or not an options file is dropped and ``message`` names it (raised once PETSc runs).
    """
    resolved, message = list(argv[:1]), None
    items = iter(argv[1:])
    for item in items:
        if item not in ("-options_file", "--options_file"):
            resolved.append(item)
            continue
        path = next(items, "")
        candidates = [path, os.path.join(ROOT, path)]
        candidates += [os.path.join(ROOT, folder, name) for folder in PRESET_FOLDERS
                       for name in (path, path + ".opts")]
        found = next((c for c in candidates if path and os.path.isfile(c)), None)
        problem = options_file_error(path, found)
        if problem:
            message = message or problem
            continue
        resolved += [item, found]
    return resolved, message


def options_file_error(path, found):
    """Why ``-options_file path`` (found at ``found``, or None) cannot be given to PETSc, or None if it can.

    PETSc dumps an error on a line that is not blank, a ``#`` comment, ``-name [value]`` or ``alias -new -old``.
    """
    if not path:
        return "-options_file: give a file name"
    if found is None:
        return (f"-options_file {path}: no such file (looked in the current folder and in {ROOT}; -help lists the "
                "presets)")
    try:
        with open(found, encoding="utf-8") as handle:
            lines = handle.read().splitlines()
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or "not a text file"
        return f"-options_file {path}: cannot read it as an options file ({reason})"
    for number, line in enumerate(lines, 1):
        words = line.split("#", 1)[0].split()
        if words and not (words[0].startswith("-") or words[0] == "alias"):
            shown = line.strip() if len(line.strip()) <= 60 else line.strip()[:57] + "..."
            return (f"-options_file {path}: line {number} '{shown}' is not an option (an options file holds "
                    "'-name value' lines and # comments)")
    return None


# Measured peak of a solve (studies/output/memory.md): at most 40 doubles per grid point of a rank.
PEAK_BYTES_PER_POINT = 40 * 8


def available_memory():
    """MemAvailable of /proc/meminfo in bytes, or None where there is no such file."""
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def check_memory(reader, comm, mode):
    """Refuse, before anything is allocated, a generated surface too large for this machine's memory.

    :data:`PEAK_BYTES_PER_POINT` per grid point a rank holds, summed over the ranks of this host; surfaces read
    from a file are not estimated.
    """
    from mpi4py import MPI

    from . import surface_options

    if mode not in ("solve", "stats", "ensemble") or reader.getString("surface_file", ""):
        return
    grid = surface_options.grid_from_options(reader)
    share = {"solve": comm.Get_size(), "stats": 1, "ensemble": max(1, reader.getInt("ensemble_group_ranks", 1))}[mode]
    host = comm.Split_type(MPI.COMM_TYPE_SHARED)
    ranks_here = host.Get_size()
    host.Free()
    needed = PEAK_BYTES_PER_POINT * grid.n0 * grid.n1 / share * ranks_here
    available = available_memory()
    if available is not None and needed > available:
        raise UserError(f"-surface_N: a {grid.n0}x{grid.n1} grid needs about {needed / 2**30:.3g} GiB "
                        f"({ranks_here} rank(s) on this machine, {PEAK_BYTES_PER_POINT // 8} doubles per grid "
                        f"point of a rank) but {available / 2**30:.3g} GiB are available; use a smaller grid or "
                        f"more machines")


def hide_unused_petsc_stages():
    """-log_view: hide PETSc's never-used stage PCMPI, which it lists as an empty stage 'Unknown'."""
    from petsc4py import PETSc

    PETSc.Log.Stage("PCMPI").visible = False


def print_version():
    """``-version``: roughpetsc's version, then PETSc's and the rest of the stack's (after PETSc starts)."""
    from .. import __version__
    from ..store.outputs import versions

    found = versions()
    stack = ", ".join(f"{'PETSc' if name == 'petsc' else name} {version}" for name, version in found.items()
                      if name != "roughpetsc")
    print(f"roughpetsc {__version__}\n{stack}", flush=True)


def main(argv=None):
    """The command line: the exit status. Ctrl-C before a mode can keep any work ends in one line (status 130)."""
    try:
        return run_command_line(argv)
    except KeyboardInterrupt:  # while Python or PETSc start, before a mode runs
        if launcher_rank() == 0:
            print("roughpetsc: interrupted", file=sys.stderr, flush=True)
        return 130


def run_command_line(argv=None):
    import petsc4py

    from .terminal import ClosedPipeTolerant

    # Before PETSc starts: it reads the options files, and prints its own -help, as it is initialised.
    argv, preset_error = resolve_presets(sys.argv if argv is None else argv)
    show_help = any(item in ("-help", "--help") for item in argv[1:])
    if show_help:
        # Help piped into `head` ends quietly, not in PETSc's SIGPIPE handler.
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)
        argv = [*argv, "-no_signal_handler"]
    version = any(item in ("-version", "--version") for item in argv[1:])
    if version:  # PETSc's banner would come first and the run go on; our line names both versions instead
        argv = [item for item in argv if item not in ("-version", "--version")]
    with held_output(show_help and launcher_rank() == 0):
        petsc4py.init(argv)
        from petsc4py import PETSc

    hide_unused_petsc_stages()

    from .options import Reader, check_names, check_values_given, translate_renamed_options

    # A reader that closes the pipe early (| head) ends the printing, not the run: no SIGPIPE abort of
    # PETSc's handler, no BrokenPipeError; the files are still written.
    signal.signal(signal.SIGPIPE, signal.SIG_IGN)
    # A batch system's time limit (SIGTERM, also what mpiexec sends its ranks on Ctrl-C) ends a run like
    # Ctrl-C, not in PETSc's handler: the finished work is kept and one line says so.
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    sys.stdout = ClosedPipeTolerant(sys.stdout)
    comm = PETSc.COMM_WORLD.tompi4py()
    reader = Reader()
    try:
        if reader.hasName("help"):
            return 0
        if version:
            if comm.Get_rank() == 0:
                print_version()
            return 0
        if preset_error:
            raise UserError(preset_error)
        translate_renamed_options()
        options = all_options()
        check_names(set(options))
        check_values_given(options)
        reader.getBool("quiet", False)  # every mode's option (read here, so that no mode reports it unused)
        mode = reader.getString("mode", "solve")
        if mode not in MODES:
            raise UserError(f"-mode: unknown mode '{mode}' (one of {', '.join(MODES)})")
        check_memory(reader, comm, mode)
        status = MODES[mode].run(reader, comm)
        return status if type(status) is int else 0
    except (UserError, ParameterError) as error:
        if comm.Get_rank() == 0:
            print(f"roughpetsc: error: {user_message(error)}", file=sys.stderr, flush=True)
        return 2
    except PETSc.Error as error:
        if comm.Get_rank() == 0:
            print(f"roughpetsc: PETSc error: {error}", file=sys.stderr, flush=True)
        return 2
    except KeyboardInterrupt:  # a mode that keeps finished work says so itself; here nothing was kept
        if comm.Get_rank() == 0:
            print("roughpetsc: interrupted", file=sys.stderr, flush=True)
        return 130
    except MemoryError:
        print("roughpetsc: error: out of memory (use a smaller grid or more machines)", file=sys.stderr, flush=True)
        if comm.Get_size() > 1:  # this rank alone may have failed: stop the others rather than leave them waiting
            comm.Abort(2)
        return 2
    except Exception:
        if comm.Get_size() > 1:  # a failure on one rank (a bug): abort the run rather than hang the other ranks
            traceback.print_exc()
            sys.stderr.flush()
            comm.Abort(1)
        raise


if __name__ == "__main__":
    sys.exit(main())
