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
    assert policies[0]["hand"] is None and policies[0]["hand_model"] == "allegro"  # (one hand's piece)
    folder = Path(policies[0]["folder"])
    assert folder.parent == models and (folder / "training.csv").exists() and Path(policies[0]["plot"]).exists()
    assert "…" not in result.stderr  # no path cut short in the summary
    assert "learning curves: training.csv" in " ".join(result.stderr.split())
    again = run("train", EXAMPLES / "one-note.mid", *QUICK, "--models", models, "--json", tmp_path / "t.json")
    assert again.exit_code == 0 and json.loads((tmp_path / "t.json").read_text())["policies"][0]["trained_now"] is False
    assert "already trained in" in again.output
    # the store's index says the general policy plays the phrase (no folder): said so, not "trained in" a
    # folder that is not there, and no learning curves are promised
    import shutil

    shutil.rmtree(folder)
    (models / "general-plays.json").write_text(json.dumps({folder.name: {"why": "kept its start"}}))
    judged = run("train", EXAMPLES / "one-note.mid", *QUICK, "--models", models)
    text = " ".join(judged.output.split())
    assert judged.exit_code == 0 and "played by the general policy" in text and "already trained" not in text
    assert "learning curves" not in text


def test_train_json_names_the_hand_model_each_policy_plays(tmp_path):
    result = run(
        "train", EXAMPLES / "one-note.mid", *QUICK, "--hand-model", "pianist", "--models", tmp_path, "--json", "-"
    )
    assert result.exit_code == 0, result.output
    (policy,) = json.loads(result.stdout)["policies"]
    assert policy["hand_model"] == "pianist"
    manifest = json.loads((Path(policy["folder"]) / "manifest.json").read_text())
    assert manifest["config"]["env"]["world"]["hand"]["spec"]["model"] == "pianist"


def test_train_warns_about_more_threads_than_cores_and_workers_with_a_task(tmp_path, monkeypatch):
    monkeypatch.setattr("os.cpu_count", lambda: 2)
    # three workers of one thread each: over the cores, yet torch itself runs one thread (two spun here for a minute)
    result = run("train", "--task", "one-note", *QUICK, "--workers", "3", "--threads", "1", "--models", tmp_path)
    assert result.exit_code == 0, result.output
    assert "3 busy threads on 2 cores" in result.stderr and "--task trains one policy" in result.stderr


def test_shell_completion_is_offered():
    assert "--install-completion" in run("--help").output


def test_train_on_a_local_ray_runtime(tmp_path):
    pytest.importorskip("ray")
    result = run("train", EXAMPLES / "one-note.mid", *QUICK, "--cluster", "ray", "--models", tmp_path, "--json", "-")
    assert result.exit_code == 0, result.output
    (policy,) = json.loads(result.stdout)["policies"]
    assert policy["steps"] == 60 and (Path(policy["folder"]) / "policy.safetensors").exists()
    assert run("train", EXAMPLES / "one-note.mid", "--cluster", "slurm").exit_code == 2


def test_train_the_melody_family_and_rebuild_its_policy_from_the_manifest(tmp_path):
    """`train --task melody`: a tiny run stores a policy whose manifest names its task, so that
    evaluation and play rebuild its environment (fresh phrases, fingered by the planner)."""
    import numpy as np

    from pianobot.agent.policy import load_policy, policy_configs, policy_env, policy_target
    from pianobot.agent.tasks import draw_melody
    from pianobot.learn.train import evaluate
    from pianobot.perform.perform import perform

    assert "melody" in run("train", "--help").output
    result = run("train", "--task", "melody", *QUICK, "--models", tmp_path, "--json", "-")
    assert result.exit_code == 0, result.output
    (policy,) = json.loads(result.stdout)["policies"]
    folder = Path(policy["folder"])
    assert folder.name.startswith("task-melody-") and policy_target(folder) == "melody"
    env = policy_env(folder)
    observation, info = env.reset(seed=1)
    agent = load_policy(folder, env)
    assert info["piece"].has_fingering and agent.act(observation).shape == env.action_space.shape
    env_config, _ = policy_configs(folder)
    assert 0.0 <= evaluate(agent, "melody", env_config, episodes=2)["f1"] <= 1.0
    piece = draw_melody(np.random.default_rng(5), env_config)
    played = perform(piece, lambda env: load_policy(folder, env), config=env_config)
    assert played.reference == piece


