"""The project's exceptions and warnings.

Every problem a user can cause (a bad file, a note the keyboard lacks, a finger the hand
lacks) is raised as a :class:`PianobotError` whose message is one line saying what is wrong
and how to fix it. The CLI prints that line and exits with code 2; nothing else should ever
reach the user as a traceback.
"""


class PianobotError(Exception):
    """A problem with the user's input, worded as one line: what is wrong and how to fix it."""


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
