"""Shared fixtures: built template files and a PyBullet client that always disconnects."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from urdfkit.model.catalog import build_template

TESTS = Path(__file__).parent

# Tests import mujoco themselves, before urdfkit's engine would choose EGL for a headless
# MuJoCo picture (urdfkit/engine/mujoco.py: import_mujoco): choose it as the engine does.
if not os.environ.get("DISPLAY"):
    os.environ.setdefault("MUJOCO_GL", "egl")


@pytest.fixture(scope="session", autouse=True)
def private_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """The suite's own urdfkit cache folder: never the user's ~/.cache (CLI subprocesses too)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("URDFKIT_CACHE_DIR", str(tmp_path_factory.mktemp("urdfkit-cache")))
        yield


@pytest.fixture(scope="session")
def simplecar_urdf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """simplecar.urdf built with default parameters, in a temp folder."""
    path = tmp_path_factory.mktemp("templates") / "simplecar.urdf"
    build_template("simplecar").write(path)
    return path


@pytest.fixture(scope="session")
def simpleplane_urdf(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """simpleplane.urdf built with default parameters, in a temp folder."""
    path = tmp_path_factory.mktemp("templates") / "simpleplane.urdf"
    build_template("simpleplane").write(path)
    return path


@pytest.fixture
def pb() -> Iterator[tuple[object, int]]:
    """A raw PyBullet DIRECT client: (pybullet module, client id); disconnected on teardown."""
    from urdfkit.engine.session import import_pybullet, quiet_stdout

    p = import_pybullet()
    with quiet_stdout():
        client = p.connect(p.DIRECT)
    try:
        yield p, client
    finally:
        with quiet_stdout():
            p.disconnect(physicsClientId=client)



@pytest.fixture
def free_swing(pb: tuple[object, int]) -> Callable[[Path, float], tuple[float, list[float]]]:
    """Raw PyBullet on a one-joint robot, base fixed, with its file's inertia: ``M_00`` at the
    zero pose, and the joint's speeds over 8 steps of ``dt`` under gravity, motor and link
    damping off (only the joint damping and gravity act)."""
    from urdfkit.engine.session import quiet_stdout

    p: Any
    p, c = pb

    def swing(path: Path, dt: float) -> tuple[float, list[float]]:
        p.resetSimulation(physicsClientId=c)
        with quiet_stdout():
            body = p.loadURDF(str(path), useFixedBase=True, flags=p.URDF_USE_INERTIA_FROM_FILE,
                              physicsClientId=c)
        inertia = p.calculateMassMatrix(body, [0.0], physicsClientId=c)[0][0]
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        p.setTimeStep(dt, physicsClientId=c)
        p.setJointMotorControl2(body, 0, p.VELOCITY_CONTROL, force=0, physicsClientId=c)
        for link in (-1, 0):
            p.changeDynamics(body, link, linearDamping=0, angularDamping=0, physicsClientId=c)
        speeds = []
        for _ in range(8):
            p.stepSimulation(physicsClientId=c)
            speeds.append(p.getJointState(body, 0, physicsClientId=c)[1])
        return inertia, speeds

    return swing


@pytest.fixture
def raw_loads() -> Callable[[Path], bool]:
    """Whether raw PyBullet loads a URDF: ``p.loadURDF(path)``, nothing else, in a child
    process (its C text goes to fd 1; a crash stays there)."""
    import subprocess
    import sys

    code = ("import sys, pybullet as p\nc = p.connect(p.DIRECT)\n"
            "try:\n    p.loadURDF(sys.argv[1])\nexcept p.error:\n    sys.exit(1)\n")

    def loads(path: Path) -> bool:
        return subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True,
                              timeout=60).returncode == 0

    return loads


# --------------------------------------------------------------------------- skips in CI

#: Test ids (prefixes) CI may skip. With URDFKIT_CI=1 (.ci/run sets it) any other skip fails
#: the run: CI installs Ray, pyarrow, Graphviz and Chromium, so a skip there means a test it is
#: meant to run did not run.
ALLOWED_CI_SKIPS: tuple[str, ...] = ()
_skipped: list[tuple[str, str]] = []


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    if report.skipped and not hasattr(report, "wasxfail"):
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
        _skipped.append((report.nodeid, reason))


