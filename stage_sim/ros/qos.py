"""The interface's plain QoS profiles (:mod:`stage_sim.interface.qos`) as rclpy's ``QoSProfile``."""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from stage_sim.interface.qos import Durability, History, Qos, Reliability

_RELIABILITY = {Reliability.RELIABLE: ReliabilityPolicy.RELIABLE,
                Reliability.BEST_EFFORT: ReliabilityPolicy.BEST_EFFORT}
_DURABILITY = {Durability.VOLATILE: DurabilityPolicy.VOLATILE,
               Durability.TRANSIENT_LOCAL: DurabilityPolicy.TRANSIENT_LOCAL}
_HISTORY = {History.KEEP_LAST: HistoryPolicy.KEEP_LAST, History.KEEP_ALL: HistoryPolicy.KEEP_ALL}


def qos_profile(qos: Qos) -> QoSProfile:
    """The rclpy profile of ``qos``."""
    return QoSProfile(history=_HISTORY[qos.history], depth=qos.depth, reliability=_RELIABILITY[qos.reliability],
                      durability=_DURABILITY[qos.durability])
