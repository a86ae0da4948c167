"""Griffe extension for the API reference: the docstrings' Sphinx roles (:mod:`x`, :func:`~a.b`) as inline code.

stage_sim's docstrings cross-reference with reStructuredText roles, which Markdown would show verbatim
(":func:" followed by the name). This rewrites each role to the code span Sphinx would print: the target, or
with a leading ``~`` its last part. Only the rendering changes; the docstrings stay as they are.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:mod|class|func|meth|attr|data|obj|exc|const):`(?P<tilde>~?)(?P<target>[^`]+)`")


def plain(match: re.Match[str]) -> str:
    target = match["target"]
    return f"`{target.rsplit('.', 1)[-1] if match['tilde'] else target}`"


class RstRoles(griffe.Extension):
    """Rewrites the roles of every docstring griffe loads."""

    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = ROLE.sub(plain, obj.docstring.value)