def _unexpected() -> list[tuple[str, str]]:
    return [(n, r) for n, r in _skipped
            if not (ALLOWED_CI_SKIPS and n.startswith(ALLOWED_CI_SKIPS))]


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    if os.environ.get("URDFKIT_CI") and exitstatus == 0 and _unexpected():
        session.exitstatus = 1


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    if os.environ.get("URDFKIT_CI") and _unexpected():
        terminalreporter.write_line(
            f"URDFKIT_CI: {len(_unexpected())} test(s) skipped that CI must run:", red=True)
        for nodeid, reason in _unexpected():
            terminalreporter.write_line(f"  {nodeid}: {reason}", red=True)


# --------------------------------------------------------------------------- a browser

#: Debian's Chromium (Playwright's own download is not reachable); URDFKIT_CHROMIUM overrides.
CHROMIUM = "/usr/bin/chromium"
#: Software WebGL: the machines the suite runs on have no GPU.
CHROMIUM_ARGS = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]


@pytest.fixture
def plain_lighting(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> None:
    """Viewer pages lit as by default (``URDFKIT_VIEW_ENVIRONMENT=none``: a sky light).

    A test marked ``environment_map`` gets viser's own environment map (``city``) instead:
    software WebGL prefilters it on every page, ~6 s of each page's first frame here
    (docs/view.md).
    """
    if request.node.get_closest_marker("environment_map") is None:
        monkeypatch.setenv("URDFKIT_VIEW_ENVIRONMENT", "none")
    else:
        monkeypatch.setenv("URDFKIT_VIEW_ENVIRONMENT", "city")


def _chromium() -> Iterator[Any]:
    """Debian's Chromium under Playwright (software WebGL), closed at the end.

    A skip where there is none; CI installs it (.ci/run), and URDFKIT_CI=1 fails the skip.
    """
    import shutil

    path = os.environ.get("URDFKIT_CHROMIUM") or shutil.which("chromium") or CHROMIUM
    if not os.path.exists(path):
        pytest.skip(f"no Chromium at {path}: apt-get install -y chromium (CI does)")
    sync_api = pytest.importorskip("playwright.sync_api",
                                   reason="pip install playwright (in urdfkit[test])")
    with sync_api.sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=path, args=CHROMIUM_ARGS)
        try:
            yield b
        finally:
            b.close()


@pytest.fixture
def chromium() -> Iterator[Any]:
    """:func:`_chromium` for one test."""
    yield from _chromium()


@pytest.fixture(scope="module")
def module_chromium() -> Iterator[Any]:
    """:func:`_chromium` shared by a module's tests (each closes the pages it opens)."""
    yield from _chromium()


@pytest.fixture
def settled(monkeypatch: pytest.MonkeyPatch) -> None:
    """The test's files count as settled: changed long before the run (as a checked-out
    tree's are), which a test cannot fake (no call sets a ctime back) nor wait two seconds for.
    """
    from urdfkit.checks import resultcache
    from urdfkit.core import deps

    monkeypatch.setattr(deps, "RACY_NS", 0)
    monkeypatch.setattr(resultcache, "RACY_NS", 0)


# --------------------------------------------------------------------------- viewers and pages


@pytest.fixture
def viewers() -> Iterator[Callable[..., Any]]:
    """Start ``urdfkit view`` servers (``Viewer(path, **kwargs)``); each closed after the test."""
    from urdfkit.draw.view import Viewer

    started: list[Any] = []

    def start(path: Path | str, **kwargs: Any) -> Any:
        v = Viewer(str(path), **kwargs)
        started.append(v)
        return v

    yield start
    for v in started:
        v.close()


@pytest.fixture
def open_view(module_chromium: Any) -> Iterator[Callable[..., Any]]:
    """Open a viewer's page in Chromium and wait until it says "Connected"; closed after.

    A page left open keeps drawing WebGL in software and starves the next tests of CPU.
    """
    opened: list[Any] = []

    def open_page(url: str, width: int = 1000, height: int = 700) -> Any:
        page = module_chromium.new_page(viewport={"width": width, "height": height})
        opened.append(page)
        page.goto(url)
        page.get_by_text("Connected").wait_for(timeout=60000)
        return page

    yield open_page
    for page in opened:
        page.close()


def wait_until(cond: Callable[[], Any], seconds: float = 20.0) -> bool:
    """Whether ``cond()`` came true within ``seconds`` (asked every 0.05 s, and once more at
    the end): the page and server tests' one wait."""
    import time

    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.05)
    return bool(cond())
