"""One contract, every engine: the same pendulum, box and car give the same physics.

Each case runs on every engine through the seam's :class:`urdfkit.engine.api.Simulator` and is
held to what physics says, not to the engine's own numbers: a compound pendulum's period, a
free fall's time, a rolling wheel's distance. Every tolerance is stated beside its figure;
docs/engines.md lists what each engine measured.

``pybullet`` is raw PyBullet, through :class:`RawBullet` below, until
``urdfkit/engine/pybullet.py`` is registered in :data:`urdfkit.engine.registry.ENGINES`; then
the registered engine runs the same cases.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import pytest

from urdfkit.core.errors import InputError, MissingDependencyError, ParameterError
from urdfkit.engine.api import BaseState, ContactPoint, JointInfo, JointState, LoadSettings
from urdfkit.engine.registry import ENGINES, open_engine, preload

ROBOTS = Path(__file__).parent / "fixtures" / "robots"
PENDULUM = ROBOTS / "compound_pendulum.urdf"
BOX = ROBOTS / "falling_box.urdf"
SLED = ROBOTS / "sled.urdf"
OFFSET = ROBOTS / "offset_base.urdf"
G = 9.81
DT = 1.0 / 240.0
ENGINE_NAMES = ["pybullet", "mujoco"]


class RawBullet:
    """The reference: what the contract asks of an engine, in raw PyBullet calls.

    Stands in for ``engine/pybullet.py`` until that is registered (see the module).
    """

    name = "pybullet"

    def __init__(self) -> None:
        from urdfkit.engine.session import Session

        self.session = Session()
        self.p = self.session.bullet

    def load(self, path: str, settings: LoadSettings, display: str | None = None) -> int:
        from urdfkit.engine.session import LoadOptions

        return self.session.load_urdf(path, LoadOptions(
            fixed_base=settings.fixed_base, inertia_from_file=settings.inertia_from_file,
            implicit_cylinder=settings.implicit_cylinder, self_collision=settings.self_collision,
            base_position=settings.position, base_orientation=settings.orientation), display)

    def set_gravity(self, gravity: Sequence[float]) -> None:
        self.p.setGravity(*gravity)

    def set_time_step(self, time_step: float) -> None:
        self.p.setTimeStep(time_step)

    def step(self) -> None:
        self.p.stepSimulation()

    def save(self) -> int:
        return int(self.p.saveState())

    def restore(self, state: int) -> None:
        self.p.restoreState(state)

    def joints(self, body: int) -> list[JointInfo]:
        kinds = {0: "revolute", 1: "prismatic", 2: "spherical", 3: "planar", 4: "fixed"}
        out = []
        for i in range(self.p.getNumJoints(body)):
            j = self.p.getJointInfo(body, i)
            out.append(JointInfo(i, j[1].decode(), kinds[j[2]], j[3], j[4], j[6], j[7], j[8],
                                 j[9], j[8] <= j[9], j[10], j[11], j[12].decode(),
                                 tuple(j[13]), j[16]))  # type: ignore[arg-type]
        return out

    def joint_states(self, body: int, joints: Sequence[int]) -> list[JointState]:
        return [JointState(s[0], s[1], tuple(s[2]), s[3])  # type: ignore[arg-type]
                for s in self.p.getJointStates(body, list(joints))]

    def reset_joint(self, body: int, joint: int, position: float, velocity: float = 0.0
                    ) -> None:
        self.p.resetJointState(body, joint, position, velocity)

    def motors(self, body: int, joints: Sequence[int], mode: str, targets: Sequence[float],
               forces: Sequence[float] | None = None) -> None:
        if mode == "torque":
            self.p.setJointMotorControlArray(body, list(joints), self.p.TORQUE_CONTROL,
                                             forces=list(targets))
            return
        kind = {"velocity": self.p.VELOCITY_CONTROL, "position": self.p.POSITION_CONTROL}[mode]
        key = "targetVelocities" if mode == "velocity" else "targetPositions"
        self.p.setJointMotorControlArray(body, list(joints), kind, **{key: list(targets)},
                                         forces=list(forces or [100000.0] * len(joints)))

    def change_dynamics(self, body: int, link: int, **values: Any) -> None:
        self.p.changeDynamics(body, link, **values)

    def reset_base(self, body: int, position: Sequence[float], orientation: Sequence[float]
                   ) -> None:
        self.p.resetBasePositionAndOrientation(body, position, orientation)
        self.p.resetBaseVelocity(body, [0, 0, 0], [0, 0, 0])

    def reset_base_velocity(self, body: int, linear: Sequence[float], angular: Sequence[float]
                            ) -> None:
        self.p.resetBaseVelocity(body, linear, angular)

    def base_state(self, body: int) -> BaseState:
        pos, orn = self.p.getBasePositionAndOrientation(body)
        lin, ang = self.p.getBaseVelocity(body)
        return BaseState(tuple(pos), tuple(orn), tuple(lin), tuple(ang))  # type: ignore[arg-type]

    def contacts(self, body: int, link: int | None = None, other: int | None = None
                 ) -> list[ContactPoint]:
        kw: dict[str, int] = {"bodyA": body}
        if other is not None:
            kw["bodyB"] = other
        return [ContactPoint(c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10],
                             c[11], c[12], c[13]) for c in self.p.getContactPoints(**kw)
                if link is None or c[3] == link]

    def set_joint_positions(self, body: int, positions: Sequence[float]) -> None:
        moving = [i for i in range(self.p.getNumJoints(body))
                  if self.p.getJointInfo(body, i)[2] != self.p.JOINT_FIXED]
        for i, q in zip(moving, positions, strict=True):
            self.p.resetJointState(body, i, q, 0.0)

    def link_frames(self, body: int) -> list[tuple[Any, Any]]:
        pos, orn = self.p.getBasePositionAndOrientation(body)
        d = self.p.getDynamicsInfo(body, -1)
        frames = [self.p.multiplyTransforms(pos, orn, *self.p.invertTransform(d[3], d[4]))]
        for i in range(self.p.getNumJoints(body)):
            s = self.p.getLinkState(body, i, computeForwardKinematics=True)
            frames.append((s[4], s[5]))
        return frames

    def mass_matrix(self, body: int, positions: Sequence[float]) -> list[list[float]]:
        return [list(row) for row in self.p.calculateMassMatrix(body, list(positions))]

    def inverse_dynamics(self, body: int, positions: Sequence[float],
                         velocities: Sequence[float], accelerations: Sequence[float]
                         ) -> list[float]:
        return list(self.p.calculateInverseDynamics(body, list(positions), list(velocities),
                                                    list(accelerations)))

    def close(self) -> None:
        self.session.close()


def _open(name: str) -> Any:
    return open_engine(name) if name in ENGINES else RawBullet()


@pytest.fixture(params=ENGINE_NAMES)
def engine(request: pytest.FixtureRequest) -> Iterator[Any]:
    e = _open(request.param)
    try:
        e.set_gravity((0.0, 0.0, -G))
        e.set_time_step(DT)
        yield e
    finally:
        e.close()


def _free_pendulum(e: Any, angle: float) -> int:
    """The pendulum at ``angle``, at rest, its motor and PyBullet's link damping off."""
    body = e.load(str(PENDULUM), LoadSettings(fixed_base=True, inertia_from_file=True))
    e.motors(body, [0], "velocity", [0.0], forces=[0.0])
    for link in (-1, 0):
        e.change_dynamics(body, link, linearDamping=0.0, angularDamping=0.0)
    e.reset_joint(body, 0, angle)
    return body


