"""Standard MIDI files in and out, with fingering carried in lyric or text meta events.

Fingering (:mod:`pianobot.music.finger_text`, docs/fingering.md): at the tick where notes start,
a lyric (or text) meta event in the same track holds one finger number per note starting there,
lowest pitch first (``"3"``, ``"2 4"``). Texts that are not finger lists (ordinary lyrics) are
ignored, those written like fingering otherwise in a fingered track (``"(2)"``) said in one warning, and so is every
number in a track whose texts hold one that is no finger 1-5 (a continuo's figured bass: "6", "7").

Hands: in a type 1 file, a track whose name says it holds a hand's part ('Right Hand', 'RH',
'Treble', 'Left Hand', 'Bass'...; :func:`track_hand`) gives its notes that hand; other tracks'
notes have none, and so have a type 0 file's (its one track's name is the piece's title). A piece
whose notes have hands is written as a type 1 file, one track per hand, named "Right Hand" and
"Left Hand".

Parsing uses mido; times come from the file's own tempo map unless ``bpm`` re-times the piece
so that one beat lasts 60/bpm seconds.
"""

from __future__ import annotations

import bisect
import warnings
from collections import defaultdict
from pathlib import Path

import mido

from pianobot.errors import PianobotError, PianobotWarning, SettingError, quote
from pianobot.music.finger_text import finger_text, is_fingering, looks_like_fingering, parse_finger_text
from pianobot.music.midi_file import (  # noqa: F401 (by their old address too)
    MAX_FILE_BYTES,
    MidiSource,
    open_midi,
    opened,
    source_path,
)
from pianobot.music.midi_tracks import (  # noqa: F401 (by their old address too)
    HAND_NAMES,
    PERCUSSION,
    SUSTAIN,
    TRACK_NAMES,
    UNASSIGNED_TRACK,
    TrackInfo,
    _text,
    list_tracks,
    track_hand,
)
from pianobot.music.pedal import DOWN_AT, RING, Pedal
from pianobot.music.piece import MAX_SECONDS, Note, Piece, pitch_name, resolve_overlaps


def _absolute(track: mido.MidiTrack) -> list[tuple[int, mido.Message]]:
    """(absolute tick, message) pairs; at equal ticks note-offs come before note-ons."""
    tick, out = 0, []
    for msg in track:
        tick += msg.time
        out.append((tick, msg))

    def order(item):
        t, m = item
        is_on = m.type == "note_on" and m.velocity > 0
        return (t, 1 if is_on else 0)

    return sorted(out, key=order)


def _tempo_changes(midi: mido.MidiFile) -> list[tuple[int, int]]:
    """(tick, tempo) of every set_tempo event, in time order; events at one tick in the file's order,
    so that the last of them holds from there."""
    found = [(t, m.tempo) for track in midi.tracks for t, m in _absolute(track) if m.type == "set_tempo"]
    return sorted(found, key=lambda change: change[0])


class _TempoMap:
    """Ticks to seconds through a file's set_tempo events (default 120 bpm).

    A tempo of 0 (no time per beat) is refused: every note after it would last no time.
    """

    def __init__(self, midi: mido.MidiFile, path: Path):
        changes = _tempo_changes(midi)
        self.tpb = midi.ticks_per_beat
        self.points: list[tuple[int, float, int]] = [(0, 0.0, 500_000)]  # (tick, seconds at tick, tempo from there)
        for change_tick, new_tempo in changes:
            if new_tempo <= 0:
                raise SettingError(
                    f"{path} sets a tempo of 0 (no time per beat) at beat {change_tick / self.tpb:.0f}: "
                    "re-export it, or give the tempo with load.tempo BPM",
                    "load.tempo",
                )
            tick, seconds, tempo = self.points[-1]
            self.points.append(
                (change_tick, seconds + mido.tick2second(change_tick - tick, self.tpb, tempo), new_tempo)
            )
        self.ticks = [point[0] for point in self.points]
        at_start = [tempo for tick, tempo in changes if tick == 0]
        self.first_tempo = at_start[-1] if at_start else 500_000  # (of several at once, the last holds)

    def seconds(self, tick: int) -> float:
        tick0, seconds, tempo = self.points[bisect.bisect_right(self.ticks, tick) - 1]
        return seconds + mido.tick2second(tick - tick0, self.tpb, tempo)


