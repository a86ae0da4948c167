"""The one step schedule of every entry point, in sim time against a fake wall clock: real-time pacing, the lag
cap, pause, the run's end (quit_time and --duration) and as-fast-as-possible batches; and the threads rule."""

from __future__ import annotations

import math

from stage_sim.backend import THREADS_ENV
from stage_sim.runs import pacing
from stage_sim.runs.pacing import FAST_BATCH_S, MAX_LAG_S, Pacer, run_end, run_speedup

INTERVAL = 0.125  # exact in binary, as are the wall times below


class FakeRun:
    """A simulation's sim time and a wall clock that moves only when told (or by ``step_cost`` per step)."""

    def __init__(self, step_cost: float = 0.0) -> None:
        self.wall = 100.0
        self.step_count = 0
        self.step_cost = step_cost

    @property
    def sim_time(self) -> float:
        return self.step_count * INTERVAL

    def pacer(self, speedup: float, end: float = math.inf) -> Pacer:
        return Pacer(INTERVAL, speedup, lambda: self.sim_time, end, clock=lambda: self.wall)

    def take(self, pacer: Pacer) -> int:
        """Take the steps due now, as a host's loop does in one turn; how many."""
        taken = 0
        for _ in pacer.steps():
            self.step_count += 1
            self.wall += self.step_cost
            taken += 1
        return taken

    def catch_up(self, pacer: Pacer) -> int:
        """Turns of a host that comes back while a step is due at once (a late one); how many steps in all."""
        taken = self.take(pacer)
        while pacer.wait_s() == 0.0 and not pacer.finished():
            assert self.take(pacer) == 1
            taken += 1
        return taken


def test_steps_follow_real_time_times_speedup_and_a_late_loop_catches_up() -> None:
    run = FakeRun()
    pacer = run.pacer(speedup=2.0)  # a step every 0.0625 wall seconds
    assert run.take(pacer) == 1
    assert run.take(pacer) == 0
    assert pacer.wait_s() == 0.0625
    run.wall += 0.0625
    assert run.take(pacer) == 1
    run.wall += 0.25  # woken late: the four steps it owes, one per turn of its host
    assert run.take(pacer) == 1 and pacer.wait_s() == 0.0
    assert run.catch_up(pacer) == 3
    assert pacer.wait_s() == 0.0625


def test_a_loop_behind_by_more_than_the_lag_cap_starts_afresh() -> None:
    run = FakeRun()
    pacer = run.pacer(speedup=1.0)
    run.take(pacer)
    run.wall += MAX_LAG_S + 5.0  # a stalled machine
    assert run.catch_up(pacer) == 1  # no burst of 48 steps to catch up
    assert pacer.wait_s() == INTERVAL


def test_a_paused_run_takes_no_step_and_resumes_without_debt() -> None:
    run = FakeRun()
    pacer = run.pacer(speedup=1.0)
    run.take(pacer)
    pacer.set_paused(True)
    run.wall += 10.0
    assert run.take(pacer) == 0
    assert pacer.wait_s() == math.inf
    pacer.set_paused(False)
    assert run.catch_up(pacer) == 1
    assert run.take(pacer) == 0
    assert run.sim_time == 2 * INTERVAL


def test_the_users_speedup_else_the_worlds() -> None:
    assert run_speedup(None, world_speedup=0.0) == 0.0
    assert run_speedup(4.0, world_speedup=0.0) == 4.0
    assert run_speedup(-1.0, world_speedup=2.0) == -1.0


def test_the_run_ends_at_the_earlier_of_quit_time_and_duration() -> None:
    assert run_end(quit_time=0.0) == math.inf
    assert run_end(quit_time=0.0, duration=3.0) == 3.0
    assert run_end(quit_time=2.0, duration=3.0) == 2.0
    assert run_end(quit_time=2.0, duration=1.5) == 1.5
    run = FakeRun()
    pacer = run.pacer(speedup=0.0, end=run_end(quit_time=1.0))
    while not pacer.finished():
        run.take(pacer)
    assert run.sim_time == 1.0
    assert run.take(pacer) == 0 and pacer.wait_s() == 0.0  # the host's loop ends rather than waits


