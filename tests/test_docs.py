"""The examples in docs/api.md run as written (one namespace, in order, from the repository's root)."""

import os
import re
from pathlib import Path

ROOT = Path(__file__).parent.parent


def test_the_api_page_examples_run_each_on_its_own(capsys):
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "api.md").read_text(), re.S)
    assert len(blocks) >= 5
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        namespaces = []
        for block in blocks:  # each in a fresh namespace: it runs pasted alone
            namespaces.append({})
            exec(compile(block, "docs/api.md", "exec"), namespaces[-1])
    finally:
        os.chdir(here)
    printed = capsys.readouterr().out
    assert "14 notes" in printed and "note F1 1.00" in printed  # twinkle; its committed phrase policy plays
    perform = next(n for n in namespaces if "performance" in n)
    assert perform["report"].f1 >= 0.95 and perform["performance"].plan.performer == "general policy"
    assert "own policies ['own policy', 'own policy', 'own policy']" in printed


def test_the_model_format_page_runs_a_policy_as_pianobot_does():
    """docs/models.md's torch-only reader acts exactly as pianobot's loaded policy, on a tactile
    policy (every tensor kind) from several hand starts and steps."""
    import numpy as np

    import pianobot

    source = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "models.md").read_text(), re.S)
    namespace: dict = {}
    exec(compile(source[-1], "docs/models.md", "exec"), namespace)
    piece = pianobot.load_piece(ROOT / "examples" / "midi" / "twinkle.mid")
    phrase = pianobot.split_phrases(piece)[0]
    folder = next((ROOT / "models").glob(f"{phrase.hash}-*"))
    env_config, _ = pianobot.policy_configs(folder)
    assert env_config.tactile
    env = pianobot.PianoEnv(piece=phrase.piece(), config=env_config)
    policy = pianobot.load_policy(folder, env)
    for seed in (0, 1):
        observation, _ = env.reset(seed=seed)
        for _ in range(25):
            ours, theirs = policy.act(observation), namespace["act"](folder, observation)
            assert np.allclose(ours, theirs, atol=1e-6), (ours, theirs)
            observation, *_ = env.step(ours)
    env.close()


def test_the_model_format_page_runs_a_finger_shared_policy_as_pianobot_does(tmp_path):
    """The same reader on a policy with the 'fingers' actor (trained briefly here), two joints a finger."""
    from dataclasses import replace

    import numpy as np

    import pianobot
    from pianobot.agent.config import SACConfig
    from pianobot.env.piano import EnvConfig
    from pianobot.learn.config import DaggerConfig, TrainConfig
    from pianobot.learn.dagger import dagger_policy

    source = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "models.md").read_text(), re.S)
    namespace: dict = {}
    exec(compile(source[-1], "docs/models.md", "exec"), namespace)
    phrase = pianobot.Piece((pianobot.Note(0.0, 64, 0.5, 80, 3),), bpm=60)
    sac = SACConfig(hidden=16, actor="fingers")
    config = TrainConfig(
        learner="dagger",
        steps=70,
        eval_episodes=1,
        sac=sac,
        dagger=DaggerConfig(round_steps=70, batch_size=16),
        env=EnvConfig(tactile=False, actuated=("mcp", "pip")),
    )
    for name, run in (("plain", config), ("score", replace(config, sac=replace(sac, score_input=True)))):
        dagger_policy(phrase, run, tmp_path / name)
        env = pianobot.PianoEnv(piece=phrase, config=run.env)
        policy = pianobot.load_policy(tmp_path / name, env)
        observation, _ = env.reset(seed=0)
        for _ in range(10):
            ours, theirs = policy.act(observation), namespace["act"](tmp_path / name, observation)
            assert ours.shape == (7,) and np.allclose(ours, theirs, atol=1e-6), (ours, theirs)
            observation, *_ = env.step(ours)
        env.close()


def test_the_api_page_says_which_hand_plays_both_hands():
    """`pianobot.play` of a two-hand piece plays the Allegro-like hand unless `hand=` names another,
    where `pianobot play` gives a two-hand file to the pianist's hands: the page says so, and the call
    it gives for the pianist's hands plays them."""
    import pianobot
    from pianobot.sim.hand import default_fingers

    text = " ".join((ROOT / "docs" / "api.md").read_text().split())
    assert 'hand=pianobot.sim.hand.default_fingers("pianist")' in text and "Allegro-like hand by default" in text
    duet = pianobot.load_two_hands(ROOT / "examples" / "midi" / "ode-to-joy-performed.mid")
    for hand, model in ((None, "allegro"), (default_fingers("pianist"), "pianist")):
        played = pianobot.play(duet, controller="scripted", hand=hand).to_dict()
        assert {h["hand_model"] for h in played["hands"].values()} == {model}
