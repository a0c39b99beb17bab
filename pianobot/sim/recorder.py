"""What the simulated keyboard sounded, as a Piece: note-on/off events and touch -> notes."""

from __future__ import annotations

from dataclasses import replace

from pianobot.music.piece import Note, Piece
from pianobot.sim.keyboard import KeyEvent


class NoteRecorder:
    """Collects key events (and the finger that touched each struck key) into notes."""

    def __init__(self) -> None:
        self._open: dict[int, tuple[float, int, int | None, str | None]] = {}
        self._notes: list[Note] = []
        self.last_time = 0.0

    def add(self, events: list[KeyEvent], fingers: dict[int, int], hands: dict[int, str] | None = None) -> None:
        """``fingers`` (and ``hands``: 'right', 'left'): pitch -> the finger (hand) that struck the key."""
        for event in events:
            self.last_time = max(self.last_time, event.time)
            if event.on:
                self._open[event.pitch] = (
                    event.time,
                    event.velocity,
                    fingers.get(event.pitch),
                    (hands or {}).get(event.pitch),
                )
            elif event.pitch in self._open:
                self._close(event.pitch, event.time)

    def _close(self, pitch: int, time: float) -> None:
        onset, velocity, finger, hand = self._open.pop(pitch)
        offset = max(time, onset + 0.001)
        self._notes.append(Note(onset, pitch, offset, velocity, finger, hand))

    def piece(self, end: float, start: float = 0.0, bpm: float = 120.0) -> Piece:
        """The notes played so far, times shifted by ``-start``; notes still held end at ``end``."""
        notes = list(self._notes)
        for pitch, (onset, velocity, finger, hand) in self._open.items():
            notes.append(Note(onset, pitch, max(end, onset + 0.001), velocity, finger, hand))
        shifted = []
        for n in notes:
            if n.onset - start < 0:  # struck during the lead-in: keep it, at time 0
                shifted.append(replace(n, onset=0.0, offset=max(n.offset - start, 0.001)))
            else:
                shifted.append(replace(n, onset=n.onset - start, offset=n.offset - start))
        return Piece(tuple(shifted), bpm=bpm)
