"""Playing: one episode with any controller (:mod:`~pianobot.perform.rollout`), a whole piece in one
simulation (:mod:`~pianobot.perform.perform`), the phrase policies one after another
(:mod:`~pianobot.perform.compose`), and sound (:mod:`~pianobot.perform.audio`)."""
