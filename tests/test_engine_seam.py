"""The engine seam (issue 50): who may reach PyBullet, and what PyBulletEngine gives.

Everything above ``engine/`` speaks to :class:`urdfkit.engine.api.Simulator`; the modules that
still import an engine's package or call PyBullet's functions themselves are listed here by
name, each a step left for its owner. The lists only shrink: an entry that no longer needs its
place fails the test until it is dropped.

The engine's own behaviour is held against raw PyBullet and physics: what it reports of a
loaded body, an exact restore with an infinite plane left in place, a mimic coupling, a rack,
a floating base's mass matrix.
"""

from __future__ import annotations

import ast
import math
import random
import struct
from collections.abc import Iterator
from pathlib import Path

import pytest

import urdfkit
from urdfkit.engine.api import LoadSettings
from urdfkit.engine.pybullet import PyBulletEngine
from urdfkit.engine.session import import_pybullet

PACKAGE = Path(urdfkit.__file__).parent
ROBOTS = Path(__file__).parent / "fixtures" / "robots"
PENDULUM = str(Path(__file__).parent.parent / "examples" / "pendulum.urdf")

#: The engines' own packages: a module outside engine/ that imports one reaches the engine
#: itself. (pybullet_data is a folder of model files, not an engine.)
ENGINE_PACKAGES = {"pybullet", "pybullet_utils", "pybullet_envs", "mujoco"}

#: Modules outside engine/ that still import an engine's package (lazily counts), or
#: PyBullet through the session's importer, and why.
IMPORTS_AN_ENGINE: dict[str, str] = {}

#: Modules outside engine/ that still call PyBullet's functions (through a session's bound
#: client), each for its owner to port to the seam.
CALLS_PYBULLET: set[str] = set()

#: The modules ported to the seam: no PyBullet but the escape hatch they hand out.
PORTED = ["motion/simulation.py", "motion/sim_world.py", "motion/sim_robot.py",
          "motion/sim_control.py", "motion/sim_sensors.py", "motion/sim_dynamics.py",
          "motion/sim_episode.py", "motion/sim_record.py", "motion/vehicle.py",
          "motion/vehicle_shapes.py", "motion/mimic.py", "motion/gazebo_load.py",
          "motion/sac.py", "motion/sweep_plan.py", "draw/view_model.py"]


def _outside_engine() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py")
                  if p.relative_to(PACKAGE).parts[0] != "engine")


def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text("utf-8"))


