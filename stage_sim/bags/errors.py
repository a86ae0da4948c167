"""The one error a user can cause when recording: kept light so entry points can catch it cheaply."""

from __future__ import annotations

BAG_SUFFIX = ".mcap"
"""Readers (rosbags, ros2 bag) choose the storage format of a bare file by this suffix."""


class BagError(Exception):
    """The bag cannot be written or read (wrong suffix, bad path, full disk): a message for the user, not a bug."""
