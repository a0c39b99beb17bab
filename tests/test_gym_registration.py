"""The gymnasium ids: every spec says how long an episode runs at most, and pianobot/Piano-v1
reads a piece from a path (issue 36, item 5)."""

from pathlib import Path

import gymnasium
import numpy as np
import pytest

import pianobot
from pianobot.env import DEFAULT_STEPS, LONGEST_BEATS, env_id
from pianobot.errors import PianobotError
from pianobot.music.tasks import BPM, TASKS, make_task

SONG = Path(__file__).parent.parent / "examples" / "midi" / "twinkle.mid"
QUIET = pianobot.EnvConfig(tactile=False)


def test_the_registered_figures_are_the_environments():
    config = pianobot.EnvConfig()
    assert DEFAULT_STEPS == {"control_hz": config.world.control_hz, "lead_in": config.lead_in, "tail": config.tail}
    rng = np.random.default_rng(0)
    for task in TASKS:
        longest = max(make_task(task, rng).duration for _ in range(300))
        assert longest == pytest.approx(LONGEST_BEATS[task] * 60.0 / BPM), task


def test_every_id_has_max_episode_steps_and_an_episode_ends_there():
    ids = ["pianobot/Piano-v1"] + [env_id(task) for task in TASKS]
    assert all(isinstance(gymnasium.spec(i).max_episode_steps, int) for i in ids)
    env = gymnasium.make("pianobot/OneNote-v1", config=QUIET)
    assert env.spec.max_episode_steps == 45
    env.reset(seed=0)
    steps, done = 0, False
    while not done:
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        steps, done = steps + 1, terminated or truncated
    assert steps == env.spec.max_episode_steps == env.unwrapped.horizon
    env.close()
    six = gymnasium.make("pianobot/SixNote-v1", config=QUIET)
    six.reset(seed=1)
    assert six.unwrapped.horizon == six.spec.max_episode_steps == 20 + 125  # lead-in, six seconds and the tail
    six.close()


def test_a_path_is_read_where_a_piece_is(tmp_path):
    env = gymnasium.make("pianobot/Piano-v1", piece=str(SONG), config=QUIET)
    assert env.unwrapped.piece == pianobot.load_piece(SONG)
    assert env.unwrapped.horizon <= env.spec.max_episode_steps
    env.close()
    with pytest.raises(PianobotError, match="no such file"):
        gymnasium.make("pianobot/Piano-v1", piece=tmp_path / "missing.mid")


def test_a_config_with_longer_episodes_warns_with_the_number():
    with pytest.warns(UserWarning, match="up to 65 steps.*max_episode_steps=65"):
        env = gymnasium.make("pianobot/OneNote-v1", config=pianobot.EnvConfig(tactile=False, lead_in=2.0))
    env.close()
    with pytest.warns(UserWarning, match="unless you gave it"):  # (the entry point cannot see it was given)
        env = gymnasium.make(
            "pianobot/OneNote-v1", config=pianobot.EnvConfig(tactile=False, lead_in=2.0), max_episode_steps=65
        )
    assert env.spec.max_episode_steps == 65
    env.close()


def test_every_id_the_api_page_names_is_registered_with_its_steps():
    """docs/api.md names ids a user can pass to gymnasium.make, and their max_episode_steps."""
    import re

    text = (Path(__file__).parent.parent / "docs" / "api.md").read_text()
    named = re.findall(r"`(?:pianobot/)?([A-Z]\w+-v\d+)`", text)
    assert {"OneNote-v1", "SixNote-v1", "Piano-v1"} <= set(named)
    for name in named:
        assert f"pianobot/{name}" in gymnasium.registry, name
    for steps, name in re.findall(r"(\d+) (?:steps )?for `(\w+-v\d+)`", text):
        assert gymnasium.spec(f"pianobot/{name}").max_episode_steps == int(steps), name
