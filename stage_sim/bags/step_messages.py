"""What the bag writer process needs to turn a step into its messages, without the simulation.

The stepping side copies each step into a :class:`~stage_sim.bags.step_state.StepBatch` (a few array copies)
and sends batches of steps to the writer process (:mod:`stage_sim.bags.writer`), which refills each endpoint's
CDR bytes from it (:class:`StepMessages`, the per-step part of :class:`stage_sim.bags.messages.MessageBuilder`,
sent to the writer once: its layouts travel as their template bytes, its endpoints as registry references).
This module imports neither the simulation nor its kernels: the writer process starts in a fraction of a
second.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from stage_sim.bags.layouts import Layout
from stage_sim.bags.step_state import StepState
from stage_sim.interface.topics import Topic


@dataclass
class StepChannel:
    """One per-step interface topic in the bag: the bag topic of each recorded endpoint, in the order of the
    layout's endpoints, and the layout that refills all their messages."""

    topic: Topic
    names: list[str]
    layout: Layout


@dataclass
class StepMessages:
    """Turns :class:`StepState` into (bag topic, log time ns, CDR bytes), as stageros publishes each step."""

    channels: list[StepChannel]
    stepped: tuple[Topic, ...] = field(init=False)
    """The topics whose values a :class:`~stage_sim.bags.step_state.StepBatch` copies, in this order (made
    once: the stepping side reads it every step)."""

    def __post_init__(self) -> None:
        self.stepped = tuple(channel.topic for channel in self.channels)

    def step(self, state: StepState) -> list[tuple[str, bytes]]:
        """Everything one step publishes on the recorded topics (bag topic, CDR bytes), in stageros'
        publishing order; their log time is the step's stamp."""
        sim_time_us = state.sim_time_us
        messages = []
        for channel, values in zip(self.channels, state.values, strict=True):
            refilled = channel.layout.refill(values, sim_time_us)
            messages += [(name, data) for name, data in zip(channel.names, refilled, strict=True) if data is not None]
        return messages

    def publications(self, state: StepState) -> int:
        """How many messages :meth:`step` makes of ``state`` (without building them)."""
        return sum(channel.layout.count(values) for channel, values in zip(self.channels, state.values, strict=True))
