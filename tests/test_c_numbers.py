"""Numbers as PyBullet reads them: C's atof of each token (urdfkit.model.spec), against raw
PyBullet's own reading of the same text, and what check, info and export say of them."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.model.spec import atof, c_number

runner = CliRunner()

INERTIA = 'ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"'


def _two_links(mass: str, xyz: str = "0 0 0.5") -> str:
    return f"""<?xml version="1.0"?>
<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia {INERTIA}/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="tip"><inertial><mass value="{mass}"/><inertia {INERTIA}/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>
    <origin xyz="{xyz}"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


# Tokens where Python's float() and C's atof part ways, and the plain ones.
TOKENS = ["0x1p3", "0X10", "-0x1.8p1", "0x.8", "1_0", "8abc", "1.5e", "8.", "+8", ".5", "1e1",
          "\uff18", "0x", "infinity", "-inf", "nan", "abc", "2"]


@pytest.mark.parametrize("token", TOKENS)
def test_atof_reads_a_mass_as_pybullet_does(pb: tuple, tmp_path: Path, token: str) -> None:
    bullet, cid = pb
    path = tmp_path / "r.urdf"
    path.write_text(_two_links(token), encoding="utf-8")
    body = bullet.loadURDF(str(path), physicsClientId=cid)  # type: ignore[attr-defined]
    loaded = bullet.getDynamicsInfo(body, 0, physicsClientId=cid)[0]  # type: ignore[attr-defined]
    ours = atof(token)
    assert ours == loaded or (math.isnan(ours) and math.isnan(loaded)), (token, ours, loaded)
    # c_number takes a token whole or not at all: what it reads is what PyBullet reads
    whole = c_number(token)
    assert whole is None or whole == loaded or (math.isnan(whole) and math.isnan(loaded))
    if token in ("1_0", "\uff18"):  # float() reads 10 and 8, PyBullet 1 and 0
        assert whole is None and float(token) != loaded


def test_atof_reads_a_vector_as_pybullet_does(pb: tuple, tmp_path: Path) -> None:
    bullet, cid = pb
    path = tmp_path / "r.urdf"
    path.write_text(_two_links("1", xyz="0x1p1 1_0 3abc"), encoding="utf-8")
    body = bullet.loadURDF(str(path), physicsClientId=cid)  # type: ignore[attr-defined]
    # a revolute joint's parent frame: the origin less the parent's (zero) inertial offset
    loaded = bullet.getJointInfo(body, 0, physicsClientId=cid)[14]  # type: ignore[attr-defined]
    assert tuple(atof(t) for t in "0x1p1 1_0 3abc".split()) == pytest.approx(loaded) == (2, 1, 3)


def _check(path: Path) -> list[dict]:
    r = runner.invoke(app, ["check", str(path), "--json"])
    assert r.exit_code in (0, 1), r.output
    return json.loads(r.stdout)["findings"]


def test_a_hexadecimal_mass_is_a_warning_saying_what_pybullet_reads(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(_two_links("0x1p3"))
    (u401,) = [f for f in _check(path) if f["code"] == "U401"]
    assert u401["level"] == "warning" and "PyBullet reads 8" in u401["message"]
    assert u401["line"] == 5
    r = runner.invoke(app, ["links", str(path), "--json"])
    assert r.exit_code == 0, r.output
    assert [ln["mass"] for ln in json.loads(r.stdout)["links"]] == [1.0, 8.0]


def test_an_underscored_mass_is_an_error_not_the_number_python_reads(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(_two_links("1_0"))
    assert {(f["code"], f["level"]) for f in _check(path)} >= {("U401", "error")}


def test_a_nan_mass_is_said_to_be_nan(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(_two_links("nan"))
    codes = {f["code"] for f in _check(path)}
    assert "U401" in codes and "U602" not in codes  # PyBullet reads NaN, not 0
    r = runner.invoke(app, ["export", "mjcf", str(path), "-o", str(tmp_path / "r.xml")])
    assert r.exit_code == 2
    assert "not numbers (NaN)" in r.stderr and "overflow" not in r.stderr
    # a mass PyBullet reads as 0 is U602 as before
    path.write_text(_two_links("abc"))
    assert "U602" in {f["code"] for f in _check(path)}
