"""The sustain pedal: when it is down, and what a listener hears because of it.

A :class:`Pedal` is the times the sustain pedal is held down, as sorted, separate spans of
seconds (whole milliseconds, as note times are). A MIDI file says the same with control change
64: a value of :data:`DOWN_AT` or more presses the pedal, a smaller one lets it up. That rounds a
half-pedal (a value between 1 and 126) to the nearer of up and down, as the MIDI specification's
on/off reading of controller 64 does.

While the pedal is down the piano's dampers stay off the strings: a note whose key rises goes
on sounding until the pedal comes up, or until its own key is struck again.
:meth:`Pedal.sounding` gives those sounding durations; the keys' own notes (a
:class:`~pianobot.music.piece.Piece`) say when each key was down.
"""

from __future__ import annotations

import bisect
import math
import numbers
from dataclasses import dataclass, replace
from typing import Iterable

import numpy as np

from pianobot.errors import PianobotError
from pianobot.music.piece import MAX_SECONDS, Piece, _ms

DOWN_AT = 64
"""A control change 64 value at or above this presses the pedal; below it lets the pedal up."""
RING = 10.0
"""Seconds after a piece's last note ends that its pedal is still read: a piano's note has died
away by then, so the pedal holds nothing, and a stray pedal event far after the music (an hour on)
neither lengthens the simulation nor refuses the file."""


@dataclass(frozen=True)
class Pedal:
    """The spans (down, up) in seconds during which the sustain pedal is held; sorted, each at
    least 1 ms long, apart or touching (a pedal change: up and down again at once, the dampers
    falling for a moment). ``Pedal()`` is a piece played without the pedal."""

    spans: tuple[tuple[float, float], ...] = ()

    def __post_init__(self) -> None:
        spans = []
        for span in self.spans:
            if len(span) != 2 or not all(isinstance(t, numbers.Real) and math.isfinite(t) for t in span):
                raise PianobotError(f"pedal span {span!r}: give (down, up) as finite seconds")
            down, up = _ms(span[0]), _ms(span[1])
            if not 0 <= down < up <= MAX_SECONDS:
                raise PianobotError(
                    f"the pedal goes down at {down:.3f} s and up at {up:.3f} s: it must go down at 0 s or later, "
                    f"come up after it went down, and within {MAX_SECONDS / 60:.0f} minutes"
                )
            if spans and down < spans[-1][1]:
                raise PianobotError(
                    f"the pedal goes down at {down:.3f} s while it is still down from {spans[-1][0]:.3f} s: "
                    "pedal spans must not overlap"
                )
            spans.append((down, up))
        object.__setattr__(self, "spans", tuple(spans))
        object.__setattr__(self, "_presses", [down for down, _ in spans])  # (for bisect)

    @staticmethod
    def from_changes(changes: Iterable[tuple[float, bool]], end: float | None = None) -> "Pedal":
        """The pedal of a sequence of (time, down) changes in time order (a press while it is down, or
        a release while it is up, changes nothing); a pedal still down after the last change comes up
        at ``end`` (left out where there is no ``end``, or it comes no later). Times before 0 count as 0."""
        spans: list[tuple[float, float]] = []
        pressed: float | None = None
        for time, down in changes:
            time = max(0.0, _ms(time))
            if down and pressed is None:
                pressed = time
            elif not down and pressed is not None:
                if time > pressed:
                    spans.append((pressed, time))
                pressed = None
        if pressed is not None and end is not None and _ms(end) > pressed:
            spans.append((pressed, _ms(end)))
        return Pedal(tuple(spans))

    def __bool__(self) -> bool:
        return bool(self.spans)

    def __len__(self) -> int:
        """How many times the pedal is pressed."""
        return len(self.spans)

    def down_at(self, time: float) -> bool:
        """Whether the pedal is down at ``time`` (down from its press, up from its release)."""
        return self.release_after(time) is not None

    def release_after(self, time: float) -> float | None:
        """When the pedal comes up, if it is down at ``time``; else None."""
        i = bisect.bisect_right(self._presses, time) - 1  # (the last press at or before it)
        return self.spans[i][1] if i >= 0 and time < self.spans[i][1] else None

    def changes(self) -> list[tuple[float, bool]]:
        """(time, down) for every press and release, in time order."""
        return [change for down, up in self.spans for change in ((down, True), (up, False))]

    def steps(self, count: int, hz: float, start: float = 0.0) -> np.ndarray:
        """Whether the pedal is down at each of ``count`` control steps ``start + i / hz`` (bool array).
        A pedal up between two steps (a change, up and down at once as a score marks it) is up for
        the step it comes down in, so that the dampers fall for a moment, as a pianist's foot lets them."""
        times = start + np.arange(count) / hz
        if not self.spans:
            return np.zeros(count, bool)
        presses, releases = np.array(self.spans).T
        last = np.searchsorted(presses, times + 1e-9, side="right") - 1  # (each step's last press)
        down = (last >= 0) & (times < releases[np.maximum(last, 0)] - 1e-9)
        firsts = np.searchsorted(times, presses - 1e-9)  # (each span's first step)
        for i in range(1, len(self.spans)):  # up between two steps: up for the step it comes down in
            first = firsts[i]
            if np.searchsorted(times, releases[i - 1] - 1e-9) == first and first < count and down[first]:
                down[first] = False
        return down

    # -- transforms (all return new pedals) ----------------------------------------------
    def shift(self, seconds: float) -> "Pedal":
        """Every time moved by ``seconds``; what falls before 0 is cut off there."""
        moved = [(max(0.0, d + seconds), u + seconds) for d, u in self.spans if u + seconds > 0.001]
        return Pedal(tuple((d, u) for d, u in moved if _ms(u) > _ms(d)))

    def retime(self, factor: float) -> "Pedal":
        """Every time multiplied by ``factor`` (as :meth:`Piece.retime`)."""
        if factor <= 0:
            raise PianobotError(f"time factor {factor} must be positive")
        return Pedal(tuple((d * factor, u * factor) for d, u in self.spans))

    def until(self, end: float) -> "Pedal":
        """The pedal up to ``end`` seconds (a span still down there comes up at ``end``)."""
        return Pedal(tuple((d, min(u, end)) for d, u in self.spans if d < end and _ms(min(u, end)) > _ms(d)))

    def sounding(self, piece: Piece) -> Piece:
        """``piece`` as a listener hears it with this pedal: a note whose key rises while the pedal is
        down sounds on until the pedal comes up, or until its pitch is struck again, whichever is first."""
        if not self.spans:
            return piece
        strikes: dict[int, list[float]] = {}
        for note in piece.notes:  # (in onset order)
            strikes.setdefault(note.pitch, []).append(note.onset)
        out = []
        for note in piece.notes:
            release = self.release_after(note.offset)
            if release is None:
                out.append(note)
                continue
            onsets = strikes[note.pitch]
            later = bisect.bisect_right(onsets, note.onset)  # (its pitch's next strike, if any)
            end = min(release, onsets[later]) if later < len(onsets) else release
            out.append(replace(note, offset=max(note.offset, end)))
        return Piece(tuple(out), bpm=piece.bpm)