def _period(small: float, amplitude: float) -> float:
    """A pendulum's period at ``amplitude`` (rad): the small-swing period times 2 K(k) / pi,
    k = sin(amplitude / 2), K by the arithmetic-geometric mean."""
    a, b = 1.0, math.cos(amplitude / 2)
    for _ in range(40):
        a, b = (a + b) / 2, math.sqrt(a * b)
    return small / a


#: The pendulum (tests/fixtures/robots/compound_pendulum.urdf): I about the hinge, m, d.
I_HINGE, MASS, D = 0.27, 1.0, 0.5


def test_pendulum_swings_with_the_compound_pendulum_period(engine: Any) -> None:
    """Released from 0.5 rad, the period is 2 pi sqrt(I / (m g d)) with its amplitude factor
    (1.0159 at 0.5 rad), to 0.05 %, and the swing keeps its amplitude to 0.5 %."""
    body = _free_pendulum(engine, 0.5)
    crossings, peak, prev = [], 0.0, 0.5
    for n in range(1, int(7.0 / DT)):
        engine.step()
        q = engine.joint_states(body, [0])[0].position
        if prev > 0 >= q:  # downward through the bottom, interpolated within the step
            crossings.append((n - 1 + prev / (prev - q)) * DT)
        peak = max(peak, q) if n * DT > 5.0 else peak
        prev = q
    periods = [b - a for a, b in zip(crossings, crossings[1:], strict=False)]
    small = 2 * math.pi * math.sqrt(I_HINGE / (MASS * G * D))
    expected = _period(small, 0.5)
    assert len(periods) >= 3
    assert sum(periods) / len(periods) == pytest.approx(expected, rel=5e-4), (periods, expected)
    assert peak == pytest.approx(0.5, rel=5e-3)


