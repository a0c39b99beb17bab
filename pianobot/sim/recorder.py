"""What the simulated keyboard sounded, as a Piece: note-on/off events and touch -> notes; and the
sustain pedal, as a Pedal."""

from __future__ import annotations

from dataclasses import replace

from pianobot.music.pedal import Pedal
from pianobot.music.piece import Note, Piece
from pianobot.sim.keyboard import KeyEvent


class NoteRecorder:
    """Collects key events (and the finger that touched each struck key) into notes, and the pedal's changes."""

    def __init__(self) -> None:
        self._open: dict[int, tuple[float, int, int | None, str | None]] = {}
        self._notes: list[Note] = []
        self._pedal: list[tuple[float, bool]] = []
        self.last_time = 0.0

    def press(self, time: float, down: bool) -> None:
        """The sustain pedal is ``down`` (or up) from world time ``time`` on."""
        if down != (bool(self._pedal) and self._pedal[-1][1]):
            self._pedal.append((time, down))

    def pedal(self, end: float, start: float = 0.0) -> Pedal:
        """The pedal so far, times shifted by ``-start`` (cut at 0); still down, it comes up at ``end``."""
        return Pedal.from_changes(self._pedal, end=end).shift(-start)

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
