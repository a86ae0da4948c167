"""What the bag writer process needs to turn steps into their messages, without the simulation.

The stepping side copies each step into a :class:`~stage_sim.bags.step_state.StepBatch` (a few array copies) and
sends batches of steps to the writer process (:mod:`stage_sim.bags.writer`), which refills every endpoint's CDR
bytes from a whole batch at once, topic by topic (:class:`StepMessages`, the per-step part of
:class:`stage_sim.bags.messages.MessageBuilder`, sent to the writer once: its layouts travel as their template
bytes, its endpoints as registry references). This module imports neither the simulation nor its kernels: the
writer process starts in a fraction of a second.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from stage_sim.bags.layouts import Layout
from stage_sim.bags.step_state import StepBatch
from stage_sim.interface import fields
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
    """Turns a :class:`StepBatch` into each step's (bag topic, CDR bytes), as stageros publishes each step."""

    channels: list[StepChannel]
    stepped: tuple[Topic, ...] = field(init=False)
    """The topics whose values a :class:`~stage_sim.bags.step_state.StepBatch` copies, in this order (made
    once: the stepping side reads it every step)."""

    def __post_init__(self) -> None:
        self.stepped = tuple(channel.topic for channel in self.channels)

    def steps(self, batch: StepBatch) -> Iterator[tuple[int, list[tuple[str, bytes]]]]:
        """Per step of ``batch``, its log time (ns) and everything it published on the recorded topics (bag topic,
        CDR bytes), in stageros' publishing order. Each topic's messages are refilled for the whole batch at
        once."""
        times = batch.times
        refilled = [channel.layout.refill(values, times) for channel, values
                    in zip(self.channels, batch.values(), strict=True)]
        for k, time in enumerate(times.tolist()):
            messages = []
            for channel, topic_messages in zip(self.channels, refilled, strict=True):
                messages += [(name, data) for name, data in zip(channel.names, topic_messages[k], strict=True)
                             if data is not None]
            yield fields.stamp_ns(time), messages

    def publications(self, batch: StepBatch) -> int:
        """How many messages :meth:`steps` makes of ``batch`` (without making them)."""
        return sum(channel.layout.count(values) for channel, values in zip(self.channels, batch.values(), strict=True))
