"""The `pianobot` command line: thin wrappers that read arguments, call the library and print.

Every :class:`PianobotError` becomes one red line on stderr and exit code 2; warnings about
repaired input are printed in yellow and do not stop the command. Option defaults come from the
configuration dataclasses. The simulator, torch and the metrics are imported inside the commands
that need them, so that `pianobot --version` and `pianobot score` start quickly.
"""

from __future__ import annotations

import contextlib
import functools
import re
import signal
import threading
import warnings

import typer
from typer.core import TyperCommand, TyperGroup

from pianobot import __version__
from pianobot.cli.commands.export import export
from pianobot.cli.commands.finger import finger
from pianobot.cli.commands.inspect import inspect
from pianobot.cli.commands.play import play
from pianobot.cli.commands.score import score
from pianobot.cli.commands.train import train
from pianobot.cli.flags import phrase
from pianobot.cli.terminal import err, out, said
from pianobot.errors import QUOTE_LIMIT, PianobotError, PianobotWarning, quote
from pianobot.files import why
from pianobot.learn.config import TrainConfig

EXIT_BAD_INPUT = 2
USAGE_ERROR = typer.BadParameter.__base__  # click's UsageError (typer re-exports only its subclass)


@contextlib.contextmanager
def usage_in_one_line():
    """Typer's own usage errors (a value not among an option's choices, an unknown option, a
    missing argument) as one red line and exit 2, like every other error, instead of a panel."""
    try:
        yield
    except USAGE_ERROR as e:
        if type(e).__name__ == "NoArgsIsHelpError":  # (`pianobot` alone: the help, as typer prints it)
            raise
        where = f" (`{e.ctx.command_path} --help` lists the options)" if e.ctx is not None else ""
        message = re.sub(r"'([^']{%d,})'" % (QUOTE_LIMIT + 1), lambda m: f"'{quote(m.group(1))}'", e.format_message())
        err.print(f"[red]error:[/red] {said(message + where)}", highlight=False, emoji=False, soft_wrap=True)
        raise typer.Exit(e.exit_code) from None


class OneLineUsageGroup(TyperGroup):
    """The command group, parsing its own and its commands' arguments through :func:`usage_in_one_line`."""

    def make_context(self, *args, **kwargs):
        with usage_in_one_line():
            return super().make_context(*args, **kwargs)

    def invoke(self, ctx):
        with usage_in_one_line():
            return super().invoke(ctx)


COLUMN = 24
"""Widest option name beside its help in ``--help`` (a longer one puts its help on the next line)."""


class PanelledCommand(TyperCommand):
    """A command whose ``--help`` is click's plain text, wrapped to the terminal (at most 80
    columns), each option with its full names (a flag as ``--thumb / --no-thumb``, no value), and
    the options grouped under their panel's title (``rich_help_panel``: "Reading the piece")."""

    def format_options(self, ctx, formatter) -> None:
        sections: dict[str, list[tuple[str, str]]] = {}
        for param in self.get_params(ctx):
            record = param.get_help_record(ctx)
            if record is not None:
                title = "Arguments" if param.param_type_name == "argument" else param.rich_help_panel or "Options"
                sections.setdefault(title, []).append(record)
        for title, records in sections.items():
            with formatter.section(title):
                formatter.write_dl(records, col_max=COLUMN)


app = typer.Typer(
    cls=OneLineUsageGroup,
    help="Teach a simulated robot hand with touch sensors to play the piano from MIDI files.",
    no_args_is_help=True,
    add_completion=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # (typer's panels squeeze the help into a narrow column at 80 columns)
)


INTERRUPTED = {
    "train": ": run the same command again to go on; a phrase's run resumes from its last checkpoint "
    f"(SAC's every {TrainConfig.checkpoint_every} steps, DAgger's at the end of each round), and one without a "
    "checkpoint yet starts again; a phrase a --force run had not finished plays as it did before",
}
"""What an interrupted command adds to the line that says so."""


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, a job scheduler's stop) raised in the main thread, so that it unwinds as
    Ctrl-C does: every ``finally`` runs and a file being written is left whole or not at all."""


def _terminate(signum, frame):
    raise Terminated


@contextlib.contextmanager
def _sigterm_unwinds():
    """While in the block, SIGTERM raises :class:`Terminated` (only the main thread may set handlers)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def friendly(command):
    """Turn PianobotError into one red line + exit 2, and show warnings in yellow; either names
    the settings it mentions by their options (:func:`pianobot.cli.flags.phrase`).

    An OSError that escaped the library (the file system failed us where no one expected it)
    gets the same one line, never a traceback. Ctrl-C and SIGTERM unwind the command (its files
    left whole or not written) and say so: exit code 130 and 143.
    """

    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        error = None
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", PianobotWarning)
            try:
                with _sigterm_unwinds():
                    return command(*args, **kwargs)
            except PianobotError as e:
                error, code = phrase(e), EXIT_BAD_INPUT
            except OSError as e:
                error, code = (f"{e.filename}: " if e.filename else "") + why(e), EXIT_BAD_INPUT
            except KeyboardInterrupt as e:
                error, code = None, 143 if isinstance(e, Terminated) else 130
                stopped = "terminated" if isinstance(e, Terminated) else "interrupted"
                err.print(f"[yellow]{stopped}[/yellow]{INTERRUPTED.get(command.__name__, '')}")
            finally:
                lines = dict.fromkeys(  # (a file read twice warns twice: each line is said once)
                    phrase(w.message) for w in caught if issubclass(w.category, PianobotWarning)
                )
                for line in lines:  # the warnings first: the error, last, is what stopped the command
                    err.print(
                        f"[yellow]warning:[/yellow] {said(line)}",
                        highlight=False,
                        emoji=False,
                        soft_wrap=True,
                    )
        if error is not None:
            err.print(f"[red]error:[/red] {said(error)}", highlight=False, emoji=False, soft_wrap=True)
        raise typer.Exit(code) from None

    return wrapper


for command in (inspect, finger, score, play, train, export):
    app.command(cls=PanelledCommand)(friendly(command))


def _version(value: bool):
    if value:
        out.print(f"pianobot {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Show the version and exit."
    ),
):
    """pianobot: teach a simulated robot hand to play the piano from MIDI files."""


if __name__ == "__main__":
    app()