def test_pendulum_mass_matrix_and_inverse_dynamics(engine: Any) -> None:
    """M = I about the hinge; at rest at 0.5 rad gravity takes m g d sin(0.5) (1e-9)."""
    body = _free_pendulum(engine, 0.0)
    assert engine.mass_matrix(body, [0.3]) == [[pytest.approx(I_HINGE, rel=1e-9)]]
    torque = engine.inverse_dynamics(body, [0.5], [0.0], [0.0])
    assert torque == [pytest.approx(MASS * G * D * math.sin(0.5), rel=1e-9)]
    accel = engine.inverse_dynamics(body, [0.0], [0.0], [2.0])
    assert accel == [pytest.approx(2.0 * I_HINGE, rel=1e-9)]


def test_change_dynamics_mass_and_inertia(engine: Any) -> None:
    """A heavier arm (2 kg, I_cm 0.05 about the hinge's axis): M = 0.05 + 2 d^2, and gravity's
    torque doubles (1e-9)."""
    body = _free_pendulum(engine, 0.0)
    engine.change_dynamics(body, 0, mass=2.0, localInertiaDiagonal=[0.05, 0.05, 0.002])
    assert engine.mass_matrix(body, [0.0]) == [[pytest.approx(0.05 + 2.0 * D * D, rel=1e-9)]]
    torque = engine.inverse_dynamics(body, [0.5], [0.0], [0.0])
    assert torque == [pytest.approx(2.0 * G * D * math.sin(0.5), rel=1e-9)]


def test_a_position_motor_follows_pybullets_law() -> None:
    """PyBullet's POSITION_CONTROL asks each step for v' = 0.1 (q* - q) / dt (its default
    gains): without gravity, q_n = q* (1 - 0.9^n) (measured on PyBullet). Both engines, to
    5e-5 rad: MuJoCo's motor row meets 0.9999 of what it asks each step (its hardest
    impedance), so it follows 1 - 0.90001^n, at most 3.9e-5 rad off."""
    for name in ENGINE_NAMES:
        e = _open(name)
        try:
            e.set_time_step(DT)
            body = e.load(str(PENDULUM), LoadSettings(fixed_base=True, inertia_from_file=True))
            e.motors(body, [0], "position", [1.0], forces=[100000.0])
            for n in range(1, 31):
                e.step()
                q = e.joint_states(body, [0])[0].position
                assert q == pytest.approx(1.0 - 0.9 ** n, abs=5e-5), (name, n)
        finally:
            e.close()


def test_the_engines_swing_the_same_pendulum() -> None:
    """Both engines integrate a free swing alike: semi-implicit Euler at the same step, to
    1e-9 rad over 2 s."""
    traces = []
    for name in ENGINE_NAMES:
        e = _open(name)
        try:
            e.set_gravity((0.0, 0.0, -G))
            e.set_time_step(DT)
            body = _free_pendulum(e, 0.5)
            trace = []
            for _ in range(int(2.0 / DT)):
                e.step()
                trace.append(e.joint_states(body, [0])[0].position)
            traces.append(trace)
        finally:
            e.close()
    worst = max(abs(a - b) for a, b in zip(*traces, strict=True))
    assert worst < 1e-9, worst


def _ground(e: Any) -> int:
    """pybullet_data's plane.urdf (lateral friction 1), as both engines load it."""
    from urdfkit.sources.resolve import locate

    return e.load(str(locate("plane.urdf")), LoadSettings(fixed_base=True), "plane.urdf")


