"""Lockstep never steps without every controller's answer: a late answer only slows the run (same run as a
prompt one), is reported once, and a controller that has gone ends the run with an error."""

from __future__ import annotations

import threading
import time

import pytest
from rclpy.context import Context

from stage_sim.ros import session as lockstep
from stage_sim.ros.session import ControllerGone, WanderSession


def run_session(context: Context, slow_scans: set[int] = frozenset()) -> list[dict]:
    """5 sim seconds of rooms.world in lockstep; robot 0's wanderer answers the scans numbered in
    ``slow_scans`` 0.6 wall seconds late (as a starved process does)."""
    session = WanderSession("rooms.world", 0.0, 11, duration=5.0, context=context)
    try:
        if slow_scans:
            wanderer = session.wanderers[0]
            decide, seen = wanderer.decide, [0]

            def late_decide(scan, pose) -> None:
                seen[0] += 1
                if seen[0] in slow_scans:
                    time.sleep(0.6)
                decide(scan, pose)

            wanderer.decide = late_decide
        session.run()
        return session.summaries()
    finally:
        session.close()


def test_late_answers_give_the_same_run_and_are_reported_once(ros_context: Context, capfd, monkeypatch) -> None:
    prompt = run_session(ros_context)
    monkeypatch.setattr(lockstep, "LATE_ANSWER_S", 0.3)
    late = run_session(ros_context, slow_scans={3, 17, 18, 40})
    assert late == prompt
    assert prompt[0]["sim_seconds"] == 5.0 and prompt[0]["distance_m"] > 0.5
    warnings = [line for line in capfd.readouterr().err.splitlines() if "lockstep:" in line]
    assert len(warnings) == 4  # once per late step
    assert "waited 0.3 s for the commands of cmd_vel (nodes wander_0); still waiting" in warnings[0]


def test_a_controller_that_has_gone_ends_the_run_with_an_error(ros_context: Context, monkeypatch) -> None:
    monkeypatch.setattr(lockstep, "LATE_ANSWER_S", 0.2)
    session = WanderSession("rooms.world", 0.0, 11, duration=5.0, context=ros_context)
    wanderer = session.wanderers[0]

    def crash_after_three_steps() -> None:  # the controller process dies between two steps
        if session.stage.sim.sim_time_us == 300_000:
            session.executor.remove_node(wanderer)
            wanderer.destroy_node()

    session.stage.add_step_listener(crash_after_three_steps)
    try:
        with pytest.raises(ControllerGone, match=r"nothing publishes cmd_vel any more \(controller wander_0\)"):
            session.run(threading.Event())
        assert session.stage.sim.sim_time_us == 300_000  # no step without the answer
    finally:
        session.wanderers.remove(wanderer)  # already destroyed
        session.close()
