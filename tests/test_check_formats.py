"""``urdfkit check --format sarif|junit|github``: valid documents, exact escaping, same exits.

SARIF is validated against the official SARIF 2.1.0 JSON schema, vendored as
tests/data/sarif-schema-2.1.0.json: the OASIS errata01 schema ("id":
https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json),
copied byte for byte from github.com/oasis-tcs/sarif-spec, sarif-2.1/schema/, at commit
e0583813964ec43cea53b6b531b402866095ed1f (the tests run without internet). JUnit XML has no
official schema: tests/data/junit.xsd is ours, the core that CI report readers share.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path
from urllib.parse import unquote

import pytest
from lxml import etree
from typer.testing import CliRunner

from urdfkit.checks.check import CheckResult, FileResult
from urdfkit.checks.ci import (
    FORMATS,
    github_commands,
    junit_xml,
    relative_path,
    sarif_log,
    xml_safe,
)
from urdfkit.checks.validate import CODES
from urdfkit.cli import app
from urdfkit.core.finding import Finding

DATA = Path(__file__).parent / "data"
ROOT = Path(__file__).parent.parent
runner = CliRunner()

INERTIAL = ('<inertial><mass value="1"/>'
            '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>')
#: No error, no warning; one note: U607 (file inertia ignored) on line 3.
GOOD = ('<robot name="good">\n<link name="base">\n' + INERTIAL + '\n'
        '<collision><geometry><box size="0.5 0.5 0.5"/></geometry></collision>\n'
        "</link>\n</robot>\n")
#: U102 (duplicate link name, an error) and U606 (no <inertial>, a warning) on line 3.
BAD = '<robot name="bad">\n<link name="a"/>\n<link name="a"/>\n</robot>\n'
#: Not expanded with --no-exec: one U006 warning, with no line.
XACRO = ('<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="x">\n'
         '<xacro:property name="w" value="1"/>\n<link name="a"/>\n</robot>\n')


def invoke(*args: str) -> tuple[int, str, str]:
    r = runner.invoke(app, ["check", *args])
    return r.exit_code, r.stdout, r.stderr


@pytest.fixture
def repo(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A checkout (the current folder) with a good file, a bad one and a xacro file."""
    root = tmp_path / "repo"
    (root / "robots" / "sub").mkdir(parents=True)
    (root / "robots" / "good.urdf").write_text(GOOD)
    (root / "robots" / "sub" / "bad.urdf").write_text(BAD)
    (root / "robots" / "arm.urdf.xacro").write_text(XACRO)
    monkeypatch.chdir(root)
    return root


@pytest.fixture(scope="module")
def sarif_validator() -> object:
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((DATA / "sarif-schema-2.1.0.json").read_text("utf-8"))
    assert schema["id"].endswith("/errata01/os/schemas/sarif-schema-2.1.0.json")
    jsonschema.Draft4Validator.check_schema(schema)
    return jsonschema.Draft4Validator(schema)


def assert_valid_sarif(validator: object, log: object) -> None:
    errors = sorted(validator.iter_errors(log), key=str)  # type: ignore[attr-defined]
    assert not errors, "\n".join(f"{list(e.absolute_path)}: {e.message}" for e in errors)


# --------------------------------------------------------------------------- SARIF


def test_sarif_validates_against_the_official_schema(repo: Path, tmp_path: Path,
                                                      sarif_validator: object) -> None:
    outside = tmp_path / "elsewhere.urdf"  # outside the current folder: an absolute URI
    outside.write_text(BAD)
    code, out, _ = invoke("robots", str(outside), "--no-exec", "--format", "sarif")
    assert code == 1
    log = json.loads(out)
    assert_valid_sarif(sarif_validator, log)
    assert log["version"] == "2.1.0" and "sarif-schema-2.1.0.json" in log["$schema"]
    [run] = log["runs"]
    assert {r["ruleId"] for r in run["results"]} >= {"U102", "U606", "U607", "U006"}


