"""What the fingering planner (:mod:`pianobot.pianist.fingering`) gives for a piece: its fingering, the
wrist's path and the places the hand cannot play in time."""

from __future__ import annotations

from dataclasses import dataclass, field

from pianobot.music.piece import Piece

SAID_PROBLEMS = 3
"""How many of a plan's places too fast for the hand are said one by one (then how many more)."""


@dataclass(frozen=True)
class FingeringPlan:
    """The planner's result: the fingered piece, the wrist's path and what could not be met."""

    piece: Piece
    wrist: tuple[float, ...]
    """Wrist position (m along the rail) for each chord, in time order."""
    travel: float
    """Total wrist travel (m)."""
    moves: int
    """Number of wrist moves."""
    problems: tuple[str, ...] = field(default=())
    """Notes this hand cannot play as written at this tempo, and why."""

    def said(self, most: int = SAID_PROBLEMS) -> list[str]:
        """:attr:`problems` as lines to say: the first ``most``, then how many more there are."""
        if len(self.problems) <= most:
            return list(self.problems)
        rest = len(self.problems) - most
        return [
            *self.problems[:most],
            f"and {rest} more place(s) faster than this hand can (slow down with load.tempo)",
        ]
