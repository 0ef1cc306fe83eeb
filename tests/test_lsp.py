"""`urdfkit lsp`, driven as an editor drives it (pytest-lsp over stdio).

Diagnostics are held to the lines of the text the editor has (and to the included file a
xacro finding was written in), hovers to raw PyBullet's joint and link tables, the fix code
action to `urdfkit fix`'s own output, byte for byte; a half-typed file, a xacro that will not
finish and 1,000 edits sent at once leave the server answering, with the newest text's
diagnostics last.
"""

from __future__ import annotations

import asyncio
import subprocess
import sys
from pathlib import Path

import pybullet as p
import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import ClientServerConfig, LanguageClient

BAD = """<?xml version="1.0"?>
<robot name="bad">
  <link name="base">
    <inertial>
      <mass value="2"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>
    </inertial>
    <colision>
      <geometry><box size="0.2 0.2 0.2"/></geometry>
    </colision>
    <collision>
      <geometry><box size="0.2 0.2 0.2"/></geometry>
    </collision>
  </link>
  <link name="arm">
    <inertial>
      <mass value="0.5"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial>
  </link>
  <joint name="elbow" type="revolute">
    <parent link="base"/>
    <child link="arm"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="7" velocity="2"/>
  </joint>
</robot>
"""

PARTS = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="arm_mass" value="0.5"/>
  <xacro:macro name="arm_link" params="name">
    <link name="${name}">
      <inertial>
        <mass value="${arm_mass}"/>
        <inertia ixx="1" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
      </inertial>
    </link>
  </xacro:macro>
</robot>
"""

MAIN = """<?xml version="1.0"?>
<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="parts.xacro"/>
  <xacro:property name="reach" value="0.4"/>
  <link name="base">
    <inertial><mass value="1"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <visul><geometry><box size="0.1 0.1 0.1"/></geometry></visul>
  </link>
  <xacro:arm_link name="arm"/>
  <joint name="j" type="revolute">
    <parent link="base"/>
    <child link="arm"/>
    <origin xyz="0 0 ${reach}"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>
"""


def _line(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(text.splitlines()) if needle in line)


@pytest_lsp.fixture(config=ClientServerConfig(
    server_command=[sys.executable, "-m", "urdfkit", "lsp"]))
async def client(lsp_client: LanguageClient) -> object:
    published: dict[str, int | None] = {}
    lsp_client.published = published  # type: ignore[attr-defined]

    # pytest-lsp keeps each document's diagnostics, not the version they were for: kept too
    features = lsp_client.protocol.fm.features
    keep = features[lsp.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS]

    def diagnostics(params: lsp.PublishDiagnosticsParams) -> object:
        published[params.uri] = params.version
        return keep(params)

    features[lsp.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS] = diagnostics

    await lsp_client.initialize_session(lsp.InitializeParams(
        capabilities=lsp.ClientCapabilities(), initialization_options={"xacroTimeout": 3}))
    yield
    await lsp_client.shutdown_session()


async def _open(client: LanguageClient, path: Path, text: str | None = None) -> str:
    uri = path.as_uri()
    client.text_document_did_open(lsp.DidOpenTextDocumentParams(lsp.TextDocumentItem(
        uri, "xml", 1, path.read_text() if text is None else text)))
    await _settled(client, uri)
    return uri


async def _settled(client: LanguageClient, uri: str, version: int | None = None) -> None:
    """Wait for the document's diagnostics (of ``version``, when given)."""
    published = client.published  # type: ignore[attr-defined]

    async def wait() -> None:
        while uri not in published or (version is not None and published[uri] != version):
            await asyncio.sleep(0.02)
    await asyncio.wait_for(wait(), 60)


def _rss(client: LanguageClient) -> int:
    """The server process's resident memory, bytes."""
    pid = client._server.pid  # type: ignore[union-attr]
    status = Path(f"/proc/{pid}/status").read_text()
    return int(next(ln.split()[1] for ln in status.splitlines()
                    if ln.startswith("VmRSS:"))) * 1024


def _codes(client: LanguageClient, uri: str) -> dict[str, int]:
    return {str(d.code): d.range.start.line for d in client.diagnostics[uri]}


