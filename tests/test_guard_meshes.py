"""Mesh files PyBullet 3.2.7 crashes or hangs on, with its raw outcome: U712 and U713.

As tests/test_guard.py does for the URDF's own crash classes, every row is measured against
raw PyBullet (``loadURDF`` in a subprocess with a timeout) on each run, so a PyBullet that
stops crashing shows up here; the guard must refuse every row whose raw outcome is a crash or
a hang, in one line naming the URDF, the line of the ``<mesh>`` and the mesh, and let every
row PyBullet loads through. Where a NaN falls decides between a segfault, an endless loop and
a load (urdfkit.sources.meshfaults says why), so the table holds rows of all three that the
guard refuses alike, and the neighbours it must let through: the same NaN in a visual mesh or
a ``concave`` collision, a NaN on every vertex, infinities, an ASCII STL.
"""

from __future__ import annotations

import json
import math
import struct
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest
from test_guard import raw_outcome
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.sources import meshfaults

NAN, INF = math.nan, math.inf
MESHES = Path(__file__).parent / "fixtures" / "meshes"

#: The unit cube's corners and triangles (outward), as tests/fixtures/meshes/unit_cube.stl.
CORNERS = [(float(x), float(y), float(z)) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
TRIANGLES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7),
             (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]


def corners(changes: dict[tuple[int, int], float] | None = None) -> list[list[float]]:
    """The cube's corners, with ``{(corner, axis): value}`` written over them."""
    points = [list(c) for c in CORNERS]
    for (corner, axis), value in (changes or {}).items():
        points[corner][axis] = value
    return points


def every(value: float) -> dict[tuple[int, int], float]:
    return {(c, a): value for c in range(8) for a in range(3)}


def stl(points: list[list[float]]) -> bytes:
    """A binary STL (the only kind PyBullet 3.2.7 reads)."""
    out = b"urdfkit test mesh".ljust(80, b" ") + struct.pack("<I", len(TRIANGLES))
    for tri in TRIANGLES:
        out += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *points[i])
                                                      for i in tri) + b"\0\0"
    return out


def ascii_stl(points: list[list[float]]) -> bytes:
    facets = "".join(" facet normal 0 0 0\n  outer loop\n" + "".join(
        f"   vertex {' '.join(str(v) for v in points[i])}\n" for i in tri)
        + "  endloop\n endfacet\n" for tri in TRIANGLES)
    return f"solid c\n{facets}endsolid c\n".encode()


def obj(points: list[list[float]], extra: str = "") -> bytes:
    return ("".join(f"v {' '.join(str(v) for v in p)}\n" for p in points) + extra
            + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in TRIANGLES)).encode()


ASSET = '<asset><unit meter="1" name="m"/><up_axis>Z_UP</up_axis></asset>'


def dae(points: list[list[float]] | None = None, asset: str = ASSET, geometry: bool = True,
        after: str = "") -> bytes:
    values = " ".join(str(v) for p in (points or corners()) for v in p)
    index = " ".join(str(i) for tri in TRIANGLES for i in tri)
    library = (f'<library_geometries><geometry id="c"><mesh><source id="c-pos">'
               f'<float_array id="c-pos-a" count="24">{values}</float_array>'
               '<technique_common><accessor source="#c-pos-a" count="8" stride="3"/>'
               '</technique_common></source><vertices id="c-v"><input semantic="POSITION" '
               'source="#c-pos"/></vertices><triangles count="12"><input semantic="VERTEX" '
               f'source="#c-v" offset="0"/><p>{index}</p></triangles></mesh></geometry>'
               '</library_geometries>') if geometry else ""
    return ('<?xml version="1.0"?>\n<COLLADA xmlns="http://www.collada.org/2005/11/'
            f'COLLADASchema" version="1.4.1">\n{asset}\n{library}\n<library_visual_scenes>'
            '<visual_scene id="s"><node id="n"><instance_geometry url="#c"/></node>'
            '</visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/>'
            f"</scene>{after}\n</COLLADA>\n").encode()


@dataclass(frozen=True)
class Case:
    """One mesh, how a link uses it, PyBullet 3.2.7's raw outcome, and the guard's code."""

    name: str
    mesh: bytes
    suffix: str
    part: str  # "visual", "collision" or "concave" (<collision concave="yes">)
    raw: str  # "crash" (a signal), "hang" (still running after the timeout), "loads"
    code: str | None  # what every loading command refuses it as; None: let through
    refusal: str = ""  # a fragment of the refusal
    scale: str | None = None


