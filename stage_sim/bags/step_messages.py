"""What the bag writer process needs to turn steps into their messages, without the simulation.

The stepping side copies each step into a :class:`~stage_sim.bags.step_state.StepBatch` (a few array copies) and
sends batches of steps to the writer process (:mod:`stage_sim.bags.writer`), which refills every endpoint's CDR
bytes from a whole batch at once, topic by topic (:class:`StepMessages`, the per-step part of
:class:`stage_sim.bags.messages.MessageBuilder`, sent to the writer once: its layouts travel as their template
bytes, its endpoints as registry references). This module imports neither the simulation nor its kernels: the
writer process starts in a fraction of a second.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from itertools import accumulate, chain
from operator import itemgetter

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
    """Turns a :class:`StepBatch` into each step's messages, as stageros publishes each step."""

    channels: list[StepChannel]
    stepped: tuple[Topic, ...] = field(init=False)
    """The topics whose values a :class:`~stage_sim.bags.step_state.StepBatch` copies, in this order (made
    once: the stepping side reads it every step)."""
    names: tuple[str, ...] = field(init=False)
    """The bag topic of each message of a step, in stageros' publishing order."""
    _order: dict[int, Callable[[list[bytes | None]], Sequence[bytes | None]]] = field(
        init=False, default_factory=dict, repr=False)
    """Per batch size, what takes the topics' refilled messages (one after another) in step order."""

    def __post_init__(self) -> None:
        self.stepped = tuple(channel.topic for channel in self.channels)
        self.names = tuple(name for channel in self.channels for name in channel.names)

    def steps(self, batch: StepBatch) -> tuple[list[int], Sequence[bytes | None]]:
        """The log time (ns) of each step of ``batch`` and all the steps' messages: per step, one per name of
        :attr:`names` (None: that endpoint published nothing), step after step. Each topic's messages are refilled
        for the whole batch at once, and put in step order by one C call: the writer's Python per message was
        most of its CPU."""
        times = batch.times
        refilled = [channel.layout.refill(values, times) for channel, values
                    in zip(self.channels, batch.values(), strict=True)]
        log_times = [fields.stamp_ns(time) for time in times.tolist()]
        if len(refilled) <= 1:  # one topic's are in step order already; no topic (only latched ones): none
            return log_times, refilled[0] if refilled else []
        return log_times, self._in_step_order(len(log_times))(list(chain.from_iterable(refilled)))

    def _in_step_order(self, steps: int) -> Callable[[list[bytes | None]], Sequence[bytes | None]]:
        """What takes the messages of ``steps`` steps, given every topic's (step after step) one topic after
        another, in step order."""
        if steps not in self._order:
            firsts = accumulate((steps * len(channel.names) for channel in self.channels[:-1]), initial=0)
            starts = list(zip(firsts, self.channels, strict=True))
            order = [first + step * len(channel.names) + endpoint for step in range(steps)
                     for first, channel in starts
                     for endpoint in range(len(channel.names))]
            # itemgetter returns a tuple, except of one index
            self._order[steps] = itemgetter(*order) if len(order) > 1 else lambda messages: messages[:len(order)]
        return self._order[steps]

    def publications(self, batch: StepBatch) -> int:
        """How many messages :meth:`steps` makes of ``batch`` (without making them)."""
        return sum(channel.layout.count(values) for channel, values in zip(self.channels, batch.values(), strict=True))
