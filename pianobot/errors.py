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
