"""Property-based tests: whatever bytes or MIDI files come in, the reader answers with a Piece
or with a PianobotError, never another exception."""

import io
import warnings

import mido
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pianobot.errors import PianobotError
from pianobot.music.midi_io import midi_bytes, read_midi
from pianobot.music.piece import Piece

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
