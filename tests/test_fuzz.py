"""Property-based tests: whatever bytes, MIDI files, PIG files or file names come in, the
readers answer with a Piece or with a PianobotError, and every command either works or exits 2
with exactly one 'error:' line, in bounded time; never another exception."""

import io
import tempfile
import time
import warnings
from pathlib import Path

import hypothesis
import mido
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from pianobot.cli.app import app
from pianobot.errors import PianobotError
from pianobot.music.midi_io import midi_bytes, read_midi
from pianobot.music.piece import MAX_SECONDS, Note, Piece
from pianobot.music.pig import HEADER, apply_fingering, read_pig_rows

FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


def read_bytes(tmp_path, data: bytes):
    path = tmp_path / "fuzz.mid"
    path.write_bytes(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return read_midi(path)
        except PianobotError as e:
            assert "\n" not in str(e)
            return None


@FUZZ
@given(data=st.binary(max_size=400))
def test_random_bytes_never_crash(tmp_path, data):
    read_bytes(tmp_path, data)


@FUZZ
@given(tail=st.binary(max_size=300), fmt=st.integers(0, 3), ntracks=st.integers(0, 3), tpb=st.integers(0, 0xFFFF))
def test_random_bytes_after_a_valid_header_never_crash(tmp_path, tail, fmt, ntracks, tpb):
    header = (
        b"MThd" + (6).to_bytes(4, "big") + fmt.to_bytes(2, "big") + ntracks.to_bytes(2, "big") + tpb.to_bytes(2, "big")
    )
    read_bytes(tmp_path, header + b"MTrk" + len(tail).to_bytes(4, "big") + tail)


@FUZZ
@given(data=st.data())
def test_corrupting_a_valid_file_never_crashes(tmp_path, data):
    good = tmp_path / "seed.mid"
    from conftest import midi_file, off, on

    midi_file(good, [("m", [(0, on(60)), (480, off(60)), (480, on(64)), (960, off(64))])])
    raw = bytearray(good.read_bytes())
    for _ in range(data.draw(st.integers(1, 5))):
        raw[data.draw(st.integers(0, len(raw) - 1))] = data.draw(st.integers(0, 255))
    cut = data.draw(st.integers(1, len(raw)))
    read_bytes(tmp_path, bytes(raw[:cut]))


event = st.tuples(
    st.integers(0, 2000),  # delta ticks
    st.sampled_from(["on", "off", "tempo", "lyric"]),
    st.integers(0, 127),  # pitch / tempo scale
    st.integers(0, 127),  # velocity
    st.integers(0, 15),  # channel
)


@FUZZ
@given(
    tracks=st.lists(st.lists(event, max_size=30), min_size=1, max_size=3),
    tpb=st.integers(1, 960),
    texts=st.lists(st.sampled_from(["1", "2 3", "la", "9", "3_1", "-", "1,2,3,4,5"]), min_size=1),
)
def test_random_valid_midi_files_read_or_fail_clearly(tmp_path, tracks, tpb, texts):
    midi = mido.MidiFile(type=1, ticks_per_beat=tpb)
    for events in tracks:
        track = mido.MidiTrack()
        for i, (delta, kind, a, b, channel) in enumerate(events):
            if kind == "on":
                track.append(mido.Message("note_on", note=a, velocity=b, channel=channel, time=delta))
            elif kind == "off":
                track.append(mido.Message("note_off", note=a, velocity=b, channel=channel, time=delta))
            elif kind == "tempo":
                track.append(mido.MetaMessage("set_tempo", tempo=5000 + a * 20000, time=delta))
            else:
                track.append(mido.MetaMessage("lyrics", text=texts[i % len(texts)], time=delta))
        midi.tracks.append(track)
    buffer = io.BytesIO()
    midi.save(file=buffer)
    piece = read_bytes(tmp_path, buffer.getvalue())
    if piece is not None:
        assert isinstance(piece, Piece)
        ons = sum(1 for t in tracks for e in t if e[1] == "on" and e[3] > 0)
        assert len(piece) <= ons
        # whatever was read writes and reads back unchanged
        (tmp_path / "again.mid").write_bytes(midi_bytes(piece))
        assert read_midi(tmp_path / "again.mid") == piece


# -- PIG files ---------------------------------------------------------------------------------
def read_pig_text(tmp_path, text: str):
    """read_pig_rows on ``text``: the rows, or None after a one-line PianobotError."""
    path = tmp_path / "fuzz.txt"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    try:
        rows = read_pig_rows(path)
    except PianobotError as e:
        assert "\n" not in str(e) and len(str(e)) < 600, str(e)
        return None
    for note, channel in rows:  # whatever was read is a valid, bounded note
        assert 0 <= note.onset < note.offset <= MAX_SECONDS and channel in (0, 1) and 1 <= note.finger <= 5
    return rows


@FUZZ
@given(text=st.text(max_size=400))
def test_random_text_as_a_pig_file_never_crashes(tmp_path, text):
    read_pig_text(tmp_path, text)


odd_number = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-10, 10**15).map(str),
    st.sampled_from(["nan", "inf", "-inf", "1e400", "1e12", "3600", "3599.9999", "-0", "0x10", "", "1_0", "٣"]),
)


