"""Expand one xacro file into a file: run, contained, by :mod:`urdfkit.sources.expand`.

xacro's ``${}`` expressions evaluate Python, so a user's xacro file is code. It runs here, in
a child process that limits itself (memory, CPU, core dumps), adopts any descendant that tries
to daemonize (child subreaper), and kills all its descendants before it exits or when told to
stop (SIGTERM).

``$(find NAME)`` is answered without ROS: a stand-in ``ament_index_python`` module looks the
package up in the :class:`~urdfkit.sources.uris.PackageIndex` the parent passed (``--package``,
``--package-path``, ROS_PACKAGE_PATH, AMENT_PREFIX_PATH), then above the file.

Each element is tagged, as its file is read, with the file and line it was written on (an
attribute in urdfkit's own namespace, which xacro copies like any other, including into
every expansion of a macro). After expansion the tags are taken off and written, in
document order, to ``OUT.origins`` (JSON): the true source of every element, for findings.

Usage: ``python -m urdfkit.sources._xacro_worker OUT ERR TIMEOUT MEMORY PACKAGES_JSON FILE
[name:=value ...]``
"""

from __future__ import annotations

import math
import os
import signal
import sys

PR_SET_CHILD_SUBREAPER = 36

#: The namespace of the source tags (never in the output).
ORIGIN_NS = "urn:urdfkit:origin"
#: Files read so far (an origin names one by its index here).
FILES: list[str] = []


#: An included file larger than this is refused (xmlio.MAX_FILE_BYTES, the cap of every read).
MAX_INCLUDE_BYTES = 32 * 1024 * 1024


def _refuse_special(xacro: object, filename: str, path: str) -> None:
    """Refuse to include a FIFO, a device or a huge file: xacro would wait or read forever.

    The file is opened non-blocking (a FIFO would wait for a writer) and judged by ``fstat``
    on the open descriptor, as :func:`urdfkit.model.xmlio.read_regular` does for every other read.
    """
    import stat

    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError:
        return  # missing or unreadable: xacro says so, its own way
    try:
        st = os.fstat(fd)
    finally:
        os.close(fd)
    what = None
    if stat.S_ISFIFO(st.st_mode):
        what = "is a FIFO (named pipe), not a regular file"
    elif stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode):
        what = "is a device, not a regular file"
    elif stat.S_ISSOCK(st.st_mode):
        what = "is a socket, not a regular file"
    elif stat.S_ISREG(st.st_mode) and st.st_size > MAX_INCLUDE_BYTES:
        what = f"is {st.st_size:,} bytes, more than the {MAX_INCLUDE_BYTES:,} urdfkit reads"
    if what is not None:
        raise xacro.XacroException(  # type: ignore[attr-defined]
            f"included file {filename}: {what}; urdfkit reads only regular files")


def _tag_origins(xacro: object, overlay: tuple[str, str] | None = None) -> None:
    """Make xacro's file reader tag every element it reads with ``index:line``.

    ``overlay`` is (a file, the file whose bytes stand for it): an editor's unsaved buffer.
    """
    from lxml import etree

    original = xacro.parse  # type: ignore[attr-defined]
    etree.register_namespace("urdfkit-origin", ORIGIN_NS)

    def parse(inp: object, filename: str | None = None) -> object:
        if inp is not None or not filename:
            return original(inp, filename)
        path = os.path.join(xacro.root_dir, filename)  # type: ignore[attr-defined]
        _refuse_special(xacro, filename, path)
        text: bytes | None = None
        read = overlay[1] if overlay and os.path.realpath(path) == overlay[0] else path
        try:
            with open(read, "rb") as f:
                text = f.read()
            root = etree.fromstring(text, etree.XMLParser(
                resolve_entities=False, no_network=True, strip_cdata=False,
                remove_comments=False))
        except (OSError, etree.XMLSyntaxError, ValueError):
            # xacro says what is wrong, its own way: of the overlay's text, not the file's
            if read != path and text is not None:
                return original(text.decode("utf-8", "replace"), filename)
            return original(inp, filename)
        FILES.append(os.path.abspath(path))
        index = len(FILES) - 1
        for el in root.iter(etree.Element):
            # xacro knows its own elements by the "xacro:" prefix (files use several URIs);
            # they are instructions, and a macro call's attributes are its parameters.
            ns = etree.QName(el).namespace or ""
            if el.prefix != "xacro" and "xacro" not in ns:
                el.set(f"{{{ORIGIN_NS}}}at", f"{index}:{el.sourceline}")
        return original(etree.tostring(root, encoding="unicode"), filename)

    xacro.parse = parse  # type: ignore[attr-defined]