def parse_grid(text: str) -> float:
    """A quantisation grid like '1/16' (a sixteenth note) as a fraction of a whole note."""
    try:
        top, bottom = (int(part) for part in text.strip().split("/"))
        if top < 1 or bottom < 1:
            raise ValueError
    except ValueError:
        raise SettingError(
            f"load.quantize {quote(text)}: give a note value like 1/8, 1/16 or 1/12 (triplet eighths)", "load.quantize"
        ) from None
    return top / bottom


def selected_tracks(path: str | Path | MidiSource, track: str | int | None) -> list[int]:
    """The tracks ``track`` names in the file at ``path`` (as :func:`read_midi` reads them), by index."""
    path, midi = opened(path)
    return _select_tracks(midi, track, path)


def _select_tracks(midi: mido.MidiFile, track: str | int | None, path: Path) -> list[int]:
    """The tracks ``track`` names: an index or a name (every track of that name), or several of
    these separated by commas ('2,3', 'Piano'); None: all."""
    infos = list_tracks(midi)
    if track is None:
        return [t.index for t in infos]
    with_notes = ", ".join(f"{t.index} '{quote(t.name, 30)}'" if t.name else str(t.index) for t in infos if t.notes)
    with_notes = quote(with_notes, 200)
    whole = str(track).strip()
    named = [t.index for t in infos if whole and t.name.strip().lower() == whole.lower()]
    if named:  # (a name may hold a comma: the whole value first)
        return _with_notes(named, infos, whole, with_notes, path)
    chosen: list[int] = []
    for key in (part.strip() for part in whole.split(",")):
        if key.isdigit() and int(key) < len(infos):
            hits = [int(key)]
        else:
            hits = [t.index for t in infos if key and t.name.strip().lower() == key.lower()]
        if not hits:
            raise PianobotError(
                f"{path} has no track '{quote(key)}'"
                + (f" (in '{quote(whole)}')" if key != whole else "")
                + f": choose one of the tracks with notes: {with_notes or 'none'} (several: separate them with commas)"
            )
        chosen += [index for index in hits if index not in chosen]
    return _with_notes(sorted(chosen), infos, whole, with_notes, path)


def _with_notes(chosen: list[int], infos: list[TrackInfo], whole: str, with_notes: str, path: Path) -> list[int]:
    """``chosen``, where one of those tracks has notes; else one line naming the tracks that have."""
    if not any(infos[i].notes for i in chosen):
        raise PianobotError(
            f"{path} has no notes in track {quote(whole)}: choose one of the tracks with notes: {with_notes or 'none'}"
        )
    return chosen


