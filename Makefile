# stage_sim: the two commands a newcomer needs are `make run` and `make test`; both set up first.
# Set-up is idempotent: stamps in .venv/ record what was installed, so an unchanged tree re-runs nothing.

SHELL := /bin/bash
VENV ?= .venv
PYTHON_BOOTSTRAP ?= $(shell command -v python3.11 || command -v python3)
PY := $(VENV)/bin/python
PYTEST_ARGS ?=

# Keep DDS discovery on loopback unless the user chose otherwise (project rule for every process).
export ROS_AUTOMATIC_DISCOVERY_RANGE ?= LOCALHOST

.PHONY: setup run test lint bench bench-peers train docs clean-venv

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
	@$(PY) -m stage_sim.envs.warm_up || { echo "make setup: step 'kernels' failed: see the error above" >&2; exit 1; }
	@touch $@

run: setup
	$(VENV)/bin/stageros $(RUN_ARGS) $(WORLD)

test: setup
	$(PY) -m pytest $(PYTEST_ARGS)

# make bench: every benchmark script, its JSON lines written to docs/data/bench/<script>.jsonl and the command
# that produced them to <script>.command; the docs build turns those files into the performance and fidelity
# tables (tools/docs_tables.py). `make bench QUICK=1` runs the short versions (fewer seconds, seeds and repeats).
# One configuration per process where peak RSS is reported, so that each peak_rss_mb is its own.
BENCH_DATA := docs/data/bench
SHORT_LASER := --beams 240 --fov 240 --range 5.6
LONG_LASER := --beams 1081 --fov 270 --range 30
QUICK ?=
pick = $(if $(QUICK),$(2),$(1))
SIM_SECONDS := $(call pick,,--seconds 3)
# $(call bench_run,NAME,COMMAND): COMMAND is written with `python` for the venv's interpreter.
define bench_run
	@echo '$(strip $(2))' >> $(BENCH_DATA)/$(1).command
	set -o pipefail; $(subst python ,$(PY) ,$(2)) | tee /dev/stderr | grep '^{' >> $(BENCH_DATA)/$(1).jsonl

endef

bench: setup
	@mkdir -p $(BENCH_DATA) && find $(BENCH_DATA) -maxdepth 1 \( -name '*.jsonl' -o -name '*.command' \) \
	  ! -name 'rl_peers.*' -delete
	@printf '{"cores": %s, "cpu": "%s", "quick": %s}\n' "$$(nproc)" \
	  "$$(lscpu | sed -n 's/^Model name: *//p' | head -1)" "$(if $(QUICK),true,false)" > $(BENCH_DATA)/machine.json
	$(call bench_run,raycast,python benchmarks/raycast.py)
	$(foreach laser,SHORT_LASER LONG_LASER,\
	  $(call bench_run,simulate,python benchmarks/simulate.py $($(laser)) --kernels numba --threads 1 --robots 1 10 100 1000 $(SIM_SECONDS))\
	  $(call bench_run,simulate,python benchmarks/simulate.py $($(laser)) --kernels numba --threads 2 --robots 1 10 100 1000 $(SIM_SECONDS))\
	  $(call bench_run,simulate,python benchmarks/simulate.py $($(laser)) --kernels numpy --threads 1 --robots 1 100 $(SIM_SECONDS)))
	$(call bench_run,stageros,python benchmarks/stageros.py $(call pick,,--seconds 5))
	$(call bench_run,startup,python benchmarks/startup.py $(call pick,,--runs 1))
	$(call bench_run,worlds,taskset -c 0 python benchmarks/worlds.py $(call pick,,--seconds 2))
	$(call bench_run,worlds,python benchmarks/worlds.py --worlds rl --threads 2 $(call pick,,--seconds 2))
	$(call bench_run,jump_chain,taskset -c 0 python benchmarks/jump_chain.py)
	$(call bench_run,bags,python benchmarks/bags.py $(call pick,,--duration 600 --wander-duration 60 --repeat 1))
	$(call bench_run,envs,taskset -c 0 python benchmarks/envs.py --worlds 16 64 $(call pick,,--seconds 3 --episodes 3))
	$(call bench_run,fidelity,python benchmarks/fidelity.py)
	$(call bench_run,wander_speed,taskset -c 0 python benchmarks/wander_speed.py $(call pick,,--steps 300))
	$(call bench_run,wander_sweep,python benchmarks/wander_sweep.py --core --world rooms.world $(call pick,--seeds 20 --minutes 30,--seeds 2 --minutes 30 --jobs 1))