def _take_origins(doc: object) -> list[str | None]:
    """Remove the source tags; return them in document order (None: untagged)."""
    out: list[str | None] = []
    stack = [doc.documentElement]  # type: ignore[attr-defined]
    while stack:
        el = stack.pop()
        at = el.getAttributeNS(ORIGIN_NS, "at") if el.hasAttributeNS(ORIGIN_NS, "at") else ""
        if at:
            el.removeAttributeNS(ORIGIN_NS, "at")
        out.append(at or None)
        stack.extend(reversed([c for c in el.childNodes if c.nodeType == c.ELEMENT_NODE]))
    for el in [doc.documentElement]:  # type: ignore[attr-defined]
        if el.hasAttribute("xmlns:urdfkit-origin"):
            el.removeAttribute("xmlns:urdfkit-origin")
    return out


def _limits(timeout: float, memory: int) -> None:
    import resource

    cpu = max(1, math.ceil(timeout)) + 1
    for what, value in ((resource.RLIMIT_AS, memory), (resource.RLIMIT_CPU, cpu),
                        (resource.RLIMIT_CORE, 0)):
        try:
            resource.setrlimit(what, (value, value))
        except (ValueError, OSError):  # a lower hard limit is already in place
            pass


def _subreaper() -> None:
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    except (OSError, AttributeError):  # pragma: no cover
        pass


def _descendants(root: int) -> list[int]:
    """Every process below ``root`` (from /proc), nearest first."""
    children: dict[int, list[int]] = {}
    try:
        pids = [int(p) for p in os.listdir("/proc") if p.isdigit()]
    except OSError:  # pragma: no cover - no /proc
        return []
    for pid in pids:
        try:
            with open(f"/proc/{pid}/stat", "rb") as f:
                stat = f.read()
        except OSError:
            continue
        fields = stat.rsplit(b")", 1)[-1].split()
        if len(fields) > 1:
            children.setdefault(int(fields[1]), []).append(pid)
    out, queue = [], list(children.get(root, []))
    while queue:
        pid = queue.pop(0)
        out.append(pid)
        queue.extend(children.get(pid, []))
    return out


def _kill_descendants() -> None:
    for _ in range(20):  # a fork bomb may keep forking while we kill: a few rounds
        pids = _descendants(os.getpid())
        if not pids:
            return
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        while True:  # reap what was re-parented to us, so nothing lingers as a zombie
            try:
                if os.waitpid(-1, os.WNOHANG)[0] == 0:
                    break
            except ChildProcessError:
                break


def _stop(signum: int, _frame: object) -> None:
    _kill_descendants()
    os._exit(128 + signum)


#: Packages $(find) could not locate, for the error line (xacro garbles the exception text).
MISSING: list[str] = []