def _track_notes(
    track: mido.MidiTrack, index: int, seconds, path: Path
) -> tuple[list[tuple[int, int, int, int]], dict[int, list[int | None]]]:
    """Notes as (on tick, off tick, pitch, velocity) and finger lists by tick, for one track.

    Messages are read in the file's order. A key struck again while it still sounds (a player's
    legato on a repeated note) opens a second note; a note-off ends the earliest one that began
    before it (first in, first out), so a repeated key's note-off and note-on at one tick end one
    note and begin the next in either order, and :func:`resolve_overlaps` ends a first note where
    a second starts. A note-off that finds only a note begun at its own tick ends a note of no
    length (some programs write grace notes and chord symbols so): it is left out, said in one
    warning. A track whose texts hold a number that is no finger (a figured bass) has no fingering.
    """
    open_notes: dict[tuple[int, int], list[tuple[int, int]]] = defaultdict(list)
    notes: list[tuple[int, int, int, int]] = []
    fingering: dict[int, list[int | None]] = defaultdict(list)
    figures: list[str] = []  # texts with numbers that are no fingers
    unread: list[tuple[int, str]] = []  # texts written like fingering that are none
    empty: list[tuple[int, int]] = []  # (tick, pitch) of notes of no length
    ended: dict[tuple[int, int], int] = {}  # (channel, pitch): the tick its last note ended
    tick = 0
    for msg in track:
        tick += msg.time
        if msg.type in ("lyrics", "text"):
            fingers = parse_finger_text(msg.text)
            if fingers is not None and is_fingering(fingers):
                fingering[tick].extend(fingers)
            elif fingers is not None:
                figures.append(msg.text)
            elif looks_like_fingering(msg.text):
                unread.append((tick, msg.text))
        elif msg.type in ("note_on", "note_off") and msg.channel == PERCUSSION:
            continue  # (drums: read_midi says how many it left out)
        elif msg.type == "note_on" and msg.velocity > 0:
            open_notes[(msg.channel, msg.note)].append((tick, msg.velocity))
        elif msg.type in ("note_off", "note_on"):
            sounding = open_notes.get((msg.channel, msg.note), [])
            earlier = next((i for i, (on, _) in enumerate(sounding) if on < tick), None)
            if earlier is not None:
                on, vel = sounding.pop(earlier)
                notes.append((on, tick, msg.note, vel))
                ended[(msg.channel, msg.note)] = tick
            elif sounding and ended.get((msg.channel, msg.note)) != tick:  # (else a second note-off: no note's)
                sounding.pop(0)
                empty.append((tick, msg.note))
    end = tick
    if empty:
        tick, pitch = empty[0]
        warnings.warn(
            PianobotWarning(
                f"track {index}: left out {len(empty)} note(s) of no length, their note-on and note-off at one tick "
                f"(the first: {pitch_name(pitch)} at {seconds(tick):.3f} s; grace notes or chord symbols, as some "
                "programs write them)"
            )
        )
    if unread and fingering:  # (a track without fingering: its texts are lyrics, verse numbers)
        tick, text = unread[0]
        warnings.warn(
            PianobotWarning(
                f"track {index}: {len(unread)} text(s) written like fingering are not read as fingers (the first: "
                f"'{quote(text)}' at {seconds(tick):.3f} s): write one finger per note, lowest first ('2', '1 3 5'; a "
                "substitution '3_1')"
            )
        )
    if figures and fingering:
        warnings.warn(
            PianobotWarning(
                f"track {index}: its texts hold '{quote(figures[0])}', a number that is no finger 1-5 (a figured "
                "bass?), so none of its numbers is read as fingering"
            )
        )
    if figures:
        fingering.clear()
    for (_, pitch), sounding in open_notes.items():
        for on, vel in sounding:
            warnings.warn(PianobotWarning(f"track {index}: {pitch_name(pitch)} never ends; it ends with the track"))
            if end > on:
                notes.append((on, end, pitch, vel))
    return notes, fingering


