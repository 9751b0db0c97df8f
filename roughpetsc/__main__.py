"""``python -m roughpetsc``: see :mod:`roughpetsc.cli`."""

import sys

from .app.terminal import launcher_rank

try:  # importing the modes takes a moment: Ctrl-C then ends in one line too
    from .app.cli import main
except KeyboardInterrupt:
    if launcher_rank() == 0:
        print("roughpetsc: interrupted", file=sys.stderr, flush=True)
    sys.exit(130)

sys.exit(main())
