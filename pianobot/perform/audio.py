"""Audio of a performance: FluidSynth with a General MIDI soundfont where one is installed
(Debian's fluid-soundfont-gm and the pyfluidsynth package), pretty_midi's sine synthesis otherwise."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pretty_midi
from scipy.io import wavfile

from pianobot.files import atomic_write
from pianobot.music.midi_io import midi_bytes
from pianobot.music.piece import Piece

SAMPLE_RATE = 22_050
SOUNDFONTS = (
    Path("/usr/share/sounds/sf2/FluidR3_GM.sf2"),
    Path("/usr/share/sounds/sf2/default-GM.sf2"),
    Path("/usr/share/soundfonts/default.sf2"),
)


def soundfont() -> Path | None:
    """An installed soundfont FluidSynth can use, if both are there."""
    try:
        import fluidsynth  # noqa: F401  (pyfluidsynth)
    except (ImportError, OSError):
        return None
    return next((path for path in SOUNDFONTS if path.exists()), None)


def synthesize(piece: Piece, sample_rate: int = SAMPLE_RATE) -> tuple[np.ndarray, str]:
    """(audio samples in [-1, 1], how they were made)."""
    midi = pretty_midi.PrettyMIDI(io.BytesIO(midi_bytes(piece)))
    font = soundfont()
    if font is not None:
        return midi.fluidsynth(fs=sample_rate, sf2_path=str(font)), f"FluidSynth with {font.name}"
    return midi.synthesize(
        fs=sample_rate
    ), "sine waves (pretty_midi; install fluid-soundfont-gm and pyfluidsynth for a piano)"


def write_wav(piece: Piece, path: str | Path, sample_rate: int = SAMPLE_RATE) -> str:
    """Write the piece as 16-bit mono WAV, atomically; returns how it was synthesised."""
    audio, method = synthesize(piece, sample_rate)
    peak = float(np.abs(audio).max()) if audio.size else 0.0
    samples = (audio / peak * 0.9 * 32767).astype(np.int16) if peak > 0 else audio.astype(np.int16)
    buffer = io.BytesIO()
    wavfile.write(buffer, sample_rate, samples)
    atomic_write(path, buffer.getvalue())
    return method