def test_a_dropped_box_hits_the_ground_after_sqrt_2h_over_g(engine: Any) -> None:
    """The box's first contact is within 2 steps (8.3 ms) of sqrt(2 h / g); at rest, the
    ground carries its weight to 1 %."""
    ground = _ground(engine)
    height = 0.5  # the box's underside above the ground
    box = engine.load(str(BOX), LoadSettings(inertia_from_file=True,
                                             position=(0.0, 0.0, height + 0.1)))
    engine.change_dynamics(box, -1, linearDamping=0.0, angularDamping=0.0)
    hit = None
    for n in range(1, int(1.0 / DT)):
        engine.step()
        if any(c.distance <= 0 for c in engine.contacts(box, other=ground)):
            hit = n * DT
            break
    assert hit is not None
    assert abs(hit - math.sqrt(2 * height / G)) <= 2 * DT, (hit, math.sqrt(2 * height / G))
    for _ in range(int(1.0 / DT)):
        engine.step()
    weight = sum(c.normal_force for c in engine.contacts(box, other=ground))
    assert weight == pytest.approx(MASS * G, rel=1e-2)
    assert all(c.normal[2] > 0.99 for c in engine.contacts(box, other=ground))  # B to A: up


@pytest.fixture(scope="module")
def car_urdf(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, float]:
    """simplecar as `urdfkit build simplecar` writes it, and its wheels' radius."""
    from lxml import etree

    from urdfkit.model.catalog import build_template

    path = build_template("simplecar").write(tmp_path_factory.mktemp("car") / "simplecar.urdf")
    radii = {float(c.get("radius")) for c in etree.parse(str(path)).iter("cylinder")}
    assert len(radii) == 1
    return Path(path), radii.pop()


def test_a_car_drives_wheel_speed_times_radius_times_time(engine: Any,
                                                          car_urdf: tuple[Path, float]) -> None:
    """simplecar's four wheels at 10 rad/s under a 10 N m cap, steering held at 0: after
    2 s it has gone omega r t within 5 %, straight (1 cm), its wheels at speed (1 %) and never
    past it by more than 1 % (a motor at its cap stops at its target)."""
    path, radius = car_urdf
    _ground(engine)
    car = engine.load(str(path), LoadSettings(position=(0.0, 0.0, radius)))
    names = [j.name for j in engine.joints(car)]
    wheels = [i for i, n in enumerate(names) if "wheel" in n]
    hinges = [i for i, n in enumerate(names) if "hinge" in n and "wheel" not in n]
    assert len(wheels) == 4 and len(hinges) == 2, names
    omega, seconds = 10.0, 2.0
    engine.motors(car, wheels, "velocity", [omega] * 4, forces=[10.0] * 4)
    engine.motors(car, hinges, "position", [0.0] * 2, forces=[100000.0] * 2)
    top = 0.0
    for _ in range(int(seconds / DT)):
        engine.step()
        top = max(top, *(s.velocity for s in engine.joint_states(car, wheels)))
    assert top <= omega * 1.01
    x, y, _ = engine.base_state(car).position
    assert x == pytest.approx(omega * radius * seconds, rel=0.05)
    assert abs(y) < 0.01
    for s in engine.joint_states(car, wheels):
        assert s.velocity == pytest.approx(omega, rel=0.01)


def test_default_motors_hold_what_no_motor_drives(engine: Any,
                                                  car_urdf: tuple[Path, float]) -> None:
    """PyBullet's default motor (velocity 0, 1 N m s per step) on every joint holds: a
    pendulum left at 0.5 rad stays there (1e-4 rad over 1 s), and simplecar with only its
    wheels driven keeps its steering straight against them (0.01 rad) and drives straight
    (1 cm sideways in 2 m)."""
    pendulum = engine.load(str(PENDULUM), LoadSettings(fixed_base=True, inertia_from_file=True))
    engine.reset_joint(pendulum, 0, 0.5)
    path, radius = car_urdf
    _ground(engine)
    car = engine.load(str(path), LoadSettings(position=(5.0, 0.0, radius)))
    wheels = [j.index for j in engine.joints(car) if "wheel" in j.name]
    hinges = [j.index for j in engine.joints(car) if j.name.endswith("hinge")]
    engine.motors(car, wheels, "velocity", [10.0] * 4, forces=[10.0] * 4)
    steer = 0.0
    for _ in range(int(2.0 / DT)):
        engine.step()
        steer = max(steer, *(abs(s.position) for s in engine.joint_states(car, hinges)))
    assert engine.joint_states(pendulum, [0])[0].position == pytest.approx(0.5, abs=1e-4)
    assert steer < 0.01
    assert abs(engine.base_state(car).position[1]) < 0.01


