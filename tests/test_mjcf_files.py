"""The files an MJCF makes MuJoCo open (urdfkit/formats/mjcf_files.py), checked first.

Each rule of where MuJoCo 4.0 looks is held against MuJoCo itself: the walk names the file,
MuJoCo loads the layout, and the mesh or body it loaded is the one in that file. Then a FIFO
put where MuJoCo looks is refused (file and line of the reference), and a FIFO where it does
not look is not. `urdfkit agree` on a real FIFO ends at once, exit 2, in a subprocess with a
timeout (it hung forever before).
"""

from __future__ import annotations

import os
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from urdfkit.core.errors import InputError
from urdfkit.formats.mjcf_files import MAX_MJCF_FILES, check_mjcf_files

mujoco = pytest.importorskip("mujoco")  # in the test extra: CI never skips it

ROBOT = Path(__file__).parent / "fixtures" / "robots" / "short_finger.urdf"
MESH = '<asset><mesh name="m" file="{}"/></asset><worldbody><geom type="mesh" mesh="m"/>' \
    '</worldbody>'


def _stl(scale: float) -> bytes:
    """A binary STL tetrahedron with legs of ``scale`` m (MuJoCo reads no ASCII STL)."""
    v = [(0, 0, 0), (scale, 0, 0), (0, scale, 0), (0, 0, scale)]
    out = b"\0" * 80 + struct.pack("<I", 4)
    for a, b, c in ((0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)):
        out += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v[i])
                                                     for i in (a, b, c)) + b"\0\0"
    return out


def _lay_out(root: Path, files: dict[str, str | float]) -> Path:
    for name, content in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, float):
            path.write_bytes(_stl(content))
        else:
            path.write_text(f"<mujoco>{content}</mujoco>")
    return root / "top.xml"


def _loaded(top: Path) -> str:
    """What MuJoCo loaded: the mesh's leg length, or the last body's name."""
    m = mujoco.MjModel.from_xml_path(str(top))
    if m.nmesh:
        # the tetrahedron's longest edge, whichever way MuJoCo turned and moved it: sqrt(2) legs
        v = m.mesh_vert
        edge = max(float(((a - b) ** 2).sum()) ** 0.5 for a in v for b in v)
        return f"{edge / 2 ** 0.5:.3f}"
    return mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, m.nbody - 1)


#: (rule, layout, the file MuJoCo opens, what it then loads, a candidate it does not open)
RULES = [
    ("an include: the top model's folder first",
     {"top.xml": '<include file="sub/a.xml"/>', "sub/a.xml": '<include file="b.xml"/>',
      "b.xml": '<worldbody><body name="top_b"/></worldbody>',
      "sub/b.xml": '<worldbody><body name="sub_b"/></worldbody>'},
     "b.xml", "top_b", "sub/b.xml"),
    ("an include: then the including file's folder",
     {"top.xml": '<include file="sub/a.xml"/>', "sub/a.xml": '<include file="b.xml"/>',
      "sub/b.xml": '<worldbody><body name="sub_b"/></worldbody>'},
     "sub/b.xml", "sub_b", "sub/sub/b.xml"),
    ("a mesh: meshdir, from the top model's folder",
     {"top.xml": '<compiler meshdir="meshes"/><include file="sub/m.xml"/>',
      "sub/m.xml": MESH.format("m.stl"), "meshes/m.stl": 4.0, "sub/m.stl": 2.0},
     "meshes/m.stl", "4.000", "sub/m.stl"),
    ("a mesh in an included file: then that file's folder, without meshdir",
     {"top.xml": '<compiler meshdir="meshes"/><include file="sub/m.xml"/>',
      "sub/m.xml": MESH.format("m.stl"), "sub/m.stl": 2.0},
     "sub/m.stl", "2.000", "sub/meshes/m.stl"),
    ("a compiler after the assets, in an included file, replaces meshdir",
     {"top.xml": '<compiler meshdir="md1"/>' + MESH.format("m.stl") + '<include file="c.xml"/>',
      "c.xml": '<compiler meshdir="md2"/>', "md2/m.stl": 2.0},
     "md2/m.stl", "2.000", "md1/m.stl"),
    ("meshdir wins over assetdir in the same element",
     {"top.xml": '<compiler meshdir="md" assetdir="ad"/>' + MESH.format("m.stl"),
      "md/m.stl": 3.0},
     "md/m.stl", "3.000", "ad/m.stl"),
    ("a later assetdir replaces an earlier meshdir",
     {"top.xml": '<compiler meshdir="md"/><compiler assetdir="ad"/>' + MESH.format("m.stl"),
      "ad/m.stl": 3.0},
     "ad/m.stl", "3.000", "md/m.stl"),
    ("strippath drops a mesh's folders",
     {"top.xml": '<compiler strippath="true"/>' + MESH.format("x/y/m.stl"), "m.stl": 3.0},
     "m.stl", "3.000", "x/y/m.stl"),
]


