"""`urdfkit export mjcf` on disk: a kill at any step leaves an XML that MuJoCo loads with every
mesh it names, failures leave nothing of theirs behind, and `--verify` keeps only what agrees.

Kills are real: the export runs in a subprocess whose step hook (mjcf_write._reached) sends
itself SIGKILL at step k; then what is on disk is loaded in MuJoCo and each mesh file it names
is hashed against its name. A full disk is a real one too (RLIMIT_FSIZE in the subprocess).
"""

from __future__ import annotations

import hashlib
import json
import os
import resource
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import pytest
from lxml import etree
from typer.testing import CliRunner

from urdfkit.cli import app

mujoco = pytest.importorskip("mujoco")  # in the test extra: CI never skips it

runner = CliRunner()

CUBE = [(-0.5, -0.5, -0.5), (0.5, -0.5, -0.5), (0.5, 0.5, -0.5), (-0.5, 0.5, -0.5),
        (-0.5, -0.5, 0.5), (0.5, -0.5, 0.5), (0.5, 0.5, 0.5), (-0.5, 0.5, 0.5)]
FACES = [(1, 3, 2), (1, 4, 3), (5, 6, 7), (5, 7, 8), (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6),
         (3, 4, 8), (3, 8, 7), (4, 1, 5), (4, 5, 8)]


def cube_obj(size: float) -> str:
    return "".join(f"v {x * size} {y * size} {z * size}\n" for x, y, z in CUBE) + \
        "".join(f"f {a} {b} {c}\n" for a, b, c in FACES)


def cube_dae() -> str:
    points = " ".join(f"{x} {y} {z}" for x, y, z in CUBE)
    index = " ".join(str(i - 1) for f in FACES for i in f)
    return f"""<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><unit meter="1"/><up_axis>Z_UP</up_axis></asset>
 <library_geometries><geometry id="g"><mesh>
  <source id="p"><float_array id="pa" count="24">{points}</float_array>
   <technique_common><accessor source="#pa" count="8" stride="3"><param name="X" type="float"/>
   <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common>
  </source>
  <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
  <triangles count="12"><input semantic="VERTEX" source="#v" offset="0"/><p>{index}</p>
  </triangles></mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node>
 </visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def robot(meshes: list[str], lock: bool = False) -> str:
    """A base and an arm on a hinge (locked at 0.3 rad when ``lock``), a mesh per visual."""
    visuals = "".join(f'<visual><geometry><mesh filename="{m}"/></geometry></visual>'
                      for m in meshes)
    limit = 'lower="0.3" upper="0.3"' if lock else 'lower="-1" upper="1"'
    inertia = '<inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>'
    return f"""<?xml version="1.0"?>
<robot name="pair">
  <link name="base"><inertial><mass value="1"/>{inertia}</inertial>{visuals}</link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="1 0 0"/><limit {limit} effort="1" velocity="1"/></joint>
  <link name="arm"><inertial><origin xyz="0 0 0.5"/><mass value="1"/>{inertia}</inertial>
    <visual><geometry><box size="0.1 0.1 1"/></geometry></visual></link>
</robot>
"""


def version(folder: Path, v: int) -> Path:
    """The fixture robot as of version 1 (cube, part, old) or 2 (a larger cube, part)."""
    folder.mkdir(exist_ok=True)
    (folder / "cube.obj").write_text(cube_obj(1.0 if v == 1 else 2.0))
    (folder / "part.dae").write_text(cube_dae())
    (folder / "old.obj").write_text(cube_obj(0.5))
    path = folder / "robot.urdf"
    path.write_text(robot(["cube.obj", "part.dae", "old.obj"] if v == 1
                          else ["cube.obj", "part.dae"]))
    return path


def export(urdf: Path, out: Path, *args: str, code: int = 0) -> dict:
    r = runner.invoke(app, ["export", "mjcf", str(urdf), "-o", str(out), "--json", *args])
    assert r.exit_code == code, r.output
    return json.loads(r.stdout) if r.stdout.strip() else {"stderr": r.stderr}


def state(out: Path, known: dict[bytes, str]) -> str:
    """Which XML is on disk (a name from ``known``, or "none"), proven sound: every mesh it
    names is there with the bytes its name's digest says, and MuJoCo loads it."""
    if not out.exists():
        return "none"
    text = out.read_bytes()
    assert text in known, text[:200]
    folder = out.parent / f"{out.stem}_assets"
    for el in etree.fromstring(text).iterfind("asset/mesh"):
        f = folder / el.get("file")
        assert f.is_file(), f
        assert Path(el.get("file")).stem.rsplit("_", 1)[1] == \
            hashlib.sha256(f.read_bytes()).hexdigest()[:8]
    mujoco.MjModel.from_xml_path(str(out))
    return known[text]