def test_train_envs_and_device_options(tmp_path, monkeypatch):
    import torch
    import typer.main

    from pianobot.learn.config import TrainConfig

    options = {p.name: p.default for p in typer.main.get_command(app).commands["train"].params}
    assert options["envs"] == TrainConfig.envs == 1 and options["device"] == TrainConfig.device == "auto"
    help_text = run("train", "--help").output
    assert "--envs" in help_text and "--device" in help_text
    song = EXAMPLES / "one-note.mid"
    for args, words in (
        (("--envs", "0"), ("--envs 0", "give 1 to 256")),
        (("--envs", "1000"), ("--envs 1000", "give 1 to 256")),
        (("--device", "gpu"), ("'--device'", "'gpu'", "'auto', 'cpu', 'cuda'")),
    ):
        result = run("train", song, *QUICK, *args, "--models", tmp_path)
        assert result.exit_code == 2 and len(result.stderr.strip().splitlines()) == 1, result.output
        assert all(word in result.stderr for word in words), result.stderr
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    result = run("train", song, *QUICK, "--device", "cuda", "--models", tmp_path)
    assert result.exit_code == 2 and result.stderr.strip().splitlines() == [
        f"error: --device cuda: torch {torch.__version__} sees no CUDA GPU on this machine: use --device cpu, or auto "
        "(cuda where there is one)"
    ]
    result = run("train", song, *QUICK, "--device", "auto", "--models", tmp_path, "--json", "-")
    assert result.exit_code == 0, result.output
    manifest = json.loads((Path(json.loads(result.stdout)["policies"][0]["folder"]) / "manifest.json").read_text())
    assert manifest["device"] == "cpu"


