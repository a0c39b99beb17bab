"""The terminal: the consoles the commands print to, text as it is, JSON to a file or standard output."""

from __future__ import annotations

import json
import os
from pathlib import Path

import typer
from rich.console import Console, ConsoleDimensions
from rich.markup import escape

from pianobot.errors import one_line
from pianobot.files import atomic_write

UNWRAPPED = 1000
"""Columns a console writing to a file or a pipe assumes: a table there is as wide as its words."""


class Terminal(Console):
    """A console as wide as the terminal; writing to a file or a pipe (where rich would assume 80
    columns and break a table's words, 'genera/l'), as wide as what it prints. ``COLUMNS`` set in
    the environment is obeyed either way."""

    @property
    def size(self) -> ConsoleDimensions:
        size = super().size
        if self.is_terminal or "COLUMNS" in os.environ:
            return size
        return ConsoleDimensions(UNWRAPPED, size.height)


out = Terminal()
err = Terminal(stderr=True)


def said(text) -> str:
    """Text for the terminal as it is: on one line, and any '[...]' in it not taken for rich markup."""
    return escape(one_line(str(text)))


def write_json(path: Path, data: dict) -> None:
    """``data`` as JSON to ``path``, or to standard output when ``path`` is '-'."""
    text = json.dumps(data, indent=2) + "\n"
    if str(path) == "-":
        typer.echo(text, nl=False)
    else:
        atomic_write(path, text)
