"""The worlds the bag tests record: two robots with two lasers each, on the rooms map."""

from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

TWO_ROBOTS = """
resolution 0.02
interval_sim 100
{quit_time}
define floorplan model ( color "SlateGray" boundary 1 obstacle_return 1 )
floorplan( size [27.05 21.65 1.0] pose [13.525 10.825 0 0] bitmap "{bitmap}" )
define front ranger ( sensor( range [0.0 5.6] fov 240.0 samples 90 ) size [0.06 0.06 0.06] )
define back ranger ( sensor( range [0.1 3.0] fov 90.0 samples 31 ) size [0.06 0.06 0.06] )
define bot position ( size [0.4 0.3 0.2] drive "diff" localization "odom" odom_error [0.03 0.03 0 0.05]
                      front( pose [0.2 0 -0.1 0] ) back( pose [-0.2 0 -0.1 180] ) )
bot( pose [11.1 9.2 0 90] name "alpha" )
bot( pose [4.0 4.0 0 0] name "beta" )
"""
"""Two robots (robot_0, robot_1), each with base_scan_0 (front, 90 beams) and base_scan_1 (back, 31 beams)."""

ROBOT_TOPICS = ("odom", "base_pose_ground_truth", "stall", "base_scan_0", "base_scan_1")


def two_robot_world(folder: Path, quit_time: float = 0.0) -> Path:
    """Write the two-robot world into ``folder`` (the bitmap is the repository's rooms map)."""
    path = folder / "two_robots.world"
    path.write_text(TWO_ROBOTS.format(bitmap=REPO / "maps/rooms.png",
                                      quit_time=f"quit_time {quit_time}" if quit_time else ""))
    return path
