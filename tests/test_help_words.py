"""Every command's --help keeps its words whole, piped and on a terminal (issue 49, item 7).

`drive --help` piped at 80 columns printed `differential|rear|locke` and `d` on two lines:
typer's rich option table cuts a word wider than its column. Each help is checked token by
token against the command's own help strings (its docstring, examples, every option's names,
metavar and text): a token that is not one of their words is a word cut in two.
"""

from __future__ import annotations

import os
import pty
import subprocess
import sys
from typing import Any

import pytest
import typer
from typer.testing import CliRunner

from urdfkit.cli import COMMANDS, app
from urdfkit.commands.helptext import unmarked

#: What the layout itself writes.
LAYOUT = {"Usage:", "Arguments:", "Options:", "Commands:", "Examples", "$"}


def _words(name: str | None) -> set[str]:
    """Every whitespace-separated word of a command's help strings, as the help shows them."""
    group: Any = typer.main.get_command(app)
    ctx = group.context_class(group, info_name="urdfkit", **group.context_settings)
    command = group
    if name is not None:  # its context under the group's, as when run (-h comes from there)
        command = group.commands[name]
        ctx = command.context_class(command, info_name=name, parent=ctx)
    ctx.ensure_object(dict)
    ctx.obj["TYPER_RICH_MARKUP_MODE"] = None
    text = [command.help or "", command.epilog or "", *command.collect_usage_pieces(ctx)]
    for param in command.get_params(ctx):
        record = param.get_help_record(ctx)
        if record is not None:
            text += list(record)
    for key, sub in getattr(command, "commands", {}).items():
        text += [key, sub.get_short_help_str(10_000)]
    return set(unmarked(" ".join(text)).split()) | LAYOUT


def _cut_words(out: str, name: str | None) -> list[str]:
    usage, _, rest = out.partition("\n")
    assert usage.startswith("Usage: "), usage
    words = _words(name)
    return [w for w in rest.split() if w not in words]


@pytest.mark.parametrize("name", [None, *COMMANDS])
@pytest.mark.parametrize("columns", ["80", "60", "200"])
def test_every_help_keeps_its_words_whole(name: str | None, columns: str) -> None:
    args = [name, "--help"] if name else ["--help"]
    result = CliRunner().invoke(app, args, env={"COLUMNS": columns})
    assert result.exit_code == 0, result.stderr
    assert _cut_words(result.stdout, name) == [], result.stdout
    if name is not None:  # every option is there, whole
        assert all(f"--{p}" in result.stdout for p in ("help",))


def test_drive_help_piped_at_80_columns() -> None:
    # As the issue ran it: `COLUMNS=80 urdfkit drive --help | cat`.
    done = subprocess.run([sys.executable, "-m", "urdfkit", "drive", "--help"],
                          capture_output=True, text=True, timeout=60,
                          env={**os.environ, "COLUMNS": "80"})
    assert done.returncode == 0, done.stderr
    assert "--drivetrain differential|rear|locked" in done.stdout
    assert _cut_words(done.stdout, "drive") == []
    long = [line for line in done.stdout.splitlines() if len(line) > 80]
    assert all(line.startswith("  $ urdfkit") for line in long), long  # only examples run on


def test_drive_help_on_an_80_column_terminal() -> None:
    leader, follower = pty.openpty()
    proc = subprocess.Popen([sys.executable, "-m", "urdfkit", "drive", "--help"],
                            stdout=follower, stderr=subprocess.DEVNULL,
                            env={**os.environ, "COLUMNS": "80"})
    os.close(follower)
    seen = b""
    try:
        while True:
            try:
                chunk = os.read(leader, 65536)
            except OSError:  # the child closed the terminal
                break
            if not chunk:
                break
            seen += chunk
        proc.wait(timeout=60)
    finally:
        os.close(leader)
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    text = seen.decode().replace("\r\n", "\n").replace("\x1b[1m", "").replace("\x1b[0m", "")
    assert "\x1b[" not in text.partition("Options:")[2]  # only the headings are styled
    assert _cut_words(text, "drive") == [], text
