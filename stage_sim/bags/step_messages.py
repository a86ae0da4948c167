"""What the bag writer process needs to turn a step into its messages, without the simulation.

The stepping side copies each step into a :class:`~stage_sim.bags.step_state.StepBatch` (a few array copies)
and sends batches of steps to the writer process (:mod:`stage_sim.bags.writer`), which refills each endpoint's
CDR bytes from it (:class:`StepMessages`, the per-step part of :class:`stage_sim.bags.messages.MessageBuilder`,
sent to the writer once: its layouts travel as their template bytes, its endpoints as registry references).
This module imports neither the simulation nor its kernels: the writer process starts in a fraction of a
second.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from stage_sim.bags.layouts import Layout
from stage_sim.bags.step_state import StepState
from stage_sim.interface import fields
from stage_sim.interface.topics import Endpoint, Timing, Topic

if TYPE_CHECKING:
    pass


@dataclass
class StepChannel:
    """One per-step interface topic in the bag and, per recorded endpoint, its bag topic, its layout (the
    template bytes it refills) and its endpoint."""

    topic: Topic
    outlets: list[tuple[str, Layout, Endpoint]]
    prepare: Callable[[Any], Any]
    """The layouts' :meth:`Layout.prepare`, run once per step for all of the topic's endpoints."""


@dataclass
class StepMessages:
    """Turns :class:`StepState` into (bag topic, log time ns, CDR bytes), as stageros publishes each step."""

    channels: list[StepChannel]
    stepped: tuple[Topic, ...] = field(init=False)
    """The topics whose values a :class:`~stage_sim.bags.step_state.StepBatch` copies, in this order (made
    once: the stepping side reads it every step)."""

    def __post_init__(self) -> None:
        self.stepped = tuple(channel.topic for channel in self.channels)

    def step(self, state: StepState) -> Iterator[tuple[str, int, bytes]]:
        """Everything one step publishes on the recorded topics, in stageros' publishing order."""
        sim_time_us = state.sim_time_us
        log_time = fields.stamp_ns(sim_time_us)
        for channel, values in zip(self.channels, state.values, strict=True):
            values = channel.prepare(values)
            for name, layout, endpoint in channel.outlets:
                data = layout.refill(values, endpoint, sim_time_us)
                if data is not None:
                    yield name, log_time, data

    def publications(self, state: StepState) -> int:
        """How many messages :meth:`step` makes of ``state`` (without building them)."""
        count = 0
        for channel, values in zip(self.channels, state.values, strict=True):
            if channel.topic.timing is Timing.STEP:
                count += len(channel.outlets)
            else:
                count += sum(values.measured(e.robot, e.ranger) is not None for _, _, e in channel.outlets)
        return count
