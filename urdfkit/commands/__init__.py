"""The commands of the ``urdfkit`` CLI, one module per command or group (see urdfkit/cli.py).

Imports nothing: urdfkit.cli imports only the module of the command being run.
"""
