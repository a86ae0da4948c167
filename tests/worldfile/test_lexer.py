"""Lexical rules of Stage world files (spec §8.1)."""

from __future__ import annotations

import pytest

from stage_sim.worldfile.errors import SourceLocation, WorldError
from stage_sim.worldfile.lexer import TokenKind, integer_value, is_clean_number, number_value, tokenize

K = TokenKind


def kinds(text: str) -> list[TokenKind]:
    return [t.kind for t in tokenize(text, "f")]


def texts(text: str) -> list[str]:
    return [t.text for t in tokenize(text, "f") if t.kind not in (K.NEWLINE, K.EOF)]


def test_words_may_contain_dots_dashes_underscores_and_brackets() -> None:
    assert texts("point[3] a.b-c_d x1") == ["point[3]", "a.b-c_d", "x1"]
    assert kinds("point[3]") == [K.WORD, K.EOF]


def test_bracket_after_blank_is_a_tuple_token() -> None:
    assert kinds("size [1 2]") == [K.WORD, K.OPEN_TUPLE, K.NUMBER, K.NUMBER, K.CLOSE_TUPLE, K.EOF]


def test_numbers_are_made_of_sign_dot_and_digits() -> None:
    assert texts("1.5 -2 +.5 1.2.3 - 007") == ["1.5", "-2", "+.5", "1.2.3", "-", "007"]
    assert set(kinds("1.5 -2 +.5 1.2.3 - 007")) == {K.NUMBER, K.EOF}


@pytest.mark.parametrize(
    ("text", "value"), [("1.5", 1.5), ("-2", -2.0), ("+.5", 0.5), ("1.2.3", 1.2), ("-", 0.0), ("3.", 3.0)]
)
def test_number_value_is_atof(text: str, value: float) -> None:
    assert number_value(text) == value


@pytest.mark.parametrize(("text", "value"), [("1.000", 1), ("180.9", 180), ("-3", -3), ("-", 0), (".5", 0)])
def test_integer_value_is_atoi(text: str, value: int) -> None:
    assert integer_value(text) == value


def test_clean_number_detection() -> None:
    assert is_clean_number("1.5") and is_clean_number("-.5")
    assert not is_clean_number("1.2.3") and not is_clean_number("-") and not is_clean_number("1-2")


def test_exponent_is_an_error_at_the_number() -> None:
    with pytest.raises(WorldError) as info:
        tokenize("resolution 1e-3\n", "w.world")
    assert info.value.location == SourceLocation("w.world", 1, 12)
    assert "'1e-3'" in str(info.value)


def test_number_followed_by_string_is_two_tokens() -> None:
    assert kinds('1"a"') == [K.NUMBER, K.STRING, K.EOF]


def test_strings_have_no_escapes_and_keep_spaces() -> None:
    tokens = tokenize('name "a b\\" x', "f")
    assert tokens[1].kind is K.STRING and tokens[1].text == "a b\\"
    assert tokens[2].text == "x"


def test_unterminated_string_is_reported_at_its_start() -> None:
    with pytest.raises(WorldError) as info:
        tokenize('a 1\n  name "robot\n"', "w.world")
    assert info.value.location == SourceLocation("w.world", 2, 8)
    assert "unterminated string" in str(info.value)


def test_unterminated_string_at_end_of_file() -> None:
    with pytest.raises(WorldError) as info:
        tokenize('name "robot', "w.world")
    assert info.value.location == SourceLocation("w.world", 1, 6)
    assert "end of file" in str(info.value)


def test_comments_run_to_end_of_line() -> None:
    assert texts('a # comment ( [ "\nb') == ["a", "b"]
    assert kinds("# only\n") == [K.NEWLINE, K.EOF]


@pytest.mark.parametrize("newline", ["\n", "\r", "\r\n", "\n\r"])
def test_each_newline_convention_counts_one_line(newline: str) -> None:
    tokens = tokenize(f"a{newline}b{newline}{newline}c", "f")
    words = {t.text: t.location.line for t in tokens if t.kind is K.WORD}
    assert words == {"a": 1, "b": 2, "c": 4}
    assert sum(t.kind is K.NEWLINE for t in tokens) == 3


def test_mixed_newlines_and_columns() -> None:
    tokens = tokenize("a\rb\nc\r\nd\n\r  e\tf", "f")
    where = {t.text: (t.location.line, t.location.column) for t in tokens if t.kind is K.WORD}
    assert where == {"a": (1, 1), "b": (2, 1), "c": (3, 1), "d": (4, 1), "e": (5, 3), "f": (5, 5)}


def test_punctuation_tokens_and_locations() -> None:
    tokens = tokenize("m ( [ ] )", "x.world")
    assert [t.kind for t in tokens] == [K.WORD, K.OPEN_ENTITY, K.OPEN_TUPLE, K.CLOSE_TUPLE, K.CLOSE_ENTITY, K.EOF]
    assert [t.location.column for t in tokens] == [1, 3, 5, 7, 9, 10]
    assert all(t.location.file == "x.world" for t in tokens)


def test_eof_token_location_is_after_the_last_character() -> None:
    assert tokenize("ab\ncd", "f")[-1].location == SourceLocation("f", 2, 3)


@pytest.mark.parametrize(("text", "column"), [("a @", 3), ("{", 1), ("x é", 3), ("_a", 1), ("a\x00", 2)])
def test_unexpected_characters_are_syntax_errors(text: str, column: int) -> None:
    with pytest.raises(WorldError) as info:
        tokenize(text, "w.world")
    assert info.value.location == SourceLocation("w.world", 1, column)
    assert "unexpected character" in str(info.value)


def test_token_describe() -> None:
    word, number, string, eof = tokenize('w 1 "s"', "f")
    assert word.describe() == "word 'w'" and number.describe() == "number '1'"
    assert string.describe() == 'string "s"' and eof.describe() == "end of file"
