"""The hand-written pianist: which finger plays each note (:mod:`pianobot.pianist.fingering`, the
one place that knows what the hand can reach) and how the hand moves to play them
(:mod:`pianobot.pianist.scripted`, the teacher of every policy). No learning, no torch."""