@pytest.mark.parametrize("name", ["simplecar", "r2d2.urdf", "kuka_iiwa/model.urdf"])
def test_joints_are_pybullets(name: str, car_urdf: tuple[Path, float]) -> None:
    """Every engine numbers joints and links as PyBullet does (depth-first, file order), with
    PyBullet's kinds (a continuous joint is revolute without limits), limits, dynamics, axes
    and parents; only the state vectors' indices are each engine's own.

    PyBullet's getJointInfo gives a continuous joint the bounds its <limit> writes (r2d2's
    head_swivel: -0.38 to 0) but never holds it there (measured: driven to 2 rad): the seam
    says it has no limits, and its bounds are not compared.
    """
    from lxml import etree

    from urdfkit.sources.resolve import locate

    path = car_urdf[0] if name == "simplecar" else locate(name)
    continuous = {j.get("name") for j in etree.parse(str(path)).iter("joint")
                  if j.get("type") == "continuous"}
    tables = []
    for engine_name in ENGINE_NAMES:
        e = _open(engine_name)
        try:
            body = e.load(str(path), LoadSettings())
            tables.append([(j.index, j.name, j.kind, j.damping, j.friction, j.effort,
                            j.velocity, j.link, j.parent,
                            None if j.name in continuous else (j.lower, j.upper, j.limited),
                            j.axis) for j in e.joints(body)])
            if engine_name == "mujoco":   # the seam's word: no limits
                assert not [j for j in e.joints(body) if j.name in continuous and j.limited]
        finally:
            e.close()
    assert [row[:-1] for row in tables[0]] == [row[:-1] for row in tables[1]]
    assert not [j for j in tables[1] if j[1] in continuous and j[2] != "revolute"]
    for a, b in zip(tables[0], tables[1], strict=True):
        assert a[-1] == pytest.approx(b[-1], abs=1e-12)   # the axis, normalised by each


def test_contacts_name_the_links_and_carry_the_weight(engine: Any) -> None:
    """r2d2 at rest touches the ground with its four wheels (links 2, 3, 6, 7: children of
    fixed links, which MuJoCo fuses), which carry its weight (1e-3); a box stacked on another
    rests on it, the normal from the lower box to the upper (B to A)."""
    from lxml import etree

    from urdfkit.sources.resolve import locate

    ground = _ground(engine)
    path = locate("r2d2.urdf")
    mass = sum(float(m.get("value")) for m in etree.parse(str(path)).iter("mass"))
    robot = engine.load(str(path), LoadSettings(position=(0.0, 0.0, 0.5)))
    lower = engine.load(str(BOX), LoadSettings(position=(2.0, 0.0, 0.1)))
    upper = engine.load(str(BOX), LoadSettings(position=(2.0, 0.0, 0.35)))
    for _ in range(int(2.0 / DT)):
        engine.step()
    touching = engine.contacts(robot, other=ground)
    assert sorted({c.link_a for c in touching}) == [2, 3, 6, 7]
    assert {c.link_b for c in touching} == {-1} and {c.body_b for c in touching} == {ground}
    assert sum(c.normal_force for c in touching) == pytest.approx(mass * G, rel=1e-3)
    assert engine.contacts(robot, link=2, other=ground)
    assert not engine.contacts(robot, link=0, other=ground)
    stacked = engine.contacts(upper, other=lower)
    assert sum(c.normal_force for c in stacked) == pytest.approx(MASS * G, rel=1e-3)
    assert all(c.normal[2] > 0.99 and c.body_a == upper for c in stacked)


def test_restore_steps_again_exactly(engine: Any) -> None:
    """A saved state, restored mid-contact, steps as it did the first time."""
    _ground(engine)
    box = engine.load(str(BOX), LoadSettings(inertia_from_file=True,
                                             position=(0.0, 0.0, 0.15)))
    for _ in range(20):
        engine.step()
    state = engine.save()
    runs = []
    for _ in range(2):
        engine.restore(state)
        trace = []
        for _ in range(30):
            engine.step()
            trace.append(engine.base_state(box).position)
        runs.append(trace)
    assert runs[0] == runs[1]


