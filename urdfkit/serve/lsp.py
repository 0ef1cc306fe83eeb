"""``urdfkit lsp``: a Language Server for URDF and xacro, over stdio (pygls).

Diagnostics are ``check``'s, on the text in the editor (:mod:`urdfkit.serve.analysis`), each at
the file and line it was written at; hovers, definitions, references, completion and the outline
come from the text itself (:mod:`urdfkit.serve.document`) and the robot as PyBullet loads it;
code actions are ``fix``'s repairs (the same bytes) and the nearest tag for a misspelt one.

Checks run one at a time, off the event loop, each on the newest text: an edit cancels the run
waiting for its turn (a debounce of :data:`DEBOUNCE` seconds), a run whose text changed while
it ran is dropped, and a xacro that expands longer than the timeout is stopped and said.
"""

from __future__ import annotations

import asyncio
import os
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from urdfkit.serve.analysis import Analysis, Placed, analyse, hover_text, is_xacro
from urdfkit.serve.document import XACRO_TAGS, Document, Name, read

#: Seconds an edit waits for the next before it is checked.
DEBOUNCE = 0.05
#: A xacro's expansion is stopped after this many seconds (said as a diagnostic).
XACRO_TIMEOUT = 20.0
_LEVELS = {"error": 1, "warning": 2, "info": 3}


def docs_link(code: str) -> str | None:
    """A link to docs/check.md's rules for a code, where the docs are beside the package."""
    docs = Path(__file__).resolve().parents[2] / "docs" / "check.md"
    return docs.as_uri() + "#rules" if docs.is_file() else None


class State:
    """What the server keeps: settings, each document's newest analysis and outline."""

    def __init__(self, targets: Sequence[str], packages: Mapping[str, Path],
                 xacro_args: Mapping[str, str]) -> None:
        self.targets = tuple(targets)
        self.packages = dict(packages)
        self.xacro_args = dict(xacro_args)
        self.timeout = XACRO_TIMEOUT
        self.analysis: dict[str, Analysis] = {}
        self.published: dict[str, set[str]] = {}
        #: Each document's diagnostics by the document whose check placed them there.
        self.contrib: dict[str, dict[str, list[Any]]] = {}
        self.pending: dict[str, asyncio.Task[None]] = {}
        self.pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="urdfkit-check")
        self._outline: dict[str, tuple[str, Document]] = {}

    def outline(self, uri: str, text: str) -> Document:
        """The text's names, read once per text."""
        kept = self._outline.get(uri)
        if kept is None or kept[0] is not text and kept[0] != text:
            kept = (text, read(text))
            self._outline[uri] = kept
        return kept[1]

    def forget(self, uri: str) -> None:
        """Drop a closed document's state."""
        self._outline.pop(uri, None)
        self.analysis.pop(uri, None)
        task = self.pending.pop(uri, None)
        if task is not None:
            task.cancel()


def build_server(targets: Sequence[str] = (), packages: Mapping[str, Path] | None = None,
                 xacro_args: Mapping[str, str] | None = None) -> Any:
    """The language server, its handlers registered (start it with ``start_io()``).

    Raises:
        MissingDependencyError: pygls is not installed (``urdfkit[lsp]`` named).
    """
    from urdfkit.core.errors import import_optional

    import_optional("pygls.lsp.server", "pygls", "urdfkit lsp", "lsp")
    from lsprotocol import types as lsp
    from pygls.lsp.server import LanguageServer

    from urdfkit import __version__

    server = LanguageServer("urdfkit", __version__)
    h = Handlers(server, State(targets, packages or {}, xacro_args or {}))
    server.urdfkit_state = h.state  # type: ignore[attr-defined]
    for feature, handler in ((lsp.INITIALIZE, h.initialize),
                             (lsp.TEXT_DOCUMENT_DID_OPEN, h.did_open),
                             (lsp.TEXT_DOCUMENT_DID_CHANGE, h.did_change),
                             (lsp.TEXT_DOCUMENT_DID_SAVE, h.did_save),
                             (lsp.TEXT_DOCUMENT_DID_CLOSE, h.did_close),
                             (lsp.TEXT_DOCUMENT_HOVER, h.hover),
                             (lsp.TEXT_DOCUMENT_DEFINITION, h.definition),
                             (lsp.TEXT_DOCUMENT_REFERENCES, h.references),
                             (lsp.TEXT_DOCUMENT_DOCUMENT_SYMBOL, h.symbols),
                             (lsp.TEXT_DOCUMENT_CODE_ACTION, h.code_action)):
        server.feature(feature)(_plain(handler))
    server.feature(lsp.TEXT_DOCUMENT_COMPLETION, lsp.CompletionOptions(
        trigger_characters=["<", "{", '"', " ", ":"]))(_plain(h.completion))
    return server


