"""The page in a real headless Chromium: what it draws, and what mouse and keys do to the simulation."""

from __future__ import annotations

import io
import math
import time
from collections.abc import Iterator

import numpy as np
import pytest
from PIL import Image

from tests.view.conftest import REPO, Served, serve

pytestmark = pytest.mark.browser

START = (11.1, 9.2, math.pi / 2)  # the robot's pose in rooms.world
VIEWPORT = {"width": 900, "height": 700}


@pytest.fixture
def page(browser, served: Served) -> Iterator:
    """A page on ``served``, with every console error and uncaught exception collected in ``page.errors``."""
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    tab = context.new_page()
    tab.errors = []
    tab.on("console", lambda message: tab.errors.append(message.text) if message.type == "error" else None)
    tab.on("pageerror", lambda error: tab.errors.append(str(error)))
    tab.goto(served.url)
    tab.wait_for_function("window.stageView && stageView.state.drawnFrame !== null")
    try:
        yield tab
    finally:
        context.close()


def settle(page, served: Served) -> None:
    """Pause the simulation and wait until the page has drawn its final state."""
    served.loop.set_paused(True)
    time.sleep(0.1)
    page.wait_for_function(
        "t => stageView.state.drawnFrame.paused && Math.abs(stageView.state.drawnFrame.time - t) < 1e-6",
        arg=served.sim.sim_time)


def canvas_pixel(page, x: float, y: float) -> tuple[float, float]:
    """Page coordinates of world point (x, y), through the page's own world -> canvas transform."""
    box = page.locator("#world").bounding_box()
    cx, cy = page.evaluate("([x, y]) => stageView.worldToCanvas(x, y)", [x, y])
    return box["x"] + cx, box["y"] + cy


def screenshot(page) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)


def colour_at(image: np.ndarray, point: tuple[float, float]) -> tuple[int, int, int]:
    return tuple(image[math.floor(point[1]), math.floor(point[0])])


def is_red(rgb: tuple[int, int, int]) -> bool:
    """The robot's body colour ("red" in simple_robot.inc)."""
    r, g, b = rgb
    return r > 180 and g < 90 and b < 90


def body_point(pose: np.ndarray) -> tuple[float, float]:
    """A point on the robot's chassis, 8 cm behind its centre (clear of the black heading line)."""
    x, y, yaw = pose
    return x - 0.08 * math.cos(yaw), y - 0.08 * math.sin(yaw)


def hold(page, key: str, seconds: float) -> None:
    page.keyboard.down(key)
    time.sleep(seconds)
    page.keyboard.up(key)


def test_the_page_draws_the_robot_where_the_simulation_has_it_and_keys_drive_it(page, served) -> None:
    settle(page, served)
    before = served.sim.true_poses[0].copy()
    image = screenshot(page)
    assert is_red(colour_at(image, canvas_pixel(page, *body_point(before))))
    assert not is_red(colour_at(image, canvas_pixel(page, before[0] + 1.0, before[1])))  # free floor beside it

    served.loop.set_paused(False)
    page.locator("#world").focus()
    hold(page, "i", 1.5)  # teleop_twist_keyboard's "forward"; the one robot is selected on load
    settle(page, served)
    after = served.sim.true_poses[0].copy()
    assert after[1] - before[1] > 0.3  # it drove forward (+y, its heading)
    image = screenshot(page)
    assert is_red(colour_at(image, canvas_pixel(page, *body_point(after))))
    assert not is_red(colour_at(image, canvas_pixel(page, *body_point(before) - np.array([0.0, 0.1]))))
    assert page.errors == []


def test_keys_stop_when_released_because_the_watchdog_still_applies(page, served) -> None:
    page.locator("#world").focus()
    page.keyboard.down("j")  # turn left on the spot
    time.sleep(0.6)
    assert served.sim.velocities[0][2] > 0.5
    page.close()  # gone with the key still down: no stop command ever comes
    time.sleep(0.5)  # the watchdog's 0.2 s of sim time, and then some
    assert tuple(served.sim.velocities[0]) == (0.0, 0.0, 0.0)


