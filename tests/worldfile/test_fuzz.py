"""Mutated world files either load or raise WorldError: never another exception, never a hang."""

from __future__ import annotations

import random
import re
import time
from pathlib import Path

from stage_sim.worldfile.errors import WorldError
from stage_sim.worldfile.loader import load_world_text
from tests.worldfile.test_loader import ROOMS_WORLD, SIMPLE_ROBOT_INC, WILLOW_PR2_WORLD

CASES = 10_000
SEED = 20240607
WORLD_PATH = "/fuzz/worlds/w.world"

EXTRA_WORLD = """\
unit_length "cm"
unit_angle "radians"
interval_sim 50 threads 2 quit_time 10
define sick sensor ( samples 5 fov 3.14 range [0 400] noise [0.01 0.01 0.01] )
define base position (
  size [40 40 25] origin [0 0 0 0] drive "car" wheelbase 30
  velocity_bounds [-100 100 -50 50 0 0 -1.5 1.5]
  localization "odom" localization_origin [0 0 0 0] odom_error [0.01 0.02 0 0.03]
  block( points 5 point[0] [0 0] point[1] [1 0] point[2] [1.5 0.5] point[3] [1 1] point[4] [0 1] z [0 1] )
  ranger( pose [10 0 5 0] sick( ) sick( pose [0 0 0 1.57] ) )
  laser( samples 90 range_max 800 fov 3 )
  camera( )
)
base( pose [100 200 0 0.5] name "r0" color "DarkGreen" )
base( pose [300 200 0 0 ] color_rgba [0.1 0.2 0.3 1] size3 [30 30 20] )
model( pose [0 0 0 0] size [1000 800 50] boundary 1 ranger_return 0.5 model( pose [1 2 3] ) )
window( size [400 300] center [0 0] rotate [0 0] scale 20 )
"""

# Without the bitmaps: each case must run from memory (the bitmap loaders have their own tests).
BASES = [
    ROOMS_WORLD.replace('bitmap "../maps/rooms.png"', ""),
    WILLOW_PR2_WORLD.replace('bitmap "../maps/willow-full.pgm"', ""),
    EXTRA_WORLD,
]
INCLUDES = {Path("/fuzz/robots/simple_robot.inc"): SIMPLE_ROBOT_INC}
MESSAGE = re.compile(r"^/fuzz/\S+:\d+:\d+: .+ \(found .+, expected .+\)$", re.DOTALL)
PIECES = re.compile(r'\s+|"[^"\n]*"?|[()\[\]]|#[^\n]*|[^\s()\[\]"#]+')
NOISE = [*'()[]"#\n\r\t -+.0123456789xyz_é\x00', "block", "define", "include", "sensor", "1e5", "[]"]


def reader(path: Path) -> str:
    if path not in INCLUDES:
        raise FileNotFoundError(2, "No such file or directory")
    return INCLUDES[path]


def mutate(text: str, rng: random.Random) -> str:
    """One to three token-level or byte-level changes."""
    for _ in range(rng.randint(1, 3)):
        pieces = PIECES.findall(text)
        tokens = [i for i, p in enumerate(pieces) if not p.isspace()]
        op = rng.randrange(7)
        if op <= 3 and tokens:
            i = rng.choice(tokens)
            if op == 0:  # drop a token
                pieces[i] = ""
            elif op == 1:  # duplicate a token
                pieces[i] = pieces[i] + " " + pieces[i]
            elif op == 2:  # swap two tokens
                j = rng.choice(tokens)
                pieces[i], pieces[j] = pieces[j], pieces[i]
            else:  # replace a token with noise
                pieces[i] = rng.choice(NOISE)
            text = "".join(pieces)
        elif op == 4 and text:  # flip a byte
            data = bytearray(text.encode())
            k = rng.randrange(len(data))
            data[k] ^= 1 << rng.randrange(8)
            text = data.decode("utf-8", errors="replace")
        elif op == 5:  # insert noise anywhere
            k = rng.randrange(len(text) + 1)
            text = text[:k] + rng.choice(NOISE) + text[k:]
        elif text:  # cut the file short
            text = text[: rng.randrange(len(text))]
    return text


def test_base_worlds_load() -> None:
    for text in BASES:
        assert load_world_text(text, WORLD_PATH, reader).models


def test_mutated_worlds_load_or_raise_world_error() -> None:
    rng = random.Random(SEED)
    outcomes = {"loaded": 0, "error": 0}
    slowest = 0.0
    started = time.perf_counter()
    for case in range(CASES):
        text = mutate(rng.choice(BASES), rng)
        begin = time.perf_counter()
        try:
            load_world_text(text, WORLD_PATH, reader)
            outcomes["loaded"] += 1
        except WorldError as error:
            assert error.location is not None and MESSAGE.match(str(error)), (case, str(error))
            outcomes["error"] += 1
        except Exception as exc:  # pragma: no cover - the failure report
            raise AssertionError(f"case {case}: {type(exc).__name__}: {exc}\n--- world ---\n{text}") from exc
        slowest = max(slowest, time.perf_counter() - begin)
    assert sum(outcomes.values()) == CASES
    assert outcomes["loaded"] > CASES // 10 and outcomes["error"] > CASES // 10  # both paths exercised
    assert slowest < 2.0 and time.perf_counter() - started < 60.0