class PackageNotFoundError(KeyError):
    """The stand-in for ament_index_python's: a package $(find) cannot locate."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else "package not found"


def _install_find(packages_json: str, source: str) -> None:
    """Make ``$(find NAME)`` work without ROS (xacro imports ament_index_python for it)."""
    import json
    import types
    from pathlib import Path

    from urdfkit.sources.uris import PackageIndex, find_package

    index = PackageIndex.from_json(json.loads(packages_json))
    base = Path(source).resolve().parent

    def get_package_share_directory(name: str) -> str:
        found = index.get(name) or find_package(name, base)
        if found is None:
            MISSING.append(name)
            raise PackageNotFoundError(name)
        return str(found)

    module = types.ModuleType("ament_index_python.packages")
    module.get_package_share_directory = get_package_share_directory  # type: ignore[attr-defined]
    module.PackageNotFoundError = PackageNotFoundError  # type: ignore[attr-defined]
    parent = types.ModuleType("ament_index_python")
    parent.packages = module  # type: ignore[attr-defined]
    sys.modules.setdefault("ament_index_python", parent)
    sys.modules.setdefault("ament_index_python.packages", module)


def _record_reads(deps: str) -> None:
    """Note every file xacro opens for reading (includes, YAML, ...).

    The list goes to ``deps`` (JSON) when the worker exits, failed or not: check's result
    cache reuses a result only while none of them changed (:mod:`urdfkit.core.deps`).
    """
    import atexit
    import builtins
    import json

    read: set[str] = set()
    real_open = builtins.open

    def recording_open(file: object, mode: str = "r", *args: object, **kwargs: object) -> object:
        if isinstance(file, (str, bytes, os.PathLike)) and not any(c in mode for c in "wax+"):
            path = os.path.abspath(os.fsdecode(file))
            if not path.startswith(("/proc/", "/sys/", "/dev/")):
                read.add(path)
        return real_open(file, mode, *args, **kwargs)  # type: ignore[call-overload]

    def write() -> None:
        try:
            with real_open(deps, "w", encoding="utf-8", errors="surrogateescape") as f:
                json.dump(sorted(read), f)
        except OSError:
            pass

    builtins.open = recording_open  # type: ignore[assignment]
    atexit.register(write)


def main(argv: list[str]) -> int:
    """Expand FILE with ``name:=value`` mappings into OUT; errors go to ERR (last line)."""
    if len(argv) < 6:
        print(__doc__, file=sys.stderr)
        return 2
    out, _err, timeout, memory, packages, source, *items = argv
    lenient = "--lenient-args" in items
    overlay = next((i.partition("=")[2] for i in items if i.startswith("--overlay=")), None)
    items = [i for i in items if i != "--lenient-args" and not i.startswith("--overlay=")]
    _limits(float(timeout), int(memory))
    _install_find(packages, source)
    _subreaper()
    signal.signal(signal.SIGTERM, _stop)
    mappings = {}
    for item in items:
        key, sep, value = item.partition(":=")
        if not sep:
            print(f"bad argument {item!r}: expected name:=value", file=sys.stderr)
            return 2
        mappings[key] = value
    _record_reads(out + ".deps")
    try:
        import xacro

        _tag_origins(xacro, (os.path.realpath(source), overlay) if overlay else None)
        doc = xacro.process_file(source, mappings=mappings)
        origins = _take_origins(doc)
        data = doc.toxml(encoding="utf-8")
    except MemoryError:
        print("MemoryError: the expansion needed more memory than its limit", file=sys.stderr)
        return 1
    except BaseException as e:  # xacro raises bare Exceptions and SystemExit
        if MISSING:
            name = MISSING[-1]
            print(f"$(find {name}): package {name!r} not found; give its folder with "
                  f"`packages` ({name}=PATH) or a folder holding it with `package_paths` (or "
                  "set ROS_PACKAGE_PATH)", file=sys.stderr)
            return 1
        module = sys.modules.get("xacro")
        read = [source, *(getattr(module, "all_includes", None) or [])]
        text = _message(e, list(getattr(module, "filestack", None) or []))
        if any(k in text for k in ("is not defined", "unknown macro name", "has no value")):
            text += _unprefixed(read) or _defined_later(text, read)
        print(text, file=sys.stderr)
        return 1
    finally:
        _kill_descendants()
    unknown = sorted(set(mappings) - _declared_args([source, *xacro.all_includes]))
    if unknown and not lenient:
        from urdfkit.core.suggest import hint

        declared = sorted(_declared_args([source, *xacro.all_includes]))
        print(f"`xacro_args`: {unknown[0]!r} is not an argument of this file or its includes"
              f"{hint(unknown[0], declared)} (its arguments: {', '.join(declared) or 'none'})",
              file=sys.stderr)
        return 3  # urdfkit.sources.expand.BAD_ARGS
    import json

    with open(out + ".origins", "w", encoding="utf-8") as f:
        json.dump({"files": FILES, "origins": origins}, f)
    with open(out, "wb") as f:
        f.write(data)
    return 0


#: xacro's substitutions that work without ROS (urdfkit answers $(find) itself). Not
#: $(dirname): xacro 2.1.1 never tells its substitutions which file they stand in, so it
#: refuses $(dirname) wherever it stands, in a property or an include alike.
SUBSTITUTIONS = ("find", "arg", "env", "optenv")


def _message(e: BaseException, filestack: list[str] | None = None) -> str:
    """One line for a xacro failure: the inner error, without xacro's class-name wrapping.

    ``filestack`` is xacro's stack of files being read when it failed: its last entry other
    than the missing file is the one whose ``<xacro:include>`` named it.
    """
    import re

    lines = [ln.strip() for ln in str(e).strip().splitlines() if ln.strip()]
    if not lines:
        return type(e).__name__
    # an include of a missing file: xacro says the path twice (its text and the OSError's)
    missing = re.match(r"No such file or directory: (.+?) \[Errno 2\]", lines[0])
    if missing:
        stack = [f for f in filestack or [] if f and f != missing.group(1)]
        by = f" (included by {stack[-1]})" if stack else ""
        return f"<xacro:include> of a file that does not exist: {missing.group(1)}{by}"
    # xacro prefixes the inner exception's class and repeats its text: keep it once.
    text = re.sub(r"^<class '[\w.]+'>: ", "", lines[0])
    inner = str(getattr(e, "exc", "") or "").strip()
    if inner and text.startswith(inner) and len(text) > len(inner):
        text = inner
    context = next((ln for ln in lines[1:] if ln.startswith(("when evaluating", "when "
                                                             "instantiating"))), None)
    if context:
        text = f"{text} ({context})"
    undefined = re.match(r"Undefined substitution argument (\S+)", text)
    if undefined:
        name = undefined.group(1)
        return (f"$(arg {name}) has no value where it is used: give it with `xacro_args` "
                f"({name}:=VALUE) (a <xacro:arg> default counts only after its declaration, "
                "and never in the root element's attributes)")
    if "Cannot substitute $(dirname)" in text:
        return ("$(dirname) does not work in the xacro urdfkit runs (xacro 2.1.1 never knows "
                "which file a substitution stands in, and refuses it); write the path from "
                f"$(find PACKAGE) instead{f' ({context})' if context else ''}")
    unknown = re.search(r"Unknown substitution command \[([^\]]*)\]", text)
    if unknown:
        return (f"$({unknown.group(1)}) is a ROS substitution urdfkit cannot run; without ROS "
                f"only {', '.join(f'$({s})' for s in SUBSTITUTIONS)} work")
    return text


#: The xacro commands ROS 1's xacro read without their ``xacro:`` prefix until 1.14 (Noetic).
UNPREFIXED = ("macro", "property", "include", "arg", "insert_block", "if", "unless")


def _unprefixed(files: list[str]) -> str:
    """A note on the first xacro command written without ``xacro:`` in the files read, or "".

    xacro 1.14 (ROS Noetic) and 2.x read only ``<xacro:macro>`` and its kind: a bare
    ``<macro>`` is copied as plain XML, so its body's ``${param}`` is evaluated where no
    parameter exists, and xacro fails with "name 'param' is not defined" and no file or line
    (Toyota HSR's ``common.xacro``, written for Kinetic).
    """
    import re

    pattern = re.compile(r"<(" + "|".join(UNPREFIXED) + r")[\s/>]")
    for path in dict.fromkeys(files):
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                for number, line in enumerate(f, 1):
                    found = pattern.search(re.sub(r"<!--.*?(-->|$)", "", line))
                    if found:
                        tag = found.group(1)
                        return (f"; {path}:{number} writes <{tag}> without the xacro: prefix, "
                                "which xacro has needed since 1.14 (ROS Noetic): write "
                                f"<xacro:{tag}> (and so for every bare xacro command there)")
        except OSError:
            continue
    return ""


def _defined_later(text: str, files: list[str]) -> str:
    """Where the property xacro did not know is defined, when a file read defines it, or "".

    xacro reads in order (the default since ROS Melodic, the only way since Noetic): a
    ``<xacro:property>`` counts only below its definition. ABB YuMi's yumi.urdf.xacro
    (OrebroUniversity/yumi) uses ``${yumi_parent}`` on line 16 and defines it on line 31.
    """
    import re

    name = re.search(r"name '([A-Za-z_]\w*)' is not defined", text)
    if name is None:
        return ""
    pattern = re.compile(r"<xacro:property\s[^>]*name\s*=\s*[\"']" + re.escape(name.group(1))
                         + r"[\"']")
    for path in dict.fromkeys(files):
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                for number, line in enumerate(f, 1):
                    if pattern.search(line):
                        return (f"; {path}:{number} defines {name.group(1)!r}, but xacro "
                                "knows a property only below its definition (it reads in "
                                "order: the default since ROS Melodic, the only way since "
                                "Noetic) and, defined in a macro, only inside it: move the "
                                "definition above its first use")
        except OSError:
            continue
    return ""


def _declared_args(files: list[str]) -> set[str]:
    """The arguments the files xacro read take: every ``<xacro:arg>``, and every ``$(arg X)``.

    xacro itself accepts any ``name:=value`` and a file may use ``$(arg DEBUG)`` without
    declaring it (unitree_ros does): such a name is an argument too, only one with no default.
    """
    import re

    pattern = re.compile(rb"<xacro:arg\s[^>]*?name\s*=\s*[\"']([^\"']+)[\"']"
                         rb"|\$\(arg\s+([^)\s]+)\s*\)")
    names: set[str] = set()
    for path in set(files):
        try:
            with open(path, "rb") as f:
                for declared, used in pattern.findall(f.read()):
                    names.add((declared or used).decode("utf-8", "replace"))
        except OSError:
            continue
    return names


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
