"""The one exception type for broken worlds and maps, carrying where the problem is."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SourceLocation:
    """A position in a world file (1-based line and column), kept on every token."""

    file: str
    line: int
    column: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


class WorldError(Exception):
    """A world file, include, bitmap or map that cannot be loaded.

    The message reads ``file:line:column: what is wrong (found X, expected Y)`` so that editors and
    users can jump straight to the problem; without a location it is just the description.
    """

    def __init__(
        self,
        what: str,
        location: SourceLocation | None = None,
        *,
        found: str | None = None,
        expected: str | None = None,
    ) -> None:
        self.what = what
        self.location = location
        self.found = found
        self.expected = expected
        super().__init__(self._format())

    def _format(self) -> str:
        text = self.what
        details = []
        if self.found is not None:
            details.append(f"found {self.found}")
        if self.expected is not None:
            details.append(f"expected {self.expected}")
        if details:
            text += f" ({', '.join(details)})"
        return f"{self.location}: {text}" if self.location is not None else text