def usually(value: str, odd):
    """Mostly a valid ``value``, sometimes something odd: a bad line is found after good ones."""
    return st.one_of(st.just(value), st.just(value), st.just(value), odd)


@st.composite
def pig_line(draw) -> tuple[str, ...]:
    onset, length = draw(st.floats(0, 100)), draw(st.floats(0.001, 10))
    pitches = ["C4", "C#4", "Bb3", "E-4", "G9", "C-1", "60", "b#3"]
    return (
        draw(st.integers(0, 99).map(str)),
        draw(usually(f"{onset:.3f}", odd_number)),
        draw(usually(f"{onset + length:.3f}", odd_number)),
        draw(
            usually(
                draw(st.sampled_from(pitches)),
                st.one_of(st.sampled_from(["H4", "200", "C" + "9" * 5000]), st.text(max_size=5)),
            )
        ),
        draw(usually(str(draw(st.integers(1, 127))), st.sampled_from(["9" * 5000, "x", "1.5", "-5", "300"]))),
        draw(st.integers(0, 127).map(str)),
        draw(usually(draw(st.sampled_from(["0", "1"])), st.sampled_from(["2", "-1", "x"]))),
        draw(
            usually(
                draw(st.sampled_from(["1", "+2", "-5", "3_1", "+3", "-2_4"])),
                st.one_of(st.sampled_from(["0", "6", "", "9" * 5000]), st.text(max_size=3)),
            )
        ),
    )


@FUZZ
@given(lines=st.lists(pig_line(), max_size=12), sep=st.sampled_from(["\t", " "]), header=st.booleans())
def test_random_valid_looking_pig_files_read_or_fail_clearly(tmp_path, lines, sep, header):
    text = (HEADER + "\n" if header else "") + "\n".join(sep.join(cols) for cols in lines) + "\n"
    rows = read_pig_text(tmp_path, text)
    if rows:  # as a sidecar: the notes it holds take their fingers from it
        notes = {(n.onset, n.pitch): n for n, _ in rows}
        piece = Piece(tuple(notes.values()))
        try:
            assert apply_fingering(piece.without_fingering(), tmp_path / "fuzz.txt").has_fingering
        except PianobotError as e:  # two notes of one pitch within the matching tolerance may swap
            assert "\n" not in str(e)


# -- the command line, end to end --------------------------------------------------------------
runner = CliRunner()
TINY = Piece((Note(0.0, 60, 0.5, 80, 2), Note(0.5, 64, 1.0, 90, 3)), bpm=60)
CLI = settings(FUZZ, max_examples=40)
PLAY = settings(FUZZ, max_examples=6)  # each one simulates a piece: a second or two


def cli(*args, limit: float = 60.0):
    """Run a command; it must succeed, or exit 2 with exactly one 'error:' line, within ``limit`` seconds."""
    start = time.perf_counter()
    result = runner.invoke(app, [str(a) for a in args])
    assert time.perf_counter() - start < limit, f"{args} took {time.perf_counter() - start:.1f} s"
    assert result.exit_code in (0, 2), (args, result.exit_code, result.exception, result.output)
    assert result.exception is None or isinstance(result.exception, SystemExit), (args, result.exception)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert all(line.startswith(("error: ", "warning: ")) for line in lines), result.stderr
    assert sum(line.startswith("error: ") for line in lines) == (result.exit_code == 2), result.stderr
    hypothesis.event(f"{args[0]} exit {result.exit_code}")  # (--hypothesis-show-statistics: how many runs worked)
    return result


def every_command(song: Path, folder: Path, play: bool = False) -> None:
    reference = write_tiny(folder)
    cli("inspect", song, "--models", folder)
    cli("finger", song, "-o", folder / "fingered.mid")
    cli("score", song, reference, "--json", folder / "score.json")
    cli("score", reference, song)
    if play:
        cli("play", song, "-o", folder / "played.mid", "--controller", "scripted", limit=120)


def write_tiny(folder: Path) -> Path:
    path = folder / "tiny.mid"
    if not path.exists():
        path.write_bytes(midi_bytes(TINY))
    return path


def fresh(tmp_path) -> Path:
    """A new folder for one example (hypothesis runs many in one tmp_path)."""
    return Path(tempfile.mkdtemp(dir=tmp_path))