def test_sarif_results_rules_levels_and_lines(repo: Path) -> None:
    code, out, _ = invoke("robots", "--no-exec", "--format", "sarif")
    assert code == 1
    [run] = json.loads(out)["runs"]
    driver = run["tool"]["driver"]
    assert driver["name"] == "urdfkit" and driver["version"]
    rules = driver["rules"]
    assert [r["id"] for r in rules] == sorted({r["ruleId"] for r in run["results"]})
    for rule in rules:
        assert rule["shortDescription"]["text"] == CODES[rule["id"]]
        assert "docs/check.md" in rule["help"]["text"]
    levels = {r["id"]: r["defaultConfiguration"]["level"] for r in rules}
    assert levels["U102"] == "error" and levels["U606"] == "warning"
    assert levels["U607"] == "note" and levels["U006"] == "warning"

    def where(r: dict) -> tuple[str, str, str, int | None]:
        [loc] = r["locations"]
        phys = loc["physicalLocation"]
        assert phys["artifactLocation"]["uriBaseId"] == "%SRCROOT%"
        line = phys["region"]["startLine"] if "region" in phys else None
        assert rules[r["ruleIndex"]]["id"] == r["ruleId"]
        return r["ruleId"], r["level"], phys["artifactLocation"]["uri"], line

    got = {where(r) for r in run["results"]}
    assert ("U102", "error", "robots/sub/bad.urdf", 3) in got
    assert ("U606", "warning", "robots/sub/bad.urdf", 3) in got
    assert ("U607", "note", "robots/good.urdf", 3) in got
    # No line (xacro input): the file is the location, with no region rather than a false one.
    assert ("U006", "warning", "robots/arm.urdf.xacro", None) in got
    duplicate = next(r for r in run["results"] if r["ruleId"] == "U102")
    assert "duplicate link name 'a'" in duplicate["message"]["text"]


def test_sarif_uri_is_relative_forward_slashed_and_percent_encoded(
        repo: Path, sarif_validator: object) -> None:
    name = "odd dir/a #1,é%:b.urdf"
    (repo / "odd dir").mkdir()
    (repo / name).write_text(BAD)
    for given in (name, f"./{name}", str(repo / name)):
        code, out, _ = invoke(given, "--format", "sarif")
        assert code == 1
        log = json.loads(out)
        assert_valid_sarif(sarif_validator, log)
        uris = {r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
                for r in log["runs"][0]["results"]}
        assert uris == {"odd%20dir/a%20%231%2C%C3%A9%25%3Ab.urdf"}, given
        assert unquote(uris.pop()) == name


def test_sarif_outside_the_current_folder_is_an_absolute_file_uri(
        repo: Path, tmp_path: Path, sarif_validator: object) -> None:
    outside = tmp_path / "else where.urdf"
    outside.write_text(BAD)
    log = sarif_log(CheckResult([FileResult(str(outside), [
        Finding("U102", "error", "duplicate", str(outside), 3)])]))
    assert_valid_sarif(sarif_validator, log)
    location = log["runs"][0]["results"][0]["locations"][0]["physicalLocation"]
    assert location["artifactLocation"] == {"uri": outside.absolute().as_uri()}
    assert location["region"] == {"startLine": 3}


def test_sarif_location_is_where_xacro_wrote_the_element(
        repo: Path, sarif_validator: object) -> None:
    f = Finding("U606", "warning", "<link name='a'> has no <inertial>", "robots/arm.urdf.xacro",
                None, "robots/inc/macros.xacro:12")
    log = sarif_log(CheckResult([FileResult(f.file, [f])]))
    assert_valid_sarif(sarif_validator, log)
    [result] = log["runs"][0]["results"]
    assert result["locations"][0]["physicalLocation"] == {
        "artifactLocation": {"uri": "robots/inc/macros.xacro", "uriBaseId": "%SRCROOT%"},
        "region": {"startLine": 12}}
    [related] = result["relatedLocations"]
    assert related["physicalLocation"] == {
        "artifactLocation": {"uri": "robots/arm.urdf.xacro", "uriBaseId": "%SRCROOT%"}}
    assert result["message"]["text"].endswith("(written at robots/inc/macros.xacro:12)")
    # and GitHub annotates that line
    from urdfkit.checks.ci import github_commands

    [command] = github_commands(CheckResult([FileResult(f.file, [f])]))
    assert command.startswith("::warning file=robots/inc/macros.xacro,line=12,title=U606::")


