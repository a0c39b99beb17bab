"""MusicXML scores (.musicxml, .xml, .mxl) in, as a :class:`~pianobot.music.midi_file.MidiSource`.

A score is read with music21 (the ``musicxml`` extra, imported only here and only when a score is
read or written) and rendered into an in-memory type 1 MIDI file, so that every later step
(:mod:`pianobot.music.midi_io`) reads it as it reads a .mid file:

- a tempo track with every tempo mark (``<metronome>``, ``<sound tempo>``), 120 bpm where none;
- one track per staff of a pitched part: a two-staff part's staff 1 is named "Right Hand", its
  staff 2 "Left Hand"; a one-staff part keeps its part's name (a hand where the name says one, as
  for a MIDI track); other staves are named for their part and staff;
- notes with their ties merged; grace notes and unpitched (percussion) notes left out, each said in
  one line; tuplets at their true length; repeat signs and endings written out as a pianist plays
  them (music21's ``expandRepeats``), said in one line; a score that jumps (da capo, dal segno), or
  whose repeats music21 cannot follow, played once as written, said in one line;
- each ``<fingering>`` 1-5 as the note's finger, written as lyric events in midi_io's convention
  (a chord's notes each their own); a mark such as "1-2" or "3_1" counts as its first finger, one
  that is no finger is dropped, each kind said in one line;
- the sustain pedal (``<pedal>`` start, change, stop) as control change 64 (127 down, 0 up) on the
  right hand's track (the first track where there is none), at the marks' own times.

music21 gives a chord's fingering marks to its notes in pitch order and loses which note a mark
was written on; so before music21 reads the XML, each unfingered note of a chord that has marks is
given a placeholder mark ("-", no finger), and a note's alternate marks are removed (its first
mark is the one that strikes). The pedal's times are read from the XML itself
(:mod:`pianobot.music.musicxml_tree`), since music21 keeps only the notes a pedal mark spans.
"""

from __future__ import annotations

import warnings
from collections import defaultdict
from fractions import Fraction
from pathlib import Path

import mido

from pianobot.errors import PianobotError, PianobotWarning, quote
from pianobot.music.finger_text import finger_text
from pianobot.music.midi_file import MidiSource
from pianobot.music.midi_io import TRACK_NAMES
from pianobot.music.musicxml_tree import Score, read_tree

SUFFIXES = (".musicxml", ".xml", ".mxl")
"""The file names read (and written by ``pianobot finger -o``) as MusicXML."""
EXTRA = "pip install 'pianobot[musicxml]'"
"""How to install the library MusicXML needs."""
TICKS_PER_BEAT = 960
"""Ticks per quarter note of the rendering: triplets and quintuplets of any note fall on a tick."""
VELOCITY = 80
"""The loudness of every note of a score (its dynamics are not read)."""


def is_musicxml(path: str | Path) -> bool:
    """Whether ``path`` names a MusicXML file (by its suffix)."""
    return Path(path).suffix.lower() in SUFFIXES


def music21():
    """The music21 package, or a one-line error that names the extra to install."""
    try:
        import music21 as m21
    except ImportError:
        raise PianobotError(f"reading and writing MusicXML needs music21, which is not installed: {EXTRA}") from None
    return m21


def open_musicxml(path: str | Path) -> MidiSource:
    """The score at ``path`` read and rendered as a type 1 MIDI file (see the module's text), kept
    with the score's own path so that messages name the user's file; refused in one line where it
    is no readable score."""
    path = Path(path)
    m21 = music21()
    tree = read_tree(path)
    try:
        importer = m21.musicxml.xmlToM21.MusicXMLImporter()
        importer.xmlRootToScore(tree.root, importer.stream)
        score = importer.stream
        score.toSoundingPitch(inPlace=True)  # a clarinet's or horn's part is written transposed
    except Exception as e:  # music21 raises many types on odd scores
        reason = quote(str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__)
        raise PianobotError(f"{path} is not a score pianobot can read ({reason}): re-export it as MusicXML") from None
    return MidiSource(path, _render(*_expand_repeats(m21, score, tree), tree, path))