HEADER_1_TRACK = b"MThd\x00\x00\x00\x06\x00\x01\x00\x01\x01\xe0"


@CLI
@given(data=st.one_of(st.binary(max_size=300), st.binary(max_size=300).map(lambda tail: HEADER_1_TRACK + tail)))
def test_the_cli_on_random_bytes(tmp_path, data):
    folder = fresh(tmp_path)
    song = folder / "random.mid"
    song.write_bytes(data)
    every_command(song, folder)


@CLI
@given(
    tracks=st.lists(st.lists(event, max_size=12), min_size=1, max_size=3),
    tpb=st.integers(1, 960),
    texts=st.lists(st.sampled_from(["1", "2 3", "la", "9", "3_1", "-", "1,2,3,4,5", "[/x]", "2\n3"]), min_size=1),
)
def test_the_cli_on_random_small_midi_files(tmp_path, tracks, tpb, texts):
    folder = fresh(tmp_path)
    midi = mido.MidiFile(type=1, ticks_per_beat=tpb)
    for events in tracks:
        track = mido.MidiTrack()
        for i, (delta, kind, a, b, channel) in enumerate(events):
            if kind in ("on", "off"):
                track.append(mido.Message(f"note_{kind}", note=a, velocity=b, channel=channel, time=delta))
            elif kind == "tempo":
                track.append(mido.MetaMessage("set_tempo", tempo=a * 20000, time=delta))  # 0 included
            else:
                track.append(mido.MetaMessage("lyrics", text=texts[i % len(texts)], time=delta))
        midi.tracks.append(track)
    midi.save(folder / "random.mid")
    every_command(folder / "random.mid", folder)


tiny_note = st.tuples(
    st.integers(0, 8),  # onset, in eighths of a beat
    st.integers(1, 8),  # duration, in eighths of a beat
    st.one_of(st.integers(60, 83), st.integers(48, 96)),  # pitch: mostly on the keyboard C4-B5
    st.integers(1, 127),  # velocity
    st.one_of(st.none(), st.sampled_from([2, 3, 4]), st.sampled_from([1, 5])),  # finger: mostly the hand's
)


@PLAY
@given(notes=st.lists(tiny_note, min_size=1, max_size=3), bpm=st.sampled_from([60, 120, 240]))
def test_play_on_random_tiny_pieces(tmp_path, notes, bpm):
    folder = fresh(tmp_path)
    events = []
    for onset, length, pitch, velocity, finger in notes:
        if finger is not None:
            events.append((onset * 60, mido.MetaMessage("lyrics", text=str(finger))))
        events.append((onset * 60, mido.Message("note_on", note=pitch, velocity=velocity)))
        events.append(((onset + length) * 60, mido.Message("note_off", note=pitch, velocity=0)))
    track, last = mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(bpm))]), 0
    for tick, msg in sorted(events, key=lambda e: e[0]):
        track.append(msg.copy(time=tick - last))
        last = tick
    midi = mido.MidiFile(type=0, ticks_per_beat=480)
    midi.tracks.append(track)
    midi.save(folder / "tiny piece.mid")
    every_command(folder / "tiny piece.mid", folder, play=True)


file_name = st.text(st.characters(exclude_categories=("Cs",), exclude_characters="/\x00"), min_size=1, max_size=12)
file_name = file_name.filter(lambda name: name not in (".", "..") and len(name.encode()) < 100)


@CLI
@given(name=file_name)
def test_any_file_name_works_for_finger_and_score(tmp_path, name):
    """Non-Latin-1 characters, spaces, brackets, line breaks: pianobot writes the name inside the file too."""
    folder = fresh(tmp_path)
    song = folder / f"{name}.mid"
    song.write_bytes(midi_bytes(TINY.without_fingering()))
    assert cli("inspect", song, "--models", folder).exit_code == 0
    assert cli("finger", song, "-o", folder / f"{name} fingered.mid").exit_code == 0
    assert read_midi(folder / f"{name} fingered.mid") == TINY.with_fingers(
        [n.finger for n in read_midi(folder / f"{name} fingered.mid")]
    )
    assert cli("score", folder / f"{name} fingered.mid", song, "--json", folder / f"{name}.json").exit_code == 0


@PLAY
@given(name=file_name)
def test_any_file_name_works_for_play(tmp_path, name):
    folder = fresh(tmp_path)
    song = folder / f"{name}.mid"
    song.write_bytes(midi_bytes(TINY))
    result = cli("play", song, "-o", folder / f"{name} played.mid", "--controller", "scripted", limit=120)
    assert result.exit_code == 0, result.output
    assert read_midi(folder / f"{name} played.mid").has_fingering
