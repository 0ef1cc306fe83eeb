"""What a :class:`~urdfkit.motion.simulation.Simulation` is asked of its robots' physics.

:class:`RobotPhysics`, mixed into ``Simulation``: the dynamics quantities on shadow models
(:mod:`urdfkit.motion.sim_dynamics`) and the setters of a robot's physical parameters
(:mod:`urdfkit.motion.sim_robot`), each by robot name.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from urdfkit.motion.sim_dynamics import Dynamics
    from urdfkit.motion.sim_robot import SimRobot
    from urdfkit.motion.sim_world import World


class RobotPhysics:
    """A simulation's dynamics queries and physical setters, by robot name (mixed in).

    Attributes:
        world: The simulation's world.
        dynamics: Its shadow models.
    """

    world: World
    dynamics: Dynamics
    #: The handle of a robot by name (``Simulation.robot``).
    robot: Callable[[str], SimRobot]

    # ---- dynamics on shadow models (urdfkit/motion/sim_dynamics.py)

    def dynamics_joints(self, robot: str) -> list[str]:
        """The joints the dynamics quantities are ordered by (PyBullet's order).

        The movable joints; a floating base adds 6 base coordinates before them in
        :meth:`mass_matrix`.
        """
        return [j.name for j in self.dynamics.joints(self.robot(robot))]

    def mass_matrix(self, robot: str) -> np.ndarray:
        """The joint-space mass matrix M(q) now (numpy, PyBullet's calculateMassMatrix).

        Physical joint coordinates, in :meth:`dynamics_joints` order; a floating base puts its
        6 coordinates first, as PyBullet does.
        """
        return self.dynamics.mass_matrix(self.robot(robot))

    def coriolis_and_gravity(self, robot: str) -> np.ndarray:
        """C(q, qd) qd + g(q) now: the torques that hold the current motion (numpy)."""
        return self.dynamics.coriolis_and_gravity(self.robot(robot))

    def gravity_torques(self, robot: str) -> np.ndarray:
        """g(q) now: the torques that hold the robot still against gravity (numpy)."""
        return self.dynamics.gravity_torques(self.robot(robot))

    def forward_dynamics(self, robot: str, tau: Sequence[float]) -> np.ndarray:
        """The joint accelerations ``tau`` would cause now, without contacts (numpy).

        qdd = M^-1 (tau - C qd - g).
        """
        return self.dynamics.forward_dynamics(self.robot(robot), tau)

    def jacobian(self, robot: str, link: str, point: Sequence[float] = (0.0, 0.0, 0.0)
                 ) -> np.ndarray:
        """The 6 x n Jacobian (linear rows, then angular) of a point of a link now (numpy).

        ``point`` is from the link's URDF frame's origin (the joint), along the link's inertial
        frame's axes (the URDF frame's unless its ``<inertial>`` is turned): PyBullet 3.2.7's
        calculateJacobian takes it so, whatever its docs say of the centre of mass (measured:
        the point (0, 0, 0) of a pendulum's bob link is on the hinge, J = 0).
        """
        return self.dynamics.jacobian(self.robot(robot), link, point)

    # ---- setters: a robot's physical parameters (urdfkit/motion/sim_robot.py)

    def set_mass(self, robot: str, link: str, mass: float) -> None:
        """A link's mass, kg; its inertia scales with it (the same body, heavier).

        PyBullet's changeDynamics(mass=...) alone throws the inertia away and recomputes it
        from the collision shapes (a link without any gets ~1e-6): not what "heavier" means.
        """
        self.robot(robot).set_mass(link, mass)

    def set_inertia(self, robot: str, link: str, diagonal: Sequence[float]) -> None:
        """A link's principal moments of inertia, kg m^2 (in its inertial frame)."""
        self.robot(robot).set_inertia(link, diagonal)

    def set_friction(self, robot: str, link: str | None, lateral: float) -> None:
        """Lateral friction of a link (every link when ``link`` is None).

        Robot ``"ground"`` is the floor.
        """
        self._change(robot, link, lateralFriction=float(lateral))

    def set_restitution(self, robot: str, link: str | None, restitution: float) -> None:
        """Restitution (bounciness) of a link, or of the floor with robot ``"ground"``."""
        self._change(robot, link, restitution=float(restitution))

    def _change(self, target: str, link: str | None, **values: float) -> None:
        if target == "ground":
            self.world.change_ground(**values)
        else:
            self.robot(target).change(link, **values)

    def set_joint_damping(self, robot: str, joint: str, damping: float) -> None:
        """PyBullet's joint damping of one joint (N m s/rad)."""
        self.robot(robot).set_joint_damping(joint, damping)

    def set_joint_friction(self, robot: str, joint: str, friction: float) -> None:
        """A joint's dry (Coulomb) friction, N m (N for a prismatic joint); 0 removes it.

        The joint holds against up to ``friction`` of torque and is slowed by that much when
        it moves (PyBullet's joint motor at velocity 0 with that force limit). While a
        PyBullet position or velocity command drives the joint (a ``joints`` segment without
        a ``motor`` table, or a car's wheels and hinges), that command owns the motor; the
        friction comes back when it ends. It stays across ``reset()``.
        """
        self.robot(robot).set_joint_friction(joint, friction)

    def set_link_damping(self, robot: str, linear: float, angular: float) -> None:
        """Every link's linear and angular velocity damping (PyBullet's default is 0.04)."""
        self._change(robot, None, linearDamping=float(linear), angularDamping=float(angular))

    def set_motor_gains(self, robot: str, kp: float | Mapping[str, float] | None = None,
                        kd: float | Mapping[str, float] | None = None) -> None:
        """The servo's position and velocity gains: one for every joint, or per joint name.

        A gain not given keeps its value. Needs the robot's ``motor`` table (the servo).
        """
        self.robot(robot).set_motor_gains(kp, kd)

    def set_time_step(self, time_step: float) -> None:
        """The physics time step, s (times already recorded keep theirs)."""
        self.world.set_time_step(time_step)
