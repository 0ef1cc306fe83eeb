"""check's result cache: a warm run says exactly what a fresh run says, and a change to any
dependency (the file, a mesh, a package.xml, a xacro include, a YAML file, an option)
invalidates exactly the files that use it. Damaged or half-written entries are never trusted."""

from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from urdfkit.checks.check import check_paths
from urdfkit.checks.resultcache import FOLDER, ResultCache


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv("URDFKIT_CACHE_DIR", str(folder))
    return folder


def _stl(path: Path, size: float) -> None:
    """A binary STL cube of edge ``size`` (12 triangles, outward normals not needed)."""
    h = size / 2
    v = [(x, y, z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    data = b"\0" * 80 + struct.pack("<I", len(faces))
    for f in faces:
        data += struct.pack("<3f", 0, 0, 0)
        for i in f:
            data += struct.pack("<3f", *v[i])
        data += b"\0\0"
    path.write_bytes(data)


INERTIA = 'ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"'
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base">
    <inertial><mass value="1"/><inertia {INERTIA}/></inertial>
    <collision><geometry><mesh filename="{mesh}"/></geometry></collision>
  </link>
  <link name="tip">
    <inertial><mass value="1"/><inertia {INERTIA}/></inertial>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
""".replace("{INERTIA}", INERTIA)


def _codes(result: object, name: str) -> set[str]:
    return {f.code for fr in result.files  # type: ignore[attr-defined]
            if Path(fr.file).name == name for f in fr.findings}


def _cached(result: object) -> dict[str, bool]:
    return {Path(fr.file).name: fr.cached for fr in result.files}  # type: ignore[attr-defined]


def _fresh(paths: list[Path], **kw: object) -> list[dict[str, object]]:
    return check_paths(paths, jobs=1, cache=False, **kw).to_dict()["findings"]  # type: ignore[arg-type, return-value]


def test_a_warm_run_reports_what_a_fresh_run_reports(cache: Path, simplecar_urdf: Path) -> None:
    import pybullet_data

    data = Path(pybullet_data.getDataPath())
    paths = [data / "quadruped", data / "kuka_iiwa", data / "r2d2.urdf", simplecar_urdf]
    first = check_paths(paths, jobs=1)
    assert not any(fr.cached for fr in first.files)
    second = check_paths(paths, jobs=1)
    assert all(fr.cached for fr in second.files) and len(second.files) > 10
    fresh = _fresh(paths)
    assert first.to_dict()["findings"] == second.to_dict()["findings"] == fresh
    assert fresh  # not vacuous: these files have findings
    # select/ignore filter after the cache: a hit with a filter equals a fresh filtered run
    only = check_paths(paths, jobs=1, select=["U6"])
    assert all(fr.cached for fr in only.files)
    assert only.to_dict()["findings"] == _fresh(paths, select=["U6"])


def test_the_file_itself_and_its_mesh_invalidate_only_their_file(cache: Path,
                                                                tmp_path: Path) -> None:
    (tmp_path / "m").mkdir()
    _stl(tmp_path / "m" / "a.stl", 0.1)
    _stl(tmp_path / "m" / "b.stl", 0.1)
    a, b = tmp_path / "a.urdf", tmp_path / "b.urdf"
    a.write_text(ARM.format(mesh="m/a.stl"))
    b.write_text(ARM.format(mesh="m/b.stl"))
    before = _codes(check_paths([tmp_path], jobs=1), "a.urdf")
    assert _cached(check_paths([tmp_path], jobs=1)) == {"a.urdf": True, "b.urdf": True}
    # a mesh 1000x larger: a.urdf's findings change (its inertia no longer fits the shape),
    # and b.urdf, which does not use that mesh, is still a hit
    _stl(tmp_path / "m" / "a.stl", 100.0)
    warm = check_paths([tmp_path], jobs=1)
    assert _cached(warm) == {"a.urdf": False, "b.urdf": True}
    assert _codes(warm, "a.urdf") != before
    assert warm.to_dict()["findings"] == _fresh([tmp_path])
    # the file itself
    b.write_text(ARM.format(mesh="m/b.stl").replace('effort="1"', 'effort="2"'))
    assert _cached(check_paths([tmp_path], jobs=1)) == {"a.urdf": True, "b.urdf": False}


def test_a_mesh_answered_from_memory_is_still_a_dependency(cache: Path,
                                                           tmp_path: Path) -> None:
    # The mesh's integrals come from memory (a run without the result cache read them), so
    # no mesh reader runs while the entry is recorded: the reference's own note of the path
    # is what must record it (the mesh lookup relies on it and does not note it again).
    (tmp_path / "m").mkdir()
    _stl(tmp_path / "m" / "a.stl", 0.1)
    robot = tmp_path / "a.urdf"
    robot.write_text(ARM.format(mesh="m/a.stl"))
    check_paths([tmp_path], jobs=1, cache=False)
    before = _codes(check_paths([tmp_path], jobs=1), "a.urdf")
    assert _cached(check_paths([tmp_path], jobs=1)) == {"a.urdf": True}
    _stl(tmp_path / "m" / "a.stl", 100.0)
    warm = check_paths([tmp_path], jobs=1)
    assert _cached(warm) == {"a.urdf": False}
    assert _codes(warm, "a.urdf") != before


def test_a_missing_mesh_that_appears_invalidates_the_file(cache: Path, tmp_path: Path) -> None:
    robot = tmp_path / "r.urdf"
    robot.write_text(ARM.format(mesh="later.stl"))
    assert "U701" in _codes(check_paths([robot], jobs=1), "r.urdf")
    _stl(tmp_path / "later.stl", 0.1)
    again = check_paths([robot], jobs=1)
    assert _cached(again) == {"r.urdf": False} and "U701" not in _codes(again, "r.urdf")


def test_a_package_xml_change_invalidates_the_files_it_resolved(cache: Path,
                                                               tmp_path: Path) -> None:
    # The folder is not named after the package: only its package.xml says it is my_robot.
    pkg = tmp_path / "ws" / "src_checkout"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "urdf").mkdir()
    _stl(pkg / "meshes" / "a.stl", 0.1)
    (pkg / "package.xml").write_text("<package><name>my_robot</name></package>")
    robot = pkg / "urdf" / "r.urdf"
    robot.write_text(ARM.format(mesh="package://my_robot/meshes/a.stl"))
    other = tmp_path / "other.urdf"
    other.write_text(ARM.format(mesh="nothing.stl"))
    first = check_paths([robot, other], jobs=1)
    assert not {"U701", "U702"} & _codes(first, "r.urdf")
    assert _cached(check_paths([robot, other], jobs=1)) == {"r.urdf": True, "other.urdf": True}
    (pkg / "package.xml").write_text("<package><name>another_robot</name></package>")
    again = check_paths([robot, other], jobs=1)
    assert _cached(again) == {"r.urdf": False, "other.urdf": True}
    assert again.to_dict()["findings"] == _fresh([robot, other])
    assert _codes(again, "r.urdf") != _codes(first, "r.urdf")


XACRO_TOP = """<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="inc.xacro"/>
  <xacro:property name="p" value="${xacro.load_yaml('params.yaml')}"/>
  <link name="base">
    <inertial><mass value="${p['mass']}"/><inertia {INERTIA}/></inertial>
  </link>
  <xacro:arm/>
</robot>
""".replace("{INERTIA}", INERTIA)
XACRO_INC = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="arm">
    <link name="tip">
      <inertial><mass value="{mass}"/><inertia {INERTIA}/></inertial>
    </link>
    <joint name="j" type="fixed"><parent link="base"/><child link="tip"/></joint>
  </xacro:macro>
</robot>
""".replace("{INERTIA}", INERTIA)


def test_a_xacro_include_and_its_yaml_invalidate_the_top_file(cache: Path,
                                                             tmp_path: Path) -> None:
    (tmp_path / "top.urdf.xacro").write_text(XACRO_TOP)
    (tmp_path / "inc.xacro").write_text(XACRO_INC.format(mass=1))
    (tmp_path / "params.yaml").write_text("mass: 1.0\n")
    (tmp_path / "other.urdf").write_text(ARM.format(mesh="none.stl"))
    first = check_paths([tmp_path], jobs=1)
    assert "U601" not in _codes(first, "top.urdf.xacro")
    assert _cached(check_paths([tmp_path], jobs=1))["top.urdf.xacro"] is True
    (tmp_path / "inc.xacro").write_text(XACRO_INC.format(mass=-1))  # a negative mass
    warm = check_paths([tmp_path], jobs=1)
    assert _cached(warm)["top.urdf.xacro"] is False and _cached(warm)["other.urdf"] is True
    assert warm.to_dict()["findings"] == _fresh([tmp_path])
    assert _codes(warm, "top.urdf.xacro") != _codes(first, "top.urdf.xacro")
    (tmp_path / "inc.xacro").write_text(XACRO_INC.format(mass=1))
    check_paths([tmp_path], jobs=1)
    (tmp_path / "params.yaml").write_text("mass: -2.0\n")
    warm = check_paths([tmp_path], jobs=1)
    assert _cached(warm)["top.urdf.xacro"] is False
    assert warm.to_dict()["findings"] == _fresh([tmp_path])


def test_options_that_change_findings_are_part_of_the_key(cache: Path, tmp_path: Path) -> None:
    (tmp_path / "r.urdf.xacro").write_text(
        '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:arg name="m" default="1"/>\n  <link name="a"><inertial><mass '
        'value="$(arg m)"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
        '</inertial></link>\n</robot>\n')
    check_paths([tmp_path], jobs=1)
    other = check_paths([tmp_path], jobs=1, xacro_args={"m": "-1"})
    assert _cached(other) == {"r.urdf.xacro": False}
    assert other.to_dict()["findings"] == _fresh([tmp_path], xacro_args={"m": "-1"})
    assert _cached(check_paths([tmp_path], jobs=1, no_exec=True)) == {"r.urdf.xacro": False}


def test_damaged_entries_are_never_trusted(cache: Path, tmp_path: Path,
                                           simplecar_urdf: Path) -> None:
    robot = tmp_path / "r.urdf"
    robot.write_text(ARM.format(mesh="missing.stl"))
    truth = _fresh([robot])
    check_paths([robot], jobs=1)
    entries = [p for p in (cache / FOLDER).rglob("*.json") if p.parent.name != "runs"]
    assert len(entries) == 1
    for damage in (entries[0].read_bytes()[:20],  # cut short
                   b'{"deps": {}, "findings": [1, 2]}',  # the wrong shape
                   b'{"deps": {}, "findings": [{"code": "U999", "level": "error"}]}',
                   b"\xff\xfe not json"):
        entries[0].write_bytes(damage)
        result = check_paths([robot], jobs=1)
        assert _cached(result) == {"r.urdf": False}
        assert result.to_dict()["findings"] == truth
    # the entry was rewritten whole: the next run is a hit again
    assert _cached(check_paths([robot], jobs=1)) == {"r.urdf": True}
    # an entry replaced by a FIFO is skipped, not waited on
    entries[0].unlink()
    os.mkfifo(entries[0])
    assert check_paths([robot], jobs=1).to_dict()["findings"] == truth


@pytest.mark.slow
def test_two_checks_at_once_both_report_the_truth(cache: Path, tmp_path: Path) -> None:
    import pybullet_data

    data = Path(pybullet_data.getDataPath()) / "random_urdfs"
    cmd = [sys.executable, "-m", "urdfkit", "check", str(data), "--json", "--jobs", "1"]
    env = dict(os.environ, URDFKIT_CACHE_DIR=str(cache))
    procs = [subprocess.Popen(cmd, stdout=subprocess.PIPE, env=env) for _ in range(2)]
    outs = [json.loads(p.communicate(timeout=300)[0]) for p in procs]
    fresh = json.loads(subprocess.run([*cmd, "--no-cache"], stdout=subprocess.PIPE, env=env,
                                      timeout=300).stdout)
    assert outs[0]["findings"] == outs[1]["findings"] == fresh["findings"]
    warm = json.loads(subprocess.run(cmd, stdout=subprocess.PIPE, env=env,
                                     timeout=300).stdout)
    assert warm["findings"] == fresh["findings"]


def test_off_switches_write_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                    simplecar_urdf: Path) -> None:
    folder = tmp_path / "cache"
    monkeypatch.setenv("URDFKIT_CACHE_DIR", str(folder))
    check_paths([simplecar_urdf], jobs=1, cache=False)
    assert not (folder / FOLDER).exists()
    monkeypatch.setenv("URDFKIT_CACHE_DIR", "")
    check_paths([simplecar_urdf], jobs=1)
    assert not (folder / FOLDER).exists() and ResultCache.open({}) is None


def test_the_cache_is_capped_and_the_oldest_entries_go(cache: Path, tmp_path: Path) -> None:
    store = ResultCache.open({})
    assert store is not None
    for i in range(40):
        key = f"{i:02d}" + "0" * 38
        store.put(key, {}, [{"code": "U000", "level": "error", "message": "x" * 1000,
                             "file": "f", "line": None, "origin": None}])
        os.utime(store._entry(key), ns=(i * 10**9, i * 10**9))
    sizes = sum(p.stat().st_size for p in (cache / FOLDER).rglob("*.json"))
    removed = store.trim(limit=sizes // 2)
    left = sorted(p.name[:2] for p in (cache / FOLDER).rglob("*.json"))
    assert removed > 0 and len(left) == 40 - removed
    assert left == [f"{i:02d}" for i in range(removed, 40)]  # the newest stay
    assert sum(p.stat().st_size for p in (cache / FOLDER).rglob("*.json")) <= sizes // 2 * 3 // 4


def test_a_fresh_checkout_hits_and_a_same_size_edit_misses(cache: Path, tmp_path: Path) -> None:
    # CI restores the cache onto a fresh checkout: every file has a new mtime (and inode),
    # the same bytes. The stat differs, so the dependency is read and compared by digest.
    _stl(tmp_path / "a.stl", 0.1)
    robot = tmp_path / "r.urdf"
    robot.write_text(ARM.format(mesh="a.stl"))
    check_paths([robot], jobs=1)
    for path in (robot, tmp_path / "a.stl"):
        data = path.read_bytes()
        path.unlink()
        path.write_bytes(data)  # a new inode
        os.utime(path, ns=(10**18, 10**18))  # and a new mtime
    assert _cached(check_paths([robot], jobs=1)) == {"r.urdf": True}
    # the same size, different bytes: a miss (a 0.1 m cube becomes a 0.2 m one)
    _stl(tmp_path / "b.stl", 0.2)
    os.replace(tmp_path / "b.stl", tmp_path / "a.stl")
    os.utime(tmp_path / "a.stl", ns=(10**18, 10**18))
    assert _cached(check_paths([robot], jobs=1)) == {"r.urdf": False}


def test_the_keyed_size_limit_is_the_readers() -> None:
    from urdfkit.checks import resultcache
    from urdfkit.model import xmlio

    assert resultcache.MAX_FILE_BYTES == xmlio.MAX_FILE_BYTES


# The run manifest: one file per run that lets a re-run skip reading each file and its entry.

def _manifest_hits(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    from urdfkit.checks.resultcache import RunManifest

    hits: list[str] = []
    lookup = RunManifest.lookup

    def counted(self: RunManifest, display: str, path: str) -> object:
        found = lookup(self, display, path)
        if found is not None:
            hits.append(Path(path).name)
        return found

    monkeypatch.setattr(RunManifest, "lookup", counted)
    return hits


def test_an_unchanged_tree_is_answered_from_the_manifest(
        cache: Path, settled: None, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _stl(tmp_path / "a.stl", 0.1)
    (tmp_path / "r.urdf").write_text(ARM.format(mesh="a.stl"))
    (tmp_path / "s.urdf").write_text(ARM.format(mesh="missing.stl"))
    truth = _fresh([tmp_path])
    hits = _manifest_hits(monkeypatch)
    check_paths([tmp_path], jobs=1)
    assert hits == []  # no manifest yet
    # Remove every per-file entry: what is still a hit can only come from the manifest.
    for entry in (cache / FOLDER).rglob("*.json"):
        if entry.parent.name != "runs":
            entry.unlink()
    warm = check_paths([tmp_path], jobs=1)
    assert sorted(hits) == ["r.urdf", "s.urdf"]
    assert _cached(warm) == {"r.urdf": True, "s.urdf": True}
    assert warm.to_dict()["findings"] == truth


def test_the_manifest_misses_on_any_change(cache: Path, settled: None, tmp_path: Path,
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    _stl(tmp_path / "a.stl", 0.1)
    robot, other = tmp_path / "r.urdf", tmp_path / "s.urdf"
    robot.write_text(ARM.format(mesh="a.stl"))
    other.write_text(ARM.format(mesh="missing.stl"))
    check_paths([tmp_path], jobs=1)
    hits = _manifest_hits(monkeypatch)
    # A mesh of another size: only the file that reads it misses, and its findings change.
    _stl(tmp_path / "a.stl", 0.3)
    result = check_paths([tmp_path], jobs=1)
    assert hits == ["s.urdf"]
    assert result.to_dict()["findings"] == _fresh([tmp_path])
    # An edit that keeps the size and puts the mtime back: the ctime still tells.
    hits.clear()
    before = os.stat(robot)
    text = robot.read_text().replace('upper="1"', 'upper="2"')
    robot.write_text(text)
    os.utime(robot, ns=(before.st_atime_ns, before.st_mtime_ns))
    assert os.stat(robot).st_size == before.st_size
    result = check_paths([tmp_path], jobs=1)
    assert hits == ["s.urdf"]
    assert result.to_dict()["findings"] == _fresh([tmp_path])


def test_a_file_written_just_before_a_run_is_read_again(cache: Path, tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    # Within the clock's grain an edit can keep a file's stat (git's "racily clean" entry):
    # a file modified less than two seconds before the run that recorded it is never trusted.
    # (In a folder of its own: the missing mesh's U701 depends on its folder's listing, which
    # the cache folder appearing in tmp_path would change.)
    robot = tmp_path / "robot" / "r.urdf"
    robot.parent.mkdir()
    robot.write_text(ARM.format(mesh="missing.stl"))
    check_paths([robot], jobs=1)
    hits = _manifest_hits(monkeypatch)
    assert _cached(check_paths([robot], jobs=1)) == {"r.urdf": True}  # by its content
    assert hits == []


def test_a_damaged_manifest_is_never_trusted(cache: Path, settled: None,
                                            tmp_path: Path) -> None:
    robot = tmp_path / "r.urdf"
    robot.write_text(ARM.format(mesh="missing.stl"))
    truth = _fresh([robot])
    check_paths([robot], jobs=1)
    (manifest,) = (cache / FOLDER / "runs").glob("*.json")
    good = json.loads(manifest.read_bytes())
    record = good["files"][str(robot)]
    wrong_findings = [record[0], record[1], record[2], [{"code": "U999"}]]
    for damage in (manifest.read_bytes()[:30], b"[]", b'{"started": "x", "files": {}}',
                   json.dumps({"started": good["started"],
                               "files": {str(robot): wrong_findings}}).encode(),
                   json.dumps({"started": good["started"],
                               "files": {str(robot): ["other.urdf", *record[1:]]}}).encode()):
        manifest.write_bytes(damage)
        assert check_paths([robot], jobs=1).to_dict()["findings"] == truth
    manifest.unlink()
    os.mkfifo(manifest)  # a FIFO in its place is skipped, not waited on
    assert check_paths([robot], jobs=1).to_dict()["findings"] == truth


def _rescale_in_place(path: Path, size: float) -> None:
    """Rewrite a mesh's bytes in place (same inode, same size), its mtime put back."""
    before = os.stat(path)
    _stl(path, size)
    os.utime(path, ns=(before.st_atime_ns, before.st_mtime_ns))
    after = os.stat(path)
    assert (after.st_size, after.st_mtime_ns, after.st_ino) == \
        (before.st_size, before.st_mtime_ns, before.st_ino)


@pytest.mark.parametrize("cached", [True, False])
def test_a_mesh_rescaled_in_place_with_its_mtime_kept_gives_fresh_findings(
        cache: Path, tmp_path: Path, cached: bool) -> None:
    # A binary STL in millimetres rescaled to metres keeps its triangle count, so its size;
    # a tool that puts the mtime back (rsync -t, tar, a careful script) keeps that too. Only
    # the ctime (and the bytes) tell: every cache must see the edit, the result cache's and
    # the mesh cache's, in memory and on disk.
    folder = tmp_path / "robot"
    folder.mkdir()
    _stl(folder / "a.stl", 100.0)  # 100 m across: U613, millimetres read as metres
    robot = folder / "r.urdf"
    robot.write_text(ARM.format(mesh="a.stl").replace(
        "</robot>", '<joint name="k" type="fixed"><parent link="tip"/><child link="c"/>'
        '<origin xyz="0 0 0.3"/></joint><link name="c"/></robot>'))
    assert "U613" in _codes(check_paths([robot], jobs=1, cache=cached), "r.urdf")
    _rescale_in_place(folder / "a.stl", 0.1)
    truth = subprocess.run(
        [sys.executable, "-m", "urdfkit", "check", "--json", str(robot)],
        env={**os.environ, "URDFKIT_CACHE_DIR": ""}, capture_output=True, text=True)
    fresh = {f["code"] for f in json.loads(truth.stdout)["findings"]}
    assert "U613" not in fresh
    assert _codes(check_paths([robot], jobs=1, cache=cached), "r.urdf") == fresh