def test_train_with_the_dagger_learner_in_rounds_of_round_steps(tmp_path):
    """`--learner dagger --round-steps N`: the stored policy's manifest says so, and it learnt in
    rounds of N steps (each ending in an evaluation); bad values are one line and exit code 2."""
    song = EXAMPLES / "one-note.mid"
    result = run(
        "train", song, "--steps", "100", "--learner", "dagger", "--round-steps", "40", "--no-tactile",
        "--dagger-learning-rate", "1e-5", "--dagger-hold-guard", "--models", tmp_path, "--json", "-",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    manifest = json.loads((Path(json.loads(result.stdout)["policies"][0]["folder"]) / "manifest.json").read_text())
    assert manifest["config"]["learner"] == "dagger" and manifest["config"]["dagger"]["round_steps"] == 40
    assert manifest["config"]["dagger"]["hold_guard"] is True
    # the step size starts where --dagger-learning-rate says and falls no lower than it when it is below the default end
    assert manifest["config"]["dagger"]["learning_rate"] == manifest["config"]["dagger"]["final_learning_rate"] == 1e-5
    rounds = [e["round"] for e in manifest["evaluations"] if "round" in e]
    assert rounds == [1, 2, 3]  # rounds end at the first episode ends after 40, 80 and 100 steps
    for args, words in (
        (("--learner", "ppo"), ("'--learner'", "'ppo'", "'sac', 'dagger'")),
        (("--learner", "dagger", "--round-steps", "0"), ("--round-steps 0",)),
        (("--learner", "dagger", "--dagger-learning-rate", "0"), ("--dagger-learning-rate 0", "above 0")),
        (("--learner", "dagger", "--dagger-learning-rate", "inf"), ("--dagger-learning-rate inf", "above 0")),
        (("--learner", "dagger", "--control", "torque", "--explore", "prior"), ("velocity or position",)),
        (("--learner", "dagger", "--dagger-hold-guard", "--control", "torque"), ("--dagger-hold-guard", "velocity")),
    ):
        result = run("train", song, *QUICK, *args, "--models", tmp_path / "bad")
        assert result.exit_code == 2 and len(result.stderr.strip().splitlines()) == 1, result.output
        assert all(word in result.stderr for word in words), result.stderr


def test_a_ray_worker_killed_mid_phrase_is_run_again_from_its_checkpoint(tmp_path):
    """Issue 36, item 6: the worker training a phrase dies after its first checkpoint; Ray runs the
    task again, which resumes from that checkpoint, and the phrase ends trained to its last step."""
    pytest.importorskip("ray")
    import os
    import signal
    import subprocess

    from pianobot.agent import store
    from pianobot.agent.config import SACConfig
    from pianobot.env.piano import EnvConfig
    from pianobot.learn.config import TrainConfig
    from pianobot.learn.jobs import phrase_jobs, run_jobs_on_ray
    from pianobot.music.load import load_piece
    from pianobot.music.phrases import split_phrases

    config = TrainConfig(
        steps=150,
        eval_every=50,
        checkpoint_every=50,
        eval_episodes=1,
        from_general=False,
        sac=SACConfig(exploration_steps=30),
        env=EnvConfig(tactile=False),
    )
    (job,) = phrase_jobs(split_phrases(load_piece(EXAMPLES / "one-note.mid")), config, tmp_path)
    killed, resumed = [], []

    def on_progress(key, progress):
        resumed.extend([progress.step] if progress.resumed else [])
        if not killed and store.checkpoint_state(job.folder) is not None:
            found = subprocess.run(["pgrep", "-f", "ray::_run_job"], capture_output=True, text=True).stdout.split()
            for pid in found:
                os.kill(int(pid), signal.SIGKILL)
            killed.extend(found)

    results = run_jobs_on_ray([job], config, on_progress)
    assert killed, "no worker was found to kill"
    assert resumed and resumed[0] >= 50  # the second run began at the checkpoint, not at step 0
    manifest = results[job.key]
    assert manifest["steps"] >= 150 and (job.folder / store.POLICY_FILE).exists()


def test_train_says_why_nothing_was_trained_where_the_whole_piece_still_loses_notes(tmp_path, monkeypatch):
    """Every phrase plays at its stop F1 from a fresh start, so none is trained; where the piece
    played whole still loses notes (here made so), one line says what the phrase-by-phrase
    evaluation does not see, where before the run ended in silence (a new user's trial)."""
    import dataclasses

    import pianobot.learn.accept as accept

    settle = accept.settle_piece

    def losing(*args, **kwargs):
        verdict = settle(*args, **kwargs)
        return dataclasses.replace(verdict, before=(0.9,) * len(verdict.before), after=(0.9,) * len(verdict.after))

    monkeypatch.setattr(accept, "settle_piece", losing)
    args = ("train", EXAMPLES / "c-major-scale.mid", "--steps", "60", "--learner", "dagger", "--round-steps", "30")
    result = run(*args, "--models", tmp_path)
    text = " ".join(result.output.split())
    assert result.exit_code == 0, result.output
    assert "no phrase policy of its own" in text and "so none was trained" in text
    monkeypatch.setattr(accept, "settle_piece", settle)  # the piece as it plays: whole, nothing to say
    assert "so none was trained" not in run(*args, "--models", tmp_path / "again").output


def test_train_finish_ends_an_interrupted_run_at_its_checkpoint(tmp_path, monkeypatch):
    """`--finish`: a run cut after its first round, rerun with it, trains no further: its best policy
    so far is stored and its manifest says the steps it took (the same command would have gone on)."""
    import pianobot.learn.dagger as dagger

    song = EXAMPLES / "one-note.mid"
    args = ("train", song, "--steps", "120", "--learner", "dagger", "--round-steps", "40", "--no-tactile")
    fresh = run(*args, "--finish", "--models", tmp_path / "fresh")  # nothing to end: said, and trained as usual
    assert fresh.exit_code == 0 and "holds no checkpoint of this run" in " ".join(fresh.output.split())
    real = dagger._dagger
    monkeypatch.setattr(dagger, "_dagger", lambda r, stop_after: real(r, 40))  # cut after the first round
    assert run(*args, "--models", tmp_path).exit_code == 0
    monkeypatch.setattr(dagger, "_dagger", real)
    result = run(*args, "--finish", "--models", tmp_path, "--json", "-")
    assert result.exit_code == 0, result.output
    assert "ending at its checkpoint (--finish) at step 45" in result.stderr  # (episodes of 45 steps)
    (policy,) = json.loads(result.stdout)["policies"]
    manifest = json.loads((Path(policy["folder"]) / "manifest.json").read_text())
    assert policy["steps"] == 45 == manifest["steps"] and manifest["config"]["steps"] == 120
    assert [e["step"] for e in manifest["evaluations"]] == [45]
