"""pianobot: teach a simulated dexterous robot hand to play the piano from real MIDI files."""

__version__ = "0.1.0"