def _expand_repeats(m21, score, tree: Score) -> tuple[object, dict[str, list] | None]:
    """``score`` with its repeat signs and endings written out, as a pianist plays them (music21's
    ``expandRepeats``), and each part's measure numbers as written (by which the pedal's marks are
    placed again); ``score`` itself and None where it has none, where it jumps (da capo, dal segno:
    not taken), where its measure numbers repeat, or where music21 cannot expand it."""
    words = any(True for _ in score.recurse().getElementsByClass(m21.repeat.RepeatExpression))
    if not tree.repeats or tree.jumps or words:  # (a jump written as words, "D.C. al Fine", music21 would take)
        return score, None
    numbers = {
        name: [m.number for m in staves[0].getElementsByClass("Measure")]
        for name, staves in _score_parts(m21, score, tree)
    }
    if any(len(set(n)) != len(n) for n in numbers.values()):
        return score, None
    try:
        return score.expandRepeats(), numbers
    except Exception:  # music21 raises many types on repeats it cannot follow
        return score, None


def _render(score, numbers: dict[str, list] | None, tree: Score, path: Path) -> mido.MidiFile:
    """The MIDI file of a music21 ``score`` (its pedal marks from ``tree``; ``numbers``: each part's
    measure numbers as written, where ``score`` has its repeats written out)."""
    m21 = music21()
    said: dict[str, int] = defaultdict(int)
    tracks: list[mido.MidiTrack] = []
    parts = _score_parts(m21, score, tree)
    for name, part in _staves(parts):
        unpitched = said["unpitched"]
        events = _part_events(m21, part, said)
        if events:
            tracks.append(_track(name, events))
        elif said["unpitched"] > unpitched:
            said["unpitched"], said["percussion"] = unpitched, said["percussion"] + 1
    if not tracks:
        what = " (only percussion)" if said["percussion"] else ""
        raise PianobotError(f"{path} holds no pitched notes{what}: give a score with notes for the piano")
    tempo = _tempo_track(score, said)
    said["expanded"] = numbers is not None
    _say(path, said, tree)
    midi = mido.MidiFile(type=1, ticks_per_beat=TICKS_PER_BEAT)
    midi.tracks.append(tempo)
    pedal_track = next((t for t in tracks if t.name == TRACK_NAMES["right"]), tracks[0])
    _add_pedal(pedal_track, _pedal_times(parts, tree, numbers))
    midi.tracks.extend(tracks)
    return midi


def _score_parts(m21, score, tree: Score) -> list[tuple[str, list]]:
    """(the XML part's id, its staves as music21 parts) for each part of the score, in order. A part
    of several staves is music21's run of PartStaffs of one id ('P1-Staff1', 'P1-Staff2'); any other
    music21 part is a part of its own, whatever its name (music21 may give a part its name as its id,
    so four parts named "Voice" share one)."""
    groups: list[list] = []
    last = None
    for part in score.parts:
        staff = str(part.id).rsplit("-Staff", 1)[0] if isinstance(part, m21.stream.PartStaff) else None
        if staff is not None and staff == last:
            groups[-1].append(part)
        else:
            groups.append([part])
        last = staff
    ids = [element.get("id", "") for element in tree.root.iter("part")]
    if len(ids) != len(groups):  # (not expected: then music21's ids)
        ids = [str(group[0].id).rsplit("-Staff", 1)[0] for group in groups]
    return list(zip(ids, groups))


def _staves(parts: list[tuple[str, list]]) -> list[tuple[str, object]]:
    """(track name, music21 part) for each staff of the score's ``parts`` (:func:`_score_parts`): see
    the module's text."""
    named = []
    number = 0
    for _, staves in parts:
        for index, part in enumerate(staves):
            number += 1
            title = (part.partName or "").strip() or f"Part {number}"
            if len(staves) == 1:
                named.append((title, part))
            elif index < 2:
                named.append((TRACK_NAMES["right" if index == 0 else "left"], part))
            else:
                named.append((f"{title} staff {index + 1}", part))
    return named


def _unpitched(m21, element) -> bool:
    return isinstance(element, (m21.note.Unpitched, m21.percussion.PercussionChord))


def _part_events(m21, part, said: dict[str, int]) -> list[tuple[int, int, int, int | None]]:
    """(on tick, off tick, pitch, finger) of every pitched note of ``part``, ties merged (grace,
    unpitched and doubled notes left out, counted in ``said``)."""
    written = []  # (on, off, pitch, finger, tie type)
    for element in part.flatten().notes:
        if _unpitched(m21, element):
            said["unpitched"] += 1
        elif element.duration.isGrace:
            said["grace"] += len(element.pitches)
        else:
            on, off = _tick(element.offset), _tick(element.offset + element.quarterLength)
            ties = (
                [n.tie for n in sorted(element.notes, key=lambda n: n.pitch.midi)] if element.isChord else [element.tie]
            )
            for (pitch, finger), tie in zip(_fingered(m21, element, said), ties):
                if off > on:
                    written.append((on, off, pitch, finger, tie.type if tie is not None else None))
    return _merge_ties(written, said)