# make train: PPO on the obstacles scenario (examples/train_ppo.py), its learning curve written to
# docs/data/train/ppo_obstacles.jsonl. torch is heavy, so it lives in a venv of its own; the CPU build is
# installed first, by itself, so that the `train` extra finds torch there and pip pulls no CUDA build. The
# main requirements.lock is not applied here (torch needs a newer setuptools than it pins).
TRAIN_VENV := .venv-train
TRAIN_DATA := docs/data/train

$(TRAIN_VENV)/.package.stamp: setup.py setup.cfg pyproject.toml
	@echo "[train] creating $(TRAIN_VENV) (CPU torch, then stage_sim[train])"
	@test -x $(TRAIN_VENV)/bin/python || $(PYTHON_BOOTSTRAP) -m venv $(TRAIN_VENV)
	@$(TRAIN_VENV)/bin/pip install --quiet --disable-pip-version-check torch==2.13.0
	@$(TRAIN_VENV)/bin/pip install --quiet --disable-pip-version-check torch==2.13.0 -e '.[train]'
	@touch $@

train: $(TRAIN_VENV)/.package.stamp
	@mkdir -p $(TRAIN_DATA)
	@echo 'python examples/train_ppo.py $(TRAIN_ARGS)' > $(TRAIN_DATA)/ppo_obstacles.command
	nice $(TRAIN_VENV)/bin/python examples/train_ppo.py --out $(TRAIN_DATA)/ppo_obstacles.jsonl $(TRAIN_ARGS)

# make bench-peers: benchmarks/rl_peers.py, stage_sim beside navground, irsim-x and ir-sim on one RL scenario.
# Each peer gets a venv of its own, .venv-peers/<peer>, installed from benchmarks/peers/<peer>.lock (so that
# their dependencies never meet stage_sim's); the run writes docs/data/bench/rl_peers.jsonl, .command, and
# rl_peers.machine.json (cores, CPU, and NOTE, e.g. NOTE="other jobs running": its own run note in the docs).
PEERS := navground irsim-x ir-sim
PEER_VENVS := .venv-peers
PEER_ARGS ?=
NOTE ?=

$(PEER_VENVS)/%/.lock.stamp: benchmarks/peers/%.lock
	@echo "[bench-peers] $* into $(PEER_VENVS)/$*"
	@test -x $(PEER_VENVS)/$*/bin/python || $(PYTHON_BOOTSTRAP) -m venv $(PEER_VENVS)/$*
	@$(PEER_VENVS)/$*/bin/pip install --quiet --disable-pip-version-check -r $<
	@touch $@

bench-peers: setup $(foreach peer,$(PEERS),$(PEER_VENVS)/$(peer)/.lock.stamp)
	@mkdir -p $(BENCH_DATA) && rm -f $(BENCH_DATA)/rl_peers.*
	@printf '{"cores": %s, "cpu": "%s", "quick": false, "make": "make bench-peers", "note": "%s"}\n' "$$(nproc)" \
	  "$$(lscpu | sed -n 's/^Model name: *//p' | head -1)" "$(NOTE)" > $(BENCH_DATA)/rl_peers.machine.json
	$(call bench_run,rl_peers,python benchmarks/rl_peers.py $(PEER_ARGS))

# The documentation site (mkdocs.yml, docs/) into site/, in strict mode: a broken link, reference or table fails.
docs: setup
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict

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
