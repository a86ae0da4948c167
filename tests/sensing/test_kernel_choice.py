"""The threads of a run: one when paced to the wall clock, every core when not; idle workers of a paced run sleep."""

from __future__ import annotations

from stage_sim import backend
from stage_sim.sensing import kernels as choice


def test_idle_threads_sleep_only_in_paced_runs_on_several_threads(monkeypatch):
    monkeypatch.setenv("OMP_WAIT_POLICY", "")  # restored after the test
    for realtime, threads in ((False, 2), (True, 1)):
        monkeypatch.delenv("OMP_WAIT_POLICY", raising=False)
        choice.let_idle_threads_sleep(realtime, threads)
        assert "OMP_WAIT_POLICY" not in choice.os.environ
    choice.let_idle_threads_sleep(True, 2)
    assert choice.os.environ["OMP_WAIT_POLICY"] == "PASSIVE"
    monkeypatch.setenv("OMP_WAIT_POLICY", "ACTIVE")  # the user's choice stands
    choice.let_idle_threads_sleep(True, 2)
    assert choice.os.environ["OMP_WAIT_POLICY"] == "ACTIVE"


def test_a_paced_run_takes_one_thread_an_unpaced_one_every_core(monkeypatch):
    monkeypatch.delenv(backend.THREADS_ENV, raising=False)
    monkeypatch.setenv("OMP_WAIT_POLICY", "")  # restored after the test
    monkeypatch.delenv("OMP_WAIT_POLICY")
    cores = len(choice.os.sched_getaffinity(0))
    assert choice.threads_for_run(None, 1.0) == 1
    assert choice.threads_for_run(None, 0.0) == cores
    assert "OMP_WAIT_POLICY" not in choice.os.environ
    assert choice.threads_for_run(2, 4.0) == 2
    assert choice.os.environ["OMP_WAIT_POLICY"] == "PASSIVE"  # paced on several threads: idle workers sleep
    monkeypatch.setenv(backend.THREADS_ENV, "3")
    assert choice.threads_for_run(None, 0.0) == 3
