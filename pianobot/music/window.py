"""Where one hand's part is played by a simulated right hand: the part mirrored about D when it
is the left hand's (:meth:`~pianobot.music.piece.Piece.mirror`: the mirror image of a left hand
is a right hand with the same finger numbers), then moved by whole octaves onto the keyboard its
player knows. Both keep every key's colour and every distance between keys, so the simulated
hand plays the part as written, on other keys.
"""

from __future__ import annotations

from dataclasses import dataclass

from pianobot.music.instrument import PIANO, KeyboardSpec, keyboard_for
from pianobot.music.piece import Piece, mirror_pitch

OCTAVE = 12


@dataclass(frozen=True)
class Window:
    """Where a hand's part is played: ``hand``'s notes, mirrored for the left hand, moved by
    ``octaves`` whole octaves onto ``keyboard``."""

    hand: str
    keyboard: KeyboardSpec
    octaves: int

    def inward(self, pitch: int) -> int:
        """A written pitch of this hand -> the key the simulated (right) hand plays."""
        return (mirror_pitch(pitch) if self.hand == "left" else pitch) + OCTAVE * self.octaves

    def outward(self, pitch: int) -> int:
        """A key the simulated hand played -> the written pitch it stands for."""
        moved = pitch - OCTAVE * self.octaves
        return mirror_pitch(moved) if self.hand == "left" else moved

    def written_keys(self) -> KeyboardSpec:
        """The keys of the piece, at their written pitches, that this window's keys stand for: the
        left hand's are the mirror image of its player's (the player's C4-B5 are the left hand's
        F2-E4), and a window moved by octaves stands for keys as many octaves the other way."""
        ends = (self.outward(self.keyboard.lowest), self.outward(self.keyboard.highest))
        return KeyboardSpec(min(ends), self.keyboard.count)

    def moved(self) -> str:
        """Where its player's keys lie from the keys its window stands for (:meth:`written_keys`), in the
        piece's own terms ('' where the part was not moved): "its player's keys 1 octave up". The part
        sounds where it is written either way (what the player plays is read back at the written
        pitches); a left hand's part moved up in its mirror image has its player's keys an octave down."""
        if not self.octaves:
            return ""
        up = (self.octaves > 0) != (self.hand == "left")
        count = abs(self.octaves)
        return f"its player's keys {count} octave{'s' * (count > 1)} {'up' if up else 'down'}"


def window_for(part: Piece, hand: str, keyboard: KeyboardSpec | None, grow: bool = False) -> Window:
    """The window for ``hand``'s ``part``: on ``keyboard`` (a policy's) the octave shift that keeps
    the most notes on it (the smallest shift on a tie); with ``keyboard`` None, the part's own range
    rounded out to octaves (:func:`~pianobot.music.instrument.keyboard_for`: every note kept).
    ``grow``: a part that does not fit on ``keyboard`` gets its own range instead, for a player
    that plays any keyboard of at least its own keys
    (:func:`~pianobot.agent.general.plays_keyboard`)."""
    piano = KeyboardSpec(mirror_pitch(PIANO.highest), PIANO.count) if hand == "left" else PIANO  # (as the hand sees it)
    own = Window(hand, keyboard_for(part.mirror() if hand == "left" else part, piano), 0)
    if keyboard is None:
        return own
    plain = Window(hand, KeyboardSpec(), 0)
    pitches = [plain.inward(n.pitch) for n in part.notes]
    spans = range(-10, 11)
    kept = {k: sum(p + OCTAVE * k in keyboard for p in pitches) for k in spans}
    best = max(spans, key=lambda k: (kept[k], -abs(k)))
    if grow and kept[best] < len(pitches):
        return own
    return Window(hand, keyboard, best)
