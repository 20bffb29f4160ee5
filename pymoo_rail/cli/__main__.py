"""``python -m pymoo_rail.cli``: the ``pymoo-rail`` command."""

import sys

from pymoo_rail.cli.app import main

if __name__ == "__main__":  # imported (e.g. by pkgutil.walk_packages), it runs nothing
    sys.exit(main())
