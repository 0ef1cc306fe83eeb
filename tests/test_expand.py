"""xacro is code: expansion runs contained (time, memory, process group, daemons, pipes,
secrets), and can be refused outright (--no-exec, URDFKIT_NO_EXEC)."""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.checks.check import check_paths
from urdfkit.cli import app
from urdfkit.core.errors import InputError, ParameterError
from urdfkit.sources.expand import NO_EXEC_ENV, XacroNotExpanded, execution_allowed, expand_xacro

runner = CliRunner()


def xacro_file(tmp_path: Path, expr: str, name: str = "r.urdf.xacro", head: str = "") -> Path:
    """A robot whose link name is the xacro expression ``expr`` (escaped for XML)."""
    text = expr.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
    path = tmp_path / name
    path.write_text(f'<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">{head}'
                    f'<link name="${{{text}}}"/></robot>')
    return path


def shell(command: str) -> str:
    """A xacro expression that escapes xacro's restricted eval to os.system: it walks from a
    running generator's frame up to xacro's module globals. xacro's guard does not stop it;
    urdfkit's containment must hold anyway."""
    return ("[[x['os'].system(" + repr(command) + ") for x in h] for k in [0] if "
            "(h := (h.gi_frame.f_back.f_back.f_back.f_back.f_globals for _ in [1]))][0]")


def alive(pid: int) -> bool:
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    return "State:\tZ" not in status


def test_the_escape_is_real(tmp_path: Path) -> None:
    # Without this, the containment tests below would prove nothing.
    marker = tmp_path / "ran"
    path = xacro_file(tmp_path, shell(f"touch {marker}"))
    expand_xacro(path, timeout=20)
    assert marker.exists()


def test_a_runaway_expansion_is_stopped_quickly(tmp_path: Path) -> None:
    path = xacro_file(tmp_path, "[x for x in python.range(10**12) if x < 0]")
    start = time.monotonic()
    with pytest.raises(InputError, match="longer than 1 s and was stopped"):
        expand_xacro(path, timeout=1.0)
    assert time.monotonic() - start < 4.0


def test_a_background_child_holding_the_output_does_not_delay_us(tmp_path: Path) -> None:
    pidfile = tmp_path / "bg.pid"
    path = xacro_file(tmp_path, shell(f"sleep 30 & echo $! > {pidfile}"))
    start = time.monotonic()
    data = expand_xacro(path, timeout=20)
    assert time.monotonic() - start < 8.0  # not the 20 s timeout, nor the 30 s sleep
    assert b"<robot" in data
    deadline = time.monotonic() + 3
    pid = int(pidfile.read_text())
    while alive(pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not alive(pid)


def test_a_daemonized_grandchild_does_not_outlive_the_expansion(tmp_path: Path) -> None:
    # setsid leaves the worker's process group and session, and the shell that started it
    # exits at once: the sleep is re-parented, as a daemon would be. (xacro reads "$$" itself,
    # so the daemon is found by its unique command line.)
    marker = b"sleep\x0030.4242"
    path = xacro_file(tmp_path, shell("setsid sleep 30.4242 > /dev/null 2>&1 < /dev/null &"))

    def daemons() -> list[int]:
        found = []
        for pid in filter(str.isdigit, os.listdir("/proc")):
            try:
                if Path(f"/proc/{pid}/cmdline").read_bytes().startswith(marker) \
                        and alive(int(pid)):
                    found.append(int(pid))
            except OSError:
                continue
        return found

    assert daemons() == []
    expand_xacro(path, timeout=20)
    deadline = time.monotonic() + 3
    while daemons() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert daemons() == []


def test_memory_is_limited(tmp_path: Path) -> None:
    path = xacro_file(tmp_path, "len([0] * (4 * 1024**3 // 8))")  # a 4 GiB list
    with pytest.raises(InputError, match="xacro failed"):
        expand_xacro(path, timeout=20)


def test_env_values_never_reach_messages(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROBOT_TOKEN", "hunter2-very-secret")
    path = xacro_file(tmp_path, "1 / 0", head='<xacro:property name="t" '
                      'value="$(env ROBOT_TOKEN)"/><link name="${t + t.nope}"/>')
    with pytest.raises(InputError) as e:
        expand_xacro(path, timeout=20)
    assert "hunter2" not in str(e.value)


def test_unknown_arg_names_get_a_suggestion(tmp_path: Path) -> None:
    path = tmp_path / "arm.urdf.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    '<xacro:arg name="wheel_radius" default="1"/>'
                    '<link name="a$(arg wheel_radius)"/></robot>')
    with pytest.raises(ParameterError, match="did you mean 'wheel_radius'"):
        expand_xacro(path, {"wheel_radiu": "2"}, timeout=20)
    code = runner.invoke(app, ["tree", str(path), "--arg", "wheel_radiu:=2"])
    assert code.exit_code == 2 and "--arg: 'wheel_radiu'" in code.stderr
    assert b'name="a2"' in expand_xacro(path, {"wheel_radius": "2"}, timeout=20)


def test_an_empty_arg_keeps_the_default_as_xacros_command_line(tmp_path: Path) -> None:
    """``--arg namespace:=`` is xacro's ``namespace:=``: the file's default, not ""."""
    import shutil
    import subprocess
    import sys

    path = tmp_path / "ns.urdf.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    '<xacro:arg name="namespace" default="dflt_"/>'
                    '<link name="$(arg namespace)base"/></robot>')
    xacro = shutil.which("xacro", path=os.path.dirname(sys.executable)) or shutil.which("xacro")
    assert xacro is not None  # the xacro package urdfkit depends on installs it
    theirs = subprocess.run([xacro, str(path), "namespace:="], capture_output=True, text=True,
                            timeout=60, check=True).stdout
    assert 'name="dflt_base"' in theirs
    assert b'name="dflt_base"' in expand_xacro(path, {"namespace": ""}, timeout=20)
    out = tmp_path / "out.urdf"
    result = runner.invoke(app, ["build", str(path), "-o", str(out), "--arg", "namespace:="])
    assert result.exit_code == 0, result.stderr
    assert 'name="dflt_base"' in out.read_text()
    assert b'name="x_base"' in expand_xacro(path, {"namespace": "x_"}, timeout=20)


