"""Library parameter names shown as the command-line flags that feed them.

No typer here: ``urdfkit check``'s fast start (:mod:`urdfkit.commands.check_run`) reports its
errors with these too.
"""

import re

#: Library parameter -> the flag that feeds it, for messages (`time_step` -> --time-step).
#: A parameter not listed maps to ``--`` plus its name with dashes.
FLAGS = {
    "params": "--set", "template_params": "--set", "xacro_args": "--arg",
    "packages": "--package", "package_paths": "--package-path", "types": "--type",
    "urdf": "--urdf", "force=True": "--force",
    "force": "--force", "joints": "--joints", "views": "--views", "guard=False": "--no-guard",
    "kind": "KIND",
}


def flag_message(message: str) -> str:
    """A library message with its backquoted parameter names shown as CLI flags."""
    return re.sub(r"`([A-Za-z_][\w]*(?:=True|=False)?)`",
                  lambda m: FLAGS.get(m.group(1), "--" + m.group(1).replace("_", "-")),
                  message)


#: Parameters every loading command takes from the same flags: their names are translated in
#: any message (a xacro or package error deep in a load, a check finding), not only in errors
#: about a parameter. None of them is ever a scenario key.
INPUT_PARAMS = ("xacro_args", "packages", "package_paths")


def input_flags(message: str) -> str:
    """A message with the input parameters (``xacro_args``) shown as their flags (``--arg``)."""
    return re.sub(r"`(" + "|".join(INPUT_PARAMS) + r")`", lambda m: FLAGS[m.group(1)], message)
