"""`pianobot train` around the loop: JSON output, warnings about the cores, shell completion, Ray."""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pianobot.cli.app import app

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"
QUICK = ("--steps", "60", "--exploration-steps", "30", "--no-tactile")


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def test_train_json_to_standard_output_and_a_summary_that_keeps_whole_paths(tmp_path):
    models = tmp_path / "a-folder-with-a-long-name-that-would-not-fit-in-eighty-columns" / "models"
    result = run("train", EXAMPLES / "one-note.mid", *QUICK, "--models", models, "--json", "-")
    assert result.exit_code == 0, result.output
    policies = json.loads(result.stdout)["policies"]  # stdout holds the JSON alone; the tables go to stderr
    assert len(policies) == 1 and policies[0]["steps"] == 60 and policies[0]["trained_now"]
    folder = Path(policies[0]["folder"])
    assert folder.parent == models and (folder / "training.csv").exists() and Path(policies[0]["plot"]).exists()
    assert "…" not in result.stderr  # no path cut short in the summary
    again = run("train", EXAMPLES / "one-note.mid", *QUICK, "--models", models, "--json", tmp_path / "t.json")
    assert again.exit_code == 0 and json.loads((tmp_path / "t.json").read_text())["policies"][0]["trained_now"] is False


def test_train_warns_about_more_threads_than_cores_and_workers_with_a_task(tmp_path, monkeypatch):
    monkeypatch.setattr("os.cpu_count", lambda: 2)
    result = run("train", "--task", "one-note", *QUICK, "--workers", "2", "--threads", "2", "--models", tmp_path)
    assert result.exit_code == 0, result.output
    assert "4 busy threads on 2 cores" in result.stderr and "--task trains one policy" in result.stderr


def test_shell_completion_is_offered():
    assert "--install-completion" in run("--help").output


def test_train_on_a_local_ray_runtime(tmp_path):
    pytest.importorskip("ray")
    result = run("train", EXAMPLES / "one-note.mid", *QUICK, "--cluster", "ray", "--models", tmp_path, "--json", "-")
    assert result.exit_code == 0, result.output
    (policy,) = json.loads(result.stdout)["policies"]
    assert policy["steps"] == 60 and (Path(policy["folder"]) / "policy.safetensors").exists()
    assert run("train", EXAMPLES / "one-note.mid", "--cluster", "slurm").exit_code == 2
