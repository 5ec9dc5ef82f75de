"""``python -m hinfnav``: see :mod:`hinfnav.cli`."""

import sys

from .cli import main

sys.exit(main())
