"""A private DDS domain for a process that runs a simulator and its controllers together.

Two sessions on one domain hear each other: every wanderer gets every simulator's scans and every
simulator obeys every wanderer's ``cmd_vel``, which silently corrupts both runs. Unless the user chose a
``ROS_DOMAIN_ID``, :func:`use_private_domain` reserves one with ``domain_coordinator`` (what the ROS test
tools use: a held local port per domain) among the domains where no DDS participant is already
listening, exports it for rclpy and child processes, and says which it is. The reservation lasts until
the process exits.
"""

from __future__ import annotations

import atexit
import itertools
import os
import socket
import sys
from collections.abc import Callable

from domain_coordinator import domain_id

DOMAIN_VARIABLE = "ROS_DOMAIN_ID"
FIRST_DOMAIN, LAST_DOMAIN = 1, 100
"""The range domain_coordinator hands out."""
DDS_PORT_BASE, DDS_DOMAIN_GAIN, DDS_UNICAST_OFFSET = 7400, 250, 10
"""RTPS well-known ports: a domain's first participant listens on 7400 + 250 * domain + 10 (unicast)."""


def participant_listening(domain: int) -> bool:
    """Whether a DDS participant already holds this domain's first unicast discovery port."""
    port = DDS_PORT_BASE + DDS_DOMAIN_GAIN * domain + DDS_UNICAST_OFFSET
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            probe.bind(("", port))
        except OSError:
            return True
    return False


def _quiet_domains() -> Callable[[], int]:
    """A domain_coordinator selector: the domains without a DDS participant, in order, round and round."""
    quiet = [d for d in range(FIRST_DOMAIN, LAST_DOMAIN + 1) if not participant_listening(d)]
    return itertools.cycle(quiet or range(FIRST_DOMAIN, LAST_DOMAIN + 1)).__next__


def use_private_domain(prog: str) -> int:
    """The user's ``ROS_DOMAIN_ID`` if set, else a free domain reserved for this process and exported; says
    which on stderr (stdout stays for results)."""
    given = os.environ.get(DOMAIN_VARIABLE, "").strip()
    if given:
        print(f"{prog}: on ROS_DOMAIN_ID {given} (from the environment)", file=sys.stderr, flush=True)
        return int(given)
    reservation = domain_id(selector=_quiet_domains())
    chosen = reservation.__enter__()
    atexit.register(reservation.__exit__, None, None, None)
    os.environ[DOMAIN_VARIABLE] = str(chosen)
    print(f"{prog}: on private ROS_DOMAIN_ID {chosen} (export ROS_DOMAIN_ID={chosen} to reach it from other "
          "tools; set ROS_DOMAIN_ID before starting to choose the domain)", file=sys.stderr, flush=True)
    return chosen
