"""The view's command-line options, shared by ``stageros``, the launch scripts and ``stage_sim view``."""

from __future__ import annotations

import argparse
from dataclasses import dataclass

DEFAULT_PORT = 8730
LOOPBACK_HOSTS = {"127.0.0.1", "localhost", "::1", "[::1]"}


@dataclass(frozen=True)
class ViewSettings:
    """Where to serve and whether pages may change anything."""

    host: str = "127.0.0.1"
    port: int = DEFAULT_PORT
    readonly: bool = False

    @property
    def loopback(self) -> bool:
        """Bound to this machine only."""
        return self.host in LOOPBACK_HOSTS


def add_view_arguments(parser: argparse.ArgumentParser) -> None:
    """``--view-port``, ``--view-host`` and ``--view-readonly``."""
    parser.add_argument("--view-port", type=_port, default=DEFAULT_PORT, metavar="PORT",
                        help=f"port of the browser view (default {DEFAULT_PORT}; if taken, the next free one; 0: any)")
    parser.add_argument("--view-host", default="127.0.0.1", metavar="HOST",
                        help="address to serve the view on (default 127.0.0.1; 0.0.0.0 opens it to the network)")
    parser.add_argument("--view-readonly", action="store_true", help="pages may watch but not change anything")


def view_settings(args: argparse.Namespace) -> ViewSettings:
    """The settings the parsed options ask for."""
    return ViewSettings(args.view_host, args.view_port, args.view_readonly)


def _port(text: str) -> int:
    port = int(text)
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"a port is 0-65535, not {text}")
    return port