def test_the_base_is_its_inertial_frame_as_pybullet_has_it() -> None:
    """base_state is the root's inertial frame (off the link frame, turned); reset_base and
    reset_base_velocity set that frame; both engines agree to 1e-6 (PyBullet keeps float32
    frames)."""
    turn = (0.1, -0.2, 0.3, math.sqrt(1 - 0.14))
    states = []
    for name in ENGINE_NAMES:
        e = _open(name)
        try:
            e.set_time_step(DT)   # no gravity: the body flies straight
            body = e.load(str(OFFSET), LoadSettings(inertia_from_file=True,
                                                    position=(1.0, 2.0, 3.0),
                                                    orientation=turn))
            e.change_dynamics(body, -1, linearDamping=0.0, angularDamping=0.0)
            loaded = e.base_state(body)
            e.reset_base(body, (0.5, -0.5, 2.0), (0.0, 0.0, 0.0, 1.0))
            moved = e.base_state(body)
            e.reset_base_velocity(body, (1.0, 0.0, 0.5), (0.0, 0.0, 2.0))
            launched = e.base_state(body)
            e.step()
            flown = e.base_state(body)
            states.append((loaded, moved, launched, flown))
        finally:
            e.close()
    for (_, moved, launched, flown) in states:
        assert moved.position == pytest.approx((0.5, -0.5, 2.0), abs=1e-6)
        assert moved.orientation == pytest.approx((0.0, 0.0, 0.0, 1.0), abs=1e-6)
        assert launched.linear == pytest.approx((1.0, 0.0, 0.5), abs=1e-6)
        assert launched.angular == pytest.approx((0.0, 0.0, 2.0), abs=1e-6)
        # MuJoCo moves the link frame's origin, and turns the body about it: the centre of
        # mass strays from its straight line by w^2 |arm| dt^2 / 2 (4e-6 m here)
        assert flown.position == pytest.approx((0.5 + DT, -0.5, 2.0 + 0.5 * DT), abs=1e-5)
    a, b = states
    for x, y in zip(a[:3], b[:3], strict=True):
        assert x.position == pytest.approx(y.position, abs=1e-6)
        assert x.orientation == pytest.approx(y.orientation, abs=1e-6)
        assert x.linear == pytest.approx(y.linear, abs=1e-6)
        assert x.angular == pytest.approx(y.angular, abs=1e-6)


@pytest.mark.parametrize(("name", "fixed"), [("kuka_iiwa/model.urdf", True),
                                             ("r2d2.urdf", False)])
def test_link_frames_mass_matrix_and_inverse_dynamics_agree(name: str, fixed: bool) -> None:
    """At seeded poses every link frame (fixed links fused into their parents' bodies
    included) agrees to 1e-6 m and 1e-6 in the quaternion (PyBullet's are float32), and a fixed
    arm's mass matrix and inverse dynamics to 1e-6 relative."""
    import numpy as np

    from urdfkit.sources.resolve import locate

    path = str(locate(name))
    rng = np.random.default_rng(7)
    runs = []
    for engine_name in ENGINE_NAMES:
        e = _open(engine_name)
        try:
            e.set_gravity((0.0, 0.0, -G))
            body = e.load(path, LoadSettings(fixed_base=fixed, inertia_from_file=True,
                                             position=(0.2, -0.1, 0.5)), name)
            moving = [j for j in e.joints(body) if j.kind != "fixed"]
            run = []
            for q in rng.uniform(-1.0, 1.0, (3, len(moving))).tolist():
                e.set_joint_positions(body, q)
                frames = e.link_frames(body)
                extra: tuple[Any, ...] = ()
                if fixed:
                    extra = (e.mass_matrix(body, q), e.inverse_dynamics(
                        body, q, [0.3] * len(q), [0.5] * len(q)))
                run.append((frames, extra))
            runs.append(run)
            rng = np.random.default_rng(7)
        finally:
            e.close()
    for (frames_a, extra_a), (frames_b, extra_b) in zip(*runs, strict=True):
        assert len(frames_a) == len(frames_b)
        for (pa, qa), (pb, qb) in zip(frames_a, frames_b, strict=True):
            assert pa == pytest.approx(pb, abs=1e-6)
            sign = 1.0 if sum(x * y for x, y in zip(qa, qb, strict=True)) > 0 else -1.0
            assert qa == pytest.approx([sign * x for x in qb], abs=1e-6)
        if fixed:
            assert np.allclose(extra_a[0], extra_b[0], rtol=1e-6, atol=1e-9)
            assert np.allclose(extra_a[1], extra_b[1], rtol=1e-6, atol=1e-6)