def leftovers(folder: Path) -> list[str]:
    """Temp files and temp folders of ours anywhere under ``folder``."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob(".*"))


KILLER = """
import atexit, os, signal, sys
import urdfkit.formats.mjcf_write as files
at, steps = int(sys.argv[1]), []
def reached(step):
    steps.append(step)
    if len(steps) == at:
        os.kill(os.getpid(), signal.SIGKILL)
files._reached = reached
atexit.register(lambda: print("STEPS " + " ".join(steps), file=sys.stderr))
from urdfkit.cli import main
sys.argv = ["urdfkit", *sys.argv[2:]]
main()
"""


def run_killed(at: int, *args: str, limit: int | None = None) -> subprocess.CompletedProcess:
    """``urdfkit ARGS`` in a subprocess killed at step ``at`` (0: never)."""
    def fsize() -> None:
        if limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return subprocess.run([sys.executable, "-c", KILLER, str(at), *args], capture_output=True,
                          text=True, timeout=120, preexec_fn=fsize, check=False)


@pytest.fixture(scope="module")
def references(tmp_path_factory: pytest.TempPathFactory) -> dict[bytes, str]:
    """The XML of each version, exported whole: what a pair on disk may be."""
    known = {}
    for v in (1, 2):
        folder = tmp_path_factory.mktemp(f"v{v}")
        out = folder / "out" / "robot.xml"
        out.parent.mkdir()
        export(version(folder, v), out)
        known[out.read_bytes()] = f"v{v}"
    return known


def test_a_kill_at_any_step_leaves_a_pair_mujoco_loads(
        tmp_path: Path, references: dict[bytes, str]) -> None:
    # the steps of a re-export over version 1: the cube is new, part kept, old removed
    first = tmp_path / "probe"
    out = first / "out" / "robot.xml"
    first.mkdir()
    (first / "out").mkdir()
    export(version(first, 1), out)
    r = run_killed(0, "export", "mjcf", str(version(first, 2)), "-o", str(out), "--force")
    steps = r.stderr.split("STEPS ")[1].split()
    assert r.returncode == 0 and steps == ["locked", "cleaned", "temp", "added", "assets",
                                           "staged", "replaced", "pruned"], r.stderr
    for k, step in enumerate(steps, 1):
        here = tmp_path / f"kill{k}"
        here.mkdir()
        (here / "out").mkdir()
        out = here / "out" / "robot.xml"
        export(version(here, 1), out)
        (here / "out" / ".robot_assets.abcd_123").mkdir()  # an older urdfkit's temp folder
        r = run_killed(k, "export", "mjcf", str(version(here, 2)), "-o", str(out), "--force")
        assert r.returncode == -9, (step, r.stderr)
        assert state(out, references) == ("v2" if step in ("replaced", "pruned") else "v1"), \
            step
        # the next run finishes the job and leaves nothing of the killed one
        export(here / "robot.urdf", out, "--force")
        assert state(out, references) == "v2" and leftovers(here / "out") == [], step
        names = sorted(p.name for p in (here / "out" / "robot_assets").iterdir())
        assert [n.split("_")[0] for n in names] == ["cube", "part"], step


def test_a_killed_first_export_is_finished_by_the_next_run_without_force(
        tmp_path: Path, references: dict[bytes, str]) -> None:
    for k, step in enumerate(["locked", "temp", "added", "staged"], 1):
        here = tmp_path / f"first{k}"
        (here / "out").mkdir(parents=True)
        out = here / "out" / "robot.xml"
        urdf = version(here, 1)
        at = {"locked": 1, "temp": 3, "added": 4, "staged": 10}[step]
        r = run_killed(at, "export", "mjcf", str(urdf), "-o", str(out))
        assert r.returncode == -9 and state(out, references) == "none", (step, r.stderr)
        export(urdf, out)  # no --force needed: only this export's own files were there
        assert state(out, references) == "v1" and leftovers(here / "out") == [], step


def test_a_full_disk_leaves_the_old_pair_and_nothing_else(
        tmp_path: Path, references: dict[bytes, str]) -> None:
    (tmp_path / "out").mkdir()
    out = tmp_path / "out" / "robot.xml"
    export(version(tmp_path, 1), out)
    before = {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()}
    urdf = version(tmp_path, 2)
    big = cube_obj(2.0) + "# padding\n" * 20_000  # 200 kB: over the limit below
    (tmp_path / "cube.obj").write_text(big)
    r = run_killed(0, "export", "mjcf", str(urdf), "-o", str(out), "--force", limit=100_000)
    assert r.returncode == 2, r.stderr
    errors = [ln for ln in r.stderr.splitlines() if ln.startswith("urdfkit:")]
    assert len(errors) == 1 and "file size limit" in errors[0] and "robot_assets" in errors[0]
    assert "Traceback" not in r.stderr
    after = {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()}
    assert after == before and state(out, references) == "v1"


def test_a_symlinked_assets_folder_is_refused_and_never_followed(tmp_path: Path) -> None:
    urdf = version(tmp_path, 1)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "keep.txt").write_text("mine")
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "robot_assets").symlink_to(elsewhere)
    out = tmp_path / "out" / "robot.xml"
    for force in ([], ["--force"]):
        r = runner.invoke(app, ["export", "mjcf", str(urdf), "-o", str(out), *force])
        assert r.exit_code == 2 and "is a symlink" in r.stderr, r.output
        assert len(r.stderr.strip().splitlines()) == 1
    assert [p.name for p in elsewhere.iterdir()] == ["keep.txt"] and not out.exists()


def test_the_assets_folder_others_can_read_and_a_private_mesh_stays_private(
        tmp_path: Path) -> None:
    urdf = version(tmp_path, 1)
    os.chmod(tmp_path / "cube.obj", 0o600)
    (tmp_path / "out").mkdir()
    out = tmp_path / "out" / "robot.xml"
    old = os.umask(0o022)
    try:
        export(urdf, out)
    finally:
        os.umask(old)
    folder = tmp_path / "out" / "robot_assets"
    mode = {p.name.split("_")[0]: stat.S_IMODE(p.stat().st_mode) for p in folder.iterdir()}
    assert stat.S_IMODE(folder.stat().st_mode) == 0o755
    assert mode == {"cube": 0o600, "part": 0o644, "old": 0o644}
    assert stat.S_IMODE(out.stat().st_mode) == 0o644


def test_verify_that_disagrees_leaves_nothing_and_keeps_the_old_pair(
        tmp_path: Path, references: dict[bytes, str], monkeypatch: pytest.MonkeyPatch) -> None:
    """agree exits 1 on the staged pair. No honest robot is known to disagree any more (a
    joint with lower == upper did, until agree welded it for the swing as PyBullet holds it),
    so agree is made to report one failing row: what is kept on disk is what is tested."""
    import urdfkit.exchange.agree as agree_module

    real = agree_module.agree

    def disagreeing(*args: object, **kwargs: object) -> object:
        result = real(*args, **kwargs)  # type: ignore[arg-type]
        result.add("swing", "free swing", 1.0, 1e-9, "rad", "hinge (planted)")
        return result

    monkeypatch.setattr(agree_module, "agree", disagreeing)
    (tmp_path / "cube.obj").write_text(cube_obj(1.0))
    locked = tmp_path / "locked.urdf"
    locked.write_text(robot(["cube.obj"], lock=True))
    (tmp_path / "out").mkdir()
    out = tmp_path / "out" / "locked.xml"
    data = export(locked, out, "--verify", code=1)
    assert data["written"] is False and data["paths"] == []
    assert not data["agreement"]["ok"]
    assert list((tmp_path / "out").iterdir()) == []  # no XML, no folder, no temp file
    r = runner.invoke(app, ["export", "mjcf", str(locked), "-o", str(out), "--verify"])
    assert r.exit_code == 1 and "not written" in r.stderr and "nothing" in r.stderr
    # over an old pair: it stays as it was, byte for byte
    export(version(tmp_path, 1), out)
    before = {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()}
    export(locked, out, "--verify", "--force", code=1)
    after = {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()}
    assert after == before


def test_verify_on_a_file_mujoco_refuses_leaves_nothing(tmp_path: Path) -> None:
    """The library road: MuJoCo refuses the staged XML (a sphere of size 0), agree raises its
    one-line error naming the file the user asked for, and nothing is left."""
    from urdfkit.core.errors import InputError
    from urdfkit.exchange.agree import agree
    from urdfkit.formats.mjcf import Export, write_export
    from urdfkit.sources.resolve import resolve

    (tmp_path / "cube.obj").write_text(cube_obj(1.0))
    data = (tmp_path / "cube.obj").read_bytes()
    name = f"cube_{hashlib.sha256(data).hexdigest()[:8]}.obj"
    bad = Export(b'<mujoco><compiler meshdir="bad_assets"/><asset><mesh name="m" file="'
                 + name.encode() + b'"/></asset><worldbody><body><geom type="sphere" '
                 b'size="0"/></body></worldbody></mujoco>\n',
                 {name: tmp_path / "cube.obj"}, "bad_assets",
                 digests={name: hashlib.sha256(data).hexdigest()})
    out = tmp_path / "out" / "bad.xml"
    out.parent.mkdir()
    with resolve(version(tmp_path / "v", 1)) as r, pytest.raises(InputError) as e:
        write_export(bad, out, verify=lambda staged: agree(r, staged).ok)
    assert e.value.file == str(out) and "MuJoCo" in e.value.message
    assert list(out.parent.iterdir()) == []
    shutil.rmtree(tmp_path / "v")
