"""Audio of a performance: FluidSynth with a General MIDI soundfont (``--soundfont FILE.sf2``, or
one installed by Debian's fluid-soundfont-gm or timgm6mb-soundfont, with the FluidSynth library
and the pyfluidsynth package: ``make sound``), pretty_midi's sine synthesis otherwise."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from pianobot.errors import PianobotError
from pianobot.files import atomic_write
from pianobot.music.midi_io import midi_bytes
from pianobot.music.pedal import Pedal
from pianobot.music.piece import Piece

SAMPLE_RATE = 22_050
SOUND = "`make sound` installs the FluidSynth library and a soundfont (Debian's libfluidsynth3 and timgm6mb-soundfont)"
"""What `make sound` installs (the Makefile's recipe names the same packages: a test checks)."""
SOUNDFONTS = (
    Path("/usr/share/sounds/sf2/FluidR3_GM.sf2"),
    Path("/usr/share/sounds/sf2/default-GM.sf2"),
    Path("/usr/share/sounds/sf2/TimGM6mb.sf2"),
    Path("/usr/share/soundfonts/default.sf2"),
)


def has_fluidsynth() -> bool:
    """Whether the FluidSynth library and pyfluidsynth are installed."""
    try:
        import fluidsynth  # noqa: F401  (pyfluidsynth; raises ImportError without the library)
    except (ImportError, OSError):
        return False
    return True


def soundfont() -> Path | None:
    """An installed soundfont FluidSynth can use, if both are there."""
    if not has_fluidsynth():
        return None
    return next((path for path in SOUNDFONTS if path.exists()), None)


def check_soundfont(path: Path) -> Path:
    """``path`` if FluidSynth can play it; else a one-line PianobotError saying what to install or fix."""
    if not path.is_file():
        raise PianobotError(
            f"soundfont {path} does not exist: give a .sf2 file (e.g. /usr/share/sounds/sf2/FluidR3_GM.sf2)"
        )
    with open(path, "rb") as f:
        header = f.read(12)
    if header[:4] != b"RIFF" or header[8:12] != b"sfbk":
        raise PianobotError(f"{path} is not a SoundFont 2 (.sf2) file")
    if not has_fluidsynth():
        raise PianobotError(
            f"a soundfont needs the FluidSynth library and pyfluidsynth: {SOUND}; pip install 'pianobot[sound]'"
        )
    return path


def synthesize(
    piece: Piece, sample_rate: int = SAMPLE_RATE, font: Path | None = None, delay: float = 0.0, pedal: Pedal = Pedal()
) -> tuple[np.ndarray, str]:
    """(audio samples in [-1, 1], how they were made): with the soundfont ``font`` (checked with
    :func:`check_soundfont`), else an installed one, else sine waves; ``delay`` seconds of
    silence before the piece's time 0 (a video's lead-in). With the sustain ``pedal`` each note
    sounds as long as the pedal holds it (:meth:`~pianobot.music.pedal.Pedal.sounding`), with
    the soundfont and the sine waves alike."""
    import pretty_midi  # (imported when sound is made: it and scipy take most of a second)

    piece = pedal.sounding(piece)

    midi = pretty_midi.PrettyMIDI(io.BytesIO(midi_bytes(piece.shift(delay) if delay else piece)))
    font = font or soundfont()
    if font is not None:
        return midi.fluidsynth(fs=sample_rate, sf2_path=str(font)), f"FluidSynth with {font.name}"
    return midi.synthesize(fs=sample_rate), f"sine waves; for a piano, {SOUND}, with pyfluidsynth (pianobot[sound])"


def write_wav(
    piece: Piece,
    path: str | Path,
    sample_rate: int = SAMPLE_RATE,
    font: Path | None = None,
    delay: float = 0.0,
    pedal: Pedal = Pedal(),
) -> str:
    """Write the piece (sounding with its sustain ``pedal``, as :func:`synthesize`) as 16-bit mono
    WAV, atomically; returns how it was synthesised."""
    audio, method = synthesize(piece, sample_rate, font, delay, pedal)
    peak = float(np.abs(audio).max()) if audio.size else 0.0
    samples = (audio / peak * 0.9 * 32767).astype(np.int16) if peak > 0 else audio.astype(np.int16)
    buffer = io.BytesIO()
    from scipy.io import wavfile

    wavfile.write(buffer, sample_rate, samples)
    atomic_write(path, buffer.getvalue())
    return method