# --------------------------------------------------------------------------- MuJoCo's own


def test_mujoco_refuses_an_inertia_it_cannot_simulate_naming_the_link_and_fix(
        tmp_path: Path) -> None:
    """PyBullet zeroes a tensor that breaks the triangle inequality; MuJoCo refuses the moving
    body it leaves: one error (exit code 2) naming the link and `urdfkit fix`."""
    bad = tmp_path / "bad.urdf"
    bad.write_text(PENDULUM.read_text().replace(
        'ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.001"',
        'ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.05"'))
    e = open_engine("mujoco")
    try:
        with pytest.raises(InputError) as caught:
            e.load(str(bad), LoadSettings(fixed_base=True, inertia_from_file=True), "bad.urdf")
    finally:
        e.close()
    err = caught.value
    assert err.exit_code == 2
    assert "'arm'" in err.message and "urdfkit fix" in err.message, err.message
    assert err.file == "bad.urdf"


@pytest.mark.parametrize(("key", "value", "said"), [
    ("contactStiffness", 1e4, "solref"), ("maxJointVelocity", 50.0, "velocity cap"),
    ("restitution", 0.5, "bounce"), ("linearDamping", 0.04, "per-body velocity damping"),
    ("lateralFricton", 0.5, "did you mean 'lateralFriction'")])
def test_mujoco_names_what_it_cannot_carry(key: str, value: float, said: str) -> None:
    e = open_engine("mujoco")
    try:
        body = e.load(str(BOX), LoadSettings())
        with pytest.raises(ParameterError) as caught:
            e.change_dynamics(body, -1, **{key: value})
    finally:
        e.close()
    assert key in caught.value.message and said in caught.value.message


def _sliding_friction(engine: Any, push: float) -> float:
    """The friction the sled's block slides with, pushed along at ``push`` m g (a torque on
    its slide each step) from 0.2 to 0.8 s: (F - m a) / (m g)."""
    sled = engine.load(str(SLED), LoadSettings(fixed_base=True, inertia_from_file=True))
    engine.motors(sled, [0, 1], "velocity", [0.0, 0.0], forces=[0.0, 0.0])
    for link in (-1, 0, 1):
        engine.change_dynamics(sled, link, linearDamping=0.0, angularDamping=0.0)
    for _ in range(24):   # settle onto the ground
        engine.step()
    speeds = []
    for _ in range(int(1.0 / DT)):
        engine.motors(sled, [0], "torque", [push * MASS * G])
        engine.step()
        speeds.append(engine.joint_states(sled, [0])[0].velocity)
    a, b = int(0.2 / DT), int(0.8 / DT)
    accel = (speeds[b] - speeds[a]) / ((b - a) * DT)
    return (push * MASS * G - (MASS + 0.001) * accel) / (MASS * G)


def test_ground_friction_is_the_product_of_the_two(engine: Any) -> None:
    """PyBullet multiplies two links' friction: a block of 0.5 (its default) on pybullet_data's
    plane (1.0) slides with 0.5, where MuJoCo's own rule (the larger) would give 1.0 and hold
    it. Pushed at 0.7 m g, the friction it slides with is 0.5 (5 %)."""
    _ground(engine)
    assert _sliding_friction(engine, 0.7) == pytest.approx(0.5, rel=0.05)


def test_changed_ground_friction_is_the_product_too(engine: Any) -> None:
    """The ground's friction set to 0.5 (changeDynamics on it): the block (0.5) now slides
    with 0.25 (5 %), pushed at 0.5 m g."""
    ground = _ground(engine)
    engine.change_dynamics(ground, -1, lateralFriction=0.5)
    assert _sliding_friction(engine, 0.5) == pytest.approx(0.25, rel=0.05)


def test_mujoco_adds_a_body_mid_run_keeping_the_world_as_it_was() -> None:
    """A body loaded after steps recompiles the world: the pendulum swings on from where it
    was, its motor still driving it, its joint's changed damping still there."""
    e = open_engine("mujoco")
    try:
        e.set_gravity((0.0, 0.0, -G))
        e.set_time_step(DT)
        body = _free_pendulum(e, 0.5)
        e.change_dynamics(body, 0, jointDamping=0.01)
        e.motors(body, [0], "velocity", [1.0], forces=[100.0])
        for _ in range(24):
            e.step()
        before = e.joint_states(body, [0])[0]
        e.load(str(BOX), LoadSettings(position=(3.0, 0.0, 0.5)))
        assert e.joint_states(body, [0])[0] == before
        e.step()
        after = e.joint_states(body, [0])[0]
        assert after.velocity == pytest.approx(1.0, abs=1e-3)
        assert after.position == pytest.approx(before.position + DT, abs=1e-5)
        assert e.joints(body)[0].damping == 0.01
    finally:
        e.close()


