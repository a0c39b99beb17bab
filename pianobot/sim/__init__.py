"""Physics only: the keyboard, the hand, touch sensing and the PyBullet world. No score, no torch."""