def _engine_imports(tree: ast.AST) -> list[str]:
    """The engine packages ``tree`` imports anywhere (functions too), and the session's
    importer of PyBullet."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.split(".")[0] in ENGINE_PACKAGES]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            if node.module.split(".")[0] in ENGINE_PACKAGES:
                found.append(node.module)
            elif node.module == "urdfkit.engine.session":
                found += [a.name for a in node.names if a.name == "import_pybullet"]
        elif isinstance(node, ast.Call) and node.args and \
                isinstance(node.args[0], ast.Constant) and \
                str(node.args[0].value).split(".")[0] in ENGINE_PACKAGES and \
                ((isinstance(node.func, ast.Attribute) and node.func.attr == "import_module")
                 or (isinstance(node.func, ast.Name) and node.func.id == "__import__")):
            found.append(str(node.args[0].value))
    return found


def _pybullet_functions() -> set[str]:
    p = import_pybullet()
    return {n for n in dir(p) if not n.startswith("_") and callable(getattr(p, n))
            and not isinstance(getattr(p, n), type)}


def _pybullet_uses(tree: ast.AST, functions: set[str]) -> set[str]:
    """PyBullet functions ``tree`` names as attributes (``bullet.getJointInfo``, called or
    bound to a local first)."""
    return {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute) and n.attr in functions}


def test_the_seam_sees_what_it_looks_for() -> None:
    """The checks below find imports and calls, lazy ones included (a check that finds
    nothing would pass)."""
    source = ("def f():\n    import pybullet as p\n    from mujoco import MjModel\n"
              "    import importlib\n    importlib.import_module('mujoco')\n"
              "    from urdfkit.engine.session import import_pybullet\n"
              "    step = s.bullet.stepSimulation\n    s.bullet.getJointInfo(0, 1)\n")
    tree = ast.parse(source)
    assert sorted(_engine_imports(tree)) == ["import_pybullet", "mujoco", "mujoco", "pybullet"]
    assert _pybullet_uses(tree, _pybullet_functions()) == {"stepSimulation", "getJointInfo"}


def test_no_module_outside_engine_imports_an_engine_but_the_listed_ones() -> None:
    found = {p.relative_to(PACKAGE).as_posix(): _engine_imports(_tree(p))
             for p in _outside_engine()}
    found = {k: v for k, v in found.items() if v}
    unlisted = {k: v for k, v in found.items() if k not in IMPORTS_AN_ENGINE}
    assert not unlisted, f"import the engine through urdfkit.engine instead: {unlisted}"
    stale = sorted(set(IMPORTS_AN_ENGINE) - set(found))
    assert not stale, f"no longer imports an engine: drop from IMPORTS_AN_ENGINE: {stale}"


def test_no_module_outside_engine_calls_pybullet_but_the_listed_ones() -> None:
    functions = _pybullet_functions()
    found = {p.relative_to(PACKAGE).as_posix(): _pybullet_uses(_tree(p), functions)
             for p in _outside_engine()}
    found = {k: v for k, v in found.items() if v}
    unlisted = {k: sorted(v) for k, v in found.items() if k not in CALLS_PYBULLET}
    assert not unlisted, f"call the engine seam (urdfkit.engine.api) instead: {unlisted}"
    stale = sorted(CALLS_PYBULLET - set(found))
    assert not stale, f"no longer calls PyBullet: drop from CALLS_PYBULLET: {stale}"
    assert not set(PORTED) & (CALLS_PYBULLET | set(IMPORTS_AN_ENGINE))


@pytest.mark.parametrize("module", PORTED)
def test_a_ported_module_reaches_pybullet_only_as_the_escape_hatch(module: str) -> None:
    """No session of its own, nothing called through ``.bullet`` or ``.session``; the engine
    modules it imports at run time are the seam's (``api``, ``registry``), and
    ``engine.pybullet`` only where ``World`` hands out ``Simulation.bullet``."""
    tree = _tree(PACKAGE / module)
    chained = [f"{n.lineno}: .{n.value.attr}.{n.attr}" for n in ast.walk(tree)
               if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Attribute)
               and n.value.attr in ("bullet", "session", "p")]
    assert not chained, chained
    # What only the type checker reads: TYPE_CHECKING blocks and annotations.
    typed: list[ast.AST] = [node for node in ast.walk(tree) if isinstance(node, ast.If)
                            and isinstance(node.test, ast.Name)
                            and node.test.id == "TYPE_CHECKING"]
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.returns:
            typed.append(node.returns)
        elif isinstance(node, ast.arg) and node.annotation:
            typed.append(node.annotation)
        elif isinstance(node, ast.AnnAssign):
            typed.append(node.annotation)
    checking = {id(n) for node in typed for n in ast.walk(node)}
    wrong = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("urdfkit.engine") \
                and id(node) not in checking:
            if node.module in ("urdfkit.engine.api", "urdfkit.engine.registry"):
                continue
            if node.module == "urdfkit.engine.pybullet" and module == "motion/sim_world.py" \
                    and [a.name for a in node.names] == ["PyBulletEngine"]:
                continue
            wrong.append(f"{node.lineno}: from {node.module} import ...")
        elif isinstance(node, ast.Name) and node.id in ("Session", "Bullet") and \
                isinstance(node.ctx, ast.Load) and id(node) not in checking:
            wrong.append(f"{node.lineno}: {node.id}")
    assert not wrong, wrong


# --------------------------------------------------------------------------- the engine


@pytest.fixture
def engine() -> Iterator[PyBulletEngine]:
    e = PyBulletEngine()
    try:
        yield e
    finally:
        e.close()


def test_the_registry_opens_engines_by_name_and_refuses_others() -> None:
    from urdfkit.core.errors import ParameterError
    from urdfkit.engine.registry import ENGINES, open_engine

    e = open_engine("pybullet")
    try:
        assert isinstance(e, PyBulletEngine) and e.name == "pybullet" and "pybullet" in ENGINES
        assert e.bullet.getNumBodies() == 0 and e.connected()
    finally:
        e.close()
    assert not e.connected()
    with pytest.raises(ParameterError, match="no engine named 'bullet3'; engines: pybullet"):
        open_engine("bullet3")


def test_joints_and_links_are_what_pybullet_loaded(engine: PyBulletEngine) -> None:
    body = engine.load(str(ROBOTS / "mimic_gripper.urdf"), LoadSettings(fixed_base=True))
    raw = engine.bullet
    joints = engine.joints(body)
    assert len(joints) == raw.getNumJoints(body) == 3
    for j in joints:
        info = raw.getJointInfo(body, j.index)
        assert (j.name, j.link, j.parent) == (info[1].decode(), info[12].decode(), info[16])
        assert (j.kind, j.lower, j.upper, j.limited) == ("prismatic", info[8], info[9], True)
    assert engine.link_names(body)[0] == raw.getBodyInfo(body)[0].decode()
    engine.set_joint_positions(body, [0.01, 0.02, 0.03], [0.1, 0.2, 0.3])
    rows = engine.joint_rows(body, [0, 1, 2])
    assert list(rows) == list(raw.getJointStates(body, [0, 1, 2]))
    assert [(r[0], r[1]) for r in rows] == [(0.01, 0.1), (0.02, 0.2), (0.03, 0.3)]
    assert [tuple(s.__dict__.values()) for s in engine.joint_states(body, [0, 1, 2])] == \
        [tuple(r) for r in rows]  # the rows are the records' fields, in order
    assert list(engine.joint_rows(body, [])) == []


def test_a_continuous_joint_has_no_limits(engine: PyBulletEngine, simplecar_urdf: Path) -> None:
    body = engine.load(str(simplecar_urdf), LoadSettings())
    kinds = {j.name: (j.kind, j.limited) for j in engine.joints(body)}
    assert kinds["base_to_left_back_wheel"] == ("revolute", False)  # continuous
    assert kinds["base_to_left_hinge"] == ("revolute", True)


def test_the_root_link_frame_is_the_urdf_frame_not_the_centre_of_mass(
        engine: PyBulletEngine) -> None:
    # The pendulum's base_link has its <inertial> 0.5 m above its link frame.
    body = engine.load(PENDULUM, LoadSettings(fixed_base=True, inertia_from_file=True,
                                              position=(1.0, 2.0, 3.0)))
    pose = engine.link_pose(body, -1)
    assert pose.position == pytest.approx((1.0, 2.0, 3.0), abs=1e-6)  # float32 transforms
    assert pose.inertial_position == pytest.approx((1.0, 2.0, 3.5), abs=1e-12)
    assert engine.base_pose(body)[0] == pose.inertial_position
    assert engine.link_frames(body)[0][0] == pose.position
    assert engine.link_frame(body, -1) == (pose.position, pose.orientation)
    arm = engine.link_pose(body, 0)
    assert engine.link_frame(body, 0) == (arm.position, arm.orientation)
    assert arm.inertial_position[2] == pytest.approx(arm.position[2] - 0.5)  # its bob, below
    engine.reset_base_frame(body, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0))
    assert engine.base_pose(body)[0] == pytest.approx((0.0, 0.0, 1.5), abs=1e-6)


def test_restore_replays_a_run_exactly_and_leaves_an_infinite_plane_in_place(
        engine: PyBulletEngine) -> None:
    """plane.urdf is an infinite plane: moved apart with the robot, it would still touch it."""
    from urdfkit.sources.resolve import open_input

    with open_input("plane.urdf") as plane_file:
        plane = engine.load(str(plane_file.load_path), LoadSettings(fixed_base=True,
                                                                    scenery=True))
    body = engine.load(str(ROBOTS / "quadruped_like.urdf"),
                       LoadSettings(inertia_from_file=True, position=(0.0, 0.0, 0.4)))
    engine.set_gravity((0.0, 0.0, -9.81))
    engine.set_physics(deterministic_pairs=True)
    start = engine.save()
    runs = []
    for _ in range(2):
        states = []
        for _ in range(120):
            engine.step()
            states.append(engine.base_state(body))
        runs.append(states)
        engine.restore(start)
    assert runs[0] == runs[1]  # bit for bit, contacts and all
    assert runs[0][-1].position[2] == pytest.approx(0.3, abs=0.15)  # it stood on the plane
    assert engine.base_pose(plane)[0] == (0.0, 0.0, 0.0)


BOX = """<robot name="box"><link name="box"><inertial><mass value="2"/>
<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link></robot>"""


def test_contacts_carry_a_resting_box_and_are_frozen_records(engine: PyBulletEngine,
                                                             simpleplane_urdf: Path,
                                                             tmp_path: Path) -> None:
    import dataclasses

    from urdfkit.engine.api import ContactPoint

    (tmp_path / "box.urdf").write_text(BOX)
    ground = engine.load(str(simpleplane_urdf), LoadSettings(fixed_base=True, scenery=True))
    box = engine.load(str(tmp_path / "box.urdf"), LoadSettings(position=(0.0, 0.0, 0.2)))
    engine.set_gravity((0.0, 0.0, -9.81))
    for _ in range(480):
        engine.step()
    points = engine.contacts(box, -1, ground)
    assert len(points) == 4  # the box's four bottom corners
    assert sum(pt.normal_force for pt in points) == pytest.approx(2 * 9.81, rel=1e-3)
    raw = engine.bullet.getContactPoints(bodyA=box, linkIndexA=-1, bodyB=ground)
    for pt, row in zip(points, raw, strict=True):
        assert pt == ContactPoint(*row[1:14])  # the same record the dataclass makes
        assert (pt.body_a, pt.body_b) == (box, ground) and pt.normal[2] == pytest.approx(1.0)
        assert hash(pt) == hash(ContactPoint(*row[1:14]))
        with pytest.raises(dataclasses.FrozenInstanceError):
            pt.normal_force = 0.0  # type: ignore[misc]
    assert engine.contacts(box, -1, box) == []


def test_a_coupled_follower_keeps_the_mimic_relation(engine: PyBulletEngine) -> None:
    from urdfkit.motion.mimic import couple_mimics, mimic_relations
    from urdfkit.sources.resolve import open_input

    with open_input(str(ROBOTS / "mimic_gripper.urdf")) as res:
        body = engine.load(str(res.load_path), LoadSettings(fixed_base=True))
        followers = couple_mimics(engine, body, mimic_relations(res.root))
    assert sorted(followers) == ["right_finger_joint", "thumb_joint"]
    engine.motors(body, [1, 2], "velocity", [0.0, 0.0], forces=[0.0, 0.0])
    engine.motors(body, [0], "position", [0.015], forces=[20.0])
    for _ in range(240):
        engine.step()
    left, right, thumb = (r[0] for r in engine.joint_rows(body, [0, 1, 2]))
    assert left == pytest.approx(0.015, abs=1e-3)
    assert right == pytest.approx(-1 * left + 0.01, abs=1e-4)
    assert thumb == pytest.approx(left, abs=1e-4)


def test_a_held_base_stays_where_it_was_and_its_joints_still_move(
        engine: PyBulletEngine) -> None:
    body = engine.load(PENDULUM, LoadSettings(inertia_from_file=True,
                                              position=(0.0, 0.0, 2.0)))
    engine.set_gravity((0.0, 0.0, -9.81))
    before = engine.base_pose(body)
    engine.hold_base(body)
    engine.motors(body, [0], "velocity", [0.0], forces=[0.0])
    engine.reset_joint(body, 0, 0.5)
    for _ in range(240):
        engine.step()
    after = engine.base_pose(body)
    assert after[0] == pytest.approx(before[0], abs=1e-3)
    assert abs(engine.joint_rows(body, [0])[0][0] - 0.5) > 0.1  # it swung


@pytest.mark.parametrize("robot", [PENDULUM, str(ROBOTS / "panda_like.urdf")])
def test_a_floating_mass_matrix_has_the_total_mass_on_its_linear_diagonal(
        engine: PyBulletEngine, robot: str) -> None:
    """Robots whose root has an <inertial> (PyBullet counts a root without one, which it
    simulates at 1 kg, as 0 kg here: see PyBulletEngine.floating_mass_matrix)."""
    body = engine.load(robot, LoadSettings(inertia_from_file=True, position=(0.0, 0.0, 1.0)))
    joints = [j.index for j in engine.joints(body) if j.kind != "fixed"]
    total = sum(engine.dynamics(body, k).mass for k in range(-1, len(engine.joints(body))))
    pos, orn = engine.base_pose(body)
    m = engine.floating_mass_matrix(body, pos, orn, [0.3] * len(joints))
    assert len(m) == len(m[0]) == 6 + len(joints)
    for k in range(3):
        assert m[k][k] == pytest.approx(total, rel=1e-9)
    assert all(m[i][j] == pytest.approx(m[j][i], abs=1e-9) for i in range(len(m))
               for j in range(len(m)))


def test_an_engine_refusal_names_pybullet_and_why(engine: PyBulletEngine) -> None:
    from urdfkit.core.errors import EngineError

    body = engine.load(str(ROBOTS / "id_asymmetric.urdf"), LoadSettings(fixed_base=True))
    n = sum(1 for j in engine.joints(body) if j.kind != "fixed")
    for _ in range(2):  # the second time from what the first learnt
        with pytest.raises(EngineError, match="inertia of link 'link_1' asymmetric"):
            engine.mass_matrix(body, [0.0] * n)


def test_rpy_to_unit_quat_is_pybullets_quaternion_bit_for_bit() -> None:
    """The scenario's start turn, once PyBullet's getQuaternionFromEuler, now the spec's."""
    from urdfkit.model.spec import rpy_to_quat, rpy_to_unit_quat

    p = import_pybullet()
    rng = random.Random(50)
    angles = [(rng.uniform(-7, 7), rng.uniform(-7, 7), rng.uniform(-7, 7))
              for _ in range(20000)]
    angles += [(a, b, c) for a in (0.0, -0.0, math.pi / 2, math.pi, 1.5708)
               for b in (0.0, -0.0, 0.3, -math.pi) for c in (0.0, -0.0, 0.7, 2 * math.pi)]

    def bits(q: tuple[float, ...]) -> bytes:
        return struct.pack("<4d", *q)

    assert all(bits(tuple(p.getQuaternionFromEuler(a))) == bits(rpy_to_unit_quat(*a))
               for a in angles)
    # The premise: without the scaling a third of them differ in the last bit.
    differ = sum(bits(tuple(p.getQuaternionFromEuler(a))) != bits(rpy_to_quat(*a))
                 for a in angles[:3000])
    assert differ > 500


