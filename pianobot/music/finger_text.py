"""Fingering written as text in a MIDI file's lyric or text events (docs/fingering.md).

At the tick where notes start, one finger number per note starting there, lowest pitch first,
separated by spaces or commas: ``"3"`` for a melody note, ``"2 4"`` for a two-note chord. A
substitution written ``3_1`` (as in PIG) counts as its first finger, the one that strikes; ``-``
marks a note without a finger. A text that is not such a list (an ordinary lyric) is no
fingering. In a track that writes fingering so, a text that looks like fingering but is none
(``"(2)"``, ``"1-3-5"``, ``"3-1"``: a dash may join a chord's fingers as well as a substitution's)
is said by the reader (:func:`looks_like_fingering`).
"""

from __future__ import annotations

import re

_TOKEN = r"(?:[0-9](?:_[0-9])?|-)"
_LIST = re.compile(rf"^\s*{_TOKEN}(?:[\s,]+{_TOKEN})*\s*$")
_MARKS = r"[\s,()\[\]_\-–]"
_FINGERISH = re.compile(rf"^{_MARKS}*[1-5](?:{_MARKS}+[1-5])*{_MARKS}*$")
"""Fingers 1-5, one digit each, among brackets, dashes and spaces (not a slash: '3/4' is a meter)."""


def parse_finger_text(text: str) -> list[int | None] | None:
    """Finger numbers in a lyric/text event, or None when the text is not a list of numbers. A
    number may be no finger 1-5 (a figured bass's "6"): :func:`is_fingering` tells."""
    if not _LIST.match(text):
        return None
    return [None if token == "-" else int(token[0]) for token in re.split(r"[\s,]+", text.strip())]


def is_fingering(fingers: list[int | None]) -> bool:
    """Whether every number of a :func:`parse_finger_text` list is a finger, 1 (thumb) to 5 (little)."""
    return all(f is None or 1 <= f <= 5 for f in fingers)


def looks_like_fingering(text: str) -> bool:
    """Whether a text that :func:`parse_finger_text` does not read is made of fingers 1-5 and
    brackets or dashes only (``"(2)"``, ``"1-3-5"``, ``"3-1"``): fingering written otherwise."""
    return parse_finger_text(text) is None and bool(_FINGERISH.match(text))


def finger_text(fingers: list[int | None]) -> str:
    """The inverse of :func:`parse_finger_text`."""
    return " ".join("-" if f is None else str(f) for f in fingers)
