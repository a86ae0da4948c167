"""Page messages: what is accepted, and the reason given for what is not."""

from __future__ import annotations

import pytest

from stage_sim.view.messages import (
    MAX_MESSAGE_BYTES,
    BadMessage,
    Drive,
    MessageReader,
    Pause,
    Place,
    Reset,
    Speed,
    Strikes,
)

READER = MessageReader(["robot_0", "robot_1"], (0.0, 0.0, 20.0, 10.0))


def test_well_formed_messages_become_actions() -> None:
    assert READER.read('{"type": "drive", "robot": "robot_1", "vx": 0.5, "vy": 0, "va": -1}') == Drive(1, 0.5, 0, -1)
    assert READER.read('{"type": "pose", "robot": "robot_0", "x": 3, "y": 4.5, "yaw": 1}') == Place(0, 3, 4.5, 1)
    assert READER.read('{"type": "pose", "robot": "robot_0", "x": 3, "y": 4.5}') == Place(0, 3, 4.5, None)
    assert READER.read('{"type": "pause", "paused": true}') == Pause(True)
    assert READER.read('{"type": "speed", "speedup": 0}') == Speed(0.0)
    assert READER.read('{"type": "reset"}') == Reset()


@pytest.mark.parametrize(("text", "reason"), [
    (b'{"type": "reset"}', "binary"),
    ("x" * (MAX_MESSAGE_BYTES + 1), "at most"),
    ("{", "not JSON"),
    ("[" * 3000, "not JSON"),
    ("[]", "not a JSON object"),
    ('{"type": "fly"}', "unknown message type"),
    ('{"type": "drive", "robot": "robot_9", "vx": 0, "vy": 0, "va": 0}', "unknown robot"),
    ('{"type": "drive", "robot": 0, "vx": 0, "vy": 0, "va": 0}', "unknown robot"),
    ('{"type": "drive", "robot": "robot_0", "vx": NaN, "vy": 0, "va": 0}', "not finite"),
    ('{"type": "drive", "robot": "robot_0", "vx": 1e999, "vy": 0, "va": 0}', "not finite"),
    ('{"type": "drive", "robot": "robot_0", "vx": 5000, "vy": 0, "va": 0}', "beyond"),
    ('{"type": "drive", "robot": "robot_0", "vx": true, "vy": 0, "va": 0}', "must be a number"),
    ('{"type": "drive", "robot": "robot_0", "vx": "1", "vy": 0, "va": 0}', "must be a number"),
    ('{"type": "drive", "robot": "robot_0", "vx": 1, "va": 0}', "'vy' must be a number"),
    ('{"type": "pose", "robot": "robot_0", "x": -15, "y": 5}', "outside the world"),
    ('{"type": "pose", "robot": "robot_0", "x": 1, "y": 5, "yaw": Infinity}', "not finite"),
    ('{"type": "pause", "paused": "yes"}', "true or false"),
    ('{"type": "speed", "speedup": -Infinity}', "not finite"),
])
def test_malformed_messages_are_refused_with_a_reason(text: str | bytes, reason: str) -> None:
    with pytest.raises(BadMessage, match=reason):
        READER.read(text)


def test_strikes_close_a_connection_only_for_a_burst_of_garbage() -> None:
    strikes = Strikes(limit=3, window_s=5.0)
    assert [strikes.add(now=t) for t in (0.0, 1.0, 2.0)] == [False, False, False]
    assert strikes.add(now=3.0)
    slow = Strikes(limit=3, window_s=5.0)
    assert not any(slow.add(now=t) for t in range(0, 100, 2))