def _merge_ties(written: list, said: dict[str, int]) -> list[tuple[int, int, int, int | None]]:
    """Notes tied to the next note of their pitch starting where they end made one note (with the
    first one's finger); two notes on one key at once (two voices) made one, the longer."""
    notes: dict[tuple[int, int], list] = {}
    tied: dict[int, list] = {}  # pitch: the note its next note of that pitch is tied to
    for on, off, pitch, finger, tie in sorted(written, key=lambda w: (w[0], w[2])):
        held = tied.pop(pitch, None)
        if held is not None and held[0] == on and tie in ("stop", "continue"):
            held[0] = off
            if tie == "continue":
                tied[pitch] = held
            continue
        if (on, pitch) in notes:
            said["doubled"] += 1
            notes[(on, pitch)][0] = max(off, notes[(on, pitch)][0])
            continue
        notes[(on, pitch)] = [off, finger]
        if tie in ("start", "continue"):
            tied[pitch] = notes[(on, pitch)]
    return [(on, off, pitch, finger) for (on, pitch), (off, finger) in sorted(notes.items())]


def _tick(offset) -> int:
    return round(Fraction(offset) * TICKS_PER_BEAT)


def _fingered(m21, element, said: dict[str, int]) -> list[tuple[int, int | None]]:
    """(MIDI pitch, finger) of each note of a note or chord: a chord's marks go to its notes in pitch order."""
    marks = [a for a in element.articulations if isinstance(a, m21.articulations.Fingering)]
    if isinstance(element, m21.chord.Chord):
        pitches = sorted(p.midi for p in element.pitches)
    else:
        pitches = [element.pitch.midi]
    if len(marks) != len(pitches):
        if marks:
            said["ambiguous"] += 1
        marks = [None] * len(pitches)
    return [(pitch, _finger(mark, said)) for pitch, mark in zip(pitches, marks)]


def _finger(mark, said: dict[str, int]) -> int | None:
    """A fingering mark's finger: '3' is 3; '3-1', '3_1' or '3/1' its first finger; else none."""
    if mark is None:
        return None
    text = str(mark.fingerNumber if mark.fingerNumber is not None else "").strip()
    if text in ("", "-"):
        return None
    head = text[0]
    if head in "12345" and (len(text) == 1 or not text[1].isdigit()):
        if len(text) > 1:
            said["substitution"] += 1
        return int(head)
    said["not a finger"] += 1
    said.setdefault("example", text)  # type: ignore[arg-type]
    return None


def _track(name: str, events: list[tuple[int, int, int, int | None]]) -> mido.MidiTrack:
    """A track named ``name`` with ``events``' notes, and their fingers as lyric events at each onset."""
    timed: list[tuple[int, int, mido.Message]] = []  # (tick, order, message): offs, lyrics, ons
    by_onset: dict[int, list[tuple[int, int | None]]] = defaultdict(list)
    for on, off, pitch, finger in events:
        by_onset[on].append((pitch, finger))
        timed.append((on, 2, mido.Message("note_on", note=pitch, velocity=VELOCITY, channel=0)))
        timed.append((off, 0, mido.Message("note_off", note=pitch, velocity=0, channel=0)))
    for on, starting in by_onset.items():
        fingers = [finger for _, finger in sorted(starting)]
        if any(f is not None for f in fingers):
            timed.append((on, 1, mido.MetaMessage("lyrics", text=finger_text(fingers))))
    track = mido.MidiTrack([mido.MetaMessage("track_name", name=name)])
    return _timed(track, timed)


def _timed(track: mido.MidiTrack, timed: list[tuple[int, int, object]]) -> mido.MidiTrack:
    """``track`` with ``timed`` (tick, order at that tick, message) appended in time order, as delta times."""
    now = 0
    for tick, _, message in sorted(timed, key=lambda item: (item[0], item[1])):
        track.append(message.copy(time=tick - now))
        now = tick
    return track


TEMPO_RANGE = (10.0, 1000.0)
"""The tempos (quarter notes a minute) a mark is read at: one outside is read as the nearest of these
(a "rit." written as a tempo of 1 is beyond what a MIDI tempo holds), said; as ``--tempo`` allows."""


