"""check leaves no reference cycles behind, file after file.

The command line runs check with the cyclic garbage collector off (it found nothing, and
scanning cost ~4% of a run), which is safe only while a checked file leaves no cycle: one
did (a nested function in a compiled rule held the whole document), and every file's tree
stayed in memory until the collector ran. Counted here on real files and on the fixtures.
"""

from __future__ import annotations

import gc
from pathlib import Path

import pybullet_data

from urdfkit.checks.check import check_paths

DATA = Path(pybullet_data.getDataPath())
FIXTURES = Path(__file__).parent / "fixtures"


def _garbage_after(paths: list[Path]) -> int:
    # A first run reads meshes it has not seen, and importing numpy for them leaves cycles
    # of its own, once; the second run is what every file costs.
    check_paths(paths, jobs=1, cache=False)
    gc.collect()
    enabled = gc.isenabled()
    gc.disable()
    try:
        result = check_paths(paths, jobs=1, cache=False)
        assert result.files
        return gc.collect()
    finally:
        if enabled:
            gc.enable()


def test_checked_files_leave_no_cycles() -> None:
    few = _garbage_after(sorted(DATA.glob("random_urdfs/00[0-2]")))
    many = _garbage_after([DATA / "random_urdfs", DATA / "quadruped", DATA / "a1",
                           DATA / "kuka_iiwa"])
    # What a run leaves once (say, the discovery closure), not per file: >300 files here.
    assert few < 40 and many < 40, (few, many)
    assert _garbage_after([FIXTURES]) < 40