@pytest.mark.parametrize(("rule", "files", "opened", "loaded", "unused"), RULES,
                         ids=[r[0] for r in RULES])
def test_the_walk_opens_the_file_mujoco_opens(rule: str, files: dict[str, str | float],
                                              opened: str, loaded: str, unused: str,
                                              tmp_path: Path) -> None:
    top = _lay_out(tmp_path, files)
    assert tmp_path / opened in check_mjcf_files(top)
    assert _loaded(top) == loaded
    # a FIFO where MuJoCo does not look is no reason to refuse
    (tmp_path / unused).parent.mkdir(parents=True, exist_ok=True)
    (tmp_path / unused).unlink(missing_ok=True)
    os.mkfifo(tmp_path / unused)
    assert tmp_path / opened in check_mjcf_files(top)
    # one where it looks is
    (tmp_path / opened).unlink()
    os.mkfifo(tmp_path / opened)
    with pytest.raises(InputError, match="is a FIFO") as e:
        check_mjcf_files(top)
    holder = e.value.file
    assert holder is not None and e.value.line == 1
    assert Path(holder).read_text().count(Path(opened).name) >= 1


def test_what_mujoco_would_not_open_is_not_checked(tmp_path: Path) -> None:
    top = _lay_out(tmp_path, {"top.xml": '<asset><texture name="t" type="2d" builtin="checker" '
                              'width="8" height="8" file="pipe.png"/><mesh name="v" file="" '
                              'vertex="0 0 0 1 0 0 0 1 0 0 0 1"/></asset><worldbody>'
                              '<flexcomp name="f" type="grid" count="2 2 1" spacing="1 1 1" '
                              'dim="2" file="pipe.obj"/></worldbody>'})
    os.mkfifo(tmp_path / "pipe.png")
    os.mkfifo(tmp_path / "pipe.obj")
    assert check_mjcf_files(top) == []
    from urdfkit.formats.mjwarn import mujoco_warnings

    with mujoco_warnings(mujoco) as said:  # not into ./MUJOCO_LOG.TXT
        assert mujoco.MjModel.from_xml_path(str(top)).nmesh == 1
    assert said == ["flex 'f' is not rigid and has no equality constraints or passive forces "
                    "(Element name 'f', id 0)"]


