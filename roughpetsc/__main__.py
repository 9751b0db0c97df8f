"""``python -m roughpetsc``: see :mod:`roughpetsc.cli`."""

import sys

from .cli import main

sys.exit(main())