CASES = [
    # 1. COLLADA whose reader PyBullet crashes, visual or collision alike.
    Case("dae without <asset> (visual)", (MESHES / "no_asset.dae").read_bytes(), ".dae",
         "visual", "crash", "U712", "has no <asset> element in its <COLLADA>"),
    Case("dae without <asset> (collision)", (MESHES / "no_asset.dae").read_bytes(), ".dae",
         "collision", "crash", "U712", "has no <asset> element"),
    Case("dae with an empty <asset/>", dae(asset="<asset/>"), ".dae", "visual", "loads", None),
    Case("dae with its <asset> last", dae(asset="", after="<asset/>"), ".dae", "visual",
         "loads", None),
    Case("dae with a prefixed <c:asset>", dae(asset='<c:asset xmlns:c="urn:c"><c:unit '
                                                    'meter="1"/></c:asset>'),
         ".dae", "visual", "crash", "U712", "has no <asset> element"),
    Case("dae whose <unit> has no meter", dae(asset='<asset><unit name="m"/></asset>'), ".dae",
         "visual", "crash", "U712", "<unit> without a meter attribute"),
    Case("dae whose <up_axis> is blank", dae(asset="<asset><up_axis> </up_axis></asset>"),
         ".dae", "visual", "crash", "U712", "<up_axis> without text"),
    Case("dae without <library_geometries>", dae(geometry=False), ".dae", "visual", "crash",
         "U712", "has no <library_geometries>"),
    Case("dae of a declaration and a comment only", b'<?xml version="1.0"?>\n<!-- none -->\n',
         ".dae", "visual", "crash", "U712", "holds no XML element"),
    Case("dae tinyxml2 cannot parse", dae(asset="").replace(b"</COLLADA>", b""), ".dae",
         "visual", "loads", None),
    # 2. NaN in a collision mesh PyBullet builds a convex hull of.
    Case("binary STL, z of one corner NaN", (MESHES / "nan_vertex.stl").read_bytes(), ".stl",
         "collision", "hang", "U713", "mix NaN with numbers along z"),
    Case("binary STL, one corner all NaN", stl(corners({(0, a): NAN for a in range(3)})),
         ".stl", "collision", "crash", "U713", "along x and y and z"),
    Case("binary STL, x of one corner NaN", stl(corners({(7, 0): NAN})), ".stl", "collision",
         "loads", "U713", "along x"),  # loads by where it falls: refused with the rest
    Case("binary STL, the NaN corner as a visual", (MESHES / "nan_vertex.stl").read_bytes(),
         ".stl", "visual", "loads", None),
    Case("binary STL, the NaN corner in a concave collision",
         (MESHES / "nan_vertex.stl").read_bytes(), ".stl", "concave", "loads", None),
    Case("binary STL, every corner NaN", stl(corners(every(NAN))), ".stl", "collision",
         "loads", None),
    Case("binary STL, x NaN on every corner (scale nan 1 1)", stl(corners()), ".stl",
         "collision", "loads", None, scale="nan 1 1"),
    Case("binary STL, one corner infinite", stl(corners({(7, 2): INF})), ".stl", "collision",
         "loads", None),
    Case("binary STL, one NaN beside an infinity on its axis",
         stl(corners({(0, 2): NAN, (7, 2): -INF})), ".stl", "collision", "loads", None),
    Case("ASCII STL, one corner NaN (PyBullet reads no ASCII STL)",
         ascii_stl(corners({(7, 2): NAN})), ".stl", "collision", "loads", None),
    Case("OBJ, z of one vertex NaN", obj(corners({(7, 2): NAN})), ".obj", "collision", "hang",
         "U713", "mix NaN with numbers along z"),
    Case("OBJ, a NaN vertex no face uses", obj(corners(), "v nan nan nan\n"), ".obj",
         "collision", "loads", None),
    Case("OBJ, one corner infinite", obj(corners({(7, 2): INF})), ".obj", "collision", "loads",
         None),
    Case("dae, one corner all NaN", dae(corners({(0, a): NAN for a in range(3)})), ".dae",
         "collision", "crash", "U713", "mix NaN with numbers"),
    Case("dae, one corner all NaN, as a visual", dae(corners({(0, a): NAN for a in range(3)})),
         ".dae", "visual", "loads", None),
]

