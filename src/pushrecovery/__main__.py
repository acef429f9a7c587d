"""``python -m pushrecovery`` runs the command-line interface."""

from pushrecovery.cli import main

main()