# --------------------------------------------------------------------------- no exec


def test_no_exec_refuses_to_run_anything(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    marker = tmp_path / "ran"
    path = xacro_file(tmp_path, shell(f"touch {marker}"))
    assert execution_allowed()
    with pytest.raises(XacroNotExpanded):
        expand_xacro(path, no_exec=True)
    monkeypatch.setenv(NO_EXEC_ENV, "1")
    assert not execution_allowed()
    with pytest.raises(XacroNotExpanded):
        expand_xacro(path)
    result = runner.invoke(app, ["joints", str(path)])
    assert result.exit_code == 2 and "executing xacro is disabled" in result.stderr
    assert not marker.exists()


def test_check_no_exec_reports_each_xacro(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    xacro_file(tmp_path, shell(f"touch {marker}"))
    result = check_paths([tmp_path], no_exec=True, jobs=1)
    (finding,) = result.findings
    assert finding.code == "U006" and finding.level == "warning"
    assert not marker.exists()
    cli = runner.invoke(app, ["check", str(tmp_path), "--no-exec", "--json"])
    assert [f["code"] for f in json.loads(cli.stdout)["findings"]] == ["U006"]
    assert not marker.exists()
    env = runner.invoke(app, ["check", str(tmp_path), "--json"], env={NO_EXEC_ENV: "yes"})
    assert [f["code"] for f in json.loads(env.stdout)["findings"]] == ["U006"]
    assert not marker.exists()
    os.environ.pop(NO_EXEC_ENV, None)


def _raw_xacro_error(top: Path) -> str:
    """What raw xacro (``xacro.process_file``, run from the file's folder) fails with."""
    import xacro

    cwd = os.getcwd()
    os.chdir(top.parent)
    try:
        with pytest.raises(Exception) as raw:
            xacro.process_file(str(top))
    finally:
        os.chdir(cwd)
    return str(raw.value)


def test_an_include_of_a_missing_file_names_it_once_and_its_includer(tmp_path: Path) -> None:
    """Doosan's m1013.urdf.xacro with gripper:=robotiq_2f includes a file one folder off:
    the error said the path twice (xacro's text, then the OSError's) and not which file
    included it. Raw xacro fails on the same path; urdfkit now names it once, with the file
    whose <xacro:include> named it (here one include deep)."""

    ns = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
    top = tmp_path / "top.urdf.xacro"
    top.write_text(f'<robot name="r" {ns}><link name="a"/>'
                   '<xacro:include filename="parts.xacro"/></robot>')
    (tmp_path / "parts.xacro").write_text(f'<robot {ns}><xacro:include filename="gone.xacro"/>'
                                          "</robot>")
    raw = _raw_xacro_error(top)
    assert "gone.xacro" in raw  # raw xacro fails on the same file
    with pytest.raises(InputError) as ours:
        expand_xacro(top, timeout=20)
    message = str(ours.value)
    gone, parts = str(tmp_path / "gone.xacro"), str(tmp_path / "parts.xacro")
    assert message.count("gone.xacro") == 1, message
    assert f"does not exist: {gone} (included by {parts})" in message, message


@pytest.mark.parametrize("where", ["property", "include"])
def test_dirname_is_said_to_fail_as_raw_xacro_fails(tmp_path: Path, where: str) -> None:
    """$(dirname): urdfkit's advice listed it among the substitutions that work without ROS,
    but xacro 2.1.1 never tells its substitutions which file they stand in and refuses it
    everywhere (youBot-style `$(dirname)/...` paths). The refusal now says so and what to
    write instead; the advice no longer lists it."""

    ns = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
    body = ('<xacro:property name="d" value="$(dirname)"/><link name="a"><visual><geometry>'
            '<mesh filename="file://${d}/m.stl"/></geometry></visual></link>'
            if where == "property" else '<link name="a"/>'
            '<xacro:include filename="$(dirname)/parts.xacro"/>')
    top = tmp_path / "top.urdf.xacro"
    top.write_text(f'<robot name="r" {ns}>{body}</robot>')
    (tmp_path / "parts.xacro").write_text(f'<robot {ns}><link name="b"/></robot>')
    raw = _raw_xacro_error(top)
    assert "Cannot substitute $(dirname)" in raw  # raw xacro refuses it too
    r = runner.invoke(app, ["build", str(top), "-o", str(tmp_path / "out.urdf")])
    assert r.exit_code == 2
    assert "$(dirname) does not work" in r.stderr and "$(find PACKAGE)" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    # an unknown substitution's advice lists only what works
    (tmp_path / "u.urdf.xacro").write_text(f'<robot name="r" {ns}><link name="$(pwd)"/></robot>')
    r = runner.invoke(app, ["build", str(tmp_path / "u.urdf.xacro"), "-o",
                            str(tmp_path / "u.urdf")])
    assert r.exit_code == 2 and "$(optenv)" in r.stderr and "$(dirname)" not in r.stderr, r.stderr
def test_a_bare_xacro_macro_is_named_with_its_file_and_line(tmp_path: Path) -> None:
    """Toyota HSR's common.xacro (written for Kinetic) defines `<macro name=... params="joint
    reduction">` without the xacro: prefix. xacro has read only prefixed commands since 1.14
    (Noetic): the bare macro is copied as XML, its `${joint}` evaluated where no `joint`
    exists, and raw xacro fails with "name 'joint' is not defined", naming no file. urdfkit
    fails the same way and now names the file and line of the bare command and the fix."""

    ns = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
    top = tmp_path / "robot.urdf.xacro"
    top.write_text(f'<robot name="r" {ns}>\n<xacro:include filename="common.xacro"/>\n'
                   '<link name="a"/>\n</robot>\n')
    (tmp_path / "common.xacro").write_text(
        f'<robot {ns}>\n  <!-- <macro> in a comment is not one -->\n'
        '  <macro name="transmission" params="joint">\n'
        '    <transmission name="${joint}_transmission"/>\n  </macro>\n</robot>\n')
    raw = _raw_xacro_error(top)
    assert "name 'joint' is not defined" in raw  # raw xacro, and no file named
    assert "common.xacro" not in raw
    with pytest.raises(InputError) as ours:
        expand_xacro(top, timeout=20)
    message = str(ours.value)
    assert "name 'joint' is not defined" in message, message
    assert f"{tmp_path / 'common.xacro'}:3 writes <macro> without the xacro: prefix" in message
    assert "write <xacro:macro>" in message
    fixed = (tmp_path / "common.xacro").read_text().replace("<macro", "<xacro:macro") \
        .replace("</macro>", "</xacro:macro>")
    (tmp_path / "common.xacro").write_text(fixed)
    assert expand_xacro(top, timeout=20)  # the advice, followed, expands


def test_a_property_used_above_its_definition_is_named(tmp_path: Path) -> None:
    """ABB YuMi's yumi.urdf.xacro (OrebroUniversity/yumi) uses ${yumi_parent} on line 16 and
    defines it on line 31, as xacro before in-order reading allowed. Raw xacro fails with
    "name 'yumi_parent' is not defined" and no file; urdfkit now says where it is defined and
    why that is too late, and moving it up (the advice) expands."""

    ns = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
    use = '<link name="${parent}"/>\n'
    define = '<xacro:property name="parent" value="world"/>\n'
    top = tmp_path / "robot.urdf.xacro"
    top.write_text(f'<robot name="r" {ns}>\n{use}{define}</robot>\n')
    raw = _raw_xacro_error(top)
    assert "name 'parent' is not defined" in raw
    assert "robot.urdf.xacro" not in raw
    with pytest.raises(InputError) as ours:
        expand_xacro(top, timeout=20)
    assert f"{top}:3 defines 'parent', but xacro knows a property only below its definition" \
        in str(ours.value), str(ours.value)
    top.write_text(f'<robot name="r" {ns}>\n{define}{use}</robot>\n')
    assert expand_xacro(top, timeout=20)
