"""From a file on disk to a validated piece: the one entry point the CLI and training use."""

from __future__ import annotations

import bisect
import warnings
from dataclasses import dataclass, replace
from pathlib import Path

from pianobot.errors import PianobotError, PianobotWarning, SettingError, quote
from pianobot.music import midi_io, pig
from pianobot.music.instrument import PIANO, HandSpec, beyond_piano, octave_shifts
from pianobot.music.metrics import DEFAULT_ONSET_TOLERANCE
from pianobot.music.pedal import Pedal
from pianobot.music.piece import HANDS, Note, Piece, pitch_name


@dataclass(frozen=True)
class LoadOptions:
    """How to read a piece."""

    track: str | None = None
    """One track by index or name; None merges all tracks."""
    tempo: float | None = None
    """Re-time the piece at this constant tempo in bpm (the paper plays at 60); None keeps the file's tempo map."""
    transpose: int = 0
    """Shift every note by this many semitones."""
    fingering: Path | None = None
    """A PIG fingering file for the notes; None looks for the sidecar ``<name>_fingering.txt``."""
    hand: str | None = None
    """'right' or 'left': play that hand's part of a two-hand piece (tracks named for it, else
    the notes above or below ``split``); chords are thinned to what the robot hand can hold, and
    where a piece is fingered for playing, :func:`pianobot.pianist.reduce.load_for_hand` reduces
    the part further to what the hand can reach in time."""
    split: int = 60
    """With ``hand`` and no track named for it: the lowest pitch of the right hand's part (60 = C4)."""
    quantize: str | None = None
    """Move onsets and offsets to this grid, e.g. '1/16' (for recordings of human players)."""
    refinger: bool = False
    """Replace the file's fingering with the planner's (see pianobot.pianist.fingering)."""
    pedal: bool = True
    """Read the file's sustain pedal (control change 64, down at 64 or more), which ``play`` plays
    as written and ``score`` scores; False: the pedal stays up."""


def hand_tracks(tracks: list[midi_io.TrackInfo], hand: str) -> list[int]:
    """Tracks with notes whose names say they hold ``hand``'s part ('Right Hand', 'RH', 'Treble'...)."""
    return [t.index for t in tracks if t.notes and midi_io.track_hand(t.name) == hand]


CHORD_SPREAD = 0.06
"""Notes a human player starts within this many seconds of each other form one chord."""


LEGATO_OVERLAP = 0.1
"""A note that lasts at most this many seconds into the next chord ends where that chord starts."""


def gather_chords(piece: Piece, spread: float = CHORD_SPREAD) -> list[tuple[Note, ...]]:
    """Notes grouped into chords as :meth:`Piece.chords` does, but with a human player's spread:
    each note joins the chord that started at most ``spread`` seconds before it. The chord's notes
    take its onset: its first note's, or, where a later one started more than the metrics' default
    onset tolerance (50 ms) after it, the earliest onset within that tolerance of every note (one
    exists while ``spread`` is at most twice the tolerance; the default's 60 ms moves a chord at
    most 10 ms), so a chord played at its onset plays each of its notes on time. (Chords so moved
    may start less than ``spread`` apart: gathered again, they may join.)"""
    groups: list[list[Note]] = []
    for note in piece.notes:
        if groups and note.onset - groups[-1][0].onset <= spread and note.pitch not in {n.pitch for n in groups[-1]}:
            groups[-1].append(note)
        else:
            groups.append([note])
    chords = []
    for group in groups:
        start = max(group[0].onset, max(n.onset for n in group) - DEFAULT_ONSET_TOLERANCE)
        chords.append(
            tuple(
                n if n.onset == start else replace(n, onset=start, offset=max(n.offset, start + 0.001)) for n in group
            )
        )
    return chords


