"""Choosing the kernels and threads: argument, then environment, then default; numba missing is not fatal."""

from __future__ import annotations

import sys

import numba
import pytest

from stage_sim.sensing import kernels as choice


def test_argument_beats_environment_beats_default(monkeypatch):
    monkeypatch.delenv(choice.KERNELS_ENV, raising=False)
    assert choice.resolve_kernels() == "numba"
    monkeypatch.setenv(choice.KERNELS_ENV, "numpy")
    assert choice.resolve_kernels() == "numpy"
    assert choice.resolve_kernels("numba") == "numba"
    with pytest.raises(ValueError, match="kernels must be one of numba, numpy"):
        choice.resolve_kernels("fortran")


def test_threads_from_argument_environment_or_default(monkeypatch):
    monkeypatch.delenv(choice.THREADS_ENV, raising=False)
    assert choice.resolve_threads() == 1
    assert choice.resolve_threads(default=3) == 3
    monkeypatch.setenv(choice.THREADS_ENV, "2")
    assert choice.resolve_threads() == 2
    assert choice.resolve_threads(1) == 1
    assert choice.resolve_threads(0) >= 1  # all cores
    with pytest.raises(ValueError):
        choice.resolve_threads(-1)


def test_numba_that_does_not_import_falls_back_to_numpy_with_one_warning(monkeypatch):
    monkeypatch.delenv(choice.KERNELS_ENV, raising=False)
    monkeypatch.setitem(sys.modules, "numba", None)  # `import numba` now raises ImportError
    choice.numba_available.cache_clear()
    try:
        with pytest.warns(RuntimeWarning, match="numba unavailable .*; using the numpy kernels") as caught:
            assert choice.resolve_kernels() == "numpy"
            assert choice.resolve_kernels("numba") == "numpy"
        assert len(caught) == 1
    finally:
        choice.numba_available.cache_clear()


def test_read_only_package_sends_the_cache_to_the_user_cache(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", "")  # unset for the code, restored afterwards
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setattr(choice.os, "access", lambda path, mode: False)
    monkeypatch.setattr(numba.config, "CACHE_DIR", numba.config.CACHE_DIR)
    choice._configure_cache_dir()
    user_cache = tmp_path / ".cache" / "stage_sim"
    assert choice.os.environ["NUMBA_CACHE_DIR"] == str(user_cache)
    configured = numba.config.CACHE_DIR
    assert configured == str(user_cache)
    assert user_cache.is_dir()
