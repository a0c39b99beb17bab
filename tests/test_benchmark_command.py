"""benchmarks.command times `pianobot play` as a user runs it: Python may write and reuse its
bytecode cache (a sandbox's PYTHONDONTWRITEBYTECODE would make every start compile pianobot
again, the figure docs/benchmarks.md had wrong before), from the checkout it names."""

from __future__ import annotations

import subprocess
from pathlib import Path

from benchmarks import command


def test_the_command_is_timed_with_the_bytecode_cache_on_from_the_named_checkout(monkeypatch, tmp_path):
    seen = {}

    def run(args, **kwargs):
        seen.update(args=args, **kwargs)
        return subprocess.CompletedProcess(args, 0)

    monkeypatch.setenv("PYTHONDONTWRITEBYTECODE", "1")
    monkeypatch.setenv("PIANOBOT_SOMETHING_ELSE", "kept")
    monkeypatch.setattr(command.subprocess, "run", run)
    seconds = command.command_seconds("mary.mid", ["--controller", "scripted"], tmp_path, checkout=Path("/elsewhere"))
    assert seconds >= 0
    assert "PYTHONDONTWRITEBYTECODE" not in seen["env"]
    assert seen["env"]["PIANOBOT_SOMETHING_ELSE"] == "kept"  # the rest of the environment as it is
    assert seen["cwd"] == Path("/elsewhere")
    assert seen["args"][1:4] == ["-m", "pianobot", "play"] and seen["args"][-2:] == ["--controller", "scripted"]
