"""PyBullet's joint motors on MuJoCo: a velocity asked of the step, under a force cap.

PyBullet's VELOCITY_CONTROL and POSITION_CONTROL are rows of its constraint solver: each asks
that the joint's velocity at the end of the step be the target (for a position motor,
``0.1 (q* - q) / dt + v*``, PyBullet's default gains), with an impulse of at most
``cap * dt`` either way, solved together with the contacts. MuJoCo's solver has such a row: a
joint's friction loss, which asks for velocity 0 with a force of at most its ``frictionloss``.
So each motor is its joint's friction-loss row, its bound the cap, made nearly hard
(:data:`HARD`), and its reference acceleration set, between ``mj_step1`` and ``mj_step2``, to
the one that reaches the target within the step (:meth:`MotorBank.aim`). The force cap is
never exceeded, the motor pushes with exactly its cap when the target is out of reach, and the
contacts see the motor's true force.

Measured against the stiff velocity actuators tried first (an implicit servo, its gain 100
times the joint's inertia per step, capped by re-taking a step): those let MuJoCo's contact
solver see forces up to 100 times the cap before the implicit step took them back, and
simplecar with its steering left to PyBullet's default motors swung its hinges 0.24 rad in the
first step (PyBullet: held, with 1 N m); a default motor holding a pendulum against gravity
crept 0.36 mrad/s (here 0.004 mrad/s; PyBullet: 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

#: PyBullet's default motor on every revolute and prismatic joint: velocity 0 with at most
#: this impulse per step (N m s; measured: it caps at 240 N m at 1/240 s, 1000 at 1/1000).
DEFAULT_MOTOR_IMPULSE = 1.0
#: PyBullet's POSITION_CONTROL gains when none are given: positionGain, velocityGain.
POSITION_GAIN, VELOCITY_GAIN = 0.1, 1.0
#: A motor row's impedance (MuJoCo's solimp: dmin, dmax, width, midpoint, power): 0.9999 of
#: the way to its reference within the step, MuJoCo's hardest (mjMAXIMP), where its default
#: (0.9) would leave a tenth of the velocity error.
HARD = (0.9999, 0.9999, 0.001, 0.5, 2.0)

VELOCITY, POSITION = 1, 2


@dataclass
class Motor:
    """A joint's motor, as PyBullet keeps one until it is changed.

    ``force`` None is PyBullet's default motor on every revolute and prismatic joint at load:
    velocity 0 under a cap of one N s (N m s) of impulse per step.
    """

    mode: str = "velocity"
    target: float = 0.0
    velocity: float = 0.0
    force: float | None = None


class MotorBank:
    """Every motor of the world, as arrays over MuJoCo's degrees of freedom.

    Attributes:
        applied: Each degree of freedom's motor force in the last step (N m or N).
    """

    def __init__(self, np: Any, nv: int, friction_row: int) -> None:
        self.np = np
        self.friction_row = friction_row   # MuJoCo's mjCNSTR_FRICTION_DOF
        self.dofs = np.zeros(0, dtype=np.int64)      # the degrees of freedom with a motor
        self.qadr = np.zeros(0, dtype=np.int64)
        self.mode = np.zeros(nv, dtype=np.int64)
        self.target = np.zeros(nv)
        self.velocity = np.zeros(nv)
        self.force = np.full(nv, np.nan)            # NaN: PyBullet's default motor
        self.qpos_of = np.zeros(nv, dtype=np.int64)
        self.want = np.zeros(nv)
        self.applied = np.zeros(nv)
        #: The rows' bounds need writing (a motor or the time step changed).
        self.dirty = True
        self._h = 0.0
        #: Every motor a velocity motor: what each asks is its target, set once.
        self._velocities_only = True
        #: The motor rows of the step being taken (first row, count, their dofs).
        self._rows: tuple[int, int, Any] = (0, 0, None)
        #: The rows' dofs and what each asks, kept while the rows and the motors stay.
        self._cached: tuple[int, int, Any, Any] | None = None

    def place(self, dof: int, qadr: int, motor: Motor) -> None:
        """The joint at ``dof`` (its position at ``qadr``) has ``motor``."""
        self.qpos_of[dof] = qadr
        self.set(dof, motor)

    def set(self, dof: int, motor: Motor) -> None:
        """The motor at ``dof`` is ``motor`` from the next step on."""
        np = self.np
        self.mode[dof] = VELOCITY if motor.mode == "velocity" else POSITION
        self.target[dof] = motor.target
        self.velocity[dof] = motor.velocity
        self.force[dof] = np.nan if motor.force is None else motor.force
        self.dofs = np.flatnonzero(self.mode)
        self.qadr = self.qpos_of[self.dofs]
        # a velocity motor asks for its target, set here once; a position motor's ask is
        # worked out every step (aim)
        velocity = self.dofs[self.mode[self.dofs] == VELOCITY]
        self.want[velocity] = self.target[velocity]
        self._positions = self.dofs[self.mode[self.dofs] == POSITION]
        self._position_qadr = self.qpos_of[self._positions]
        self._velocities_only = not len(self._positions)
        self._cached = None
        self.dirty = True

    def caps(self, h: float) -> Any:
        """Each motor's force cap (its own, or PyBullet's default of one impulse per step)."""
        f = self.force[self.dofs]
        return self.np.where(self.np.isnan(f), DEFAULT_MOTOR_IMPULSE / h, f)

    def bound(self, m: Any, h: float) -> None:
        """Each motor's row: its cap as the joint's friction loss, made nearly hard."""
        if not (self.dirty or h != self._h) or not len(self.dofs):
            return
        m.dof_frictionloss[self.dofs] = self.caps(h)
        m.dof_solimp[self.dofs] = HARD
        self.dirty = False
        self._h = h

    def aim(self, m: Any, d: Any, h: float) -> None:
        """Each motor row's reference: the acceleration that brings its joint to its velocity.

        Called between ``mj_step1`` (which makes the rows) and ``mj_step2`` (which solves
        them).
        """
        if not len(self.dofs):
            self._rows = (0, 0, None)
            return
        if not self._velocities_only:
            p = self._positions
            self.want[p] = (POSITION_GAIN * (self.target[p] - d.qpos[self._position_qadr]) / h
                            + (1 - VELOCITY_GAIN) * d.qvel[p] + VELOCITY_GAIN * self.velocity[p])
        first, count = self.rows(m, d)
        if not count:
            self._rows = (0, 0, None)
            return
        end = first + count
        cached = self._cached
        if cached is not None and cached[:2] == (first, count):
            at = cached[2]   # the same rows as the last step
            want = cached[3] if self._velocities_only else self.want[at]
        else:
            at = d.efc_id[first:end].copy()
            want = self.want[at]
            self._cached = (first, count, at, want)
            self.applied[:] = 0.0   # a joint no longer among the rows pushed with nothing
        d.efc_aref[first:end] = (want - d.qvel[at]) / h
        self._rows = (first, count, at)

    def record(self, m: Any, d: Any) -> None:
        """After the step: each motor's force in it (the rows :meth:`aim` found)."""
        first, count, at = self._rows
        if count:
            self.applied[at] = d.efc_force[first:first + count]
        else:
            self.applied[:] = 0.0

    def rows(self, m: Any, d: Any) -> tuple[int, int]:
        """The motors' constraint rows (the joints' friction-loss rows): first, how many.

        MuJoCo puts the friction-loss rows right after the equality rows (``ne`` of them),
        ``nf`` in all; the world has no tendons, whose friction would be among them.
        """
        if m.ntendon:  # not built by the export; searched for, should a model have them
            rows = self.np.flatnonzero(d.efc_type[:d.nefc] == self.friction_row)
            return (int(rows[0]), len(rows)) if len(rows) else (0, 0)
        return int(d.ne), int(d.nf)