def test_dragging_the_robot_with_the_mouse_moves_it_in_the_simulation(page, served) -> None:
    settle(page, served)
    pose = served.sim.true_poses[0].copy()
    start = canvas_pixel(page, pose[0], pose[1])
    target = (9.5, 9.0)
    end = canvas_pixel(page, *target)
    page.mouse.move(*start)
    page.mouse.down()
    page.mouse.move(*end, steps=12)
    page.mouse.up()
    time.sleep(0.3)
    x, y, yaw = served.sim.true_poses[0]
    tolerance = 2.0 / page.evaluate("stageView.state.camera.scale")  # two pixels, in metres
    assert (x, y) == pytest.approx(target, abs=tolerance)
    assert yaw == pytest.approx(pose[2])

    # Shift-drag turns it to face the mouse.
    centre = canvas_pixel(page, x, y)
    page.mouse.move(*centre)
    page.mouse.down()
    page.keyboard.down("Shift")
    page.mouse.move(centre[0] + 80, centre[1], steps=8)
    page.mouse.up()
    page.keyboard.up("Shift")
    time.sleep(0.3)
    assert served.sim.true_poses[0][2] == pytest.approx(0.0, abs=0.05)
    assert tuple(served.sim.true_poses[0][:2]) == pytest.approx((x, y))

    page.get_by_role("button", name="Reset positions").click()
    time.sleep(0.3)
    assert tuple(served.sim.true_poses[0]) == pytest.approx(START)
    assert page.errors == []


def test_p_pauses_and_resumes_sim_time(page, served) -> None:
    page.locator("#world").focus()
    page.keyboard.press("p")
    page.wait_for_function("stageView.state.frame.paused")
    paused_at = served.sim.sim_time
    time.sleep(0.6)
    assert served.sim.sim_time == paused_at
    assert page.locator("#pause").inner_text() == "Resume"
    page.keyboard.press("P")
    page.wait_for_function("!stageView.state.frame.paused")
    time.sleep(0.6)
    assert served.sim.sim_time > paused_at + 0.3


def test_the_snapshot_button_saves_the_view_as_png(page, served) -> None:
    with page.expect_download() as download:
        page.get_by_role("button", name="Snapshot").click()
    path = download.value.path()
    image = Image.open(path)
    assert image.format == "PNG"
    assert image.size == tuple(page.evaluate("[document.getElementById('world').width, "
                                             "document.getElementById('world').height]"))
    assert len(np.unique(np.asarray(image.convert("RGB")).reshape(-1, 3), axis=0)) > 10  # not a blank canvas


def test_d_hides_and_shows_the_laser_data(page, served) -> None:
    settle(page, served)

    def laser_pixels() -> int:
        """Canvas pixels in the laser's blue (lines and hit points)."""
        image = np.asarray(Image.open(io.BytesIO(page.locator("#world").screenshot())).convert("RGB")).astype(int)
        r, g, b = image[..., 0], image[..., 1], image[..., 2]
        return int(np.count_nonzero((b > 150) & (r < 120) & (g < 120)))

    def redrawn_after(key: str) -> None:
        drawn = page.evaluate("stageView.state.framesDrawn")
        page.keyboard.press(key)
        page.wait_for_function("n => stageView.state.framesDrawn > n", arg=drawn)

    page.locator("#world").focus()
    shown = laser_pixels()
    redrawn_after("d")
    hidden = laser_pixels()
    redrawn_after("D")
    again = laser_pixels()
    assert shown > 200
    assert hidden < shown / 20
    assert again == shown


