"""Shared fixtures: built template files and a PyBullet client that always disconnects."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from urdfkit.catalog import build_template

TESTS = Path(__file__).parent


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
    from urdfkit.session import import_pybullet, quiet_stdout

    p = import_pybullet()
    with quiet_stdout():
        client = p.connect(p.DIRECT)
    try:
        yield p, client
    finally:
        with quiet_stdout():
            p.disconnect(physicsClientId=client)
