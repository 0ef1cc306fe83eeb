"""`urdfkit lsp` latency, as an editor feels it: an edit to diagnostics, a hover to its answer.

    python bench/lsp_latency.py FILE.xacro [--arg NAME:=VALUE ...] [--package-path DIR]
        [--edits 40] [--hovers 200]

Starts `urdfkit lsp` (this Python's install) over stdio, opens FILE, then makes one edit at a
time (a number on the first `<origin>` line changed, each edit a new version) and times from
sending it to receiving that version's diagnostics; then times hovers on every link and joint
name. Prints the median and 95th percentile of each, and the robot's link count. The goal
(issue "In the editor and for agents"): diagnostics within 300 ms and a hover within 50 ms at
the 95th percentile, on a xacro robot of 30+ links.

The baseline a user would otherwise have: `urdfkit check FILE` run from the command line after
saving (the same rules, a new process each time), timed over the same edits.
"""

from __future__ import annotations

import argparse
import asyncio
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from lsprotocol import types as lsp
from pygls.lsp.client import LanguageClient


def _p95(values: list[float]) -> float:
    return sorted(values)[max(0, int(round(0.95 * len(values))) - 1)]


async def main() -> None:
    """Run the bench and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--arg", action="append", default=[])
    ap.add_argument("--package-path", action="append", default=[])
    ap.add_argument("--edits", type=int, default=40)
    ap.add_argument("--hovers", type=int, default=200)
    a = ap.parse_args()
    path = Path(a.file).resolve()
    text = path.read_text()
    cmd = [sys.executable, "-m", "urdfkit", "lsp"]
    for arg in a.arg:
        cmd += ["--arg", arg]
    for pp in a.package_path:
        cmd += ["--package-path", pp]

    client = LanguageClient("bench", "1")
    seen: dict[int | None, float] = {}

    @client.feature(lsp.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    def diagnostics(params: lsp.PublishDiagnosticsParams) -> None:
        if params.uri == path.as_uri():
            seen[params.version] = time.perf_counter()

    await client.start_io(*cmd)
    await client.initialize_async(lsp.InitializeParams(capabilities=lsp.ClientCapabilities()))
    client.initialized(lsp.InitializedParams())
    uri = path.as_uri()
    start = time.perf_counter()
    client.text_document_did_open(lsp.DidOpenTextDocumentParams(
        lsp.TextDocumentItem(uri=uri, language_id="xml", version=1, text=text)))
    while 1 not in seen:
        await asyncio.sleep(0.005)
    first = seen[1] - start
    number = re.search(r'<origin[^>]*xyz="([-0-9.e ]+)"', text)
    if number is None:
        raise SystemExit("no <origin xyz> to edit in the file")
    latencies = []
    for version in range(2, a.edits + 2):
        edited = text[:number.start(1)] + f"{version * 1e-4:.4f} 0 0" + text[number.end(1):]
        sent = time.perf_counter()
        client.text_document_did_change(lsp.DidChangeTextDocumentParams(
            text_document=lsp.VersionedTextDocumentIdentifier(uri=uri, version=version),
            content_changes=[lsp.TextDocumentContentChangeWholeDocument(text=edited)]))
        while version not in seen:
            await asyncio.sleep(0.002)
        latencies.append(seen[version] - sent)
    names = [(m.start(1), m.group(1)) for m in re.finditer(r'<(?:link|joint) name="([^"$]+)"',
                                                          text)]
    hovers = []
    for i in range(a.hovers):
        offset, _ = names[i % len(names)]
        line = text.count("\n", 0, offset)
        column = offset - (text.rfind("\n", 0, offset) + 1) + 1
        sent = time.perf_counter()
        await client.text_document_hover_async(lsp.HoverParams(
            text_document=lsp.TextDocumentIdentifier(uri=uri),
            position=lsp.Position(line=line, character=column)))
        hovers.append(time.perf_counter() - sent)
    await client.shutdown_async(None)
    client.exit(None)
    await client.stop()
    links = len(re.findall(r"<link\b", subprocess.run(
        [sys.executable, "-m", "urdfkit", "build", str(path), "-o", "-",
         *[x for arg in a.arg for x in ("--arg", arg)],
         *[x for pp in a.package_path for x in ("--package-path", pp)]],
        capture_output=True, text=True, check=False).stdout))
    baseline = []
    for _ in range(min(10, a.edits)):
        sent = time.perf_counter()
        subprocess.run([sys.executable, "-m", "urdfkit", "check", str(path), "--no-cache",
                        *[x for arg in a.arg for x in ("--arg", arg)],
                        *[x for pp in a.package_path for x in ("--package-path", pp)]],
                       capture_output=True, check=False)
        baseline.append(time.perf_counter() - sent)
    ms = 1000.0
    print(f"{path.name}: {links} links; first diagnostics {first * ms:.0f} ms")
    print(f"edit -> diagnostics: median {statistics.median(latencies) * ms:.0f} ms, "
          f"p95 {_p95(latencies) * ms:.0f} ms over {len(latencies)} edits (goal 300)")
    print(f"hover: median {statistics.median(hovers) * ms:.1f} ms, p95 {_p95(hovers) * ms:.1f} ms "
          f"over {len(hovers)} (goal 50)")
    print(f"baseline, `urdfkit check --no-cache` after a save: median "
          f"{statistics.median(baseline) * ms:.0f} ms")


if __name__ == "__main__":
    asyncio.run(main())
