"""Configurations: one generic, typed rebuild from a manifest; the manifest's format history; CLI defaults."""

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from pianobot.agent import store
from pianobot.agent.config import SACConfig
from pianobot.config import ConfigError, from_dict, to_dict
from pianobot.env.piano import EnvConfig
from pianobot.env.rewards import RewardConfig
from pianobot.learn.config import TrainConfig
from pianobot.music.instrument import HandSpec
from pianobot.music.load import LoadOptions
from pianobot.music.piece import pitch_name
from pianobot.sim.hand import HandConfig
from pianobot.sim.world import WorldConfig

MODELS = Path(__file__).parent.parent / "models"


def unusual() -> TrainConfig:
    """Every kind of field away from its default: nested dataclasses, tuples, tuples of tuples, None."""
    world = WorldConfig(control="torque", hand=HandConfig(spec=HandSpec((1, 2, 3, 4))))
    env = EnvConfig(world=world, reward=RewardConfig(kind="squared"), actuated=("mcp", "pip"), tactile_pool=None)
    return TrainConfig(
        steps=123_456, seed=7, explore="prior", until_f1=0.5, sac=SACConfig(log_std_bounds=(-4.0, 1.0)), env=env
    )


def test_a_configuration_survives_the_json_round_trip_exactly():
    config = unusual()
    rebuilt = from_dict(TrainConfig, json.loads(json.dumps(to_dict(config))))
    assert rebuilt == config and hash(rebuilt.env) == hash(config.env)
    assert isinstance(rebuilt.env.world.hand.geometry.flexion_limits[0], tuple)  # tuples, not JSON's lists
    assert isinstance(rebuilt.sac.learning_rate, float)


def test_fields_left_out_take_their_defaults():
    assert from_dict(TrainConfig, {"steps": 99_999}) == TrainConfig(steps=99_999)


@pytest.mark.parametrize(
    "path, value, message",
    [
        (("sac", "hidden"), "256", r"config\.sac\.hidden: expected a whole number, got str '256'"),
        (("sac", "hidden"), True, r"config\.sac\.hidden: expected a whole number"),
        (("sac", "learning_rate"), float("inf"), r"config\.sac\.learning_rate: expected a finite number"),
        (("env", "tactile"), 1, r"config\.env\.tactile: expected true or false"),
        (("env", "tactile_pool"), [15], r"config\.env\.tactile_pool: expected 2 values, got 1"),
        (
            ("env", "world", "control"),
            "servo",
            r"config\.env\.world: control must be one of velocity, position, torque",
        ),
        (("env", "world", "hand"), [], r"config\.env\.world\.hand: expected a mapping"),
        (("env", "colour"), 1, r"config\.env\.colour: not a field of EnvConfig"),
    ],
)
def test_a_value_that_does_not_fit_names_its_field(path, value, message):
    data = to_dict(TrainConfig())
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(ConfigError, match=message):
        from_dict(TrainConfig, data)


def test_a_format_1_manifest_is_upgraded_to_what_it_meant(tmp_path):
    """Format 1 kept the agent's tactile size in sac.tactile_resolution and could lack fields
    whose absence meant: no velocity or onsets in the finger targets, the score window read."""
    config = to_dict(TrainConfig())
    config["sac"]["tactile_resolution"] = [30, 40]
    config["env"]["tactile_pool"] = [15, 20]  # overridden by the agent's resolution
    for key in ("target_velocity", "target_onsets"):
        del config["env"][key]
    del config["sac"]["score_input"]
    (tmp_path / store.MANIFEST_FILE).write_text(json.dumps({"format": 1, "config": config}))
    manifest = store.read_manifest(tmp_path)
    assert manifest["format"] == store.FORMAT == 2
    rebuilt = from_dict(TrainConfig, manifest["config"])
    assert rebuilt.env.tactile_pool == (30, 40) and not rebuilt.env.target_velocity and not rebuilt.env.target_onsets
    assert rebuilt.sac.score_input is True
    assert rebuilt == replace(
        TrainConfig(),
        env=replace(TrainConfig().env, tactile_pool=(30, 40), target_velocity=False, target_onsets=False),
        sac=replace(TrainConfig().sac, score_input=True),
    )


def test_committed_models_are_in_the_current_format_and_named_by_their_configuration():
    folders = [d for d in MODELS.iterdir() if d.is_dir()]
    assert folders
    for folder in folders:
        raw = json.loads((folder / store.MANIFEST_FILE).read_text())
        assert raw["format"] == store.FORMAT, folder.name
        config = from_dict(TrainConfig, raw["config"])
        assert folder == store.model_dir(MODELS, raw["key"], config), folder.name  # `train` finds it, and skips it
        names = store.load_tensors(folder / store.POLICY_FILE).keys()
        assert not any(".conv." in name for name in names), folder.name  # every tensor once


def test_cli_defaults_are_the_configuration_defaults():
    """The options that set a configuration field default to that field's default."""
    import typer.main

    from pianobot.cli.app import app

    commands = typer.main.get_command(app).commands
    train = {p.name: p.default for p in commands["train"].params}
    assert train["steps"] == TrainConfig.steps and train["seed"] == TrainConfig.seed
    assert train["explore"] == TrainConfig.explore and train["until_f1"] == TrainConfig.until_f1
    assert train["control"] == WorldConfig.control and train["reward"] == RewardConfig.kind
    assert train["exploration_steps"] == SACConfig.exploration_steps and train["tactile"] == EnvConfig.tactile
    assert train["joints"] == ",".join(EnvConfig.actuated) and train["fingering_gate"] == RewardConfig.fingering_gate
    for command in ("inspect", "finger", "play", "train"):
        options = {p.name: p.default for p in commands[command].params}
        assert options["split"] == pitch_name(LoadOptions.split) and options["transpose"] == LoadOptions.transpose


def test_version_and_score_start_without_torch_or_the_simulator_loop(tmp_path):
    """`pianobot --version` used to take 2.9 s, importing torch and mir_eval for nothing."""
    code = (
        "import sys\n"
        "from typer.testing import CliRunner\n"
        "from pianobot.cli.app import app\n"
        "assert CliRunner().invoke(app, ['--version']).exit_code == 0\n"
        "print(' '.join(m for m in ('torch', 'mir_eval', 'pianobot.learn.train', 'pianobot.agent.sac') if m in sys.modules))\n"
    )
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert loaded == ""