@pytest.mark.asyncio
async def test_diagnostics_are_checks_at_the_lines_written(client: LanguageClient,
                                                           tmp_path: Path) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text(BAD)
    uri = await _open(client, path)
    codes = _codes(client, uri)
    assert codes["U801"] == _line(BAD, "<colision>")
    assert codes["U604"] == _line(BAD, 'ixx="1"')
    d = next(d for d in client.diagnostics[uri] if d.code == "U604")
    assert d.severity == lsp.DiagnosticSeverity.Error and d.source == "urdfkit"
    # the same findings as `urdfkit check` on the file
    out = subprocess.run([sys.executable, "-m", "urdfkit", "check", str(path), "--json"],
                         capture_output=True, text=True, check=False)
    import json

    assert {(f["code"], f["line"] - 1) for f in json.loads(out.stdout)["findings"]} == \
        {(str(d.code), d.range.start.line) for d in client.diagnostics[uri]}


@pytest.mark.asyncio
async def test_a_xacro_finding_is_published_to_the_file_it_was_written_in(
        client: LanguageClient, tmp_path: Path) -> None:
    (tmp_path / "parts.xacro").write_text(PARTS)
    main = tmp_path / "robot.urdf.xacro"
    main.write_text(MAIN)
    uri = await _open(client, main)
    assert _codes(client, uri)["U801"] == _line(MAIN, "<visul>")
    parts = (tmp_path / "parts.xacro").as_uri()
    for _ in range(5):
        if parts in client.diagnostics:
            break
        await asyncio.sleep(0.2)
    assert _codes(client, parts)["U604"] == _line(PARTS, 'ixx="1"')
    # an unsaved edit is what is checked: the misspelling mended in the buffer only
    client.text_document_did_change(lsp.DidChangeTextDocumentParams(
        lsp.VersionedTextDocumentIdentifier(uri=uri, version=2),
        [lsp.TextDocumentContentChangeWholeDocument(text=MAIN.replace("visul", "visual"))]))
    await _settled(client, uri, 2)
    assert "U801" not in _codes(client, uri)
    assert main.read_text() == MAIN


@pytest.mark.asyncio
async def test_hover_is_what_pybullet_loads(client: LanguageClient, tmp_path: Path) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text(BAD)
    uri = await _open(client, path)
    line = _line(BAD, '<child link="arm"/>')
    column = BAD.splitlines()[line].index('"arm"') + 2
    hover = await client.text_document_hover_async(lsp.HoverParams(
        lsp.TextDocumentIdentifier(uri), lsp.Position(line, column)))
    line_j = _line(BAD, '<joint name="elbow"')
    joint = await client.text_document_hover_async(lsp.HoverParams(
        lsp.TextDocumentIdentifier(uri), lsp.Position(line_j, BAD.splitlines()[line_j]
                                                      .index("elbow") + 1)))
    client_id = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(path), flags=p.URDF_USE_INERTIA_FROM_FILE,
                          physicsClientId=client_id)
        info = p.getJointInfo(body, 0, physicsClientId=client_id)
        mass = p.getDynamicsInfo(body, 0, physicsClientId=client_id)[0]
    finally:
        p.disconnect(client_id)
    assert hover is not None and joint is not None
    assert info[12].decode() == "arm" and f"PyBullet index {info[0]}" in hover.contents.value
    assert f"mass {mass:g} kg" in hover.contents.value
    assert info[1].decode() == "elbow" and f"PyBullet index {info[0]}" in joint.contents.value
    assert f"limits {info[8]:g} .. {info[9]:g}" in joint.contents.value


@pytest.mark.asyncio
async def test_definition_references_completion_and_outline(client: LanguageClient,
                                                            tmp_path: Path) -> None:
    (tmp_path / "parts.xacro").write_text(PARTS)
    main = tmp_path / "robot.urdf.xacro"
    main.write_text(MAIN)
    uri = await _open(client, main)
    doc = lsp.TextDocumentIdentifier(uri)
    lines = MAIN.splitlines()
    at = _line(MAIN, '<child link="arm"/>')
    call = _line(MAIN, "<xacro:arm_link")
    found = await client.text_document_definition_async(lsp.DefinitionParams(
        doc, lsp.Position(call, lines[call].index("arm_link") + 2)))
    assert found and found[0].uri == (tmp_path / "parts.xacro").as_uri()
    assert found[0].range.start.line == _line(PARTS, '<xacro:macro name="arm_link"')
    use = _line(MAIN, "${reach}")
    found = await client.text_document_definition_async(lsp.DefinitionParams(
        doc, lsp.Position(use, lines[use].index("reach") + 1)))
    assert found and found[0].range.start.line == _line(MAIN, 'name="reach"')
    parent = _line(MAIN, '<parent link="base"/>')
    found = await client.text_document_definition_async(lsp.DefinitionParams(
        doc, lsp.Position(parent, lines[parent].index("base") + 1)))
    assert found and found[0].range.start.line == _line(MAIN, '<link name="base">')
    refs = await client.text_document_references_async(lsp.ReferenceParams(
        text_document=doc, position=lsp.Position(parent, lines[parent].index("base") + 1),
        context=lsp.ReferenceContext(include_declaration=True)))
    assert sorted(r.range.start.line for r in refs or []) == \
        [_line(MAIN, '<link name="base">'), parent]
    # completion: a child link, a property in ${}, a macro after <xacro:
    typed = lines[at].index('"arm"') + 1
    items = await client.text_document_completion_async(lsp.CompletionParams(
        doc, lsp.Position(at, typed)))
    assert {i.label for i in items.items} == {"base"}  # the file defines one link itself
    outline = await client.text_document_document_symbol_async(
        lsp.DocumentSymbolParams(doc))
    assert {(s.name, s.detail) for s in outline} >= {("base", "link"), ("j", "joint"),
                                                     ("reach", "property")}


