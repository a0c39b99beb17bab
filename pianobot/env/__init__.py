"""The gymnasium environment (:mod:`pianobot.env.piano`) and its rewards (:mod:`pianobot.env.rewards`).

Importing :mod:`pianobot.env.piano` registers the ids ``pianobot/Piano-v0`` and one per task
family (``pianobot/OneNote-v0``, ...) with gymnasium.
"""
