"""The subcommands of ``pymoo-rail``, one module each (see :mod:`pymoo_rail.cli.parser`)."""
