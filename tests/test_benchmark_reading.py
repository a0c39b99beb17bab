"""benchmarks/reading.py's ``--peer``: the long piece's reading timed with another checkout's pianobot."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from benchmarks import reading


def test_the_peer_s_reading_runs_this_script_with_the_peer_s_pianobot(monkeypatch, tmp_path):
    seen = {}

    def run(args, **kwargs):
        seen.update(args=args, **kwargs)
        return subprocess.CompletedProcess(args, 0, stdout="12.5\n", stderr="")

    monkeypatch.setattr(reading.subprocess, "run", run)
    assert reading.peer_seconds(tmp_path, 3) == 12.5
    assert seen["env"]["PYTHONPATH"] == str(tmp_path.resolve()) and seen["cwd"] == tmp_path
    assert seen["args"][1] == str(Path(reading.__file__).resolve())
    assert seen["args"][2:] == ["--long-only", "--repeats", "3"]

    def fails(args, **kwargs):
        return subprocess.CompletedProcess(args, 1, stdout="", stderr="Traceback ...\nImportError: no music21\n")

    monkeypatch.setattr(reading.subprocess, "run", fails)
    with pytest.raises(SystemExit, match="could not read the long piece: ImportError: no music21$"):
        reading.peer_seconds(tmp_path, 3)


def test_a_peer_that_is_not_a_checkout_is_one_line_and_exit_code_2(tmp_path, capsys):
    with pytest.raises(SystemExit) as stopped:
        reading.main(["--peer", str(tmp_path), "--repeats", "1"])
    assert stopped.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].endswith(f"--peer {tmp_path}: not a pianobot checkout (no pianobot/__init__.py there)")