def test_mujoco_names_a_solver_setting_it_has_no_meaning_for() -> None:
    """set_physics in PyBullet's terms: `solver_iterations` is named, not ignored; the cone
    is MuJoCo's elliptic one or its pyramid; sorted pairs are what MuJoCo always does."""
    e = open_engine("mujoco")
    try:
        body = e.load(str(BOX), LoadSettings())
        e.set_physics(deterministic_pairs=True, cone_friction=False)
        with pytest.raises(ParameterError, match="solver_iterations"):
            e.set_physics(solver_iterations=50)
        e.step()
        e.load(str(BOX), LoadSettings(position=(1.0, 0.0, 0.0)))   # recompiled: still a pyramid
        e.step()
        import mujoco

        assert e.world.m.opt.cone == mujoco.mjtCone.mjCONE_PYRAMIDAL
        e.set_physics(cone_friction=True)
        assert e.world.m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
        assert e.base_state(body)
    finally:
        e.close()


def test_mujoco_says_when_the_run_diverges() -> None:
    """A torque of 1e308 N m: MuJoCo's bad accelerations are an EngineError naming them, and
    the state is left as it went (MuJoCo alone warns and starts over from its initial state,
    where a run would silently go on)."""
    from urdfkit.core.errors import EngineError

    e = open_engine("mujoco")
    try:
        body = e.load(str(PENDULUM), LoadSettings(fixed_base=True, inertia_from_file=True))
        e.reset_joint(body, 0, 0.5)
        e.motors(body, [0], "torque", [1e308])
        with pytest.raises(EngineError, match="diverged"):
            e.step()
        assert not math.isfinite(e.joint_states(body, [0])[0].velocity)
    finally:
        e.close()


def test_missing_mujoco_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "mujoco", None)  # `import mujoco` raises ImportError
    with pytest.raises(MissingDependencyError) as caught:
        open_engine("mujoco")
    assert "pip install 'urdfkit[mujoco]'" in caught.value.message
    assert "\n" not in caught.value.message
    with pytest.raises(MissingDependencyError, match=r"urdfkit\[mujoco\]"):
        preload("mujoco")


def test_mujoco_has_no_gui_and_says_so() -> None:
    with pytest.raises(ParameterError, match="headless"):
        open_engine("mujoco", gui=True)


def test_an_unknown_engine_is_named_with_the_closest() -> None:
    with pytest.raises(ParameterError) as caught:
        open_engine("mujuco")
    assert "did you mean 'mujoco'" in caught.value.message


def test_restore_with_motors_at_their_caps_steps_again_exactly(
        engine: Any, car_urdf: tuple[Path, float], request: pytest.FixtureRequest) -> None:
    """Saved while its wheels' motors push at their caps, the car drives on as it did."""
    if engine.name == "pybullet":
        # Measured on PyBullet 3.2.7: the first step after each restore differs (a wheel at
        # 27.53 rad/s after one restore, 26.86 after the next) though the bodies' state is the
        # same: the motors' solver state is not in saveState, and restore_clean, which drops
        # the contact manifolds, does not reach it. Strict: it fails once PyBullet replays.
        request.applymarker(pytest.mark.xfail(strict=True, reason="PyBullet keeps its motor "
                                              "rows' warm start across restoreState"))
    path, radius = car_urdf
    _ground(engine)
    car = engine.load(str(path), LoadSettings(position=(0.0, 0.0, radius)))
    engine.motors(car, [1, 3, 4, 5], "velocity", [30.0] * 4, forces=[2.0] * 4)
    for _ in range(10):
        engine.step()
    state = engine.save()
    runs = []
    for _ in range(2):
        engine.restore(state)
        trace = []
        for _ in range(60):
            engine.step()
            trace.append((engine.base_state(car).position,
                          [s.velocity for s in engine.joint_states(car, [1, 3, 4, 5])]))
        runs.append(trace)
    assert runs[0] == runs[1]
    assert all(s.applied == pytest.approx(2.0) for s in engine.joint_states(car, [4, 5]))