def thin_chords(piece: Piece, fingers: int) -> tuple[Piece, int]:
    """A human player's part made playable for a hand of ``fingers`` fingers: notes started
    within :data:`CHORD_SPREAD` of each other form one chord; a note overlapping the next chord by
    at most :data:`LEGATO_OVERLAP` ends where it starts; a chord keeps its highest ``fingers``
    notes; and notes still held from before end where a new chord needs their fingers.
    Returns the piece and how many notes were dropped."""
    out: list[Note] = []
    dropped = 0
    for chord in gather_chords(piece):
        onset = chord[0].onset
        kept = sorted(chord, key=lambda n: n.pitch)[-fingers:]
        dropped += len(chord) - len(kept)
        for i, n in enumerate(out):  # a legato overlap is a player's habit, not a voice: it ends here
            if onset < n.offset <= onset + LEGATO_OVERLAP:
                out[i] = replace(n, offset=onset)
        sounding = sorted(
            (i for i, n in enumerate(out) if n.offset > onset), key=lambda i: (out[i].onset, out[i].pitch)
        )
        for i in sounding[: max(0, len(sounding) + len(kept) - fingers)]:
            out[i] = replace(out[i], offset=onset)
        out.extend(kept)
    return Piece(tuple(out), bpm=piece.bpm), dropped


def _read_midi(path: Path | midi_io.MidiSource, options: LoadOptions, bpm: float | None = None) -> Piece:
    grid = midi_io.parse_grid(options.quantize) if options.quantize else None
    if options.hand is None:
        return midi_io.read_midi(path, track=options.track, bpm=bpm, grid=grid)
    if options.hand not in HANDS:
        raise SettingError(f"load.hand {quote(options.hand)}: choose right or left", "load.hand")
    if options.track is not None:
        raise SettingError("give load.track or load.hand, not both", "load.track", "load.hand")
    return _read_hand(path, options, bpm, grid).with_hands(None)  # one hand's part, read as before hands


def _read_hand(path: Path | midi_io.MidiSource, options: LoadOptions, bpm: float | None, grid: float | None) -> Piece:
    """``options.hand``'s part: the tracks named for it, else the higher or lower of two tracks, else
    the notes on its side of ``options.split``."""
    tracks = midi_io.describe_tracks(path)
    named = hand_tracks(tracks, options.hand)
    if named:
        return midi_io.read_midi(path, tracks=named, bpm=bpm, grid=grid)
    parts = [t for t in tracks if t.notes]
    if len(parts) == 2:  # two unnamed parts: the higher one is the right hand's
        high, low = sorted(parts, key=lambda t: t.low + t.high, reverse=True)
        chosen = high if options.hand == "right" else low
        warnings.warn(
            PianobotWarning(
                f"no track is named for the {options.hand} hand: took track {chosen.index} (the {'higher' if chosen is high else 'lower'} of two) as the {options.hand} hand"
            )
        )
        return midi_io.read_midi(path, tracks=[chosen.index], bpm=bpm, grid=grid)
    warnings.warn(
        PianobotWarning(
            f"no track is named for the {options.hand} hand: took the notes {'at or above' if options.hand == 'right' else 'below'} {pitch_name(options.split)} (load.split)"
        )
    )
    piece = midi_io.read_midi(path, bpm=bpm, grid=grid)
    if options.hand == "right":
        notes = [n for n in piece.notes if n.pitch >= options.split]
    else:
        notes = [n for n in piece.notes if n.pitch < options.split]
    if not notes:
        raise SettingError(
            f"{midi_io.source_path(path).name} has no notes {'at or above' if options.hand == 'right' else 'below'} "
            f"{pitch_name(options.split)} for the {options.hand} hand: move the split with load.split",
            "load.split",
        )
    return Piece(tuple(notes), bpm=piece.bpm)


def load_piece(path: str | Path | midi_io.MidiSource, options: LoadOptions = LoadOptions()) -> Piece:
    """Read a .mid file (or a PIG .txt file) with its fingering, then re-time and transpose it
    (``path`` may be a file already read: :func:`~pianobot.music.midi_io.open_midi`); notes beyond the
    piano's keys where no octave shift fits the piece are played octaves in (:func:`fold_into_piano`)."""
    return fold_into_piano(_read_piece(path, options), midi_io.source_path(path).name)


