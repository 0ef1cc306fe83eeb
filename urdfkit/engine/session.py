"""The one place that talks to PyBullet's connection: connect, flags, quiet, disconnect.

PyBullet's C++ core prints diagnostics (``b3Printf``, URDF warnings, even "pybullet build
time" on import) with C ``printf`` to file descriptor 1. A Python-level ``redirect_stdout``
never sees them, and they would corrupt ``--json`` output. So every call that can print runs
inside :func:`quiet_stdout`, which points fd 1 at a temp file with ``os.dup2``, flushes the C
stdio buffer through ctypes before restoring it, and hands the captured text back as
diagnostics. The redirect stays in place across ``disconnect()``, which prints too.
"""

from __future__ import annotations

import ctypes
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, overload

from urdfkit.core import deps
from urdfkit.core.errors import EngineError
from urdfkit.model.spec import MAX_STATE_LINKS

_libc: Any = None


def _c_fflush() -> None:
    global _libc
    try:
        if _libc is None:
            _libc = ctypes.CDLL(None)
        _libc.fflush(None)
    except (OSError, AttributeError):  # pragma: no cover - non-POSIX libc
        pass


class Captured:
    """Text the C side printed while :func:`quiet_stdout` was active."""

    __slots__ = ("text",)

    def __init__(self) -> None:
        self.text = ""

    @property
    def lines(self) -> list[str]:
        """Non-empty lines, stripped."""
        return [ln.strip() for ln in self.text.splitlines() if ln.strip()]


_depth = 0


def _sink() -> Any:
    # A file, not a pipe: a pipe that nobody drains blocks PyBullet once 64 KiB of warnings
    # pile up. An anonymous memory file where Linux has one (and no tempfile import, which
    # costs a millisecond of every command's start-up); a temp file elsewhere.
    if hasattr(os, "memfd_create"):
        try:
            return os.fdopen(os.memfd_create("urdfkit-stdout", os.MFD_CLOEXEC), "w+b")
        except OSError:
            pass
    import tempfile

    return tempfile.TemporaryFile(mode="w+b")


@contextmanager
def quiet_stdout() -> Iterator[Captured]:
    """Capture everything written to fd 1 (C and Python) while the block runs.

    Re-entrant: an inner block captures nothing of its own; the outermost one collects all.
    """
    global _depth
    from urdfkit.core.stdio import LOCK

    captured = Captured()
    with LOCK:  # no other thread prints, or redirects, while fd 1 points elsewhere
        if _depth > 0:
            _depth += 1
            try:
                yield captured
            finally:
                _depth -= 1
            return
        yield from _capture_fd1(captured)


def _capture_fd1(captured: Captured) -> Iterator[Captured]:
    """The outermost :func:`quiet_stdout` block: fd 1 into a temporary file, then back."""
    global _depth
    sys.stdout.flush()
    _c_fflush()
    saved = os.dup(1)
    sink = _sink()
    os.dup2(sink.fileno(), 1)
    _depth = 1
    try:
        yield captured
    finally:
        try:
            sys.stdout.flush()
        except (OSError, ValueError):
            pass
        _c_fflush()
        os.dup2(saved, 1)
        os.close(saved)
        _depth = 0
        sink.seek(0)
        captured.text = sink.read().decode("utf-8", "replace")
        sink.close()


@contextmanager
def quiet_stderr() -> Iterator[Captured]:
    """Keep what C code prints on fd 2 (urdfdom's "Error:" lines) while the block runs.

    The text is on the returned :class:`Captured` once the block ends; fd 2 is back.
    """
    from urdfkit.core.stdio import LOCK

    captured = Captured()
    with LOCK:  # no other thread writes to fd 2 while it points elsewhere
        sys.stderr.flush()
        _c_fflush()
        saved = os.dup(2)
        sink = _sink()
        os.dup2(sink.fileno(), 2)
        try:
            yield captured
        finally:
            _c_fflush()
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            captured.text = sink.read().decode("utf-8", "replace")
            sink.close()


def import_pybullet() -> Any:
    """Import pybullet without letting its "build time" banner reach stdout."""
    if "pybullet" in sys.modules:
        return sys.modules["pybullet"]
    # The banner goes to stderr (fd 2) in the PyPI 3.2.7 wheels, to stdout in other builds:
    # silence both, so `urdfkit ... 2>&1` shows only what urdfkit says.
    sys.stderr.flush()
    saved_err = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    try:
        with quiet_stdout():
            # numpy first, from Python: when pybullet's C module init pulls numpy in itself
            # (import_array), `urdfkit joints` measured 3 to 4 ms slower end to end.
            try:
                import numpy  # noqa: F401
            except ImportError:  # pragma: no cover - pybullet built without numpy
                pass
            import pybullet
    finally:
        _c_fflush()
        os.dup2(saved_err, 2)
        os.close(saved_err)
        os.close(devnull)
    return pybullet