def test_sarif_of_a_clean_run_is_valid_and_empty(repo: Path, sarif_validator: object) -> None:
    code, out, _ = invoke("robots/good.urdf", "--ignore", "U607", "--format", "sarif")
    assert code == 0
    log = json.loads(out)
    assert_valid_sarif(sarif_validator, log)
    assert log["runs"][0]["results"] == [] and log["runs"][0]["tool"]["driver"]["rules"] == []


# --------------------------------------------------------------------------- JUnit


def parse_junit(text: str) -> etree._Element:
    root = etree.fromstring(text.encode("utf-8"))
    schema = etree.XMLSchema(etree.parse(str(DATA / "junit.xsd")))
    assert schema.validate(root), schema.error_log
    return root


def test_junit_one_case_per_file_failures_at_fail_on(repo: Path) -> None:
    code, out, _ = invoke("robots", "--no-exec", "--format", "junit")
    assert code == 1
    assert out.startswith('<?xml version="1.0" encoding="UTF-8"?>\n')
    root = parse_junit(out)
    [suite] = root.findall("testsuite")
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("3", "1", "0")
    assert (root.get("tests"), root.get("failures")) == ("3", "1")
    cases = {c.get("name"): c for c in suite.findall("testcase")}
    assert set(cases) == {"robots/good.urdf", "robots/sub/bad.urdf", "robots/arm.urdf.xacro"}
    assert {c.get("classname") for c in cases.values()} == {"urdfkit.checks.check"}
    [failure] = cases["robots/sub/bad.urdf"].findall("failure")
    assert failure.get("message") == "U102" and failure.get("type") == "U102"
    assert failure.text.splitlines() == [
        "robots/sub/bad.urdf:3: error U102: duplicate link name 'a' (first on line 2); "
        "names must be unique"]
    assert "robots/sub/bad.urdf:3: warning U606:" in cases["robots/sub/bad.urdf"].findtext(
        "system-out")
    assert cases["robots/good.urdf"].find("failure") is None
    assert "info U607" in cases["robots/good.urdf"].findtext("system-out")
    assert cases["robots/arm.urdf.xacro"].find("failure") is None

    code, out, _ = invoke("robots", "--no-exec", "--format", "junit", "--fail-on", "warning")
    assert code == 1
    suite = parse_junit(out).find("testsuite")
    assert (suite.get("tests"), suite.get("failures")) == ("3", "2")
    cases = {c.get("name"): c for c in suite.findall("testcase")}
    failure = cases["robots/sub/bad.urdf"].find("failure")
    assert failure.get("message") == "U102, U606" and failure.get("type") == "U102"
    assert len(failure.text.splitlines()) == 2
    assert cases["robots/arm.urdf.xacro"].find("failure").get("type") == "U006"


def test_junit_is_well_formed_whatever_the_names(repo: Path) -> None:
    folder = repo / "odd"
    folder.mkdir()
    names = []
    for name in ['a<&"\'é.urdf', "ロボット>.urdf", "ctl\x01.urdf", os.fsdecode(b"bad\xff.urdf")]:
        try:
            (folder / name).write_text(BAD)
        except (OSError, UnicodeEncodeError):  # a file system that refuses the name
            continue
        names.append(name)
    code, out, _ = invoke("odd", "--format", "junit")
    assert code == 1
    suite = parse_junit(out).find("testsuite")
    assert suite.get("tests") == suite.get("failures") == str(len(names))
    got = {c.get("name") for c in suite.findall("testcase")}
    assert got == {xml_safe(f"odd/{n}") for n in names}
    assert 'odd/a<&"\'é.urdf' in got and "odd/ロボット>.urdf" in got
    assert "odd/ctl\\x01.urdf" in got  # XML cannot hold U+0001 even escaped: spelled out