def _read_piece(path: str | Path | midi_io.MidiSource, options: LoadOptions) -> Piece:
    """:func:`load_piece`'s reading, every note at the pitch the file (and ``options.transpose``) gives it."""
    source, path = path, midi_io.source_path(path)
    if path.suffix.lower() == ".txt":
        if options.tempo is not None:
            raise SettingError(
                "load.tempo needs a MIDI file: a PIG file has times in seconds but no beats", "load.tempo"
            )
        if options.fingering is not None:
            raise SettingError("a PIG file carries its own fingering: drop load.fingering", "load.fingering")
        if options.quantize is not None:
            raise SettingError(
                "load.quantize needs a MIDI file: a PIG file's onsets are already in seconds", "load.quantize"
            )
        if options.track is not None:
            raise SettingError(
                "load.track needs a MIDI file: a PIG file's channels are its hands (play one with load.hand)",
                "load.track",
            )
        if options.hand is not None and options.hand not in HANDS:
            raise SettingError(f"load.hand {quote(options.hand)}: choose right or left", "load.hand")
        piece = pig.read_pig(path, hand=options.hand or "right")  # (its channel: 0 right, 1 left)
    elif options.tempo is not None and options.fingering is None and not pig.sidecar_for(path).exists():
        piece = _read_midi(source, options, bpm=options.tempo)  # the file's tempo map is never needed
    else:
        piece = _read_midi(source, options)
        sidecar = options.fingering or pig.sidecar_for(path)
        if options.fingering is not None or sidecar.exists():
            embedded = any(n.finger is not None for n in piece.notes)
            piece = pig.apply_fingering(piece, sidecar)
            if embedded:
                warnings.warn(
                    PianobotWarning(f"fingering from {sidecar.name} replaces the fingering inside {path.name}")
                )
        if options.tempo is not None:
            # re-read with the new tempo, then carry the fingering over note by note
            fingers = [n.finger for n in piece.notes]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", PianobotWarning)  # already reported by the first read
                retimed = _read_midi(source, options, bpm=options.tempo)
            piece = retimed.with_fingers(fingers)
    if not piece.notes:
        raise PianobotError(f"{path} has no notes: give a MIDI file with at least one note")
    return piece.transpose(options.transpose)


def fold_into_piano(piece: Piece, name: str) -> Piece:
    """``piece`` with each note beyond the piano's 88 keys played the fewest octaves in, as a pianist
    plays an arrangement's stray notes, said in one warning (naming the first three); one whose key
    sounds while it would is dropped. Only where no shift of the piece (or of the one hand's part read)
    by whole octaves brings every note on: where one does, the notes stay as written, and the reading
    refuses them naming that shift (:func:`_check_keys`, or the hand's check of its part). Notes on one
    key must not overlap, as the readers leave them (:func:`~pianobot.music.piece.resolve_overlaps`)."""
    outside = [n for n in piece.notes if n.pitch not in PIANO]
    if not outside or octave_shifts(piece):
        return piece
    kept = [n for n in piece.notes if n.pitch in PIANO]
    # each key's notes as (onset, offset), sorted: they never overlap (the reading ends a note where its key
    # starts again), so a folded note overlaps one only if the last to start before it ends is still sounding
    keys: dict[int, list[tuple[float, float]]] = {}
    for note in kept:
        keys.setdefault(note.pitch, []).append((note.onset, note.offset))
    for spans in keys.values():
        spans.sort()
    moved, dropped = [], 0
    for note in outside:
        pitch = note.pitch
        while pitch < PIANO.lowest:
            pitch += 12
        while pitch > PIANO.highest:
            pitch -= 12
        spans = keys.setdefault(pitch, [])
        before = bisect.bisect_left(spans, (note.offset,)) - 1
        if before >= 0 and spans[before][1] > note.onset:
            dropped += 1
            continue
        bisect.insort(spans, (note.onset, note.offset))
        kept.append(folded := replace(note, pitch=pitch))
        moved.append(f"{note.describe()} as {folded.name}")
    played = (
        f"played the fewest octaves in ({', '.join(moved[:3])}{' ...' if len(moved) > 3 else ''})"
        if moved
        else "none played"
    )
    warnings.warn(
        PianobotWarning(
            f"{name}: {len(outside)} note(s) lie beyond the piano's 88 keys {PIANO.describe()}, and no octave shift "
            f"of the piece brings them all on: {played}"
            + (f", {dropped} dropped where a note of that key sounds while it would" if dropped else "")
        )
    )
    return Piece(tuple(kept), bpm=piece.bpm)