@pytest.mark.asyncio
async def test_code_actions_are_fixs_bytes_and_the_nearest_tag(client: LanguageClient,
                                                               tmp_path: Path) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text(BAD)
    uri = await _open(client, path)
    actions = await client.text_document_code_action_async(lsp.CodeActionParams(
        lsp.TextDocumentIdentifier(uri), lsp.Range(lsp.Position(0, 0), lsp.Position(30, 0)),
        lsp.CodeActionContext(diagnostics=client.diagnostics[uri])))
    titles = [a.title for a in actions or []]
    assert "Change <colision> to <collision>" in titles
    fix = next(a for a in actions or [] if a.title.startswith("urdfkit fix"))
    (edit,) = fix.edit.changes[uri]
    out = tmp_path / "fixed.urdf"
    subprocess.run([sys.executable, "-m", "urdfkit", "fix", str(path), "-o", str(out)],
                   capture_output=True, check=False)
    assert edit.new_text.encode() == out.read_bytes()
    rename = next(a for a in actions or [] if a.title.startswith("Change"))
    edits = rename.edit.changes[uri]
    lines = BAD.splitlines()
    for e in sorted(edits, key=lambda e: (e.range.start.line, e.range.start.character),
                    reverse=True):
        row = lines[e.range.start.line]
        lines[e.range.start.line] = row[:e.range.start.character] + e.new_text + \
            row[e.range.end.character:]
    assert "<colision>" not in "\n".join(lines) and "</collision>" in "\n".join(lines)


@pytest.mark.asyncio
async def test_half_typed_and_endless_files_are_said_and_the_server_goes_on(
        client: LanguageClient, tmp_path: Path) -> None:
    path = tmp_path / "half.urdf"
    path.write_text("")
    uri = await _open(client, path, '<robot name="r">\n  <link name="a">\n    <inertial')
    (d,) = [d for d in client.diagnostics[uri] if d.code == "U000"]
    assert d.severity == lsp.DiagnosticSeverity.Error
    slow = tmp_path / "slow.xacro"
    slow.write_text('<robot name="s" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                    '  <xacro:property name="n" value="${max(i for i in range(10**10))}"/>\n'
                    '  <link name="${n}"/>\n</robot>\n')
    suri = await _open(client, slow)
    (d,) = client.diagnostics[suri]
    assert "longer than 3 s" in d.message
    hover = await client.text_document_hover_async(lsp.HoverParams(
        lsp.TextDocumentIdentifier(uri), lsp.Position(1, 15)))
    assert hover is not None and "not loaded" in hover.contents.value


@pytest.mark.asyncio
async def test_a_thousand_edits_leave_the_newest_diagnostics(client: LanguageClient,
                                                             tmp_path: Path) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text(BAD)
    uri = await _open(client, path)
    before = _rss(client)
    for version in range(2, 1002):
        # every odd version has the misspelling, every even one mends it
        text = BAD if version % 2 else BAD.replace("colision", "collision")
        client.text_document_did_change(lsp.DidChangeTextDocumentParams(
            lsp.VersionedTextDocumentIdentifier(uri=uri, version=version),
            [lsp.TextDocumentContentChangeWholeDocument(text=text)]))
    await _settled(client, uri, 1001)
    assert "U801" in _codes(client, uri)  # 1001 is odd: the misspelt text
    # bounded: the stale runs were dropped, not queued (measured: a few MiB)
    assert _rss(client) - before < 64 * 1024 * 1024
    hover = await client.text_document_hover_async(lsp.HoverParams(
        lsp.TextDocumentIdentifier(uri), lsp.Position(_line(BAD, '<link name="arm">'), 14)))
    assert hover is not None and "PyBullet index" in hover.contents.value