def _tempo_track(score, said: dict[str, int]) -> mido.MidiTrack:
    """The tempo marks of ``score`` as set_tempo events (120 bpm where it has none; a mark that
    each staff repeats, once; one outside :data:`TEMPO_RANGE` at the nearest end, counted in ``said``)."""
    timed, now, beyond = [], None, set()
    low, high = TEMPO_RANGE
    for start, _, mark in score.metronomeMarkBoundaries():
        bpm = mark.getQuarterBPM()
        if bpm and bpm > 0 and not low <= bpm <= high:
            beyond.add((start, bpm))  # (a mark each staff repeats is one)
            said.setdefault("tempo example", f"{bpm:g}")
            bpm = min(max(bpm, low), high)
        if bpm and bpm > 0 and (tempo := mido.bpm2tempo(bpm)) != now:
            timed.append((_tick(start), 0, mido.MetaMessage("set_tempo", tempo=tempo)))
            now = tempo
    said["tempo"] = len(beyond)
    return _timed(mido.MidiTrack([mido.MetaMessage("track_name", name="Tempo")]), timed)


def _pedal_times(
    parts: list[tuple[str, list]], tree: Score, numbers: dict[str, list] | None = None
) -> list[tuple[Fraction, bool]]:
    """The score's sustain pedal changes as (quarter notes from the start, down), placed by music21's
    measures (``parts``: :func:`_score_parts`; ``numbers``: each part's measure numbers as written,
    where the parts have their repeats written out: a mark is placed in every measure of its number)."""
    times = []
    for name, staves in parts:
        measures = staves[0].getElementsByClass("Measure")
        for mark in (m for m in tree.pedal if m.part == name):
            if numbers is None:
                places = [measures[mark.measure].offset] if mark.measure < len(measures) else []
            else:
                written = numbers.get(name, [])
                number = written[mark.measure] if mark.measure < len(written) else None
                places = [m.offset for m in measures if number is not None and m.number == number]
            times += [(Fraction(offset) + mark.beats, mark.down) for offset in places]
    return sorted(times)


def _add_pedal(track: mido.MidiTrack, pedal: list[tuple[Fraction, bool]]) -> None:
    """Sustain pedal changes ((quarter notes, down)) added to ``track`` as control change 64."""
    if not pedal:
        return
    timed, now = [], 0
    for message in track:
        now += message.time
        order = 0 if message.type == "note_off" else 3 if message.type == "note_on" else 2
        timed.append((now, order, message))
    for when, down in pedal:  # (at one tick: up before down, both after the notes' ends, before their starts)
        value = 127 if down else 0
        timed.append((_tick(when), 1, mido.Message("control_change", control=64, value=value, channel=0)))
    first = timed[0] if timed and timed[0][2].type == "track_name" else None
    track.clear()
    if first:
        track.append(first[2].copy(time=0))
        timed = timed[1:]
    _timed(track, timed)


def _say(path: Path, said: dict[str, int], tree: Score) -> None:
    """One warning line for each kind of thing the reading left out or changed."""
    lines = {
        "grace": "left out {n} grace note(s) (ornaments without a time of their own)",
        "unpitched": "left out {n} unpitched (percussion) note(s): they are no piano keys",
        "percussion": "left out {n} percussion part(s): they are no piano keys",
        "doubled": "{n} note(s) written twice on one key at once (two voices) played once",
        "substitution": "{n} fingering mark(s) naming two fingers (a substitution) read as their first finger",
        "not a finger": "dropped {n} fingering mark(s) that name no finger 1-5 (such as '{example}')",
        "ambiguous": "dropped the fingering of {n} chord(s) whose marks cannot be matched to their notes",
        "tempo": "read {n} tempo mark(s) outside 10-1000 quarter notes a minute (such as {tempo}) as the nearest of those",
    }
    for kind, line in lines.items():
        if said.get(kind):
            text = line.format(
                n=said[kind], example=quote(str(said.get("example", "")), 20), tempo=said.get("tempo example")
            )
            warnings.warn(PianobotWarning(f"{path.name}: {text}"))
    if tree.second_marks:
        warnings.warn(
            PianobotWarning(
                f"{path.name}: {tree.second_marks} note(s) with two fingering marks read by their first (a "
                "substitution's striking finger)"
            )
        )
    if tree.cues:
        warnings.warn(
            PianobotWarning(f"{path.name}: left out {tree.cues} cue note(s) (another part's notes, not played)")
        )
    if tree.repeats and said.get("expanded"):
        warnings.warn(
            PianobotWarning(f"{path.name}: its repeats are played as a pianist plays them, each section again")
        )
    elif tree.repeats:
        warnings.warn(
            PianobotWarning(
                f"{path.name}: its repeats (or its da capo, dal segno) are not expanded: it is played once, as written"
            )
        )
