"""``urdfkit check --format sarif|junit|github``: findings in the shapes CI systems read.

Each function turns a :class:`urdfkit.checks.check.CheckResult` into a document and returns it;
:func:`urdfkit.commands.present.check_formatted` writes it. Nothing here prints, styles or
imports rich: these formats go to files and logs, and must parse whatever the terminal.

- SARIF 2.1.0, for GitHub code scanning (``github/codeql-action/upload-sarif``) and other
  SARIF viewers.
- JUnit XML, one test case per file checked, for the test-report views of GitLab, Jenkins,
  Azure Pipelines and the like.
- GitHub Actions workflow commands (``::error file=...,line=...::``), which annotate a pull
  request straight from the log, with no upload step.

Paths are written as the user's current folder sees them (CI runs from the checkout's root),
with forward slashes, so the same file gets the same path on every runner.
"""

from __future__ import annotations

import os
import re
from typing import TYPE_CHECKING, Any, Literal

from urdfkit import __version__
from urdfkit.core.finding import LEVELS, Level

if TYPE_CHECKING:
    from urdfkit.checks.check import CheckResult

#: Every ``check --format``.
CheckFormat = Literal["text", "json", "sarif", "junit", "github"]
FORMATS: tuple[CheckFormat, ...] = ("text", "json", "sarif", "junit", "github")

SARIF_VERSION = "2.1.0"
SARIF_SCHEMA = ("https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/"
                "sarif-schema-2.1.0.json")
#: SARIF calls an info finding a ``note``.
SARIF_LEVEL = {"error": "error", "warning": "warning", "info": "note"}
#: The workflow command of each level (GitHub calls an info finding a ``notice``).
GITHUB_COMMAND = {"error": "error", "warning": "warning", "info": "notice"}


# --------------------------------------------------------------------------- paths



def _codes() -> dict[str, str]:
    """Every rule code and its title (the rules module, loaded only for SARIF's rule list)."""
    from urdfkit.checks.validate import CODES

    return CODES

def relative_path(file: str) -> str | None:
    """``file`` relative to the current folder, with ``/`` separators; None outside it.

    ``robots/./a.urdf`` and ``/checkout/robots/a.urdf`` (run in ``/checkout``) are both
    ``robots/a.urdf``: GitHub matches a result to a file of the repository by this path.
    """
    path = os.path.normpath(file)
    if os.path.isabs(path):
        try:
            path = os.path.relpath(path)
        except ValueError:  # Windows: another drive
            return None
    if path == os.pardir or path.startswith(os.pardir + os.sep):
        return None
    return path.replace(os.sep, "/")


def artifact_location(file: str) -> dict[str, str]:
    """A SARIF ``artifactLocation``: relative to ``%SRCROOT%`` when below it, else absolute.

    The URI is percent-encoded from the file name's bytes, so spaces, ``#``, ``:`` and names
    that are not UTF-8 still make a valid URI reference.
    """
    from urllib.parse import quote  # here: check --json imports this module for FORMATS only

    rel = relative_path(file)
    if rel is not None:
        return {"uri": quote(os.fsencode(rel), safe="/"), "uriBaseId": "%SRCROOT%"}
    absolute = os.path.abspath(file).replace(os.sep, "/")
    if not absolute.startswith("/"):
        absolute = "/" + absolute  # C:/x -> file:///C:/x
    return {"uri": "file://" + quote(os.fsencode(absolute), safe="/:")}


# --------------------------------------------------------------------------- SARIF


def _physical(file: str, line: int | None) -> dict[str, Any]:
    where: dict[str, Any] = {"artifactLocation": artifact_location(file)}
    if line is not None and line >= 1:  # SARIF: startLine >= 1; no region rather than a lie
        where["region"] = {"startLine": line}
    return {"physicalLocation": where}


def _origin(origin: str | None) -> tuple[str, int | None] | None:
    """``path:line`` (a finding's xacro origin) split; None if there is none."""
    if not origin:
        return None
    path, sep, line = origin.rpartition(":")
    if sep and path and line.isdigit():
        return path, int(line)
    return origin, None