#: The <mesh> is on this line of every case's URDF.
MESH_LINE = 6


def robot_urdf(case: Case) -> str:
    tag = "visual" if case.part == "visual" else "collision"
    concave = ' concave="yes"' if case.part == "concave" else ""
    scale = f' scale="{case.scale}"' if case.scale else ""
    return "\n".join([
        '<robot name="r">',
        '<link name="a">',
        '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'
        "</inertial>",
        f"<{tag}{concave}>",
        "<geometry>",
        f'<mesh filename="mesh{case.suffix}"{scale}/>',
        "</geometry>",
        f"</{tag}>",
        "</link>",
        "</robot>",
        ""])


def write(folder: Path, case: Case) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"mesh{case.suffix}").write_bytes(case.mesh)
    path = folder / "robot.urdf"
    path.write_text(robot_urdf(case))
    return path


IDS = [c.name for c in CASES]
REFUSED = [c for c in CASES if c.code is not None]


def test_raw_pybullet_still_behaves_as_recorded(tmp_path: Path) -> None:
    # Re-measured every run (two at a time; the hangs cost their 5 s timeout).
    paths = [write(tmp_path / str(i), case) for i, case in enumerate(CASES)]
    with ThreadPoolExecutor(max_workers=2) as pool:
        outcomes = list(pool.map(lambda path: raw_outcome(path, timeout=5.0), paths))
    assert [(c.name, got) for c, got in zip(CASES, outcomes, strict=True) if got != c.raw] == []


def test_the_table_refuses_every_crash_and_hang() -> None:
    assert {c.raw for c in CASES} == {"crash", "hang", "loads"}
    assert all(c.code is not None for c in CASES if c.raw != "loads")


@pytest.mark.parametrize("case", REFUSED, ids=[c.name for c in REFUSED])
def test_every_loading_command_refuses_in_one_named_line(tmp_path: Path, case: Case) -> None:
    path = write(tmp_path, case)
    for command in (["joints"], ["links", "--json"], ["info"], ["render", "-o", "-"],
                    ["joints", "--json", "--no-guard"]):
        result = CliRunner().invoke(app, [command[0], str(path), *command[1:]])
        assert result.exit_code == 2, (command, result.stderr)
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1, lines
        assert lines[0].startswith(f"urdfkit: error: {path}:{MESH_LINE}: <mesh filename="
                                   f"'mesh{case.suffix}'>"), lines[0]
        assert case.refusal in lines[0] and "Traceback" not in result.output


@pytest.mark.parametrize("case", REFUSED, ids=[c.name for c in REFUSED])
def test_check_reports_the_same_rule_as_an_error(tmp_path: Path, case: Case) -> None:
    path = write(tmp_path, case)
    result = CliRunner().invoke(app, ["check", str(path), "--json", "--no-cache"])
    assert result.exit_code == 1, result.output
    found = [(f["code"], f["line"], f["level"]) for f in json.loads(result.stdout)["findings"]
             if f["code"] in ("U712", "U713")]
    assert found == [(case.code, MESH_LINE, "error")]


LET_THROUGH = [c for c in CASES if c.code is None]


@pytest.mark.parametrize("case", LET_THROUGH, ids=[c.name for c in LET_THROUGH])
def test_what_pybullet_loads_is_let_through(tmp_path: Path, case: Case) -> None:
    path = write(tmp_path, case)
    result = CliRunner().invoke(app, ["joints", str(path), "--json"])
    assert result.exit_code == 0, result.stderr
    checked = CliRunner().invoke(app, ["check", str(path), "--json", "--no-cache"])
    assert not [f for f in json.loads(checked.stdout)["findings"]
                if f["code"] in ("U712", "U713")]


