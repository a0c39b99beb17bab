"""Physics only: the keyboard, the hand, touch sensing and the PyBullet world. No score, no torch."""

from pianobot.sim import pianist_hand  # noqa: F401 (registers the pianist's hand beside the Allegro-like one)