def test_simulation_runs_on_the_engine_and_hands_out_pybullet_as_an_escape_hatch() -> None:
    from urdfkit.sim import Simulation

    doc = {"duration": 0.1, "ground": "simpleplane",
           "robots": [{"name": "p", "urdf": PENDULUM, "base": "fixed"}]}
    with Simulation(doc) as sim:
        assert isinstance(sim.engine, PyBulletEngine)
        assert sim.bullet.client == sim.session.client == sim.engine.session.client
        assert sim.bullet.getNumBodies() == 2  # the ground and the pendulum
        shadow, _ = sim.dynamics.model(sim.robot("p"))
        assert shadow is not sim.engine and shadow.name == sim.engine.name
    with pytest.raises(Exception, match="Not connected"):
        sim.bullet.getNumBodies()


def test_a_meshs_file_and_a_links_vertices_are_what_pybullet_loaded(
        engine: PyBulletEngine) -> None:
    """What agree reads of PyBullet's meshes: the file it read, every vertex it keeps."""
    from urdfkit.sources.resolve import open_input

    with open_input("r2d2.urdf") as res:
        body = engine.load(str(res.load_path), LoadSettings(fixed_base=True))
    raw = engine.bullet
    meshes = 0
    for link in range(-1, raw.getNumJoints(body)):
        for shape, row in zip(engine.collision_shapes(body, link),
                              raw.getCollisionShapeData(body, link), strict=True):
            want = row[4].decode() if shape.kind == "mesh" else ""
            assert shape.filename == want
            meshes += shape.kind == "mesh"
            assert not want or Path(want).is_file()
        try:
            count, vertices = raw.getMeshData(body, link, -1)
        except raw.error:
            count, vertices = 0, []
        assert engine.collision_vertices(body, link) == (list(vertices) if count else [])
    assert meshes and any(engine.collision_vertices(body, k)
                          for k in range(raw.getNumJoints(body)))


