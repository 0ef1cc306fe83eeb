"""Recording: a run's rows and where they go.

:class:`Recorder` runs a simulation to an end on the world's step loop
(:mod:`urdfkit.motion.stepping`), taking a row per robot every ``record.every`` steps, and
hands each batch to a sink (a file, a viewer) as it comes.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from urdfkit.motion.sim_state import Observation, SimResult, _Summary

if TYPE_CHECKING:
    from urdfkit.motion.sim_sensors import Sensors
    from urdfkit.motion.sim_world import World

#: Where recorded rows go, a batch (one row per robot) at a time.
Sink = Callable[[list[Observation]], None]


class Recorder:
    """Runs a world forward with ``step``, recording rows through ``sensors``."""

    def __init__(self, world: World, sensors: Sensors, step: Callable[[int], None]) -> None:
        self.world = world
        self.sensors = sensors
        self.step = step

    def run(self, duration: float | None = None, sink: Sink | None = None, *,
            keep: bool = True, real_time: bool = False) -> SimResult:
        """Step to ``duration`` (default: the scenario's), recording every ``record.every``.

        See :meth:`urdfkit.sim.Simulation.run`.
        """
        world = self.world
        end = world_total_steps(world) if duration is None else \
            world.step_count + max(0, round(duration / world.time_step))
        every = world.config.record.every
        rows: list[Observation] = []
        ideal: list[Observation] = []
        summary = _Summary()
        record = self._recorder(rows, ideal, summary, sink, keep=keep)
        interrupted = world.loop.run(end, every, record, step=self.step, real_time=real_time,
                                     start=True)
        kept = min(len(rows), len(ideal))
        whole = kept - kept % max(1, len(world.robots))
        return SimResult(rows[:whole], ideal[:whole], world.time_step, world.step_count,
                         interrupted, summary.rows, summary.robots())

    def _recorder(self, rows: list[Observation], ideal: list[Observation], summary: _Summary,
                  sink: Sink | None, *, keep: bool) -> Callable[[], None]:
        robots = list(self.world.robots.values())
        sensors = self.sensors

        def record() -> None:
            # As observe() gives them (copies), without its per-call lookups; one copy when
            # what a robot reports is its true state.
            truth = [sensors.fresh(r) for r in robots]
            batch = [sensors.report(r) for r in robots]
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

        return record


def world_total_steps(world: World) -> int:
    """Steps in the scenario's ``duration``."""
    return max(1, round(world.config.duration / world.time_step))
