"""The project's exceptions and warnings.

Every problem a user can cause (a bad file, a note the keyboard lacks, a finger the hand
lacks) is raised as a :class:`PianobotError` whose message is one line saying what is wrong
and how to fix it. The CLI prints that line and exits with code 2; nothing else should ever
reach the user as a traceback.
"""

from __future__ import annotations


class PianobotError(Exception):
    """A problem with the user's input, worded as one line: what is wrong and how to fix it."""


class SettingError(PianobotError):
    """A problem with one or more settings, each named in the message by its field's dotted path
    (``load.tempo`` for :class:`~pianobot.music.load.LoadOptions`' tempo, ``keyboard.count``,
    ``hand.fingers``, ``phrases.max_notes``, ``train.device``, ``jobs.force``): a Python caller
    reads the field it set, and the command line writes its option in that place
    (:mod:`pianobot.cli.flags`). ``fields`` lists the settings the message names, the one at
    fault first."""

    def __init__(self, message: str, *fields: str):
        super().__init__(message)
        self.fields = fields

    @property
    def field(self) -> str | None:
        """The setting at fault (the first one the message names)."""
        return self.fields[0] if self.fields else None


class PianobotWarning(UserWarning):
    """Something was repaired on the way in (e.g. overlapping notes of one pitch)."""


QUOTE_LIMIT = 60
"""At most this many characters of text from a file or the command line are quoted in a message."""


def one_line(text: str) -> str:
    """``text`` on one line: line breaks and other control characters written as escapes."""
    return "".join(c if c.isprintable() or c == " " else repr(c)[1:-1] for c in str(text))


def quote(text: str, limit: int = QUOTE_LIMIT) -> str:
    """User-supplied ``text`` (a lyric, a track name, an option's value) fit to quote in a
    one-line message: on one line, and cut to ``limit`` characters with an ellipsis."""
    text = one_line(text)
    return text if len(text) <= limit else text[: limit - 1] + "…"
