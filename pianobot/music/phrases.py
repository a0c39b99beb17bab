"""Splitting a piece into short phrases, each learnable by one policy.

A phrase holds at most ``max_notes`` notes and never splits a chord. Among the splits with
the fewest phrases, breaks go where the music breathes: at rests and after long notes. Each
phrase has a content hash that ignores where in the piece it stands, so identical phrases
(a repeated bar) share one trained policy.
"""

from __future__ import annotations

import hashlib
import json
import statistics
from dataclasses import dataclass

from pianobot.errors import SettingError
from pianobot.music.piece import Note, Piece

DEFAULT_MAX_NOTES = 6
"""Phrase length that the paper's six-note task shows a policy can learn."""


@dataclass(frozen=True)
class Phrase:
    """A run of consecutive notes of a piece, with absolute times."""

    index: int
    notes: tuple[Note, ...]

    @property
    def start(self) -> float:
        return self.notes[0].onset

    @property
    def end(self) -> float:
        return max(n.offset for n in self.notes)

    @property
    def hash(self) -> str:
        return phrase_hash(self.notes)

    def piece(self, lead_in: float = 0.0) -> Piece:
        """The phrase on its own, its first note at ``lead_in`` seconds."""
        return Piece(self.notes).shift(lead_in - self.start)


def phrase_hash(notes: tuple[Note, ...]) -> str:
    """A stable 16-hex-digit digest of the notes' content relative to the first onset."""
    start = min(n.onset for n in notes)
    content = sorted(
        (n.pitch, round((n.onset - start) * 1000), round((n.offset - start) * 1000), n.velocity, n.finger or 0)
        for n in notes
    )
    return hashlib.sha256(json.dumps(content).encode()).hexdigest()[:16]


def _break_penalties(chords: list[tuple[Note, ...]]) -> list[float]:
    """Penalty in (0, 1] for a phrase break just before chord j (index 0 unused): low at rests and long notes."""
    iois = [b[0].onset - a[0].onset for a, b in zip(chords, chords[1:])]
    typical = statistics.median(iois) if iois else 1.0
    penalties = [0.0]
    latest_end = max(n.offset for n in chords[0])
    for j in range(1, len(chords)):
        rest = max(0.0, chords[j][0].onset - latest_end)
        strength = (iois[j - 1] + 2.0 * rest) / max(typical, 1e-3)
        penalties.append(1.0 / (1.0 + strength))
        latest_end = max(latest_end, max(n.offset for n in chords[j]))
    return penalties


def split_phrases(piece: Piece, max_notes: int = DEFAULT_MAX_NOTES) -> list[Phrase]:
    """Split ``piece`` into phrases of at most ``max_notes`` notes (dynamic programming).

    Cost of a split: 1 per phrase, plus each break's penalty, plus 0.1 (size / max_notes)^2 per
    phrase so that, other things equal, phrases come out even.
    """
    if max_notes < 1:
        raise SettingError(f"phrases.max_notes {max_notes}: a phrase needs at least one note", "phrases.max_notes")
    chords = piece.chords()
    if not chords:
        return []
    for chord in chords:
        if len(chord) > max_notes:
            raise SettingError(
                f"the chord at {chord[0].onset:.3f} s has {len(chord)} notes, more than phrases.max_notes {max_notes}",
                "phrases.max_notes",
            )
    penalty = _break_penalties(chords)
    sizes = [len(c) for c in chords]
    best = [0.0] + [float("inf")] * len(chords)  # best[j]: cost of splitting chords[:j]
    cut = [0] * (len(chords) + 1)
    for j in range(1, len(chords) + 1):
        size = 0
        for i in range(j - 1, -1, -1):  # last phrase = chords[i:j]
            size += sizes[i]
            if size > max_notes:
                break
            cost = best[i] + 1.0 + penalty[i] + 0.1 * (size / max_notes) ** 2
            if cost < best[j] - 1e-12:
                best[j], cut[j] = cost, i
    bounds, j = [], len(chords)
    while j > 0:
        bounds.append((cut[j], j))
        j = cut[j]
    bounds.reverse()
    return [Phrase(index=k, notes=tuple(n for chord in chords[i:j] for n in chord)) for k, (i, j) in enumerate(bounds)]