def test_completion_offers_what_the_place_takes(tmp_path: Path) -> None:
    from urdfkit.serve.document import read
    from urdfkit.serve.lsp import complete

    (tmp_path / "parts.xacro").write_text(PARTS)
    path = str(tmp_path / "robot.urdf.xacro")

    def at_end(text: str) -> set[str]:
        doc = read(text)
        line, column = doc.position(len(text))
        return {label for label, _, _ in complete(text, doc, line, column, path, {})}

    head = MAIN.split("</robot>")[0]
    assert at_end(head + '<joint name="k" type="fixed"><origin xyz="${re') >= {"reach",
                                                                              "arm_mass"}
    assert "arm_link" in at_end(head + "<xacro:")
    assert at_end(head + '<link name="c">\n    <') >= {"inertial", "visual", "collision"}
    assert "mass" in at_end(head + '<link name="c"><inertial><')
    assert {"name", "type"} <= at_end(head + "<joint ")


def test_fix_in_a_xacro_is_offered_only_where_the_numbers_are_written(tmp_path: Path) -> None:
    """A repair whose value comes from ${} cannot be carried back: no partial action."""
    from urdfkit.serve.analysis import analyse
    from urdfkit.serve.xacro_fix import xacro_fix

    head = '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">\n' \
        '  <xacro:property name="big" value="1"/>\n  <link name="base">\n' \
        '    <inertial><mass value="2"/>\n'
    tail = '\n    </inertial>\n    <collision><geometry><box size="0.2 0.2 0.2"/></geometry>' \
        '</collision>\n  </link>\n</robot>\n'
    path = str(tmp_path / "r.xacro")
    written = head + '      <inertia ixx="1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>' + tail
    fixed = xacro_fix(path, written, {"U604"}, analyse(path, written), {})
    assert fixed is not None and 'ixx="1"' not in fixed[0] and "in the xacro" in fixed[1]
    computed = written.replace('ixx="1"', 'ixx="${big}"')
    assert xacro_fix(path, computed, {"U604"}, analyse(path, computed), {}) is None


def test_a_half_typed_xacro_is_its_own_parse_error_not_the_saved_files(tmp_path: Path) -> None:
    """The buffer, not the file on disk, is what xacro is told of when it does not parse."""
    from urdfkit.serve.analysis import analyse

    (tmp_path / "parts.xacro").write_text(PARTS)
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(MAIN)
    broken = MAIN.replace('<origin xyz="0 0 ${reach}"/>', '<origin xyz="0 0 ${re')
    found = analyse(str(path), broken).findings
    assert [p.finding.code for p in found] == ["U000"]
    assert "not well-formed" in found[0].finding.message


def test_a_document_opened_through_a_symlink_keeps_its_findings(tmp_path: Path) -> None:
    from urdfkit.serve.analysis import analyse

    real = tmp_path / "real"
    real.mkdir()
    (real / "parts.xacro").write_text(PARTS)
    (real / "robot.urdf.xacro").write_text(MAIN)
    (tmp_path / "link").symlink_to(real)
    path = str(tmp_path / "link" / "robot.urdf.xacro")
    found = analyse(path, MAIN).findings
    assert any(p.path == path and p.finding.code == "U801" for p in found)


@pytest.mark.asyncio
async def test_a_link_a_macro_makes_is_defined_where_xacro_wrote_it(
        client: LanguageClient, tmp_path: Path) -> None:
    (tmp_path / "parts.xacro").write_text(PARTS)
    main = tmp_path / "robot.urdf.xacro"
    main.write_text(MAIN)
    uri = await _open(client, main)
    at = _line(MAIN, '<child link="arm"/>')
    found = await client.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri), lsp.Position(at, MAIN.splitlines()[at].index("arm"))))
    assert found and found[0].uri == (tmp_path / "parts.xacro").as_uri()
    assert found[0].range.start.line == _line(PARTS, '<link name="${name}">')
    # an included file open beside its robot keeps what the robot's check placed there
    parts = await _open(client, tmp_path / "parts.xacro")
    assert "U604" in _codes(client, parts)
