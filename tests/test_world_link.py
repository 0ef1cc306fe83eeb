"""A link named ``world``, as PyBullet treats it: mass 0 without ``<inertial>``, not 1 kg.

Measured against raw PyBullet here, not assumed: check (U606/U611/U602), info (static base),
and fix (its loaded mass) must say what ``p.loadURDF`` does.
"""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from urdfkit.cli import app

ROBOTS = Path(__file__).parent / "fixtures" / "robots"
WORLD_ROOT = ROBOTS / "world_root.urdf"

def _renamed(tmp_path: Path, name: str) -> Path:
    """The same arm with its root renamed (``World``: PyBullet gives it 1 kg, it falls)."""
    out = tmp_path / f"{name}.urdf"
    out.write_text(WORLD_ROOT.read_text().replace('"world"', f'"{name}"'))
    return out


def _run(*args: str) -> tuple[int, str]:
    r = CliRunner().invoke(app, list(args))
    return r.exit_code, r.stdout


def _raw_base(pb, path: Path) -> tuple[float, float]:
    """(PyBullet's base mass, how far the base falls in 1 s of gravity)."""
    p, c = pb
    p.resetSimulation(physicsClientId=c)  # alone: no body loaded before to land on
    body = p.loadURDF(str(path), physicsClientId=c)
    p.setGravity(0, 0, -9.81, physicsClientId=c)
    z0 = p.getBasePositionAndOrientation(body, physicsClientId=c)[0][2]
    for _ in range(240):
        p.stepSimulation(physicsClientId=c)
    z1 = p.getBasePositionAndOrientation(body, physicsClientId=c)[0][2]
    return p.getDynamicsInfo(body, -1, physicsClientId=c)[0], z0 - z1


def test_raw_pybullet_gives_world_mass_zero(pb, tmp_path: Path) -> None:
    mass, fall = _raw_base(pb, WORLD_ROOT)
    assert mass == 0.0 and fall == 0.0
    mass, fall = _raw_base(pb, _renamed(tmp_path, "World"))  # case matters
    assert mass == 1.0 and fall > 1.0


def test_check_says_static_not_one_kilogram(tmp_path: Path) -> None:
    code, out = _run("check", str(WORLD_ROOT), "--json")
    findings = json.loads(out)["findings"]
    codes = {f["code"]: f["message"] for f in findings}
    assert "U606" not in codes
    assert "1 kg" not in out.replace("not 1 kg", "")
    assert "world" in codes["U611"] and "static" in codes["U611"]
    assert next(f["level"] for f in findings if f["code"] == "U611") == "info"
    # Renamed, the root gets 1 kg, and check says so.
    code, out = _run("check", str(_renamed(tmp_path, "World")), "--json")
    codes = {f["code"]: f["message"] for f in json.loads(out)["findings"]}
    assert "1 kg" in codes["U606"] and "U611" not in codes


def test_moving_world_child_is_massless(pb, tmp_path: Path) -> None:
    """A moving link named world without <inertial>: PyBullet mass 0, and check says U602."""
    text = WORLD_ROOT.read_text().replace('"world"', '"root"').replace(
        '"upper_arm"', '"world"').replace('<link name="root"/>', '<link name="root"><inertial>'
        '<mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>'
        '</link>')
    text = text.replace('<inertial><origin xyz="0 0 0.2"/><mass value="1"/><inertia ixx="0.01" '
                        'ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/></inertial>', "")
    path = tmp_path / "child.urdf"
    path.write_text(text)
    p, c = pb
    body = p.loadURDF(str(path), physicsClientId=c)
    assert p.getDynamicsInfo(body, 1, physicsClientId=c)[0] == 0.0
    code, out = _run("check", str(path), "--json")
    codes = {f["code"]: f["message"] for f in json.loads(out)["findings"]}
    assert "U606" not in codes and "named world" in codes["U602"]
    # fix gives the moving massless link a small mass, and says the loaded mass honestly.
    code, out = _run("fix", str(path), "--json", "-o", str(tmp_path / "fixed.urdf"))
    result = json.loads(out)
    assert "U602" in {f["code"] for f in result["fixes"]}
    fixed = p.loadURDF(str(tmp_path / "fixed.urdf"), physicsClientId=c)
    assert p.getDynamicsInfo(fixed, 1, physicsClientId=c)[0] > 0


def test_info_says_static_base(pb, tmp_path: Path) -> None:
    code, out = _run("info", str(WORLD_ROOT), "--json")
    data = json.loads(out)
    assert code == 0 and data["fixed_base"] is True and "world" in data["static_base"]
    mass, _ = _raw_base(pb, WORLD_ROOT)
    assert abs(data["total_mass"] - 3.0) < 1e-9  # 0 + 2 + 1, as PyBullet loads it
    code, text = _run("info", str(WORLD_ROOT))
    assert "floating" not in text and "static base" in text and "get 1 kg" not in text
    # An explicit mass-0 root is static too; a 1 kg root floats.
    zero = tmp_path / "zero.urdf"
    zero.write_text(WORLD_ROOT.read_text().replace(
        '<link name="world"/>', '<link name="world"><inertial><mass value="0"/><inertia '
        'ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>'))
    assert _raw_base(pb, zero)[1] == 0.0
    data = json.loads(_run("info", str(zero), "--json")[1])
    assert data["fixed_base"] is True and "mass 0" in data["static_base"]
    floating = _renamed(tmp_path, "World")
    data = json.loads(_run("info", str(floating), "--json")[1])
    assert data["fixed_base"] is False and data["static_base"] is None
    assert _raw_base(pb, floating)[1] > 1.0


def test_fix_counts_world_as_pybullet_loads_it(tmp_path: Path) -> None:
    code, out = _run("fix", str(WORLD_ROOT), "--json", "-o", str(tmp_path / "out.urdf"))
    assert code == 0, out
    entry = json.loads(out)
    assert entry["mass"]["loaded_before"] == 3.0 and not entry["changed"]
    assert not entry["fixes"]