def load_part(path: str | Path | midi_io.MidiSource, options: LoadOptions, hand: HandSpec) -> Piece:
    """:func:`load_piece`; with ``options.hand``, also thin chords to what ``hand`` can hold
    (:func:`pianobot.pianist.reduce.load_for_hand` goes on to what it can reach in time); without
    it, a note lasting at most :data:`LEGATO_OVERLAP` into a later onset ends there (a player's
    legato, which a hand cannot play as two keys down at once where they lie apart)."""
    piece = load_piece(path, options)
    return end_legato(piece) if options.hand is None else thin_hand(piece, options.hand, hand)


def end_legato(piece: Piece) -> Piece:
    """``piece`` with every note that lasts at most :data:`LEGATO_OVERLAP` past a later onset
    (and begins before it) ending at that onset; the piece itself where none does."""
    onsets = sorted({n.onset for n in piece.notes})
    notes, changed = [], False
    for note in piece.notes:
        later = [t for t in onsets if note.onset < t < note.offset <= t + LEGATO_OVERLAP + 1e-9]
        if later:
            note, changed = replace(note, offset=later[0]), True
        notes.append(note)
    return Piece(tuple(notes), bpm=piece.bpm) if changed else piece


def thin_hand(piece: Piece, name: str, hand: HandSpec, kept: str = "highest") -> Piece:
    """:func:`thin_chords` to ``hand``'s fingers, said in one warning for the ``name`` hand's part
    (whose kept notes are its ``kept`` ones: 'lowest' for a left hand's part thinned in its mirror image)."""
    piece, dropped = thin_chords(piece, len(hand.fingers))
    if dropped:
        warnings.warn(
            PianobotWarning(
                f"the {name} hand's part has chords of more than {len(hand.fingers)} notes: "
                f"kept the {kept} {len(hand.fingers)}, dropped {dropped} note(s)"
            )
        )
    return piece