def read_midi(
    path: str | Path | MidiSource,
    *,
    track: str | int | None = None,
    bpm: float | None = None,
    grid: float | None = None,
    tracks: list[int] | None = None,
) -> Piece:
    """Read a .mid file into a :class:`Piece`, with fingering from lyric/text events.

    ``track`` picks one track by index or name (``tracks`` several by index; default: all
    tracks merged). ``bpm`` re-times the piece at a constant tempo, ignoring the file's tempo
    map. ``grid`` (a fraction of a whole note, e.g. 1/16) moves every onset and offset to the
    nearest grid line, in the file's beats, for recordings of human players; a note lasts at
    least one grid step. A note lasts while its key is down; the sustain pedal is :func:`read_pedal`'s.
    """
    path, midi = opened(path)
    seconds, nominal = _clock(midi, path, bpm)

    if grid is not None:
        step = max(1, round(midi.ticks_per_beat * 4 * grid))
        snap = lambda tick: round(tick / step) * step  # noqa: E731
    notes: list[Note] = []
    instant = 0  # notes dropped for lasting under 1 ms
    names = [info.name if midi.type == 1 else "" for info in list_tracks(midi)]  # type 0: a title
    chosen = tracks if tracks is not None else _select_tracks(midi, track, path)
    drums = sum(
        1
        for index in chosen
        for m in midi.tracks[index]
        if m.type == "note_on" and m.velocity > 0 and m.channel == PERCUSSION
    )
    if drums:
        warnings.warn(
            PianobotWarning(
                f"{path.name}: left out {drums} drum note(s) on MIDI channel 10 (General MIDI's percussion): "
                "they are no piano keys"
            )
        )
    for index, raw, fingering in _parts(midi, chosen, seconds, path):
        hand = track_hand(names[index]) if index is not None else None
        index = 0 if index is None else index  # (several tracks read as one: messages say track 0, as before)
        if grid is not None:
            raw = [(snap(on), max(snap(off), snap(on) + step), pitch, vel) for on, off, pitch, vel in raw]
            fingering = {snap(tick): fingers for tick, fingers in fingering.items()}
        last = max(raw, key=lambda item: item[1], default=None)
        if last is not None and seconds(last[1]) > MAX_SECONDS:
            raise SettingError(
                f"{path} track {index} lasts {seconds(last[1]) / 60:,.0f} minutes ({pitch_name(last[2])} ends at "
                f"{seconds(last[1]):,.3f} s): pianobot reads at most {MAX_SECONDS / 60:.0f} minutes of music; "
                "cut the file, or choose a part with load.track or a faster load.tempo",
                "load.track",
                "load.tempo",
            )
        by_tick: dict[int, list[tuple[int, int, int, int]]] = defaultdict(list)
        for item in raw:
            by_tick[item[0]].append(item)
        for tick, fingers in fingering.items():
            starting = sorted(by_tick.get(tick, []), key=lambda item: item[2])
            if not starting:
                warnings.warn(
                    PianobotWarning(
                        f"track {index}: fingering '{quote(finger_text(fingers))}' at {seconds(tick):.3f} s has no "
                        "note starting there; ignored"
                    )
                )
            elif len(fingers) != len(starting):  # (a figured bass's "5 3" over one note, say)
                warnings.warn(
                    PianobotWarning(
                        f"{path.name} track {index} at {seconds(tick):.3f} s: fingering '{quote(finger_text(fingers))}' "
                        f"gives {len(fingers)} finger(s) for {len(starting)} note(s) starting there "
                        f"({', '.join(pitch_name(s[2]) for s in starting)}), so none of the track's numbers is read as "
                        "fingering (a figured bass?); to finger it, give one finger per note, lowest pitch first"
                    )
                )
                fingering = {}
                break
        for on, off, pitch, vel in raw:
            starting = sorted(by_tick[on], key=lambda item: item[2])
            fingers = fingering.get(on)
            finger = fingers[starting.index((on, off, pitch, vel))] if fingers else None
            onset, offset = seconds(on), seconds(off)
            if round(offset, 3) <= round(onset, 3):
                warnings.warn(PianobotWarning(f"{pitch_name(pitch)} at {onset:.3f} s lasts under 1 ms; dropped"))
                instant += 1
                continue
            notes.append(Note(onset=onset, pitch=pitch, offset=offset, velocity=vel, finger=finger, hand=hand))
    if instant and not notes:
        raise SettingError(
            f"every note of {path} lasts under 1 ms at the file's tempo: give the tempo to play it at with load.tempo",
            "load.tempo",
        )
    if drums and not notes:
        raise PianobotError(
            f"{path} holds only drum notes (MIDI channel 10, General MIDI's percussion), no piano keys: "
            "give a file with piano notes"
        )
    return Piece(tuple(resolve_overlaps(notes)), bpm=nominal)


def _clock(midi: mido.MidiFile, path: Path, bpm: float | None):
    """(ticks -> seconds, the nominal tempo): through the file's tempo map, or at ``bpm`` throughout."""
    if bpm is not None:
        if not 10 <= bpm <= 1000:
            raise SettingError(f"load.tempo {bpm}: choose a tempo between 10 and 1000 bpm", "load.tempo")
        tpb = midi.ticks_per_beat
        return (lambda tick: tick / tpb * 60.0 / bpm), bpm
    tempo_map = _TempoMap(midi, path)
    return tempo_map.seconds, max(10.0, min(1000.0, mido.tempo2bpm(tempo_map.first_tempo)))


