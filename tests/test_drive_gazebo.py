"""drive --gazebo-contacts (issue 41, item 2): the file's <gazebo> mu1/mu2/kp/kd applied at
load, checked against the same robot with the values written as PyBullet's own <contact>."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from urdfkit.cli import app
from urdfkit.motion.drive import DriveConfig, Scenario, drive

CART = Path(__file__).parent / "fixtures" / "robots" / "gazebo_wheels.urdf"
WHEELS = {"front_left_wheel": '<lateral_friction value="0.3"/><stiffness value="1000000.0"/>'
                              '<damping value="100.0"/>',
          "front_right_wheel": '<lateral_friction value="0.3"/><stiffness value="1000000.0"/>'
                               '<damping value="100.0"/>',
          "rear_left_wheel": '<lateral_friction value="0.3"/>',
          "rear_right_wheel": '<lateral_friction value="0.3"/>',
          "bumper": '<lateral_friction value="0.6"/>'}


def _written_as_pybullet(tmp_path: Path) -> Path:
    """The cart with its Gazebo values written as PyBullet's <contact> (what PyBullet reads)."""
    text = re.sub(r"<gazebo .*?</gazebo>", "", CART.read_text(), flags=re.S)
    for link, contact in WHEELS.items():
        text = text.replace(f'<link name="{link}">',
                            f'<link name="{link}"><contact>{contact}</contact>', 1)
    out = tmp_path / "contact.urdf"
    out.write_text(text)
    return out


def test_gazebo_contacts_load_as_pybullet_contact_would(tmp_path: Path) -> None:
    cfg = DriveConfig(urdf=str(CART), steer=0.5, seconds=4, keep_trajectory=False)
    with Scenario(DriveConfig(urdf=str(CART), gazebo_contacts=True)) as sc:
        assert sc.session is not None
        p = sc.session.bullet
        index = {p.getJointInfo(sc.body, j)[12].decode(): j
                 for j in range(p.getNumJoints(sc.body))}
        assert p.getDynamicsInfo(sc.body, index["front_left_wheel"])[1] == pytest.approx(0.3)
        assert p.getDynamicsInfo(sc.body, index["front_left_wheel"])[9] == pytest.approx(1e6)
        assert p.getDynamicsInfo(sc.body, index["front_left_wheel"])[8] == pytest.approx(100.0)
        assert p.getDynamicsInfo(sc.body, index["bumper"])[1] == pytest.approx(0.6)
    raw = drive(cfg)
    applied = drive(DriveConfig(urdf=str(CART), steer=0.5, seconds=4, keep_trajectory=False,
                                gazebo_contacts=True))
    reference = drive(DriveConfig(urdf=str(_written_as_pybullet(tmp_path)), steer=0.5,
                                  seconds=4, keep_trajectory=False))
    assert raw.yaw_rate is not None and applied.yaw_rate is not None
    assert reference.yaw_rate is not None
    # The option turns the skid-steer exactly as the same friction written the PyBullet way
    # does; less grip (0.3 against PyBullet's 0.5) turns this cart less (measured on the
    # default slab, friction 4: 0.1645 against 0.1677 rad/s; on PyBullet's plane shape 0.165
    # against 0.186).
    assert applied.yaw_rate == pytest.approx(reference.yaw_rate, rel=1e-6)
    assert applied.yaw_rate < 0.99 * raw.yaw_rate
    # Without the option the slip diagnosis names what the file gives.
    note = [w for w in raw.warnings if w.startswith("the file's <gazebo> gives")]
    assert note and "front_left_wheel mu1 0.3 mu2 0.3, PyBullet uses 0.5" in note[0]
    assert note[0].endswith("--gazebo-contacts applies them")
    assert not [w for w in applied.warnings if w.startswith("the file's <gazebo>")]


def test_the_cli_applies_them_and_says_so() -> None:
    result = CliRunner().invoke(app, ["drive", "--urdf", str(CART), "--seconds", "0.5",
                                      "--gazebo-contacts", "--json"])
    import json

    doc = json.loads(result.stdout)
    assert doc["simulated"]["gazebo_contacts"]["rear_left_wheel"] == {"lateralFriction": 0.3}


@pytest.mark.parametrize("apply", [True, False])
def test_sim_applies_them_when_the_scenario_says(apply: bool) -> None:
    from urdfkit.sim import Simulation

    doc = {"duration": 0.1, "ground": "simpleplane",
           "robots": [{"name": "cart", "urdf": str(CART), "position": [0, 0, 0.2],
                       "gazebo_contacts": apply,
                       "link_dynamics": {"rear_right_wheel": {"lateral_friction": 0.9}}}]}
    with Simulation(doc) as sim:
        p, r = sim.session.bullet, sim.bodies["cart"]
        friction = {name: p.getDynamicsInfo(r.body, r.links[name])[1]
                    for name in ("front_left_wheel", "rear_left_wheel", "bumper",
                                 "rear_right_wheel")}
        stiffness = p.getDynamicsInfo(r.body, r.links["front_left_wheel"])[9]
    if apply:
        assert friction == pytest.approx({"front_left_wheel": 0.3, "rear_left_wheel": 0.3,
                                          "bumper": 0.6, "rear_right_wheel": 0.9})
        assert stiffness == pytest.approx(1e6)
    else:  # raw PyBullet: its default lateral friction, the scenario's link_dynamics
        assert friction == pytest.approx({"front_left_wheel": 0.5, "rear_left_wheel": 0.5,
                                          "bumper": 0.5, "rear_right_wheel": 0.9})