def test_junit_messages_with_markup_and_control_characters() -> None:
    f = Finding("U102", "error", "name '<a&b>' \"quoted\"\x1b[31m\nnext line", "r.urdf", 3)
    root = parse_junit(junit_xml(CheckResult([FileResult("r.urdf", [f])])))
    failure = root.find("testsuite/testcase/failure")
    assert failure.text == "r.urdf:3: error U102: name '<a&b>' \"quoted\"\\x1b[31m\nnext line\n"


def test_xml_safe_keeps_what_xml_holds() -> None:
    assert xml_safe("tab\tnl\ncr\ré<>&\U0001f916") == "tab\tnl\ncr\ré<>&\U0001f916"
    assert xml_safe("\x00\x1f\ud800\ufffe") == "\\x00\\x1f\\ud800\\ufffe"


# --------------------------------------------------------------------------- github


def test_github_commands_escape_data_and_properties() -> None:
    file = "dir/a,b:c%d.urdf"
    result = CheckResult([FileResult(file, [
        Finding("U102", "error", "100% bad,\r\nreally: yes", file, 3),
        Finding("U606", "warning", "a::b", file, 4),
        Finding("U607", "info", "note, 50%", file, None),
    ])])
    assert github_commands(result) == [
        "::error file=dir/a%2Cb%3Ac%25d.urdf,line=3,title=U102::100%25 bad,%0D%0Areally: yes",
        "::warning file=dir/a%2Cb%3Ac%25d.urdf,line=4,title=U606::a::b",
        "::notice file=dir/a%2Cb%3Ac%25d.urdf,title=U607::note, 50%25",
    ]


def test_github_format_on_a_tricky_file_name(repo: Path) -> None:
    (repo / "robots" / "we,ird:50%.urdf").write_text(BAD)
    code, out, _ = invoke("robots/we,ird:50%.urdf", "robots/good.urdf", "--format", "github")
    assert code == 1
    assert out.splitlines() == [
        "::error file=robots/we%2Cird%3A50%25.urdf,line=3,title=U102::duplicate link name 'a' "
        "(first on line 2); names must be unique",
        "::warning file=robots/we%2Cird%3A50%25.urdf,line=3,title=U606::<link name='a'> has no "
        "<inertial>; PyBullet silently gives it 1 kg and unit inertia: add <inertial> with its "
        "real mass (mass 0 would fix the robot in place)",
        "::notice file=robots/good.urdf,line=3,title=U607::PyBullet ignores <inertia> from the "
        "file and recomputes it from the collision shapes unless loaded with "
        "URDF_USE_INERTIA_FROM_FILE (urdfkit: --inertia-from-file)",
    ]


def test_github_format_without_a_line(repo: Path) -> None:
    code, out, _ = invoke("robots/arm.urdf.xacro", "--no-exec", "--format", "github")
    assert code == 0
    [line] = out.splitlines()
    assert line.startswith("::warning file=robots/arm.urdf.xacro,title=U006::not expanded")


def test_relative_path() -> None:
    cwd = os.getcwd()
    assert relative_path(os.path.join(cwd, "a", "b.urdf")) == "a/b.urdf"
    assert relative_path("./a/../b.urdf") == "b.urdf"
    assert relative_path("../b.urdf") is None
    assert relative_path(os.path.dirname(cwd) + os.sep + "x.urdf") is None


# --------------------------------------------------------------------------- the CLI