def has_display() -> bool:
    """Whether a GUI window can open: a display on Linux; always on macOS and Windows."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
                or sys.platform in ("darwin", "win32"))


#: The flags LoadOptions has a field for; any other p.URDF_* name goes to ``extra_flags``.
FLAG_FIELDS = {"URDF_USE_INERTIA_FROM_FILE": "inertia_from_file",
               "URDF_USE_IMPLICIT_CYLINDER": "implicit_cylinder",
               "URDF_USE_SELF_COLLISION": "self_collision",
               "URDF_MERGE_FIXED_LINKS": "merge_fixed_links"}


def parse_flags(text: str) -> dict[str, Any]:
    """``--flags A,B`` (or ``none``) as LoadOptions fields: exactly these flags, nothing else.

    Raises:
        ParameterError: a name that is not one of PyBullet's ``URDF_*`` flags.
    """
    from urdfkit.core.errors import ParameterError

    names = [n.strip().upper() for n in text.split(",") if n.strip()]
    if names in (["NONE"], ["0"]):
        names = []
    p = import_pybullet()
    known = sorted(n for n in dir(p) if n.startswith("URDF_"))
    out: dict[str, Any] = dict.fromkeys(FLAG_FIELDS.values(), False)
    extra, extra_names = 0, []
    for name in names:
        full = next((c for c in (name, f"URDF_{name}", f"URDF_USE_{name}") if c in known),
                    name if name.startswith("URDF_") else f"URDF_{name}")
        if full not in known:
            from urdfkit.core.suggest import hint

            raise ParameterError(f"`flags`: {name!r} is not a PyBullet loadURDF flag"
                                 f"{hint(full, known)} (or give none)", param="flags")
        if full in FLAG_FIELDS:
            out[FLAG_FIELDS[full]] = True
        else:
            extra |= int(getattr(p, full))
            extra_names.append(full)
    out["extra_flags"] = extra
    out["extra_names"] = tuple(extra_names)
    return out


@dataclass
class LoadOptions:
    """How to load a URDF.

    Attributes:
        fixed_base: Pin the root link to the world.
        inertia_from_file: Use the file's ``<inertia>``. Without this flag PyBullet discards
            it and recomputes inertia from the collision shapes.
        implicit_cylinder: Load cylinders as true cylinders. Without it PyBullet turns them
            into convex meshes, and wheels roll on facets.
        self_collision: Enable collisions between the robot's own links.
        merge_fixed_links: Let PyBullet merge links joined by fixed joints (changes indices).
        base_position: Where the root link starts.
        base_orientation: Quaternion (x, y, z, w) of the root link.
        global_scaling: Scale the whole model.
        extra_flags: Further ``p.URDF_*`` flags, or-ed in (render's URDF_IGNORE_VISUAL_SHAPES).
    """

    fixed_base: bool = False
    inertia_from_file: bool = False
    implicit_cylinder: bool = True
    self_collision: bool = False
    merge_fixed_links: bool = False
    base_position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    base_orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)
    global_scaling: float = 1.0
    extra_flags: int = 0
    #: The names of ``extra_flags`` (for messages and JSON), as the user gave them.
    extra_names: tuple[str, ...] = ()

    def flag_names(self) -> list[str]:
        """The ``loadURDF`` flags these options mean, by name (``p.URDF_*``)."""
        names = [name for on, name in (
            (self.inertia_from_file, "URDF_USE_INERTIA_FROM_FILE"),
            (self.implicit_cylinder, "URDF_USE_IMPLICIT_CYLINDER"),
            (self.self_collision, "URDF_USE_SELF_COLLISION"),
            (self.merge_fixed_links, "URDF_MERGE_FIXED_LINKS")) if on]
        return names + [n for n in self.extra_names if n not in names]

    def flags(self, p: Any) -> int:
        """The ``loadURDF`` flags these options mean."""
        flags = self.extra_flags
        if self.inertia_from_file:
            flags |= p.URDF_USE_INERTIA_FROM_FILE
        if self.implicit_cylinder:
            flags |= p.URDF_USE_IMPLICIT_CYLINDER
        if self.self_collision:
            flags |= p.URDF_USE_SELF_COLLISION
        if self.merge_fixed_links:
            flags |= p.URDF_MERGE_FIXED_LINKS
        return flags


#: Per module: its public constants (and ``error``), and its functions by name; split once.
_SPLITS: dict[Any, tuple[dict[str, Any], list[tuple[str, Any]]]] = {}


def _split(module: Any) -> tuple[dict[str, Any], list[tuple[str, Any]]]:
    split = _SPLITS.get(module)
    if split is None:
        constants: dict[str, Any] = {}
        functions: list[tuple[str, Any]] = []
        for name, attr in vars(module).items():
            if name.startswith("_"):
                continue
            if callable(attr) and not isinstance(attr, type):
                functions.append((name, attr))
            else:
                constants[name] = attr
        split = _SPLITS[module] = (constants, functions)
    return split


class Bullet:
    """The pybullet module with one client's id bound to every call.

    ``bullet.stepSimulation()`` is ``p.stepSimulation(physicsClientId=client)``: the id is
    bound here once (as ``pybullet_utils.bullet_client.BulletClient`` does), so no other module
    passes ``physicsClientId``. Every function is bound when the object is made (~60 us for
    PyBullet's 144) and kept as a plain attribute beside the module's constants
    (``bullet.POSITION_CONTROL``) and ``bullet.error``. No ``__getattr__`` runs: CPython
    specialises no attribute access on a class with one, and each ``bullet.name`` cost ~390
    instructions more than ``p.name`` (callgrind, bench/README.md, issue 39). A call
    ``bullet.f(...)`` still costs ~240 more than ``p.f(...)`` (3.11 specialises no method call
    on an instance attribute); ``f = bullet.f`` outside a hot loop, then ``f(...)``, costs what
    ``p.f(...)`` does. The partial itself adds nothing to a call without keywords and ~900
    instructions to one with keywords (it copies its own into a new dict).
    """

    client: int

    def __init__(self, module: Any, client: int) -> None:
        import functools

        constants, functions = _split(module)
        names = self.__dict__
        names.update(constants)
        bind = functools.partial
        names.update({name: bind(fn, physicsClientId=client) for name, fn in functions})
        self._module = module
        self.client = client

    if TYPE_CHECKING:
        # PyBullet's functions and constants, bound above: Any to the type checker.
        def __getattr__(self, name: str) -> Any: ...


#: Per module, the binding a closed session keeps (client -1: every call fails).
_CLOSED: dict[Any, Bullet] = {}


class Session:
    """A PyBullet physics client of its own (DIRECT by default), quiet on stdout.

    Several sessions can live in one process; each has its own ``client`` id, which
    :attr:`bullet` binds to every call.

    Use it as a context manager so the client is always disconnected::

        with Session() as s:
            body = s.load_urdf("car.urdf")
            print(s.bullet.getNumJoints(body))

    Attributes:
        gui: Whether the client is a GUI window rather than DIRECT.
        diagnostics: What PyBullet printed on stdout so far, line by line.
        p: The pybullet module (unbound: its constants, ``p.error``).
        bullet: The pybullet module with this client bound to every call (:class:`Bullet`).
        client: The physics client id; -1 once closed.
    """

    def __init__(self, gui: bool = False) -> None:
        if gui and not has_display():
            # PyBullet's GUI exits the whole process when it cannot reach an X server.
            raise EngineError("the PyBullet GUI needs a display, and DISPLAY is not set")
        self.gui = gui
        self.diagnostics: list[str] = []
        self.client = -1
        self._loaded: dict[str, tuple[int, int, int, int]] = {}  # path -> deps.version
        self.p: Any = import_pybullet()
        with quiet_stdout() as out:
            mode = self.p.GUI if gui else self.p.DIRECT
            try:
                self.client = self.p.connect(mode)
            except self.p.error as e:  # pragma: no cover - needs a display
                raise EngineError(f"cannot connect to PyBullet: {e}") from None
        self.diagnostics.extend(out.lines)
        if self.client < 0:
            raise EngineError("cannot open the PyBullet GUI: no display available "
                              "(set DISPLAY, or drop --gui)")
        #: pybullet with this client bound: ``session.bullet.getNumJoints(body)``.
        self.bullet = Bullet(self.p, self.client)

    def __enter__(self) -> Session:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Disconnect, keeping stdout quiet while PyBullet tears down."""
        if self.client >= 0:
            with quiet_stdout() as out:
                try:
                    self.p.disconnect(physicsClientId=self.client)
                except self.p.error:
                    pass
            self.diagnostics.extend(out.lines)
            self.client = -1
            # Calls after close fail as on any closed client, and never reach a later client
            # that PyBullet gives the same id. One such binding serves every closed session.
            self.bullet = _CLOSED.get(self.p) or _CLOSED.setdefault(self.p, Bullet(self.p, -1))

    def call(self, fn: str, *args: Any, **kwargs: Any) -> Any:
        """Call ``p.<fn>`` on this client with stdout captured into :attr:`diagnostics`."""
        out = None
        try:
            with quiet_stdout() as out:
                return getattr(self.bullet, fn)(*args, **kwargs)
        finally:
            # Only after the with block has exited does ``out`` hold the captured text.
            if out is not None:
                self.diagnostics.extend(out.lines)

    def load_urdf(self, path: str | Path, options: LoadOptions | None = None,
                  display: str | None = None) -> int:
        """Load a URDF file that has already passed the guard; return the body id.

        Callers must run :func:`urdfkit.sources.guard.guard` first: PyBullet segfaults on some
        malformed files instead of raising.
        """
        o = options or LoadOptions()
        name = display or str(path)
        self._forget_changed_files(str(path))
        try:
            return int(self.call(
                "loadURDF", str(path), basePosition=o.base_position,
                baseOrientation=o.base_orientation, useFixedBase=o.fixed_base,
                flags=o.flags(self.p), globalScaling=o.global_scaling,
            ))
        except self.p.error:
            said = "; ".join(self.diagnostics[-3:])
            raise EngineError(f"PyBullet could not load it{': ' + said if said else ''}",
                              file=name) from None

    def _forget_changed_files(self, path: str) -> None:
        """Make PyBullet read a file again that changed since this client loaded it.

        PyBullet caches every file it reads, by name, for the life of the client: loading a
        URDF, editing it and loading it again gives the old robot (measured on 3.2.7). When
        this session sees a path again with another size, time or inode, it turns that cache
        off for the rest of the session (setPhysicsEngineParameter(enableFileCaching=0)).
        """
        try:
            st = os.stat(path)
        except OSError:
            return
        sig = deps.version(st)
        if self._loaded.setdefault(path, sig) != sig:
            self._loaded[path] = sig
            self.call("setPhysicsEngineParameter", enableFileCaching=0)

    def require_state_queries(self, body: int, display: str) -> None:
        """Refuse bodies whose state PyBullet cannot report (128 links or more).

        ``getBasePositionAndOrientation``, ``getJointState`` and ``getLinkState`` raise on
        such bodies (MAX_DEGREE_OF_FREEDOM), so simulating commands check before they start.
        """
        links = self.bullet.getNumJoints(body) + 1
        if links >= MAX_STATE_LINKS:
            raise EngineError(f"{links} links: PyBullet cannot report the state of bodies with "
                              f"{MAX_STATE_LINKS} links or more; split the model",
                              file=display)


@overload
def restore_clean(bullet: Bullet, state: int, bodies: Sequence[int], /) -> None: ...
@overload
def restore_clean(p: Any, client: int, state: int, bodies: Sequence[int], /) -> None: ...
def restore_clean(*args: Any) -> None:
    """``restoreState`` and nothing carried over: the way to an in-place reset.

    restoreState puts positions and velocities back but leaves the contact manifolds of the
    moment before, with their cached impulses, so the next step depended on the episode
    before (measured on 3.2.7: a car's path differed by 0.2 m). Moving the bodies apart and
    running collision detection drops those manifolds; a second restore puts the bodies back.
    After :func:`prime_resets`, every reset continues exactly as a fresh load does.

    Takes the session's :class:`Bullet`; the older ``(p, client, state, bodies)`` form is kept
    for callers that still hold the module and the id.
    """
    bullet, state, bodies = _bound(args)
    bullet.restoreState(state)
    for k, body in enumerate(bodies):
        bullet.resetBasePositionAndOrientation(body, [1.0e4 * (k + 1), 0.0, 1.0e4],
                                               [0, 0, 0, 1])
    bullet.performCollisionDetection()
    bullet.restoreState(state)


@overload
def prime_resets(bullet: Bullet, state: int, bodies: Sequence[int], /) -> None: ...
@overload
def prime_resets(p: Any, client: int, state: int, bodies: Sequence[int], /) -> None: ...
def prime_resets(*args: Any) -> None:
    """Bring a new world to the state every :func:`restore_clean` reset leaves, at ``state``.

    The engine's contact bookkeeping after a reset differs from a fresh world's until it has
    been through one step and one reset; doing that here makes the first episode like all
    later ones (tested bitwise against reloading every file). Takes the same arguments as
    :func:`restore_clean`.
    """
    bullet, state, bodies = _bound(args)
    bullet.stepSimulation()
    restore_clean(bullet, state, bodies)
    bullet.stepSimulation()
    restore_clean(bullet, state, bodies)


def _bound(args: tuple[Any, ...]) -> tuple[Bullet, int, Sequence[int]]:
    """``(bullet, state, bodies)`` from either form :func:`restore_clean` takes."""
    if len(args) == 4:  # (p, client, state, bodies)
        p, client, state, bodies = args
        return Bullet(p, client), state, bodies
    bullet, state, bodies = args
    return bullet, state, bodies


#: What each of PyBullet's inverse-dynamics calls computes, for messages.
DYNAMICS_CALLS = {"calculateMassMatrix": "the mass matrix",
                  "calculateInverseDynamics": "the inverse dynamics",
                  "calculateJacobian": "Jacobians"}


def dynamics_call(bullet: Bullet, fn: str, body: int, *args: Any, **kwargs: Any) -> Any:
    """One of PyBullet's inverse-dynamics calls (:data:`DYNAMICS_CALLS`), quiet on stdout.

    The three share one model of the body, which PyBullet builds at the first of them and
    which can fail on a body that loads and simulates: KUKA KR210's link_2 inertia
    (tests/fixtures/robots/id_asymmetric.urdf) makes each raise SystemError and print
    "invalid inertia tensor" on fd 1 (measured on 3.2.7, fixed base or floating, the file's
    inertia or PyBullet's). Quieting costs 21 us over the bare call's 3 us (KUKA iiwa's mass
    matrix, measured), so callers need it only for the first call on a body: later ones meet
    the same model, built or refused.

    Raises:
        EngineError: PyBullet refused; the message is why, as a clause for the caller's
            sentence ("its inverse-dynamics model finds the inertia of link 'link_1' ...").
    """
    out: Captured | None = None
    try:
        with quiet_stdout() as out:
            return getattr(bullet, fn)(body, *args, **kwargs)
    except (SystemError, bullet.error) as e:
        # SystemError from PyBullet wraps its own error: say that one's text.
        said = str(e.__cause__ or e.__context__ or e)
    assert out is not None  # filled once the with block has exited
    raise EngineError(dynamics_refusal(bullet, body, out.lines, fn, said)) from None


def dynamics_refusal(bullet: Bullet, body: int, lines: Sequence[str], fn: str,
                     said: str) -> str:
    """Why PyBullet's ``fn`` failed on ``body``, from what it printed (``lines``) and raised.

    PyBullet's inverse-dynamics model wants each link's inertia tensor exactly symmetric. A
    URDF's always is (six numbers), but PyBullet keeps the principal moments and axes and
    rebuilds the tensor from them, and for some products of inertia the rebuilt tensor
    differs from its transpose in the last bit (KR210's link_2: 7e-15 of 33.8). It prints
    that once, at the first call, naming the link as "body N": the tree's body 0 is the base,
    body N link N - 1 (measured: a fixed joint between counts, fixed base or floating).
    """
    import re

    for line in lines:
        m = re.search(r"invalid inertia tensor for body (\d+) (I\(\d,\d\))!=(I\(\d,\d\))\. "
                      r"\S+=\s*(\S+)", line)
        if m is None:
            continue
        index = int(m.group(1)) - 1
        try:
            name = (bullet.getBodyInfo(body)[0] if index == -1
                    else bullet.getJointInfo(body, index)[12]).decode("utf-8", "replace")
            link = f"link {name[:80]!r}"
        except bullet.error:
            link = f"its body {index + 1}"
        try:
            gap = f"by {abs(float(m.group(4))):.2g} ({m.group(2)} - {m.group(3)})"
        except ValueError:
            gap = f"({m.group(2)} != {m.group(3)})"
        return (f"its inverse-dynamics model finds the inertia of {link} asymmetric {gap} "
                "once rebuilt from the principal axes PyBullet stores; a PyBullet rounding "
                "limit, not an error in the file")
    printed = [ln for ln in lines if not ln.startswith(("b3Error", "b3Warning"))]
    detail = "; ".join([said, *printed[-2:]])
    if len(detail) > 200:
        detail = detail[:197] + "..."
    return f"PyBullet's {fn} failed ({detail})"