def _plain(method: Any) -> Any:
    """A bound method as a plain function (pygls marks the functions it registers)."""
    def handler(params: Any) -> Any:
        return method(params)

    handler.__doc__ = method.__doc__
    return handler


def path_of(uri: str) -> str:
    """A document's file (absolute)."""
    from pygls.uris import to_fs_path

    return os.path.abspath(to_fs_path(uri) or uri)


class Handlers:
    """The server's answers, over its :class:`State`."""

    def __init__(self, server: Any, state: State) -> None:
        self.server = server
        self.state = state

    # ---- checking

    def schedule(self, uri: str, delay: float) -> None:
        """Check the document after ``delay`` s, cancelling the run waiting before this one."""
        old = self.state.pending.pop(uri, None)
        if old is not None:
            old.cancel()
        self.state.pending[uri] = asyncio.get_running_loop().create_task(self.run(uri, delay))

    async def run(self, uri: str, delay: float) -> None:
        """Check the newest text, off the event loop; publish unless it changed meanwhile."""
        from lsprotocol import types as lsp

        await asyncio.sleep(delay)
        state, server = self.state, self.server
        doc = server.workspace.get_text_document(uri)
        version, text = doc.version, doc.source
        loop = asyncio.get_running_loop()
        try:
            analysis = await loop.run_in_executor(
                state.pool, lambda: analyse(path_of(uri), text, packages=state.packages,
                                            xacro_args=state.xacro_args,
                                            targets=state.targets, timeout=state.timeout))
        except Exception as e:  # noqa: BLE001 - a bug must not take the server down
            server.window_log_message(lsp.LogMessageParams(
                lsp.MessageType.Error, f"urdfkit: checking {uri} failed: {e!r}"))
            return
        now = server.workspace.get_text_document(uri)
        if now.version != version or now.source != text:
            return  # a newer text is on its way
        state.analysis[uri] = analysis
        self.publish(uri, analysis, text, version)

    def publish(self, uri: str, analysis: Analysis, text: str, version: int | None) -> None:
        """The findings, each to the document it was written in (an include's to its own)."""
        from lsprotocol import types as lsp
        from pygls.uris import from_fs_path

        me = path_of(uri)
        by_path: dict[str, list[Placed]] = {me: []}
        for p in analysis.findings:
            by_path.setdefault(p.path, []).append(p)
        sent = set()
        contrib = self.state.contrib
        for path, placed in by_path.items():
            target = uri if path == me else (from_fs_path(path) or path)
            lines = text.splitlines() if path == me else _lines_of(path)
            contrib.setdefault(target, {})[uri] = [diagnostic(p, lines) for p in placed]
            sent.add(target)
        for gone in self.state.published.get(uri, set()) - sent:
            contrib.get(gone, {}).pop(uri, None)
            self.server.text_document_publish_diagnostics(lsp.PublishDiagnosticsParams(
                uri=gone, diagnostics=[d for ds in contrib.get(gone, {}).values()
                                             for d in ds]))
        for target in sent:
            # a file's diagnostics are its own check's and those that files including it
            # placed there (a macro file open beside its robot gets both)
            self.server.text_document_publish_diagnostics(lsp.PublishDiagnosticsParams(
                uri=target, diagnostics=[d for ds in contrib[target].values() for d in ds],
                version=version if target == uri else None))
        self.state.published[uri] = sent

    # ---- the document's life

    def initialize(self, params: Any) -> None:
        """Settings from the client's initializationOptions: targets, packages, args."""
        options, state = params.initialization_options, self.state
        if not isinstance(options, dict):
            return
        if isinstance(options.get("targets"), list):
            state.targets = tuple(str(t) for t in options["targets"])
        if isinstance(options.get("packages"), dict):
            state.packages.update({str(k): Path(str(v)) for k, v in
                                   options["packages"].items()})
        if isinstance(options.get("args"), dict):
            state.xacro_args.update({str(k): str(v) for k, v in options["args"].items()})
        if isinstance(options.get("xacroTimeout"), (int, float)):
            state.timeout = max(0.1, float(options["xacroTimeout"]))

    def did_open(self, params: Any) -> None:
        """Check at once."""
        self.schedule(params.text_document.uri, 0.0)

    def did_change(self, params: Any) -> None:
        """Check once the edits pause."""
        self.schedule(params.text_document.uri, DEBOUNCE)

    def did_save(self, params: Any) -> None:
        """Check at once."""
        self.schedule(params.text_document.uri, 0.0)

    def did_close(self, params: Any) -> None:
        """Forget it."""
        self.state.forget(params.text_document.uri)

    def here(self, uri: str) -> tuple[str, Document]:
        """The document's text and names now."""
        text = self.server.workspace.get_text_document(uri).source
        return text, self.state.outline(uri, text)

    def name_at(self, params: Any) -> tuple[str, Document, Name | None]:
        """The request's document, its names, and the name at the request's position."""
        uri = params.text_document.uri
        _, doc = self.here(uri)
        return uri, doc, doc.at(params.position.line, params.position.character)

    # ---- questions

    def hover(self, params: Any) -> Any:
        """A link's or joint's facts as PyBullet loads them; a xacro name's definition."""
        from lsprotocol import types as lsp

        uri, doc, name = self.name_at(params)
        if name is None:
            return None
        said: str | None
        if name.kind in ("link", "joint"):
            said = hover_text(self.state.analysis.get(uri), name.kind, name.name) or \
                f"**{name.kind} `{name.name}`**: not loaded (the file as it is cannot be " \
                "read as PyBullet reads it: see its errors)"
        else:
            said = _xacro_hover(name, _definitions(path_of(uri), doc, name,
                                                   self.state.packages))
        if not said:
            return None
        return lsp.Hover(contents=lsp.MarkupContent(lsp.MarkupKind.Markdown, said),
                         range=_range(name))

    def definition(self, params: Any) -> Any:
        """A joint's links, a macro, property or arg, an included file."""
        from lsprotocol import types as lsp
        from pygls.uris import from_fs_path

        uri, doc, name = self.name_at(params)
        if name is None:
            return None
        if name.kind == "include":
            target = _include_path(name.name, Path(path_of(uri)).parent, self.state.packages)
            if target is None:
                return None
            return [lsp.Location(from_fs_path(str(target)) or str(target),
                                 lsp.Range(lsp.Position(0, 0), lsp.Position(0, 0)))]
        found = _definitions(path_of(uri), doc, name, self.state.packages)
        if not found and name.kind in ("link", "joint"):  # made by a macro: where xacro says
            analysis = self.state.analysis.get(uri)
            at = analysis.written.get((name.kind, name.name)) if analysis else None
            if at is not None:
                where = uri if at[0] == path_of(uri) else (from_fs_path(at[0]) or at[0])
                spot = lsp.Position(max(at[1], 0), 0)
                return [lsp.Location(where, lsp.Range(spot, spot))]
        return [lsp.Location(from_fs_path(p) or p, _range(n)) for p, n in found] or None

    def references(self, params: Any) -> Any:
        """Every use of a link, joint, macro, property or arg in the document."""
        from lsprotocol import types as lsp

        uri, doc, name = self.name_at(params)
        if name is None or name.kind == "include":
            return None
        out = doc.uses(name.kind, name.name)
        if params.context.include_declaration:
            out = doc.definitions(name.kind, name.name) + out
        return [lsp.Location(uri, _range(n)) for n in out]

    def symbols(self, params: Any) -> Any:
        """The outline: links, joints, macros, properties, args."""
        from lsprotocol import types as lsp

        _, doc = self.here(params.text_document.uri)
        kinds = {"link": lsp.SymbolKind.Struct, "joint": lsp.SymbolKind.Interface,
                 "macro": lsp.SymbolKind.Function, "property": lsp.SymbolKind.Constant,
                 "arg": lsp.SymbolKind.Variable}
        return [lsp.DocumentSymbol(name=n.name, kind=kinds[n.kind], range=_range(n),
                                   selection_range=_range(n), detail=n.kind)
                for n in doc.names if not n.use and n.kind in kinds]

    def completion(self, params: Any) -> Any:
        """Tags, attributes, link names, macros, properties."""
        from lsprotocol import types as lsp

        uri = params.text_document.uri
        text, doc = self.here(uri)
        items = complete(text, doc, params.position.line, params.position.character,
                         path_of(uri), self.state.packages)
        return lsp.CompletionList(is_incomplete=False, items=[
            lsp.CompletionItem(label=label, kind=lsp.CompletionItemKind(kind), detail=detail)
            for label, kind, detail in items])

    def code_action(self, params: Any) -> Any:
        """``fix``'s repairs as one edit (its very bytes); the nearest tag for a misspelt one."""
        from lsprotocol import types as lsp

        uri = params.text_document.uri
        text, doc = self.here(uri)
        out = []
        for d in params.context.diagnostics:
            if d.code == "U801":
                out += _did_you_mean(uri, doc, d)
        codes = {str(d.code) for d in params.context.diagnostics}
        path = path_of(uri)
        if is_xacro(path):
            from urdfkit.serve.xacro_fix import xacro_fix

            found = xacro_fix(path, text, codes, self.state.analysis.get(uri),
                              self.state.packages)
        else:
            found = _fixed(path, text, codes, self.state.packages)
        if found is not None:
            new, summary = found
            end = doc.position(len(text))
            out.append(lsp.CodeAction(
                title=f"urdfkit fix: {summary}", kind=lsp.CodeActionKind.QuickFix,
                diagnostics=[d for d in params.context.diagnostics if str(d.code) in
                             _fixable()],
                edit=lsp.WorkspaceEdit(changes={uri: [lsp.TextEdit(
                    lsp.Range(lsp.Position(0, 0), lsp.Position(*end)), new)]})))
        return out or None