def sarif_log(result: CheckResult) -> dict[str, Any]:
    """``result`` as one SARIF 2.1.0 log with one run.

    ``rules`` lists the codes found in this run, each with its summary from
    :data:`urdfkit.checks.validate.CODES`. A rule's ``defaultConfiguration.level`` is the most
    severe level it was reported at (a few codes, such as U611, are a warning or a note
    depending on the model); every result carries its own level as well.

    Every result has a location, because GitHub shows nothing without one: the file checked,
    and its line when known. A xacro finding's location is where xacro says the element was
    written (the file and line to edit, which code scanning then marks), and the file checked
    is its ``relatedLocation``. Any other finding without a line (a file that cannot be read)
    points at the whole file, with no ``region``: SARIF has no line 0, and line 1 would be a
    guess.
    """
    findings = result.findings
    worst: dict[str, str] = {}
    for f in findings:
        seen = worst.get(f.code)
        if seen is None or LEVELS.index(f.level) > LEVELS.index(seen):
            worst[f.code] = f.level
    codes = sorted(worst)
    index = {code: i for i, code in enumerate(codes)}
    rules = [{"id": code,
              "shortDescription": {"text": _codes().get(code, code)},
              "help": {"text": "See docs/check.md, section Rules, in the urdfkit "
                               "repository."},
              "defaultConfiguration": {"level": SARIF_LEVEL[worst[code]]}}
             for code in codes]
    results = []
    for f in findings:
        entry: dict[str, Any] = {"ruleId": f.code, "ruleIndex": index[f.code],
                                 "level": SARIF_LEVEL[f.level], "message": {"text": f.text},
                                 "locations": [_physical(f.file, f.line)]}
        origin = _origin(f.origin)
        if origin is not None and f.line is None:
            entry["locations"] = [_physical(*origin)]
            entry["relatedLocations"] = [{"id": 0, "message": {"text": "checked through "
                                                               "this file"},
                                          **_physical(f.file, None)}]
        elif origin is not None:
            entry["relatedLocations"] = [{"id": 0, "message": {"text": "written here"},
                                          **_physical(*origin)}]
        results.append(entry)
    driver = {"name": "urdfkit", "version": __version__, "semanticVersion": __version__,
              "rules": rules}
    return {"$schema": SARIF_SCHEMA, "version": SARIF_VERSION,
            "runs": [{"tool": {"driver": driver}, "results": results}]}


# --------------------------------------------------------------------------- JUnit

#: What XML 1.0 cannot hold at all, even escaped: control characters, lone surrogates (a
#: file name that is not UTF-8), U+FFFE and U+FFFF. Compiled on first use (re keeps it):
#: the class costs ~2.5 ms to compile, which every ``check`` would pay for ``FORMATS``.
_NOT_XML = "[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]"


def xml_safe(text: str) -> str:
    r"""``text`` with the characters XML cannot hold written as ``\xNN`` or ``\uNNNN``."""
    def escape(m: re.Match[str]) -> str:
        code = ord(m.group())
        return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"

    return re.sub(_NOT_XML, escape, text)


def junit_xml(result: CheckResult, fail_on: Level = "error") -> str:
    """``result`` as a JUnit XML document: one ``<testcase>`` per file checked.

    A file fails when it has findings at or above ``fail_on``, exactly the files that make
    ``check`` exit 1: its ``<failure>`` has the failing codes as ``message`` (the first as
    ``type``) and lists those findings, ``file:line: level CODE: message``, one a line.
    Findings below ``fail_on`` are listed in the case's ``<system-out>``.
    """
    import xml.etree.ElementTree as ET

    threshold = LEVELS.index(fail_on)
    name = "urdfkit check"
    suites = ET.Element("testsuites", name=name)
    suite = ET.SubElement(suites, "testsuite", name=name)
    failed = 0
    for fr in result.files:
        shown = relative_path(fr.file) or fr.file  # `check .`: robots/a.urdf, as SARIF
        case = ET.SubElement(suite, "testcase", classname="urdfkit.checks.check",
                             name=xml_safe(shown), file=xml_safe(shown))
        failing = [f for f in fr.findings if LEVELS.index(f.level) >= threshold]
        others = [f for f in fr.findings if LEVELS.index(f.level) < threshold]
        if failing:
            failed += 1
            codes = list(dict.fromkeys(f.code for f in failing))
            failure = ET.SubElement(case, "failure", message=", ".join(codes), type=codes[0])
            failure.text = xml_safe("\n".join(str(f) for f in failing)) + "\n"
        if others:
            ET.SubElement(case, "system-out").text = xml_safe(
                "\n".join(str(f) for f in others)) + "\n"
    counts = {"tests": str(len(result.files)), "failures": str(failed), "errors": "0",
              "skipped": "0"}
    suite.attrib.update(counts)
    suites.attrib.update({k: v for k, v in counts.items() if k != "skipped"})
    ET.indent(suites)
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            + ET.tostring(suites, encoding="unicode") + "\n")


# --------------------------------------------------------------------------- GitHub


def _command_data(text: str) -> str:
    # GitHub's escaping of a workflow command's message (actions/toolkit, command.ts).
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _command_property(text: str) -> str:
    return _command_data(text).replace(":", "%3A").replace(",", "%2C")


def github_commands(result: CheckResult) -> list[str]:
    """One GitHub Actions workflow command per finding, in file order.

    ``::error file=robots/a.urdf,line=12,title=U102::duplicate link name 'b' ...``, and
    ``::warning`` and ``::notice`` for warnings and info. A xacro finding annotates where
    xacro says the element was written (its file and line). Any other finding without a line
    has no ``line=``: GitHub annotates the file. A file outside the current folder keeps its
    path as given (the log shows it; GitHub cannot place it in the pull request).
    """
    out = []
    for f in result.findings:
        file, line = f.file, f.line
        origin = _origin(f.origin)
        if origin is not None and line is None:
            file, line = origin
        props = [f"file={_command_property(relative_path(file) or file)}"]
        if line is not None:
            props.append(f"line={line}")
        props.append(f"title={_command_property(f.code)}")
        out.append(f"::{GITHUB_COMMAND[f.level]} {','.join(props)}::{_command_data(f.text)}")
    return out
