"""PyBullet's joint motors on MuJoCo: a velocity target under a force cap, met within a step.

PyBullet's VELOCITY_CONTROL and POSITION_CONTROL are rows of its constraint solver: each asks
for a joint velocity at the end of the step (the target, or for a position motor
``0.1 (q* - q) / dt + v*``, PyBullet's default gains) and gets it unless the impulse that
takes exceeds ``cap * dt``, in which case the motor pushes with exactly its cap. MuJoCo's
actuators are forces, and clamping one to a range happens before the step: a stiff velocity
servo clamped at the start of a step overshoots its target by up to a step of full force
(measured: simplecar's free wheels spun up to 29 rad/s for a 10 rad/s target).

So each motor here is, for each step, one of two things, as in the solution of PyBullet's
bounded row:

- **a servo** (not at its cap): a velocity actuator ``kv (v_des - v)`` with kv = STIFFNESS
  times the joint's inertia per step, integrated implicitly (``implicitfast``), which leaves
  ``1 / (1 + STIFFNESS)`` of the velocity error at the end of the step;
- **at its cap**: a constant force of ``+cap`` or ``-cap``.

After a step, a servo whose force (its implicit part included) exceeded its cap, or a capped
motor that went past its target velocity, changes over and the step is taken again from the
state before it (:meth:`MotorBank.settle`): an active-set solution of the same bounds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

#: A servo's gain in units of its joint's inertia per step: kv = STIFFNESS * M_jj / dt. The
#: velocity error left after a step is about 1 / (1 + STIFFNESS) of the error before it.
STIFFNESS = 100.0
#: PyBullet's default motor on every revolute and prismatic joint: velocity 0 with at most
#: this impulse per step (N m s; measured: it caps at 240 N m at 1/240 s, 1000 at 1/1000).
DEFAULT_MOTOR_IMPULSE = 1.0
#: PyBullet's POSITION_CONTROL gains when none are given: positionGain, velocityGain.
POSITION_GAIN, VELOCITY_GAIN = 0.1, 1.0
#: How often a step is taken again at most while motors change over (a motor's state carries
#: over to the next step, so that a motor at its cap for many steps costs none).
MAX_SETTLE = 4
#: A servo's force this far over its cap (relative) puts it at its cap.
CAP_SLACK = 1e-9

OFF, VELOCITY, POSITION = 0, 1, 2


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
    """Every motor of the world, as arrays over MuJoCo's actuators (one per motor).

    Attributes:
        applied: Each actuator's force in the last step (N m or N), by actuator id.
    """

    def __init__(self, np: Any, count: int) -> None:
        self.np = np
        self.act = np.zeros(0, dtype=np.int64)      # actuator ids of the motors on
        self.dof = np.zeros(0, dtype=np.int64)
        self.qpos = np.zeros(0, dtype=np.int64)
        self.mode = np.zeros(count, dtype=np.int64)
        self.target = np.zeros(count)
        self.velocity = np.zeros(count)
        self.force = np.full(count, np.nan)          # NaN: PyBullet's default motor
        self.dofs = np.zeros(count, dtype=np.int64)
        self.qadr = np.zeros(count, dtype=np.int64)
        self.state = np.zeros(count, dtype=np.int64)  # -1, +1: at its cap; 0: a servo
        self.applied = np.zeros(count)
        #: The actuators' gains and ranges need writing (a motor, a state, the step or a
        #: mass changed); each step writes only the servos' targets otherwise.
        self.dirty = True
        self._h = 0.0

    def place(self, a: int, dof: int, qadr: int, motor: Motor) -> None:
        """Actuator ``a`` drives the joint at ``dof`` (position at ``qadr``) as ``motor``."""
        self.dofs[a] = dof
        self.qadr[a] = qadr
        self.set(a, motor)

    def set(self, a: int, motor: Motor) -> None:
        """Actuator ``a`` is ``motor`` from the next step on."""
        self.mode[a] = VELOCITY if motor.mode == "velocity" else POSITION
        self.target[a] = motor.target
        self.velocity[a] = motor.velocity
        self.force[a] = self.np.nan if motor.force is None else motor.force
        self.state[a] = 0
        self.dirty = True
        on = self.np.flatnonzero(self.mode != OFF)
        self.act = on
        self.dof = self.dofs[on]
        self.qpos = self.qadr[on]

    def prepare(self, m: Any, d: Any, h: float) -> Any:
        """Each motor's velocity for the end of this step, and the actuators set to reach it.

        Returns the target velocities (by position in :attr:`act`).
        """
        np = self.np
        a = self.act
        v = d.qvel[self.dof]
        want = np.where(self.mode[a] == VELOCITY, self.target[a],
                        POSITION_GAIN * (self.target[a] - d.qpos[self.qpos]) / h
                        + (1 - VELOCITY_GAIN) * v + VELOCITY_GAIN * self.velocity[a])
        if self.dirty or h != self._h:
            self._write(m, h)
        d.ctrl[a] = np.where(self.state[a] == 0, want, 0.0)
        return want

    def caps(self, h: float) -> Any:
        """Each motor's force cap (its own, or PyBullet's default of one impulse per step)."""
        f = self.force[self.act]
        return self.np.where(self.np.isnan(f), DEFAULT_MOTOR_IMPULSE / h, f)

    def _write(self, m: Any, h: float) -> None:
        np = self.np
        a = self.act
        cap = self.caps(h)
        kv = STIFFNESS * m.dof_M0[self.dof] / h
        state = self.state[a]
        servo = (state == 0) & (cap > 0)
        m.actuator_gainprm[a, 0] = np.where(servo, kv, 0.0)
        bias = np.zeros((len(a), 3))
        bias[:, 0] = np.where(servo, 0.0, state * cap)
        bias[:, 2] = np.where(servo, -kv, 0.0)
        m.actuator_biasprm[a, :3] = bias
        # a servo's force is not clamped by MuJoCo (settle() holds it to its cap)
        big = np.where(servo, np.inf, cap)
        m.actuator_forcerange[a, 0] = -big
        m.actuator_forcerange[a, 1] = big
        self.dirty = False
        self._h = h

    def fallback(self, m: Any, h: float) -> None:
        """MuJoCo's own clamp on every servo, for a step taken :data:`MAX_SETTLE` times.

        A servo may then overshoot its target by up to a step at its cap, but never pushes
        past its cap.
        """
        a = self.act
        cap = self.caps(h)
        m.actuator_forcerange[a, 0] = -cap
        m.actuator_forcerange[a, 1] = cap
        self.dirty = True

    def settle(self, m: Any, d: Any, h: float, want: Any) -> bool:
        """After a step: whether a motor changes over (and the step must be taken again).

        ``want`` is what :meth:`prepare` returned for the step. Each motor's force in the step
        is kept in :attr:`applied`.
        """
        np = self.np
        a = self.act
        cap = self.caps(h)
        v1 = d.qvel[self.dof]
        state = self.state[a]
        kv = STIFFNESS * m.dof_M0[self.dof] / h
        # implicitfast: a servo's force over the step is kv (want - v'), its implicit part in
        force = np.where(state == 0, kv * (want - v1), state * cap)
        force = np.where(cap > 0, force, 0.0)
        self.applied[a] = np.clip(force, -cap, cap)  # past it only in a step settle redoes
        over = (state == 0) & (np.abs(force) > cap * (1 + CAP_SLACK)) & (cap > 0)
        past = (state != 0) & (state * (v1 - want) > 0)
        if not (over.any() or past.any()):
            return False
        new = state.copy()
        new[over] = np.sign(force[over])
        new[past] = 0
        self.state[a] = new
        self._write(m, h)
        d.ctrl[a] = np.where(new == 0, want, 0.0)
        return True