@pytest.mark.parametrize("fmt", FORMATS)
def test_exit_codes_do_not_depend_on_the_format(repo: Path, fmt: str) -> None:
    assert invoke("robots/good.urdf", "--format", fmt)[0] == 0
    assert invoke("robots/good.urdf", "--format", fmt, "--fail-on", "info")[0] == 1
    assert invoke("robots/sub/bad.urdf", "--format", fmt)[0] == 1
    assert invoke("robots/sub/bad.urdf", "--format", fmt, "--ignore", "U1")[0] == 0
    assert invoke("robots/sub/bad.urdf", "--format", fmt, "--ignore", "U1",
                  "--fail-on", "warning")[0] == 1
    code, out, err = invoke("robots/missing.urdf", "--format", fmt)
    assert code == 2 and "missing.urdf" in err and out == ""


def test_json_flag_is_format_json(repo: Path) -> None:
    plain = invoke("robots", "--json")
    assert plain == invoke("robots", "--format", "json")
    assert plain == invoke("robots", "--json", "--format", "json")
    assert json.loads(plain[1])["summary"]["error"] == 1


@pytest.mark.parametrize("fmt", ["text", "sarif", "junit", "github"])
def test_json_with_another_format_is_a_usage_error(repo: Path, fmt: str) -> None:
    code, out, err = invoke("robots", "--json", "--format", fmt)
    assert code == 2 and out == ""
    assert "--json" in err and f"--format {fmt}" in err


def test_unknown_format_is_a_usage_error(repo: Path) -> None:
    code, out, err = invoke("robots", "--format", "sarf")
    assert code == 2 and out == ""
    assert "--format" in err and "'sarif'" in err


@pytest.mark.parametrize("fmt", ["sarif", "junit", "github"])
def test_ci_formats_are_never_styled(repo: Path, fmt: str,
                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("FORCE_COLOR", "1")
    code, out, _ = invoke("robots", "--no-exec", "--format", fmt)
    assert code == 1 and "\x1b" not in out
    if fmt == "sarif":
        json.loads(out)
    elif fmt == "junit":
        parse_junit(out)
    else:
        assert all(re.match(r"::(error|warning|notice) file=", line) for line in out.splitlines())


def test_sarif_format_needs_no_rich(repo: Path) -> None:
    probe = ("import sys\nfrom urdfkit.cli import main\nsys.argv = ['urdfkit', *sys.argv[1:]]\n"
             "try:\n    main()\nexcept SystemExit as e:\n    code = e.code\n"
             "sys.stderr.write(f'EXIT:{code} RICH:{\"rich\" in sys.modules}')\n")
    proc = subprocess.run([sys.executable, "-c", probe, "check", "robots", "--format", "sarif"],
                          capture_output=True, text=True, timeout=60,
                          env={**os.environ, "FORCE_COLOR": "1"})
    assert "EXIT:1 RICH:False" in proc.stderr, proc.stderr
    assert json.loads(proc.stdout)["version"] == "2.1.0"


# --------------------------------------------------------------------------- pre-commit, docs


def test_pre_commit_hook() -> None:
    yaml = pytest.importorskip("yaml")
    [hook] = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text("utf-8"))
    assert hook["id"] == "urdfkit-check" and hook["entry"] == "urdfkit check"
    assert hook["language"] == "python" and hook["pass_filenames"] is True
    files = re.compile(hook["files"])
    for name in ("robot.urdf", "d/arm.urdf.xacro", "macros.xacro"):
        assert files.search(name), name
    for name in ("robot.urdf.bak", "notes.txt", "urdf/README.md"):
        assert not files.search(name), name


def test_docs_show_every_format_and_the_ci_recipes() -> None:
    text = (ROOT / "docs" / "check.md").read_text("utf-8")
    assert "--format " + "|".join(FORMATS) in text
    for needle in ("--format sarif > urdfkit.sarif", "github/codeql-action/upload-sarif",
                   "--format github", "--format junit", "id: urdfkit-check"):
        assert needle in text, needle
