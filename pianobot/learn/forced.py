"""A forced run's marks (``train --force``): what it replaces stays, and plays, until it has.

A forced run marks each phrase's folder it trains anew (:func:`mark_replacing`) with the run's name,
a digest of its phrases' folders (:func:`forced_run`). What the folder stored stays in place, and plays
as it did (a policy the piece's judgement set aside stays set aside), until the phrase's new run has
written its manifest (:func:`replaced`: what was stored goes unless a new policy was stored over it, and
the mark says finished). The command forgets the marks once it has judged the piece
(:func:`forget_replacing`). The same forced command, interrupted and run again, finds its own marks
and goes on with the phrases not finished (:func:`~pianobot.learn.jobs.plan_jobs`).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from pianobot.agent import store
from pianobot.files import atomic_write

REPLACING_FILE = "replacing"
"""In a phrase's folder: a forced run (``train --force``) is replacing what is stored there. Until it
has, what was stored stays (and plays as it did); it names the run (:func:`mark_replacing`), so that
the same command, interrupted, goes on with the phrases it had not finished."""


def mark_replacing(folder: Path, run: str) -> None:
    """Mark ``folder`` as being replaced by the forced run ``run`` (a digest of its phrases' folders)."""
    folder.mkdir(parents=True, exist_ok=True)
    atomic_write(folder / REPLACING_FILE, json.dumps({"run": run, "finished": False}) + "\n")


def replacing(folder: Path) -> dict | None:
    """The mark of the forced run replacing ``folder`` (``run``, ``finished``), or None."""
    try:
        mark = json.loads((folder / REPLACING_FILE).read_text())
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        mark = {}
    return {"run": str(mark.get("run", "")), "finished": bool(mark.get("finished", False))}


def replaced(folder: Path, policy_kept: bool) -> None:
    """A forced run's phrase in ``folder`` has finished (its manifest written): what was stored before
    goes unless the run stored a policy over it (``policy_kept``); the mark stays, finished, until the
    run's command has judged the piece (:func:`forget_replacing`)."""
    mark = replacing(folder)
    if mark is None:
        return
    if not policy_kept:
        for name in (store.POLICY_FILE, store.CRITIC_FILE):
            (folder / name).unlink(missing_ok=True)
    atomic_write(folder / REPLACING_FILE, json.dumps({**mark, "finished": True}) + "\n")


def forget_replacing(folder: Path) -> None:
    (folder / REPLACING_FILE).unlink(missing_ok=True)


def forced_run(folders: list[Path]) -> tuple[str, bool]:
    """(the forced run's name: a digest of its phrases' ``folders``; whether a forced run of these same
    phrases was interrupted: one of them still carries its mark)."""
    run = hashlib.sha256("\n".join(sorted(map(str, folders))).encode()).hexdigest()[:16]
    return run, any((replacing(folder) or {}).get("run") == run for folder in folders)
