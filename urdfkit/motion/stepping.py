"""The one step loop: every run urdfkit makes advances its world here.

:class:`StepLoop` is what :class:`~urdfkit.motion.simulation.Simulation` (and through it
``urdfkit sim``, the sweep and :class:`~urdfkit.gym.ScenarioEnv`), ``urdfkit drive`` and
:class:`~urdfkit.gym.SimpleDrivingEnv` step their worlds with:

- before each physics step, the controllers (:data:`Control`): each is given the time the step
  starts at and sets the motors for it;
- the engine's step (:mod:`urdfkit.engine.api`), counted: the loop's clock;
- after each step, what is measured every step (a delayed sensor);
- in :meth:`StepLoop.run`, a record every ``every`` steps, progress, pacing to the wall clock,
  and the three ways a run ends early with what it simulated kept: Ctrl-C, the engine's window
  closed, or a controller raising :class:`Closed` (a slider read from a closed window).

Outside ``engine/`` nothing else calls an engine's step (``tests/test_engine_seam.py``), save
agree's lockstep swing, which steps two engines side by side to compare them.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from urdfkit.engine.api import Simulator

#: A controller: called with the time (s) the coming step starts at, it sets the motors.
Control = Callable[[float], None]


class Closed(Exception):  # noqa: N818 (a signal, as StopIteration is, not an error)
    """Raised by a controller whose window was closed: the run ends there, kept."""


class StepLoop:
    """A world's physics steps, counted, with controllers before each one.

    Args:
        engine: The world (:class:`~urdfkit.engine.api.Simulator`).
        time_step: Its physics step, s (the engine is not told: it already has it).

    Attributes:
        step_count: Steps taken since the start (or since it was set back).
    """

    def __init__(self, engine: Simulator, time_step: float) -> None:
        self.engine = engine
        self.time_step = time_step
        self.step_count = 0

    @property
    def t(self) -> float:
        """Simulated time, s."""
        return self.step_count * self.time_step

    def step(self, n: int = 1, controls: Sequence[Control] = (),
             after: Callable[[], None] | None = None) -> None:
        """Advance ``n`` physics steps: ``controls`` before each, ``after`` after each."""
        step = self.engine.step  # bound once: on PyBullet it is stepSimulation itself
        if not controls and after is None:
            for _ in range(n):  # the hot loop: nothing but the step and its count
                step()
                self.step_count += 1
            return
        dt = self.time_step
        for _ in range(n):
            t = self.step_count * dt
            for control in controls:
                control(t)
            step()
            self.step_count += 1
            if after is not None:
                after()

    def run(self, end: int, every: int, record: Callable[[], None], *,
            step: Callable[[int], None] | None = None,
            progress: Callable[[int, int], None] | None = None,
            real_time: bool = False, start: bool = False, last: bool = False) -> bool:
        """Step to step ``end``, calling ``record`` at every multiple of ``every``.

        Args:
            end: The step to stop at.
            every: Steps between two records.
            record: Takes the state now.
            step: Advances ``n`` steps with the caller's controllers (default: none).
            progress: Called as ``progress(step_count, end)`` after each stretch of steps.
            real_time: Pace the steps to the wall clock, at most a 60th of a second of
                simulated time between two waits (to watch the run in a window).
            start: Record first, when the count is a multiple of ``every``.
            last: Record at ``end`` too when it is no multiple of ``every``.

        Returns:
            Whether the run ended early: Ctrl-C, the engine's window closed, or a
            controller raised :class:`Closed`. Steps and records before it are kept.
        """
        advance = self.step if step is None else step
        engine = self.engine
        chunk = max(1, round(1 / 60 / self.time_step)) if real_time else end
        start_wall, start_step = time.perf_counter(), self.step_count
        try:
            if start and self.step_count % every == 0:
                record()
            while self.step_count < end:
                advance(min(every - self.step_count % every, end - self.step_count, chunk))
                if self.step_count % every == 0 or (last and self.step_count == end):
                    record()
                if progress is not None:
                    progress(self.step_count, end)
                if real_time:
                    ahead = start_wall + (self.step_count - start_step) * self.time_step \
                        - time.perf_counter()
                    if ahead > 0:
                        time.sleep(ahead)
        except (KeyboardInterrupt, Closed):
            return True
        except engine.error:
            if not engine.gui or engine.connected():
                raise
            return True  # the window was closed
        return False
