"""Syntax tree of a Stage world file: properties, entities and defines, with includes spliced in.

Grammar (spec §8.2)::

    file     := { property | entity | define | include }
    property := WORD value                       name and value on the same line
    value    := NUMBER | STRING | '[' { NUMBER | STRING } ']'    a tuple on one line, no nesting
    entity   := WORD '(' { property | entity } ')'               '(' may be on a later line
    define   := 'define' NEWNAME PARENTNAME '(' { property | entity } ')'
    include  := 'include' STRING                 rest of the line discarded; top level only

An include is found as :mod:`stage_sim.worldfile.search_path` says: Stage's place (beside the top-level
world file, also for includes inside includes) first.
Nothing here knows what a key means; :mod:`stage_sim.worldfile.loader` gives the tree its meaning.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from stage_sim.worldfile.errors import SourceLocation, WorldError
from stage_sim.worldfile.lexer import Token, TokenKind, tokenize
from stage_sim.worldfile.search_path import SEARCH_ORDER, candidate_paths, describe_tried

MAX_NESTING = 100
"""Entities nested deeper than this are refused (no real world comes close; it keeps recursion bounded)."""

Reader = Callable[[Path], str]
"""Returns a file's text; raises OSError when it cannot. Tests pass a dict-backed one to avoid disk I/O."""

_VALUE_KINDS = (TokenKind.NUMBER, TokenKind.STRING)


@dataclass(frozen=True)
class Value:
    """One value of a property, as written (numbers are converted by the loader, which knows the key)."""

    text: str
    is_string: bool
    location: SourceLocation


@dataclass(frozen=True)
class Property:
    """``name value`` or ``name [v1 v2 ...]``; a scalar is a one-element ``values``."""

    name: str
    values: tuple[Value, ...]
    location: SourceLocation
    is_tuple: bool = False


@dataclass
class Entity:
    """``type( ... )``: its own properties in file order and its child entities in file order."""

    type: str
    location: SourceLocation
    properties: list[Property] = field(default_factory=list)
    children: list[Entity] = field(default_factory=list)


@dataclass(frozen=True)
class Define:
    """``define name parent ( body )``: a macro; ``body.type`` is the parent name."""

    name: str
    parent: str
    body: Entity
    location: SourceLocation


@dataclass
class WorldSyntax:
    """A parsed world: world-level properties, then defines and entities in file order (includes spliced)."""

    path: Path
    properties: list[Property] = field(default_factory=list)
    items: list[Entity | Define] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)


def read_text_file(path: Path) -> str:
    """Default reader: bytes decoded as UTF-8, undecodable bytes replaced (the lexer then reports them)."""
    return path.read_bytes().decode("utf-8", errors="replace")


def parse_world(path: str | Path, reader: Reader = read_text_file) -> WorldSyntax:
    """Parse the world file at ``path`` and every file it includes."""
    path = Path(path)
    try:
        text = reader(path)
    except OSError as exc:
        raise WorldError(
            "cannot read world file",
            SourceLocation(str(path), 1, 1),
            found=exc.strerror or str(exc),
            expected="a readable world file",
        ) from exc
    return parse_world_text(text, path, reader)


def parse_world_text(text: str, path: str | Path, reader: Reader = read_text_file) -> WorldSyntax:
    """Parse ``text`` as if it were the file ``path`` (includes resolve relative to its directory)."""
    path = Path(path)
    syntax = WorldSyntax(path=path)
    _FileParser(syntax, reader, [path]).parse(text, path)
    return syntax