def test_a_nan_in_one_obj_object_is_judged_on_its_own_hull(tmp_path: Path) -> None:
    # PyBullet hulls each OBJ object apart: an object NaN along x on every vertex loads beside
    # a sound one (measured); the same NaN mixed into the sound object's hull is refused.
    sound = "".join(f"v {x} {y} {z}\n" for x, y, z in CORNERS)
    nan_x = "".join(f"v nan {y} {z}\n" for _, y, z in CORNERS)
    faces = ("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in TRIANGLES),
             "".join(f"f {a + 9} {b + 9} {c + 9}\n" for a, b, c in TRIANGLES))
    apart = tmp_path / "apart.obj"
    apart.write_text(f"o a\n{sound}{faces[0]}o b\n{nan_x}{faces[1]}")
    together = tmp_path / "together.obj"
    together.write_text(f"o a\n{sound}{nan_x}{faces[0]}{faces[1]}")
    assert meshfaults.hull_fault(str(apart)) is None
    assert "mix NaN with numbers along x" in (meshfaults.hull_fault(str(together)) or "")


def test_the_scale_applies_before_the_hull(tmp_path: Path) -> None:
    # An infinity times a zero scale is a NaN beside the other corners' zeros, as in PyBullet.
    mesh = tmp_path / "inf.stl"
    mesh.write_bytes(stl(corners({(7, 0): INF})))
    assert meshfaults.hull_fault(str(mesh), (1.0, 1.0, 1.0)) is None
    assert "along x" in (meshfaults.hull_fault(str(mesh), (0.0, 1.0, 1.0)) or "")


@pytest.mark.parametrize(("asset", "fault"), [
    ('<asset><up_axis><!-- c -->Z_UP</up_axis></asset>', "without text"),  # tinyxml2's text
    ('<asset><up_axis><![CDATA[Z_UP]]></up_axis></asset>', None),  # is the first child's
    ('<asset><unit/><unit meter="1"/></asset>', "without a meter"),  # the first <unit>
    ('<asset/><asset><unit/></asset>', None),  # the first <asset>
])
def test_collada_is_read_as_tinyxml2_reads_it(asset: str, fault: str | None) -> None:
    # Each measured on PyBullet 3.2.7: the faults crash it, the others load.
    found = meshfaults.collada_data_fault(dae(asset=asset))
    assert (found is None) if fault is None else (fault in (found or ""))


CLEAN = """
import sys
from urdfkit.cli import main
sys.argv = ["urdfkit", *sys.argv[1:]]
try:
    main()
except SystemExit as e:
    print("EXIT", e.code, "numpy" in sys.modules)
"""


def test_sound_meshes_are_scanned_without_numpy(tmp_path: Path) -> None:
    # The guard runs on every load: a sound collision STL, OBJ and COLLADA are scanned at C
    # speed; only a file that fails the scan is read into numpy arrays. `tree` proves it, as
    # it runs the guard and loads no PyBullet (whose module imports numpy itself).
    for suffix, data in ((".stl", stl(corners())), (".obj", obj(corners())), (".dae", dae())):
        path = write(tmp_path / suffix[1:], Case("sound", data, suffix, "collision", "loads",
                                                 None))
        done = subprocess.run([sys.executable, "-c", CLEAN, "tree", str(path), "--json"],
                              capture_output=True, text=True, timeout=60)
        assert done.stdout.split()[-3:] == ["EXIT", "0", "False"], (suffix, done.stderr)
    hang = next(c for c in CASES if c.raw == "hang" and c.suffix == ".stl")
    done = subprocess.run([sys.executable, "-c", CLEAN, "tree", str(write(tmp_path / "nan", hang)),
                           "--json"], capture_output=True, text=True, timeout=60)
    assert done.stdout.split()[-3:] == ["EXIT", "0", "True"]  # the scan found it, and read it
    assert "mix NaN with numbers" in done.stderr and "not needed to read the tree" in done.stderr


def test_build_writes_no_urdf_whose_mesh_pybullet_crashes_on(tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch
                                                             ) -> None:
    # build writes what PyBullet loads; a mesh it crashes on is refused as a missing one is
    # (exit 1, nothing written), by the same rule.
    monkeypatch.chdir(tmp_path)
    for code in ("U712", "U713"):
        case = next(c for c in REFUSED if c.code == code)
        folder = tmp_path / code
        urdf = write(folder, case)
        source = folder / "robot.urdf.xacro"
        source.write_text(urdf.read_text().replace(
            '<robot name="r">', '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'))
        result = CliRunner().invoke(app, ["build", str(source), "-o", str(folder / "out.urdf")])
        assert result.exit_code == 1, result.output
        assert f"({case.code}); nothing written" in result.output
        assert not (folder / "out.urdf").exists()