@pytest.mark.parametrize(("files", "special", "message"), [
    ({"top.xml": "\n" + MESH.format("m.stl")}, "m.stl:dir",
     r"top.xml:2: <mesh file='m.stl'>: .*m.stl is a directory, not a regular file"),
    ({"top.xml": '\n<compiler texturedir="t"/>\n<asset><texture name="c" type="cube" '
      'fileright="r.png"/></asset>'}, "t/r.png:fifo",
     r"top.xml:3: <texture fileright='r.png'>: .*t/r.png is a FIFO .*wait on it forever"),
    ({"top.xml": '<include file="sub/a.xml"/>', "sub/a.xml": '\n\n<asset><hfield name="h" '
      'file="h.png" size="1 1 1 1"/></asset>'}, "sub/h.png:dev",
     r"sub/a.xml:3: <hfield file='h.png'>: .*sub/h.png is a character device.* \(read for "
     r".*top.xml\)"),
    ({"top.xml": '<include file="gone.xml"/>'}, "",
     r"top.xml:1: <include file='gone.xml'>: no such file \(looked for .*gone.xml\)"),
    ({"top.xml": '<include file="sub/a.xml"/>', "sub/a.xml": '<include file="gone.xml"/>'}, "",
     r"no such file \(looked for .*/gone.xml and .*sub/gone.xml\) \(read for"),
    ({"top.xml": '<include file="a.xml"/>', "a.xml": '<include file="./a.xml"/>'}, "",
     r"a.xml:1: <include file='./a.xml'>: .*a.xml is already included .*includes a file once"),
    ({"top.xml": '<include file="top.xml"/>'}, "", r"already included"),
    ({"top.xml": '<asset><model name="a" file="a.xml"/></asset>',
      "a.xml": '<asset><model name="t" file="top.xml"/></asset>'}, "",
     r"a.xml:1: <model file='top.xml'>: .*top.xml is a model this one is part of; MuJoCo "
     r"would recurse until it crashes \(read for"),
    ({"top.xml": '<include file="a.xml"/>', "a.xml": "<worldbody><body"}, "",
     r"a.xml:1: not well-formed XML.*\(read for"),
])
def test_a_bad_reference_is_refused_naming_where_it_stands(
        files: dict[str, str | float], special: str, message: str, tmp_path: Path) -> None:
    top = _lay_out(tmp_path, files)
    if "<body" in str(files.get("a.xml", "")):
        (tmp_path / "a.xml").write_text("<mujoco><worldbody><body</mujoco>")
    if special:
        name, kind = special.split(":")
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if kind == "dir":
            path.mkdir()
        elif kind == "fifo":
            os.mkfifo(path)
        else:
            path.symlink_to("/dev/zero")
    with pytest.raises(InputError, match=message) as e:
        check_mjcf_files(top)
    assert "\n" not in str(e.value)


def test_the_walk_stops_at_its_file_budget(tmp_path: Path) -> None:
    n = MAX_MJCF_FILES + 1
    for i in range(n):
        (tmp_path / f"f{i}.xml").write_text(f'<mujoco><include file="f{i + 1}.xml"/></mujoco>'
                                            if i < n - 1 else "<mujoco/>")
    with pytest.raises(InputError, match=f"more than {MAX_MJCF_FILES} files"):
        check_mjcf_files(tmp_path / "f0.xml")


@pytest.mark.parametrize("where", ["include", "mesh in an include"])
def test_agree_on_a_fifo_ends_at_once_with_one_line(where: str, tmp_path: Path) -> None:
    if where == "include":
        _lay_out(tmp_path, {"top.xml": '<include file="inc.xml"/>'})
        os.mkfifo(tmp_path / "inc.xml")
    else:
        _lay_out(tmp_path, {"top.xml": '<compiler meshdir="meshes"/>\n<include file="s/i.xml"/>',
                            "s/i.xml": "\n" + MESH.format("m.stl")})
        os.mkfifo(tmp_path / "s" / "m.stl")
    r = subprocess.run([sys.executable, "-m", "urdfkit", "agree", str(ROBOT), "top.xml"],
                       cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "is a FIFO" in lines[0], r.stderr
    expect = "top.xml:1: <include file='inc.xml'>: inc.xml" if where == "include" else \
        "s/i.xml:2: <mesh file='m.stl'>: s/m.stl is a FIFO (named pipe), not a regular file; " \
        "MuJoCo would wait on it forever (read for top.xml)"
    assert expect in lines[0]