class _FileParser:
    """Parses one file's tokens into ``syntax``; recursion into includes keeps ``chain`` for cycle checks."""

    def __init__(self, syntax: WorldSyntax, reader: Reader, chain: list[Path]) -> None:
        self.syntax = syntax
        self.reader = reader
        self.chain = chain
        self.tokens: list[Token] = []
        self.pos = 0

    def parse(self, text: str, path: Path) -> None:
        self.syntax.files.append(path)
        self.tokens = tokenize(text.removeprefix("\ufeff"), str(path))
        self.pos = 0
        while (token := self._next()).kind is not TokenKind.EOF:
            if token.kind is TokenKind.NEWLINE:
                continue
            if token.kind is not TokenKind.WORD:
                raise _unexpected(token, "at top level", "a property, entity, define or include")
            if token.text == "include":
                self._include(token, path)
            elif token.text == "define":
                self.syntax.items.append(self._define(token))
            else:
                item = self._word_item(token, 1)
                if isinstance(item, Property):
                    self.syntax.properties.append(item)
                else:
                    self.syntax.items.append(item)

    def _next(self) -> Token:
        token = self.tokens[self.pos]
        if token.kind is not TokenKind.EOF:
            self.pos += 1
        return token

    def _peek(self) -> Token:
        return self.tokens[self.pos]

    def _skip_newlines(self) -> Token:
        while self._peek().kind is TokenKind.NEWLINE:
            self.pos += 1
        return self._peek()

    def _word_item(self, word: Token, depth: int) -> Property | Entity:
        """A property when a value follows on the same line, an entity when '(' follows (maybe later)."""
        following = self._peek()
        if following.kind in _VALUE_KINDS or following.kind is TokenKind.OPEN_TUPLE:
            return self._property(word)
        if self._skip_newlines().kind is TokenKind.OPEN_ENTITY:
            return self._entity(word.text, word.location, depth)
        if following.kind in (TokenKind.NEWLINE, TokenKind.EOF):
            raise WorldError(
                f"property '{word.text}' has no value",
                word.location,
                found=following.kind.value,
                expected="a number, string or '[' on the same line, or '(' to open an entity",
            )
        raise _unexpected(following, f"after '{word.text}'", "a value or '('")

    def _property(self, name: Token) -> Property:
        token = self._next()
        if token.kind is not TokenKind.OPEN_TUPLE:
            return Property(name.text, (_value(token),), name.location)
        values: list[Value] = []
        while (item := self._next()).kind is not TokenKind.CLOSE_TUPLE:
            if item.kind in (TokenKind.NEWLINE, TokenKind.EOF):
                raise WorldError(
                    f"unterminated tuple for '{name.text}'",
                    token.location,
                    found=item.kind.value,
                    expected="']' on the same line (tuples cannot span lines or hold comments)",
                )
            if item.kind not in _VALUE_KINDS:
                raise _unexpected(item, f"in the tuple of '{name.text}'", "numbers or strings and ']'")
            values.append(_value(item))
        return Property(name.text, tuple(values), name.location, is_tuple=True)

    def _entity(self, type_name: str, location: SourceLocation, depth: int) -> Entity:
        opening = self._next()
        if depth > MAX_NESTING:
            raise WorldError(
                "entities nested too deeply",
                opening.location,
                found=f"{depth} levels",
                expected=f"at most {MAX_NESTING}",
            )
        entity = Entity(type_name, location)
        while (token := self._next()).kind is not TokenKind.CLOSE_ENTITY:
            if token.kind is TokenKind.NEWLINE:
                continue
            if token.kind is TokenKind.EOF:
                raise WorldError(
                    f"unterminated entity '{type_name}'",
                    opening.location,
                    found="end of file",
                    expected="')' closing this '('",
                )
            if token.kind is not TokenKind.WORD:
                raise _unexpected(token, f"inside '{type_name}'", "a property, an entity or ')'")
            if token.text in ("include", "define"):
                raise WorldError(
                    f"'{token.text}' is only allowed at top level",
                    token.location,
                    found=f"'{token.text}' inside '{type_name}'",
                    expected="a property, an entity or ')'",
                )
            item = self._word_item(token, depth + 1)
            if isinstance(item, Property):
                entity.properties.append(item)
            else:
                entity.children.append(item)
        return entity

    def _define(self, keyword: Token) -> Define:
        names: list[Token] = []
        for role in ("the new type name", "the parent type name"):
            token = self._next()
            if token.kind is not TokenKind.WORD:
                raise _unexpected(token, "in define", f"{role} (define NEWNAME PARENT ( ... ))")
            names.append(token)
        if self._skip_newlines().kind is not TokenKind.OPEN_ENTITY:
            raise _unexpected(self._peek(), f"after 'define {names[0].text} {names[1].text}'", "'('")
        body = self._entity(names[1].text, names[1].location, 1)
        return Define(names[0].text, names[1].text, body, keyword.location)

    def _include(self, keyword: Token, including: Path) -> None:
        target = self._next()
        if target.kind is not TokenKind.STRING:
            raise _unexpected(target, "after include", 'a quoted file name (include "file")')
        while self._peek().kind not in (TokenKind.NEWLINE, TokenKind.EOF):
            self.pos += 1  # Stage discards the rest of the include line
        path, text = self._read_include(target.text, including, keyword.location)
        _FileParser(self.syntax, self.reader, [*self.chain, path]).parse(text, path)

    def _read_include(self, name: str, including: Path, where: SourceLocation) -> tuple[Path, str]:
        """Open the first of :func:`candidate_paths` that reads (Stage's rule first); name them all if none does."""
        candidates = candidate_paths(name, self.syntax.path, including)
        problem = ""
        for candidate in candidates:
            if any(_same_file(candidate, seen) for seen in self.chain):
                names = " -> ".join(str(p) for p in [*self.chain, candidate])
                raise WorldError(
                    f"include cycle: {names}", where, found=f'include "{name}"', expected="no file including itself"
                )
            try:
                return candidate, self.reader(candidate)
            except OSError as exc:
                problem = problem or (exc.strerror or str(exc))
        raise WorldError(
            f'cannot open include file "{name}"; tried {describe_tried(candidates)}',
            where,
            found=problem,
            expected=f"a readable file; {SEARCH_ORDER}",
        )


def _value(token: Token) -> Value:
    return Value(token.text, token.kind is TokenKind.STRING, token.location)


def _unexpected(token: Token, where: str, expected: str) -> WorldError:
    return WorldError(
        f"syntax error: unexpected {token.kind.value} {where}",
        token.location,
        found=token.describe(),
        expected=expected,
    )


def _same_file(a: Path, b: Path) -> bool:
    return os.path.normcase(os.path.abspath(a)) == os.path.normcase(os.path.abspath(b))
