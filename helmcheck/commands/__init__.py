"""Command-line subcommands, one module each; :mod:`helmcheck.cli` dispatches to them."""