def test_two_pages_at_once_see_the_same_world_and_either_can_move_it(browser, page, served) -> None:
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    try:
        second = context.new_page()
        second.goto(served.url)
        second.wait_for_function("window.stageView && stageView.state.drawnFrame !== null")
        assert served.view.server.viewers == 2
        settle(page, served)
        second.wait_for_function("stageView.state.drawnFrame.paused")
        target = (14.0, 9.0)
        start = canvas_pixel(second, *served.sim.true_poses[0][:2])
        second.mouse.move(*start)
        second.mouse.down()
        second.mouse.move(*canvas_pixel(second, *target), steps=8)
        second.mouse.up()
        time.sleep(0.3)
        assert tuple(served.sim.true_poses[0][:2]) == pytest.approx(target, abs=0.1)
        # The first page draws the robot where the second one put it.
        page.wait_for_function(
            "([x, y]) => Math.hypot(stageView.state.drawnFrame.poses[0][0] - x, "
            "stageView.state.drawnFrame.poses[0][1] - y) < 1e-3", arg=list(served.sim.true_poses[0][:2]))
        image = screenshot(page)
        assert is_red(colour_at(image, canvas_pixel(page, *body_point(served.sim.true_poses[0]))))
    finally:
        context.close()
    time.sleep(0.3)
    assert served.view.server.viewers == 1
    assert page.errors == []


def test_a_world_with_several_robots_and_the_wanderer_runs_in_the_page(browser) -> None:
    running = serve(world=REPO / "worlds" / "multi_robots.world", speedup=4.0, controller=True)
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    try:
        tab = context.new_page()
        errors = []
        tab.on("console", lambda message: errors.append(message.text) if message.type == "error" else None)
        tab.on("pageerror", lambda error: errors.append(str(error)))
        tab.goto(running.url)
        tab.wait_for_function("window.stageView && stageView.state.framesReceived > 20")
        assert tab.evaluate("stageView.state.scene.robots.length") == len(running.sim.robots) > 1
        assert tab.locator("#status").inner_text().count(f"{len(running.sim.robots)} robots") == 1
        assert errors == []
    finally:
        context.close()
        running.close()


FACING_A_WALL = """resolution 0.02
model( size [4 0.2 1] pose [0 -0.45 0 0] color "gray" )
position( name "bot" size [0.4 0.4 0.2] pose [0 0 0 -90] color "red" )
"""


def test_the_panel_beside_the_map_shows_no_motion_while_stalled_and_the_robot_carries_its_name(
    browser, tmp_path
) -> None:
    world = tmp_path / "wall.world"
    world.write_text(FACING_A_WALL)
    running = serve(world=world)
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    try:
        tab = context.new_page()
        tab.goto(running.url)
        tab.wait_for_function("window.stageView && stageView.state.drawnFrame !== null")
        tab.locator("#world").focus()
        tab.keyboard.down("i")  # forward, into the wall just ahead
        tab.wait_for_function("stageView.state.drawnFrame.stalled[0] && !document.getElementById('selection').hidden")
        text = tab.locator("#selection").inner_text()
        tab.keyboard.up("i")
        assert "velocity    0.00  0.00 m/s   0.00 rad/s" in text
        assert "commanded   0.50  0.00 m/s   0.00 rad/s" in text and "STALLED" in text

        panel, canvas = tab.locator("#selection").bounding_box(), tab.locator("#world").bounding_box()
        assert panel["x"] >= canvas["x"] + canvas["width"]  # beside the map, not over it
        x0, y0, x1, y1 = tab.evaluate("stageView.state.scene.bounds")
        for corner in ((x0, y0), (x1, y1)):
            cx, cy = tab.evaluate("([x, y]) => stageView.worldToCanvas(x, y)", list(corner))
            assert 0 <= cx <= canvas["width"] and 0 <= cy <= canvas["height"]

        # The name, up and to the right of the body: dark text where the floor is otherwise light.
        pose = running.sim.true_poses[0]
        cx, cy = tab.evaluate("([x, y]) => stageView.worldToCanvas(x, y)", [float(pose[0]), float(pose[1])])
        ring = (running.sim.robots[0].radius + 0.06) * tab.evaluate("stageView.state.camera.scale") + 2
        left, bottom = round(cx + 0.75 * ring), round(cy - 0.75 * ring)
        image = np.asarray(Image.open(io.BytesIO(tab.locator("#world").screenshot())).convert("RGB")).astype(int)
        label = image[bottom - 14:bottom, left:left + 30]
        assert np.count_nonzero(label.max(axis=2) < 80) > 10
        assert tab.evaluate("stageView.state.scene.robots[0].name") == "bot"
    finally:
        context.close()
        running.close()