def load_hands(path: str | Path | midi_io.MidiSource, options: LoadOptions = LoadOptions()) -> Piece:
    """A two-hand piece (a .mid file, or a PIG .txt file with both hands' notes), each note with
    the hand its track's name says, else the channel of its note in the PIG fingering sidecar (or
    the PIG file's), None where nothing says (the fingering planner then gives it one:
    :func:`pianobot.pianist.assign.load_two_hands`).

    Bad input, in one line: notes beyond the piano's 88 keys that an octave shift of the piece fits are
    refused (:class:`SettingError` naming the setting that helps; where none fits they are played
    octaves in: :func:`fold_into_piano`). Said in one warning each: hands that cross (the robot's two
    hands share one rail) are not taken from the file, and the planner gives every note a hand;
    three or more tracks of notes that are not all named for hands are read as one part whose
    notes the planner gives to the hands."""
    source, path = path, midi_io.source_path(path)
    if options.hand is not None:
        raise SettingError(
            "load.hand takes one hand's part; a two-hand reading takes both: drop load.hand", "load.hand"
        )
    if path.suffix.lower() == ".txt":
        if options.tempo is not None or options.fingering is not None or options.quantize is not None:
            raise SettingError(
                "a PIG file has times in seconds and its own fingering: drop load.tempo, load.fingering and load.quantize",
                "load.tempo",
                "load.fingering",
                "load.quantize",
            )
        if options.track is not None:
            raise SettingError("load.track needs a MIDI file: a PIG file's channels are its hands", "load.track")
        piece = pig.read_pig(path, hand=None).transpose(options.transpose)
    else:
        piece = _read_piece(source, options)
        sidecar = options.fingering or pig.sidecar_for(path)
        if any(n.hand is None for n in piece.notes) and (options.fingering is not None or sidecar.exists()):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", PianobotWarning)  # said by the first read
                # the notes as the sidecar lists them (the file's times, no shift), in the same order
                written = pig.apply_fingering(_read_midi(source, replace(options, tempo=None)), sidecar, hands=True)
            piece = piece.with_hands([n.hand or w.hand for n, w in zip(piece.notes, written.notes)])
        tracks = [t for t in midi_io.describe_tracks(source) if t.notes]
        unnamed = [t for t in tracks if midi_io.track_hand(t.name) is None]
        if options.track is None and len(tracks) >= 3 and unnamed and any(n.hand is None for n in piece.notes):
            warnings.warn(
                PianobotWarning(
                    f"{path.name} has {len(tracks)} tracks of notes, {len(unnamed)} not named for a hand: "
                    "their notes are given to the hands by the fingering planner (to play some of them alone, name those "
                    "with load.track)"
                )
            )
        others = [t for t in tracks if not t.keyboard]  # (by program alone: a chorale's "Bass" is a voice)
        keys = [t for t in tracks if t.keyboard]
        if options.track is None and others and keys:
            said = ", ".join(
                f"{t.index}{f' {quote(t.name, 30)!r}' if t.name else ''} (General MIDI {t.instrument})" for t in others
            )
            warnings.warn(
                PianobotWarning(
                    f"{path.name}: track(s) {said} play no keyboard instrument, and their notes are played by the hands "
                    f"too; to play the keyboard's alone, name its tracks with load.track "
                    f"{','.join(str(t.index) for t in keys)}"
                )
            )
    piece = fold_into_piano(piece, path.name)
    _check_keys(piece, path, options.transpose)
    crossing = _crossing(piece)
    if crossing:
        one = "" if path.suffix.lower() == ".txt" else " (play one hand with load.hand right or load.hand left)"
        warnings.warn(
            PianobotWarning(
                f"{path.name}: the hands cross at {crossing}, and the robot's two hands cannot cross: "
                f"the fingering planner gives every note a hand instead{one}"
            )
        )
        piece = piece.with_hands(None)
    return piece


def _check_keys(piece: Piece, path: Path, transposed: int = 0) -> None:
    """Refuse notes beyond the piano's 88 keys, suggesting the octave shift that fits them, if any."""
    if said := beyond_piano(piece, transposed):
        raise SettingError(f"{path.name} has {said}", "load.transpose")


def _crossing(piece: Piece) -> str:
    """Where a left-hand note first sounds above (or on) a right-hand note at the same time, in
    words ('1.000 s: the left hand's G5 sounds at or above the right hand's D5'), else ''. Notes
    let go within :data:`LEGATO_OVERLAP` of the other's onset do not count (a player's legato)."""
    sounding: list[Note] = []
    for note in piece.notes:
        if note.hand is None:
            continue
        sounding = [n for n in sounding if n.offset > note.onset + LEGATO_OVERLAP]
        other = [n for n in sounding if n.hand != note.hand]
        crossed = [n for n in other if (n.pitch >= note.pitch if note.hand == "right" else n.pitch <= note.pitch)]
        if crossed:
            left, right = (crossed[0], note) if note.hand == "right" else (note, crossed[0])
            return f"{note.onset:.3f} s: the left hand's {left.name} sounds at or above the right hand's {right.name}"
        sounding.append(note)
    return ""


def load_pedal(source: Path | midi_io.MidiSource, options: LoadOptions) -> Pedal:
    """The file's sustain pedal, re-timed as ``options.tempo`` re-times its notes (none for a PIG
    file, or with ``options.pedal`` off)."""
    if not options.pedal or not isinstance(source, midi_io.MidiSource):
        return Pedal()
    return midi_io.read_pedal(source, bpm=options.tempo)