def diagnostic(p: Placed, lines: list[str]) -> Any:
    """A placed finding as an LSP diagnostic over its line's text."""
    from lsprotocol import types as lsp

    line = max(p.line, 0)
    text = lines[line] if line < len(lines) else ""
    start = len(text) - len(text.lstrip())
    href = docs_link(p.finding.code)
    return lsp.Diagnostic(
        range=lsp.Range(lsp.Position(line, start), lsp.Position(line, max(len(text), start))),
        message=p.finding.message,
        severity=lsp.DiagnosticSeverity(_LEVELS.get(p.finding.level, 3)),
        code=p.finding.code, source="urdfkit",
        code_description=lsp.CodeDescription(href=href) if href else None)


def _lines_of(path: str) -> list[str]:
    try:
        return Path(path).read_text("utf-8", "replace").splitlines()
    except OSError:
        return []


def _range(n: Name) -> Any:
    from lsprotocol import types as lsp

    return lsp.Range(lsp.Position(n.span.line, n.span.start),
                     lsp.Position(n.span.line, n.span.end))


def _fixable() -> tuple[str, ...]:
    from urdfkit.checks.fix import FIXABLE

    return FIXABLE


def _fixed(path: str, text: str, codes: set[str], packages: Mapping[str, Path]
           ) -> tuple[str, str] | None:
    """``fix``'s output for the buffer, when a diagnostic asked of is one it repairs."""
    from urdfkit.checks.fix import fix_file
    from urdfkit.core.errors import UrdfkitError

    if is_xacro(path) or not codes & set(_fixable()):
        return None
    try:
        result = fix_file(path, packages=packages, buffer=text.encode("utf-8"))
    except (UrdfkitError, ValueError):
        return None
    if not result.changed:
        return None
    done = sorted({r.code for r in result.repairs})
    return result.fixed.decode("utf-8"), f"{len(result.repairs)} repair(s) ({', '.join(done)})"


