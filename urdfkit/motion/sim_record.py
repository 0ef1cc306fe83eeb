"""Recording: the run loop and the link poses a viewer draws.

Methods of :class:`urdfkit.sim.Simulation`, split out of :mod:`urdfkit.sim`: each function
takes the simulation as ``self`` and is bound as a method of ``Simulation`` (a class
attribute), so a call costs what a method defined in the class costs.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from urdfkit.motion.sim_state import Observation, SimResult, _Summary


def link_poses(self: Any) -> list[list[tuple[Any, Any]]]:
    """Every robot's URDF link frames' world poses now, base first (``(xyz, xyzw)``).

    Robots in the scenario's order; the base's pose is its link frame, not the inertial
    frame ``getBasePositionAndOrientation`` reports.
    """
    p, client = self.session.p, self.session.client
    out = []
    for b in self.bodies.values():
        pos, orn = p.getBasePositionAndOrientation(b.body, physicsClientId=client)
        local = p.getDynamicsInfo(b.body, -1, physicsClientId=client)
        inv = p.invertTransform(local[3], local[4])
        poses = [p.multiplyTransforms(pos, orn, inv[0], inv[1])]
        for j in range(p.getNumJoints(b.body, physicsClientId=client)):
            st = p.getLinkState(b.body, j, computeForwardKinematics=True,
                                physicsClientId=client)
            poses.append((st[4], st[5]))
        out.append(poses)
    return out


def run(self: Any, duration: float | None = None,
        sink: Callable[[list[Observation]], None] | None = None, *,
        keep: bool = True, real_time: bool = False) -> SimResult:
    """Step to ``duration`` (default: the scenario's), recording every ``record.every``.

    Rows are taken at every step that is a multiple of ``record.every``, the starting
    state included when the run starts at step 0. ``sink`` gets each batch of rows (one
    per robot) as it is recorded, to stream them to disk; with ``keep=False`` the result
    then holds no rows, only their count and the per-robot summary, so a run's memory
    does not grow with its length. Ctrl-C ends the run early with ``interrupted`` set;
    the rows so far are kept, as they are when the GUI window is closed. ``real_time``
    paces the steps to the wall clock (to watch the run in the GUI).
    """
    end = self.total_steps if duration is None else \
        self.step_count + max(0, round(duration / self.time_step))
    every = self.config.record.every
    rows: list[Observation] = []
    ideal: list[Observation] = []
    summary = _Summary()

    bodies = list(self.bodies.values())

    def record() -> None:
        # As observe() gives them (copies), without its per-call lookups; one copy when
        # what a robot reports is its true state.
        truth = [self._fresh(b) for b in bodies]
        batch = [self._report(b) for b in bodies]
        for k, (seen, true) in enumerate(zip(batch, truth, strict=True)):
            batch[k] = seen.copy()
            truth[k] = batch[k] if seen is true else true.copy()
        # Only whole batches count: an interrupt above drops this one entirely.
        if keep:
            rows.extend(batch)
            ideal.extend(truth)
        summary.add(truth)
        if sink is not None:
            sink(batch)

    interrupted = False
    p, client = self.session.p, self.session.client
    # Real time: at most a 60th of a second of simulated time between two waits.
    chunk = max(1, round(1 / 60 / self.time_step)) if real_time else end
    start_wall, start_step = time.perf_counter(), self.step_count
    try:
        if self.step_count % every == 0:
            record()
        while self.step_count < end:
            self.step(min(every - self.step_count % every, end - self.step_count, chunk))
            if self.step_count % every == 0:
                record()
            if real_time:
                ahead = start_wall + (self.step_count - start_step) * self.time_step \
                    - time.perf_counter()
                if ahead > 0:
                    time.sleep(ahead)
    except KeyboardInterrupt:
        interrupted = True
    except p.error:
        if not self.session.gui or p.isConnected(physicsClientId=client):
            raise
        interrupted = True  # the GUI window was closed
    kept = min(len(rows), len(ideal))
    whole = kept - kept % max(1, len(self.bodies))
    return SimResult(rows[:whole], ideal[:whole], self.time_step, self.step_count,
                     interrupted, summary.rows, summary.robots())
