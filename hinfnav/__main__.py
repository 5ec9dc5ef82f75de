"""``python -m hinfnav``: see :mod:`hinfnav.cli`."""

import sys

try:
    from .cli import main

    status = main()
except KeyboardInterrupt:  # Ctrl-C outside a command (while importing, or while a cluster closes): one line too
    print("interrupted (Ctrl-C): stopped; nothing half-written is left (a campaign keeps its finished cells: run it again to resume)", file=sys.stderr)
    status = 130
sys.exit(status)