def _did_you_mean(uri: str, doc: Document, d: Any) -> list[Any]:
    """Rename a misspelt tag (and its end tag) to each of the nearest known ones."""
    from lsprotocol import types as lsp

    from urdfkit.model.spec import nearest_tags

    line = d.range.start.line
    for tag in doc.tags:
        at, _ = doc.position(tag.start)
        if at != line or f"<{tag.name}>" not in d.message:
            continue
        parent = doc.parent_tag(tag.start) or "robot"
        actions = []
        for better in nearest_tags(tag.name, parent.split(":")[-1])[:3]:
            edits = [lsp.TextEdit(lsp.Range(lsp.Position(*doc.position(tag.start + 1)),
                                            lsp.Position(*doc.position(tag.start + 1
                                                                       + len(tag.name)))),
                                  better)]
            if not tag.closed:
                close = doc.text.find(f"</{tag.name}>", tag.end)
                if close >= 0:
                    edits.append(lsp.TextEdit(
                        lsp.Range(lsp.Position(*doc.position(close + 2)),
                                  lsp.Position(*doc.position(close + 2 + len(tag.name)))),
                        better))
            actions.append(lsp.CodeAction(
                title=f"Change <{tag.name}> to <{better}>", kind=lsp.CodeActionKind.QuickFix,
                diagnostics=[d], edit=lsp.WorkspaceEdit(changes={uri: edits})))
        return actions
    return []


