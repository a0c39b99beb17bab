"""``python -m pianobot``: the command line."""

from pianobot.cli.app import app

app(prog_name="pianobot")