def test_as_fast_as_possible_steps_in_batches_that_let_the_host_in() -> None:
    run = FakeRun(step_cost=FAST_BATCH_S * 0.3)
    pacer = run.pacer(speedup=0.0)
    assert pacer.wait_s() == 0.0  # the host comes back at once
    assert run.take(pacer) == 4  # then the host services its view, its callbacks, Ctrl-C
    slow = FakeRun(step_cost=10 * FAST_BATCH_S)
    assert slow.take(slow.pacer(speedup=-1.0)) == 1  # at least one step per batch, however long it takes


def test_a_new_speedup_sets_a_new_pace_from_now() -> None:
    run = FakeRun()
    pacer = run.pacer(speedup=1.0)
    run.take(pacer)
    pacer.set_speedup(4.0)
    assert pacer.period == INTERVAL / 4
    assert run.take(pacer) == 1
    run.wall += 1.0
    assert run.catch_up(pacer) == 32
    pacer.set_speedup(0.0)
    assert pacer.period == 0.0 and pacer.wait_s() == 0.0


def test_idle_threads_sleep_only_in_paced_runs_on_several_threads(monkeypatch):
    monkeypatch.setenv("OMP_WAIT_POLICY", "")  # restored after the test
    for realtime, threads in ((False, 2), (True, 1)):
        monkeypatch.delenv("OMP_WAIT_POLICY", raising=False)
        pacing.let_idle_threads_sleep(realtime, threads)
        assert "OMP_WAIT_POLICY" not in pacing.os.environ
    pacing.let_idle_threads_sleep(True, 2)
    assert pacing.os.environ["OMP_WAIT_POLICY"] == "PASSIVE"
    monkeypatch.setenv("OMP_WAIT_POLICY", "ACTIVE")  # the user's choice stands
    pacing.let_idle_threads_sleep(True, 2)
    assert pacing.os.environ["OMP_WAIT_POLICY"] == "ACTIVE"


def test_a_paced_run_takes_one_thread_an_unpaced_one_every_core(monkeypatch):
    monkeypatch.delenv(THREADS_ENV, raising=False)
    monkeypatch.setenv("OMP_WAIT_POLICY", "")  # restored after the test
    monkeypatch.delenv("OMP_WAIT_POLICY")
    cores = len(pacing.os.sched_getaffinity(0))
    assert pacing.threads_for_run(None, 1.0) == 1
    assert pacing.threads_for_run(None, 0.0) == cores
    assert "OMP_WAIT_POLICY" not in pacing.os.environ
    assert pacing.threads_for_run(2, 4.0) == 2
    assert pacing.os.environ["OMP_WAIT_POLICY"] == "PASSIVE"  # paced on several threads: idle workers sleep
    monkeypatch.setenv(THREADS_ENV, "3")
    assert pacing.threads_for_run(None, 0.0) == 3
    assert pacing.threads_for_run(None, 0.0, recording=True) == 3  # the user's choice stands


def test_an_unpaced_recording_leaves_a_core_to_the_bag_writer(monkeypatch):
    monkeypatch.delenv(THREADS_ENV, raising=False)
    monkeypatch.setattr(pacing.os, "sched_getaffinity", lambda pid: {0, 1, 2, 3})  # a 4-core machine
    assert pacing.threads_for_run(None, 0.0, recording=True) == 3
    assert pacing.threads_for_run(None, 0.0, recording=False) == 4
    assert pacing.threads_for_run(None, 2.0, recording=True) == 1  # paced: one thread anyway
    assert pacing.threads_for_run(4, 0.0, recording=True) == 4  # asked for
    monkeypatch.setattr(pacing.os, "sched_getaffinity", lambda pid: {0})
    assert pacing.threads_for_run(None, 0.0, recording=True) == 1