def _include_path(filename: str, folder: Path, packages: Mapping[str, Path]) -> Path | None:
    """An included file's path: relative to the including file, or ``$(find pkg)/...``."""
    import re

    m = re.match(r"\$\(\s*find\s+([\w.-]+)\s*\)(.*)", filename)
    if m:
        base = packages.get(m.group(1))
        if base is None:  # the package's folder: up from here, as urdfkit's xacro finds it
            for up in [folder, *folder.parents]:
                if up.name == m.group(1) or (up / m.group(1)).is_dir():
                    base = up if up.name == m.group(1) else up / m.group(1)
                    break
        if base is None:
            return None
        target = Path(base) / m.group(2).lstrip("/")
    elif "$" in filename:
        return None
    else:
        target = folder / filename
    return target if target.is_file() else None


def _included(path: str, doc: Document, packages: Mapping[str, Path], seen: set[str]
              ) -> list[tuple[str, Document]]:
    """The documents this one includes, transitively (each once)."""
    out = []
    for inc in doc.defined("include"):
        target = _include_path(inc.name, Path(path).parent, packages)
        if target is None or str(target) in seen:
            continue
        seen.add(str(target))
        try:
            other = read(target.read_text("utf-8", "replace"))
        except OSError:
            continue
        out.append((str(target), other))
        out += _included(str(target), other, packages, seen)
    return out


def _definitions(path: str, doc: Document, name: Name, packages: Mapping[str, Path]
                 ) -> list[tuple[str, Name]]:
    """Where a name is defined: this document first, then what it includes."""
    here_found = [(path, n) for n in doc.definitions(name.kind, name.name)]
    if here_found or name.kind in ("link", "joint"):
        return here_found
    return [(p, n) for p, d in _included(path, doc, packages, {path})
            for n in d.definitions(name.kind, name.name)]


def _xacro_hover(name: Name, found: list[tuple[str, Name]]) -> str | None:
    if not found:
        return f"xacro {name.kind} `{name.name}`: not defined here or in the files included"
    path, n = found[0]
    where = f"{os.path.basename(path)}:{n.span.line + 1}"
    if name.kind == "macro":
        return f"xacro macro `{n.name}`({n.detail}), defined at {where}"
    if name.kind == "property":
        return f"xacro property `{n.name}` = `{n.detail}`, defined at {where}"
    if name.kind == "arg":
        return f"xacro arg `{n.name}` (default `{n.detail}`), defined at {where}"
    return None


def complete(text: str, doc: Document, line: int, column: int, path: str,
             packages: Mapping[str, Path]) -> list[tuple[str, int, str]]:
    """Completions at a position: (label, LSP CompletionItemKind, detail)."""
    import re

    from urdfkit.model.spec import SCHEMA

    offset = doc.offset(line, column)
    before = text[max(0, offset - 400):offset]
    expr = before.rfind("${")
    if expr >= 0 and "}" not in before[expr:]:
        names = {n.name: n.detail for n in doc.defined("property")}
        for _, d in _included(path, doc, packages, {path}):
            names.update({n.name: n.detail for n in d.defined("property")})
        return [(n, 21, f"= {v}") for n, v in sorted(names.items())]
    m = re.search(r"<(parent|child)\s[^<>]*link\s*=\s*\"[^\"]*$", before)
    if m:  # (a macro body's `${name}` is no link's name)
        return [(n.name, 22, "link") for n in doc.defined("link") if "$" not in n.name]
    m = re.search(r"<xacro:([\w-]*)$", before)
    if m:
        macros = {n.name: n.detail for n in doc.defined("macro")}
        for _, d in _included(path, doc, packages, {path}):
            macros.update({n.name: n.detail for n in d.defined("macro")})
        return [(n, 3, f"macro({p})") for n, p in sorted(macros.items())] + \
            [(t, 14, "xacro") for t in sorted(XACRO_TAGS)]
    m = re.search(r"<([A-Za-z_][\w:.-]*)(\s+[^<>]*)?\s$", before)
    if m and not before.rstrip().endswith(">"):
        known = SCHEMA.get(m.group(1).split(":")[-1])
        return [(a, 10, f"<{m.group(1)}> attribute") for a in sorted(known[0])] if known else []
    if before.endswith("<"):
        parent = (doc.parent_tag(offset) or "robot").split(":")[-1]
        known = SCHEMA.get(parent)
        return [(t, 14, f"in <{parent}>") for t in sorted(known[1])] if known else []
    return []
