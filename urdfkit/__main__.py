"""``python -m urdfkit`` runs the command-line tool."""

from urdfkit.entry import main

main()