def test_no_dynamics_are_asked_of_a_body_loaded_after_a_removal() -> None:
    """kuka_iiwa loaded after a pendulum whose mass matrix PyBullet built, then removed: raw
    PyBullet may hand kuka the pendulum's model (measured: a dimension error, then its
    SystemError); the engine refuses, naming why, on every such body."""
    from urdfkit.core.errors import EngineError

    e = PyBulletEngine()
    try:
        pendulum = e.load(PENDULUM, LoadSettings(fixed_base=True, inertia_from_file=True))
        e.mass_matrix(pendulum, [0.1])
        e.remove_body(pendulum)
        kuka = e.load(str(_kuka()), LoadSettings(fixed_base=True))
        with pytest.raises(EngineError, match="after a removeBody"):
            e.mass_matrix(kuka, [0.1] * 7)
        with pytest.raises(EngineError, match="after a removeBody"):
            e.inverse_dynamics(kuka, [0.1] * 7, [0.0] * 7, [0.0] * 7)
    finally:
        e.close()


def _kuka() -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf"


def test_a_body_out_of_every_contact_falls_through_the_ground_and_can_be_removed(
        engine: PyBulletEngine, simpleplane_urdf: Path, tmp_path: Path) -> None:
    (tmp_path / "box.urdf").write_text(BOX)
    engine.load(str(simpleplane_urdf), LoadSettings(fixed_base=True, scenery=True))
    engine.set_gravity((0.0, 0.0, -9.81))
    kept = engine.load(str(tmp_path / "box.urdf"), LoadSettings(position=(0.0, 0.0, 0.2)))
    ghost = engine.load(str(tmp_path / "box.urdf"), LoadSettings(position=(1.0, 0.0, 0.2)))
    engine.set_collision_filter(ghost, -1, 0, 0)
    for _ in range(240):
        engine.step()
    assert engine.base_pose(kept)[0][2] == pytest.approx(0.1, abs=2e-3)  # it rests
    assert engine.base_pose(ghost)[0][2] < -1.0  # it fell through
    engine.remove_body(ghost)
    assert engine.bullet.getNumBodies() == 2
    # PyBullet hands a removed body's id on: nothing the engine knew of it may stay, as
    # a refused inverse-dynamics model (KR210's asymmetric link_2) would
    from urdfkit.core.errors import EngineError

    refused = engine.load(str(ROBOTS / "id_asymmetric.urdf"), LoadSettings(fixed_base=True))
    moving = sum(1 for j in engine.joints(refused) if j.kind != "fixed")
    with pytest.raises(EngineError):
        engine.mass_matrix(refused, [0.0] * moving)
    engine.remove_body(refused)
    again = engine.load(PENDULUM, LoadSettings(fixed_base=True, inertia_from_file=True))
    assert again == refused
    # ...nor may PyBullet's: it keeps models by the body's place in memory, and a body
    # loaded after a removal can get the removed one's: refused, named, not asked
    with pytest.raises(EngineError, match="after a removeBody"):
        engine.mass_matrix(again, [0.2])
    assert PyBulletEngine.load_flags(LoadSettings(inertia_from_file=True,
                                                  self_collision=True)) == [
        "URDF_USE_INERTIA_FROM_FILE", "URDF_USE_IMPLICIT_CYLINDER", "URDF_USE_SELF_COLLISION"]
