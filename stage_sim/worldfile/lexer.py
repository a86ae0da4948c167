"""Tokens of a Stage world file, each with the file, line and column where it starts.

The rules are Stage's (``worldfile.cc``): ``#`` comments, CR / LF / CRLF / LFCR newlines, words that may
contain ``. - _ [ ]`` (so ``point[3]`` is one word), numbers made only of ``+ - . 0-9`` (no exponent) and
one-line strings without escapes. Newlines are kept as tokens because properties and tuples must fit
on one line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import Enum

from stage_sim.worldfile.errors import SourceLocation, WorldError


class TokenKind(Enum):
    """What a token is; the parser dispatches on this."""

    WORD = "word"
    NUMBER = "number"
    STRING = "string"
    OPEN_ENTITY = "'('"
    CLOSE_ENTITY = "')'"
    OPEN_TUPLE = "'['"
    CLOSE_TUPLE = "']'"
    NEWLINE = "end of line"
    EOF = "end of file"


@dataclass(frozen=True)
class Token:
    """One token: ``text`` is the word, the number as written, or a string without its quotes."""

    kind: TokenKind
    text: str
    location: SourceLocation

    def describe(self) -> str:
        """How error messages show this token ("found ...")."""
        if self.kind is TokenKind.STRING:
            return f'string "{self.text}"'
        if self.kind in (TokenKind.WORD, TokenKind.NUMBER):
            return f"{self.kind.value} '{self.text}'"
        return self.kind.value


_LETTERS = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ")
_DIGITS = frozenset("0123456789")
_WORD_CHARS = _LETTERS | _DIGITS | frozenset(".-_[]")
_NUMBER_CHARS = _DIGITS | frozenset("+-.")
_BLANKS = frozenset(" \t")
_PUNCTUATION = {
    "(": TokenKind.OPEN_ENTITY,
    ")": TokenKind.CLOSE_ENTITY,
    "[": TokenKind.OPEN_TUPLE,
    "]": TokenKind.CLOSE_TUPLE,
}
_FLOAT_PREFIX = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)")
_INT_PREFIX = re.compile(r"[+-]?\d+")


def number_value(text: str) -> float:
    """C ``atof`` of a number token: the longest valid prefix (``1.2.3`` → 1.2), 0 when there is none."""
    match = _FLOAT_PREFIX.match(text)
    return float(match.group()) if match else 0.0


def integer_value(text: str) -> int:
    """C ``atoi`` of a number token: leading digits only (``1.000`` → 1, ``-`` → 0)."""
    match = _INT_PREFIX.match(text)
    return int(match.group()) if match else 0


def is_clean_number(text: str) -> bool:
    """True when ``atof`` reads the whole text (so nothing is silently dropped)."""
    match = _FLOAT_PREFIX.match(text)
    return match is not None and match.end() == len(text)


def tokenize(text: str, file: str) -> list[Token]:
    """Split ``text`` into tokens ending with one EOF token; raise WorldError at the first bad character."""
    tokens: list[Token] = []
    line, line_start, i, n = 1, 0, 0, len(text)

    def here(pos: int) -> SourceLocation:
        return SourceLocation(file, line, pos - line_start + 1)

    while i < n:
        char = text[i]
        if char in _BLANKS:
            i += 1
        elif char in "\r\n":
            tokens.append(Token(TokenKind.NEWLINE, "", here(i)))
            pair = text[i : i + 2]
            i += 2 if pair in ("\r\n", "\n\r") else 1
            line, line_start = line + 1, i
        elif char == "#":
            while i < n and text[i] not in "\r\n":
                i += 1
        elif char in _PUNCTUATION:
            tokens.append(Token(_PUNCTUATION[char], char, here(i)))
            i += 1
        elif char == '"':
            end = i + 1
            while end < n and text[end] not in '"\r\n':
                end += 1
            if end >= n or text[end] != '"':
                found = "end of file" if end >= n else "end of line"
                raise WorldError("unterminated string", here(i), found=found, expected='a closing " on the same line')
            tokens.append(Token(TokenKind.STRING, text[i + 1 : end], here(i)))
            i = end + 1
        elif char in _LETTERS:
            end = i + 1
            while end < n and text[end] in _WORD_CHARS:
                end += 1
            tokens.append(Token(TokenKind.WORD, text[i:end], here(i)))
            i = end
        elif char in _NUMBER_CHARS:
            end = i + 1
            while end < n and text[end] in _NUMBER_CHARS:
                end += 1
            if end < n and (text[end] in _LETTERS or text[end] == "_"):
                raise WorldError(
                    "malformed number (Stage numbers have no exponent or letters)",
                    here(i),
                    found=repr(_run_of(text, i)),
                    expected="digits, '.', '+' or '-' only",
                )
            tokens.append(Token(TokenKind.NUMBER, text[i:end], here(i)))
            i = end
        else:
            raise WorldError("syntax error: unexpected character", here(i), found=repr(char), expected="a token")
    tokens.append(Token(TokenKind.EOF, "", here(i)))
    return tokens


def _run_of(text: str, start: int) -> str:
    """The non-blank run starting at ``start``, for showing a malformed number whole."""
    end = start
    while end < len(text) and text[end] not in ' \t\r\n()[]"#':
        end += 1
    return text[start:end]
