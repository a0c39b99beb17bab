"""The terminal: the consoles the commands print to, text as it is, JSON to a file or standard output."""

from __future__ import annotations

import json
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape

from pianobot.errors import one_line
from pianobot.files import atomic_write

out = Console()
err = Console(stderr=True)


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
