"""``python -m urdfkit`` runs the command-line tool."""

from urdfkit.cli import main

main()