def read_pedal(path: str | Path | MidiSource, *, bpm: float | None = None) -> Pedal:
    """The sustain pedal of a .mid file: control change 64 on any track and channel (a value of
    :data:`~pianobot.music.pedal.DOWN_AT` or more is down), timed as :func:`read_midi` times notes
    (``bpm`` as there), up to :data:`~pianobot.music.pedal.RING` seconds after the last note ends
    (what it holds has died away by then); a pedal still down there, or at the file's last event,
    comes up there."""
    path, midi = opened(path)
    seconds, _ = _clock(midi, path, bpm)
    changes, last_event, last_note = [], 0, 0
    for track in midi.tracks:
        for tick, msg in _absolute(track):
            last_event = max(last_event, tick)
            if msg.type in ("note_on", "note_off"):
                last_note = max(last_note, tick)
            elif msg.type == "control_change" and msg.control == SUSTAIN:
                changes.append((tick, msg.value >= DOWN_AT))
    changes.sort(key=lambda change: change[0])  # (one tick's events in their track's order)
    end = min(seconds(last_event), seconds(last_note) + RING, MAX_SECONDS)
    return Pedal.from_changes(((seconds(t), down) for t, down in changes if seconds(t) < end), end=end)


def _parts(midi: mido.MidiFile, chosen: list[int], seconds, path: Path) -> list[tuple[int | None, list, dict]]:
    """(track index, notes, fingering by tick) of the chosen tracks.

    Fingering normally sits in the notes' own track. Some writers move every lyric to the first
    track, away from the notes (pretty_midi does): when lyric-only tracks hold fingering and no
    chosen track has its own, the chosen tracks' notes are read as one part with that fingering
    (its index None where it merges several tracks: its notes have no hand)."""
    parts = [(index, *_track_notes(midi.tracks[index], index, seconds, path)) for index in chosen]
    if any(fingering for _, raw, fingering in parts if raw):
        return parts
    lyrics: dict[int, list[int]] = {}
    read = {index: (raw, fingering) for index, raw, fingering in parts}
    for index, track in enumerate(midi.tracks):
        if index in read:  # (read above, and said)
            raw, fingering = read[index]
            said = []
        else:
            with warnings.catch_warnings(record=True) as said:
                warnings.simplefilter("always")
                raw, fingering = _track_notes(track, index, seconds, path)
        if not raw:  # (of a track of notes not chosen, nothing is said)
            lyrics.update(fingering)
            for warning in said:
                warnings.warn(warning.message)
    if not lyrics:
        return parts
    noted = [(index, raw) for index, raw, _ in parts if raw]
    merged = [item for _, raw in noted for item in raw]
    return [(noted[0][0] if len(noted) == 1 else None, merged, lyrics)] if noted else parts


def tempi(path: str | Path | MidiSource) -> list[float]:
    """The tempos of a MIDI file in beats per minute, in the order they take effect (120 until its
    first set_tempo, where that is after the start), each change to another tempo once."""
    _, midi = opened(path)
    changes = _tempo_changes(midi)
    changes = [
        c for i, c in enumerate(changes) if i + 1 == len(changes) or changes[i + 1][0] != c[0]
    ]  # (the last at a tick)
    found = [] if changes and changes[0][0] == 0 else [120.0]
    for _, tempo in changes:
        bpm = round(mido.tempo2bpm(tempo), 3) if tempo > 0 else 0.0
        if not found or found[-1] != bpm:
            found.append(bpm)
    return found


def describe_tracks(path: str | Path | MidiSource) -> list[TrackInfo]:
    """Tracks of a MIDI file, for `pianobot inspect`."""
    return list_tracks(opened(path)[1])


def __getattr__(name: str):
    """The writers (:func:`~pianobot.music.midi_out.write_midi`, ``midi_bytes``) by their old address."""
    if name in ("write_midi", "midi_bytes"):
        from pianobot.music import midi_out

        return getattr(midi_out, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
